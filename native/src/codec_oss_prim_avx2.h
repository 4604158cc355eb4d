/*
 * AVX2 + FMA3 primitives of the OSS batch drivers (codec_oss_simd.h, codec_oss_wide_simd.h;
 * included by codec_oss_batch_avx2.c only): four double lanes (eight float / int32 lanes for
 * narrow decode), masks as all-ones lanes, the AoS weights moved with shuffles, permutes and
 * blends.
 */
#ifndef SKINPACK_CODEC_OSS_PRIM_AVX2_H
#define SKINPACK_CODEC_OSS_PRIM_AVX2_H

#include "codec_internal.h"

#if SP_X86_SIMD
#include <immintrin.h>
#include <string.h>

SP_FP_CONTRACT_OFF
#define SIMD_FN SP_TARGET("avx2,fma")
#define SIMD_NAME(name) sp_oss_##name##_avx2
#define BLOCK 4
#define ENCODE_CHUNK 16 /* K = 3 encode ~3% faster than 8 */
#define ENCODE_FUSED 0 /* in one stage K = 4 encode spills and runs ~25% slower (encode_fused) */
#define DECODE_CHUNK 16 /* K = 4 decode ~10% faster than with 8; 32 no faster */

typedef __m256d vec;
typedef __m256d mask;
typedef __m128 root;
/* stream: the decode's weights go by streaming stores (put4, put8; codec_oss_simd.h). */
typedef struct simd_layout {
    int stream;
} simd_layout;

SP_INLINE SIMD_FN vec v_splat(double x) { return _mm256_set1_pd(x); }
SP_INLINE SIMD_FN vec v_zero(void) { return _mm256_setzero_pd(); }
SP_INLINE SIMD_FN vec v_add(vec a, vec b) { return _mm256_add_pd(a, b); }
SP_INLINE SIMD_FN vec v_sub(vec a, vec b) { return _mm256_sub_pd(a, b); }
SP_INLINE SIMD_FN vec v_mul(vec a, vec b) { return _mm256_mul_pd(a, b); }
SP_INLINE SIMD_FN vec v_div(vec a, vec b) { return _mm256_div_pd(a, b); }
SP_INLINE SIMD_FN vec v_sqrt(vec a) { return _mm256_sqrt_pd(a); }
SP_INLINE SIMD_FN vec v_max(vec a, vec b) { return _mm256_max_pd(a, b); }
SP_INLINE SIMD_FN vec v_min(vec a, vec b) { return _mm256_min_pd(a, b); }
SP_INLINE SIMD_FN vec v_floor(vec a) { return _mm256_floor_pd(a); }
SP_INLINE SIMD_FN vec v_trunc(vec a) { return _mm256_round_pd(a, _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC); }
SP_INLINE SIMD_FN vec v_fmadd(vec a, vec b, vec c) { return _mm256_fmadd_pd(a, b, c); }
SP_INLINE SIMD_FN vec v_fnmadd(vec a, vec b, vec c) { return _mm256_fnmadd_pd(a, b, c); }
SP_INLINE SIMD_FN vec v_fmsub(vec a, vec b, vec c) { return _mm256_fmsub_pd(a, b, c); }
SP_INLINE SIMD_FN mask m_ge(vec a, vec b) { return _mm256_cmp_pd(a, b, _CMP_GE_OQ); }
SP_INLINE SIMD_FN mask m_gt(vec a, vec b) { return _mm256_cmp_pd(a, b, _CMP_GT_OQ); }
SP_INLINE SIMD_FN mask m_lt(vec a, vec b) { return _mm256_cmp_pd(a, b, _CMP_LT_OQ); }
SP_INLINE SIMD_FN mask m_and(mask a, mask b) { return _mm256_and_pd(a, b); }
SP_INLINE SIMD_FN unsigned m_bits(mask a) { return (unsigned)_mm256_movemask_pd(a); }
SP_INLINE SIMD_FN vec v_add_where(vec x, mask m, vec y) { return _mm256_add_pd(x, _mm256_and_pd(m, y)); }

/* Counters as the doubles 2^52 + c, stepped by integer arithmetic on their bits with the all-ones
 * mask lanes (-1): one instruction a step, where v_add_where takes two. The rounding's compares
 * run on the bits too, as 64-bit integers: vpcmpgtq runs on any of the four vector pipes, a double
 * compare on the two that also take every addition, floor and conversion of the encode (~3% faster
 * for K = 4). For doubles in [2^52, 2^53) the bits are those of 2^52 plus the integer, and
 * non-negative doubles order as their bits. */
#define COUNTER_BIAS 4503599627370496.0 /* 2^52 */
typedef __m256d counter;
SP_INLINE SIMD_FN counter c_splat(uint32_t c) { return v_splat(COUNTER_BIAS + c); }
SP_INLINE SIMD_FN counter c_inc_where(counter c, mask m)
{
    return _mm256_castsi256_pd(_mm256_sub_epi64(_mm256_castpd_si256(c), _mm256_castpd_si256(m)));
}
SP_INLINE SIMD_FN counter c_dec_where(counter c, mask m)
{
    return _mm256_castsi256_pd(_mm256_add_epi64(_mm256_castpd_si256(c), _mm256_castpd_si256(m)));
}
SP_INLINE SIMD_FN mask c_below(counter c, vec threshold)
{
    return _mm256_castsi256_pd(_mm256_cmpgt_epi64(_mm256_castpd_si256(threshold), _mm256_castpd_si256(c)));
}
/* Each slot starts beaten by every earlier one, and a later slot b that beats a (a larger
 * remainder: the one compare without a negation) takes that back and beats a instead. */
SP_INLINE SIMD_FN counter rank_start(uint32_t i, uint32_t k)
{
    (void)k;
    return c_splat(i);
}
SP_INLINE SIMD_FN void rank_pair(vec ra, vec rb, counter* rank_a, counter* rank_b)
{
    mask b_wins = _mm256_castsi256_pd(_mm256_cmpgt_epi64(_mm256_castpd_si256(rb), _mm256_castpd_si256(ra)));
    *rank_a = c_inc_where(*rank_a, b_wins);
    *rank_b = c_dec_where(*rank_b, b_wins);
}

/* 0 <= d < k for t = 2^52 + d. K = 4: t's bits less those of 2^52 (a multiple of 4) in [0, 4),
 * that is, the bits shifted right by two equal those of 2^52 so shifted (no double below 2^52
 * nor past 2^52 + 3, NaN included, has them), one shift and one compare where the two bounds'
 * compares take three operations. */
SP_INLINE SIMD_FN mask c_deficit_fits(vec threshold, uint32_t k)
{
    if (k != 4) return m_and(m_ge(threshold, v_splat(COUNTER_BIAS)), m_lt(threshold, v_splat(COUNTER_BIAS + k)));
    __m256i top = _mm256_srli_epi64(_mm256_castpd_si256(threshold), 2);
    return _mm256_castsi256_pd(_mm256_cmpeq_epi64(top, _mm256_srli_epi64(_mm256_castpd_si256(v_splat(COUNTER_BIAS)), 2)));
}

/* Eight float or int32 lanes for decode in 32-bit lanes. */
#define NBLOCK 8
#define NARROW_CHUNK 16 /* blocks a stage: K = 3, 4 ~5% faster than 8; 32 no faster */
typedef __m256 nvec;
typedef __m256i nint;
typedef __m256i nmask;
SP_INLINE SIMD_FN nvec f_splat(float x) { return _mm256_set1_ps(x); }
SP_INLINE SIMD_FN nvec f_add(nvec a, nvec b) { return _mm256_add_ps(a, b); }
SP_INLINE SIMD_FN nvec f_sub(nvec a, nvec b) { return _mm256_sub_ps(a, b); }
SP_INLINE SIMD_FN nvec f_mul(nvec a, nvec b) { return _mm256_mul_ps(a, b); }
SP_INLINE SIMD_FN nvec f_sqrt(nvec a) { return _mm256_sqrt_ps(a); }
SP_INLINE SIMD_FN nvec f_fmadd(nvec a, nvec b, nvec c) { return _mm256_fmadd_ps(a, b, c); }
SP_INLINE SIMD_FN nvec f_fnmadd(nvec a, nvec b, nvec c) { return _mm256_fnmadd_ps(a, b, c); }
SP_INLINE SIMD_FN nint i_splat(int32_t x) { return _mm256_set1_epi32(x); }
SP_INLINE SIMD_FN nint i_add(nint a, nint b) { return _mm256_add_epi32(a, b); }
SP_INLINE SIMD_FN nint i_sub(nint a, nint b) { return _mm256_sub_epi32(a, b); }
SP_INLINE SIMD_FN nint i_mullo(nint a, nint b) { return _mm256_mullo_epi32(a, b); }
SP_INLINE SIMD_FN nint i_max(nint a, nint b) { return _mm256_max_epi32(a, b); }
SP_INLINE SIMD_FN nint i_min(nint a, nint b) { return _mm256_min_epi32(a, b); }
SP_INLINE SIMD_FN nint i_shr2(nint a) { return _mm256_srai_epi32(a, 2); }
SP_INLINE SIMD_FN nmask i_gt(nint a, nint b) { return _mm256_cmpgt_epi32(a, b); }
SP_INLINE SIMD_FN nmask n_or(nmask a, nmask b) { return _mm256_or_si256(a, b); }
SP_INLINE SIMD_FN unsigned n_bits(nmask a) { return (unsigned)_mm256_movemask_ps(_mm256_castsi256_ps(a)); }
SP_INLINE SIMD_FN nvec i_to_f(nint a) { return _mm256_cvtepi32_ps(a); }
SP_INLINE SIMD_FN nint i_trunc(nvec a) { return _mm256_cvttps_epi32(a); } /* NaN and overflow: INT32_MIN */
SP_INLINE SIMD_FN nint f_as_i(nvec a) { return _mm256_castps_si256(a); }
SP_INLINE SIMD_FN nvec i_as_f(nint a) { return _mm256_castsi256_ps(a); }
SP_INLINE SIMD_FN nint i_shr1(nint a) { return _mm256_srai_epi32(a, 1); }
SP_INLINE SIMD_FN nint i_add_where(nint a, nmask m, nint b) { return _mm256_add_epi32(a, _mm256_and_si256(m, b)); }
SP_INLINE SIMD_FN nint i_sub_where(nint a, nmask m, nint b) { return _mm256_sub_epi32(a, _mm256_and_si256(m, b)); }
/* Two blocks of double lanes as NBLOCK int32 (integral, in range) or floats (rounded). */
SP_INLINE SIMD_FN nint i_from_pair(vec a, vec b) { return _mm256_set_m128i(_mm256_cvttpd_epi32(b), _mm256_cvttpd_epi32(a)); }
SP_INLINE SIMD_FN nvec f_from_pair(vec a, vec b) { return _mm256_set_m128(_mm256_cvtpd_ps(b), _mm256_cvtpd_ps(a)); }
/* The low 32 bits of each lane of two blocks (as bits), as NBLOCK int32 lanes in order. */
SP_INLINE SIMD_FN nint i_low_pair(vec a, vec b)
{
    __m256i low = _mm256_castps_si256(_mm256_shuffle_ps(_mm256_castpd_ps(a), _mm256_castpd_ps(b), 0x88)); /* 0 1 4 5 | 2 3 6 7 */
    return _mm256_permute4x64_epi64(low, 0xD8);
}
/* The inverse for int32: NBLOCK int32 lanes as two blocks of doubles (exact). */
SP_INLINE SIMD_FN void v_from_i_pair(nint a, vec* first, vec* second)
{
    *first = _mm256_cvtepi32_pd(_mm256_castsi256_si128(a));
    *second = _mm256_cvtepi32_pd(_mm256_extracti128_si256(a, 1));
}

/* floor(a / 9) = floor(a m / 2^33) with m = (2^33 + 1) / 9 for 0 <= a < 2^33 (the error
 * a / (9 2^33) stays below 1/9), on the even and the odd lanes' 64-bit products. */
SP_INLINE SIMD_FN nint i_div9(nint a)
{
    __m256i m = _mm256_set1_epi32(954437177);
    __m256i even = _mm256_srli_epi64(_mm256_mul_epu32(a, m), 33);
    __m256i odd = _mm256_srli_epi64(_mm256_mul_epu32(_mm256_srli_epi64(a, 32), m), 1); /* quotient in the high half */
    return _mm256_blend_epi32(even, odd, 0xAA);
}

SP_INLINE SIMD_FN simd_layout layout_for(uint32_t k)
{
    simd_layout layout = {0};
    (void)k;
    return layout;
}

/* Component i of four consecutive vertices of k weights, widened to double (exact). */
SP_INLINE SIMD_FN void load_weights(const float* w, uint32_t k, const simd_layout* layout, vec* x)
{
    (void)layout;
    if (k == 4) { /* two 8-float loads, two unpacks and two permutes: components 0 | 1 and 2 | 3 */
        __m256 v01 = _mm256_loadu_ps(w), v23 = _mm256_loadu_ps(w + 8);
        __m256i order = _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7); /* (v0 v2 v0 v2 | v1 v3 v1 v3) -> v0 v1 v2 v3 */
        __m256 c01 = _mm256_permutevar8x32_ps(_mm256_unpacklo_ps(v01, v23), order);
        __m256 c23 = _mm256_permutevar8x32_ps(_mm256_unpackhi_ps(v01, v23), order);
        x[0] = _mm256_cvtps_pd(_mm256_castps256_ps128(c01));
        x[1] = _mm256_cvtps_pd(_mm256_extractf128_ps(c01, 1));
        x[2] = _mm256_cvtps_pd(_mm256_castps256_ps128(c23));
        x[3] = _mm256_cvtps_pd(_mm256_extractf128_ps(c23, 1));
        return;
    }
    if (k == 3) { /* store_floats' blends and permutes backwards */
        __m128 a0 = _mm_loadu_ps(w), a1 = _mm_loadu_ps(w + 4), a2 = _mm_loadu_ps(w + 8);
        __m128 p0 = _mm_blend_ps(_mm_blend_ps(a0, a2, 0x2), a1, 0x4); /* component 0 of vertices 0 3 2 1 */
        __m128 p1 = _mm_blend_ps(_mm_blend_ps(a1, a0, 0x2), a2, 0x4); /* 1 0 3 2 */
        __m128 p2 = _mm_blend_ps(_mm_blend_ps(a2, a1, 0x2), a0, 0x4); /* 2 1 0 3 */
        x[0] = _mm256_cvtps_pd(_mm_permute_ps(p0, _MM_SHUFFLE(1, 2, 3, 0)));
        x[1] = _mm256_cvtps_pd(_mm_permute_ps(p1, _MM_SHUFFLE(2, 3, 0, 1)));
        x[2] = _mm256_cvtps_pd(_mm_permute_ps(p2, _MM_SHUFFLE(3, 0, 1, 2)));
        return;
    }
    SP_UNROLL
    for (uint32_t i = 0; i < k; ++i) x[i] = _mm256_cvtps_pd(_mm_setr_ps(w[i], w[k + i], w[2 * k + i], w[3 * k + i]));
}

/*
 * K = 4's load_weights and weights_ordered in fewer vector operations (the encode's first stage
 * is bound by them, on the three vector ports): the 4x4 transpose in float lanes, as components
 * 0 | 2 and 1 | 3 (two shuffles of the even and odd floats, two permutes), goes to memory and
 * each component comes back widened by a load-and-convert, which runs on a load port and one
 * vector port where the register form takes a shuffle port too and an extract before it; the
 * sorted check runs on the float lanes (the same compares as on the doubles they widen to: -0,
 * NaN alike), components 0 | 2 against 1 | 3 and 1 | 3 against 2 | 0, two compares for four and
 * one permute for their operands (components 0 | 1 and 2 | 3 took two).
 */
#define LOAD_ORDERED 1
SP_INLINE SIMD_FN unsigned load_weights_ordered(const float* w, vec* x)
{
    __m256 v01 = _mm256_loadu_ps(w), v23 = _mm256_loadu_ps(w + 8);
    __m256i order = _mm256_setr_epi32(0, 4, 2, 6, 1, 5, 3, 7); /* (v0 v0 v2 v2 | v1 v1 v3 v3) -> v0 v1 v2 v3 */
    __m256 c02 = _mm256_permutevar8x32_ps(_mm256_shuffle_ps(v01, v23, 0x88), order);
    __m256 c13 = _mm256_permutevar8x32_ps(_mm256_shuffle_ps(v01, v23, 0xDD), order);
    _Alignas(32) float soa[16];
    _mm256_store_ps(soa, c02);
    _mm256_store_ps(soa + 8, c13);
    SP_FORGET(soa); /* else the compiler forwards the stores to register extracts */
    SP_UNROLL
    for (uint32_t i = 0; i < 4; ++i) x[i] = _mm256_cvtps_pd(_mm_load_ps(soa + 8 * (i % 2) + 4 * (i / 2)));
    __m256 next = _mm256_permute2f128_ps(c02, c02, 0x81); /* 2 | 0 */
    __m256 ok = _mm256_and_ps(_mm256_cmp_ps(c02, c13, _CMP_GE_OQ), _mm256_cmp_ps(c13, next, _CMP_GE_OQ));
    unsigned bits = (unsigned)_mm256_movemask_ps(ok); /* vertex v: bit v (w0 >= w1, w1 >= w2), bit v + 4 (w2 >= w3, w3 >= 0) */
    return bits & (bits >> 4) & 15u;
}

/*
 * The weights' stores, streaming (non-temporal) ones where layout->stream: they write whole
 * lines to memory through the write-combining buffers, with no read for ownership of each line
 * first and without evicting the caches. Streaming stores need aligned addresses: p is 16-byte
 * aligned there (the decode entry streams only from such a start, and every store of these
 * primitives lies a multiple of 16 bytes past it), put8's 32-byte half-way ones go as two.
 */
#define STREAM_ALIGN 16

SP_INLINE SIMD_FN void put4(const simd_layout* layout, float* p, __m128 v)
{
    if (layout->stream) _mm_stream_ps(p, v);
    else _mm_storeu_ps(p, v);
}

SP_INLINE SIMD_FN void put8(const simd_layout* layout, float* p, __m256 v)
{
    if (!layout->stream) _mm256_storeu_ps(p, v);
    else if (!((uintptr_t)p & 31)) _mm256_stream_ps(p, v);
    else {
        _mm_stream_ps(p, _mm256_castps256_ps128(v));
        _mm_stream_ps(p + 4, _mm256_extractf128_ps(v, 1));
    }
}

/* Four vertices of k floats from k component vectors: transposes by shuffles and blends. */
SP_INLINE SIMD_FN void store_floats(const __m128* w, uint32_t k, const simd_layout* layout, float* out)
{
    if (k == 4) { /* a 4x4 transpose in two registers: six shuffles, not eight, and two stores */
        __m256 even = _mm256_insertf128_ps(_mm256_castps128_ps256(w[0]), w[2], 1); /* components 0 | 2 */
        __m256 odd = _mm256_insertf128_ps(_mm256_castps128_ps256(w[1]), w[3], 1);  /* components 1 | 3 */
        /* pairs (c0, c1) of vertices 0, 1 | (c2, c3) of vertices 0, 1, then the same for 2, 3 */
        __m256d lo = _mm256_castps_pd(_mm256_unpacklo_ps(even, odd)), hi = _mm256_castps_pd(_mm256_unpackhi_ps(even, odd));
        put8(layout, out, _mm256_castpd_ps(_mm256_permute4x64_pd(lo, 0xD8)));     /* vertices 0, 1 */
        put8(layout, out + 8, _mm256_castpd_ps(_mm256_permute4x64_pd(hi, 0xD8))); /* vertices 2, 3 */
    } else if (k == 3) {
        /* Output float f holds component f % 3 of vertex f / 3. Each component is permuted once
         * so that, in each of the three output vectors, the lanes it owns hold the right vertex
         * (component 0 owns lanes 0, 3 of the first vector, 2 of the second, 1 of the third:
         * vertices 0, 1 | 2 | 3), and blends pick the owner of each lane. */
        __m128 p0 = _mm_permute_ps(w[0], _MM_SHUFFLE(1, 2, 3, 0)); /* vertices 0 3 2 1 */
        __m128 p1 = _mm_permute_ps(w[1], _MM_SHUFFLE(2, 3, 0, 1)); /* 1 0 3 2 */
        __m128 p2 = _mm_permute_ps(w[2], _MM_SHUFFLE(3, 0, 1, 2)); /* 2 1 0 3 */
        put4(layout, out, _mm_blend_ps(_mm_blend_ps(p0, p1, 0x2), p2, 0x4));
        put4(layout, out + 4, _mm_blend_ps(_mm_blend_ps(p1, p2, 0x2), p0, 0x4));
        put4(layout, out + 8, _mm_blend_ps(_mm_blend_ps(p2, p0, 0x2), p1, 0x4));
    } else {
        put4(layout, out, _mm_unpacklo_ps(w[0], w[1]));
        put4(layout, out + 4, _mm_unpackhi_ps(w[0], w[1]));
    }
}

/* (float)(q * (1/s)) per component, as sp_grid_to_weights does, stored as four vertices. */
SP_INLINE SIMD_FN void store_weights(const vec* q, uint32_t k, double inverse, const simd_layout* layout, float* out)
{
    __m128 w[SP_MAX_INFLUENCES];
    SP_UNROLL
    for (uint32_t i = 0; i < k; ++i) w[i] = _mm256_cvtpd_ps(_mm256_mul_pd(q[i], v_splat(inverse)));
    store_floats(w, k, layout, out);
}

/* Codes <= max_code, compared unsigned as signed with the sign bits flipped: 64-bit lanes, or
 * for max_code < 2^31 zero high halves and low halves in 32-bit lanes; the lanes past it or-ed
 * together. */
typedef struct code_check {
    __m256i over, top64, top32;
} code_check;

SP_INLINE SIMD_FN code_check check_start(uint64_t max_code)
{
    code_check check = {_mm256_setzero_si256(), _mm256_set1_epi64x((int64_t)(max_code ^ (uint64_t)INT64_MIN)),
                        _mm256_set1_epi32((int32_t)((uint32_t)max_code ^ 0x80000000u))};
    return check;
}

SP_INLINE SIMD_FN int check_passed(const code_check* check) { return _mm256_testz_si256(check->over, check->over); }

/* The low halves of eight codes, in order. */
SP_INLINE SIMD_FN nint load_codes32(const uint64_t* codes, code_check* check)
{
    __m256 a = _mm256_loadu_ps((const float*)codes), b = _mm256_loadu_ps((const float*)(codes + 4));
    __m256i low = _mm256_castps_si256(_mm256_shuffle_ps(a, b, 0x88)); /* codes 0 1 4 5 | 2 3 6 7 */
    __m256i high = _mm256_castps_si256(_mm256_shuffle_ps(a, b, 0xDD));
    __m256i past = _mm256_cmpgt_epi32(_mm256_xor_si256(low, _mm256_set1_epi32(INT32_MIN)), check->top32);
    check->over = _mm256_or_si256(check->over, _mm256_or_si256(high, past));
    return _mm256_permute4x64_epi64(low, 0xD8);
}

/* Eight vertices of k floats from k component vectors (store_floats on eight lanes). */
SP_INLINE SIMD_FN void store_floats8(const __m256* w, uint32_t k, const simd_layout* layout, float* out)
{
    if (k == 4) {
        __m256 t0 = _mm256_unpacklo_ps(w[0], w[1]), t1 = _mm256_unpackhi_ps(w[0], w[1]); /* c0 c1 of v0 v1 | v4 v5 ... */
        __m256 t2 = _mm256_unpacklo_ps(w[2], w[3]), t3 = _mm256_unpackhi_ps(w[2], w[3]);
        __m256 v04 = _mm256_shuffle_ps(t0, t2, 0x44), v15 = _mm256_shuffle_ps(t0, t2, 0xEE); /* vertex 0 | 4, 1 | 5 */
        __m256 v26 = _mm256_shuffle_ps(t1, t3, 0x44), v37 = _mm256_shuffle_ps(t1, t3, 0xEE);
        put8(layout, out, _mm256_permute2f128_ps(v04, v15, 0x20));
        put8(layout, out + 8, _mm256_permute2f128_ps(v26, v37, 0x20));
        put8(layout, out + 16, _mm256_permute2f128_ps(v04, v15, 0x31));
        put8(layout, out + 24, _mm256_permute2f128_ps(v26, v37, 0x31));
    } else if (k == 3) { /* as store_floats: component c owns lanes f = c (mod 3) of the three outputs */
        __m256 p0 = _mm256_permutevar8x32_ps(w[0], _mm256_setr_epi32(0, 3, 6, 1, 4, 7, 2, 5));
        __m256 p1 = _mm256_permutevar8x32_ps(w[1], _mm256_setr_epi32(5, 0, 3, 6, 1, 4, 7, 2));
        __m256 p2 = _mm256_permutevar8x32_ps(w[2], _mm256_setr_epi32(2, 5, 0, 3, 6, 1, 4, 7));
        put8(layout, out, _mm256_blend_ps(_mm256_blend_ps(p0, p1, 0x92), p2, 0x24));
        put8(layout, out + 8, _mm256_blend_ps(_mm256_blend_ps(p0, p1, 0x24), p2, 0x49));
        put8(layout, out + 16, _mm256_blend_ps(_mm256_blend_ps(p0, p1, 0x49), p2, 0x92));
    } else {
        __m256 lo = _mm256_unpacklo_ps(w[0], w[1]), hi = _mm256_unpackhi_ps(w[0], w[1]); /* v0 v1 | v4 v5, v2 v3 | v6 v7 */
        put8(layout, out, _mm256_permute2f128_ps(lo, hi, 0x20));
        put8(layout, out + 8, _mm256_permute2f128_ps(lo, hi, 0x31));
    }
}

/* store_weights of two blocks, one after the other: K = 3 as eight vertices (store_floats8
 * takes fewer shuffles than two store_floats), K = 2, 4 as two blocks. */
SP_INLINE SIMD_FN void store_pair(const vec* first, const vec* second, uint32_t k, double inverse,
                                  const simd_layout* layout, float* out)
{
    if (k != 3) {
        store_weights(first, k, inverse, layout, out);
        store_weights(second, k, inverse, layout, out + BLOCK * k);
        return;
    }
    __m256 w[3];
    SP_UNROLL
    for (uint32_t i = 0; i < 3; ++i)
        w[i] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm256_cvtpd_ps(_mm256_mul_pd(first[i], v_splat(inverse)))),
                                    _mm256_cvtpd_ps(_mm256_mul_pd(second[i], v_splat(inverse))), 1);
    store_floats8(w, 3, layout, out);
}

/*
 * store_weights of eight vertices from int32 components 0 <= q <= s < 2^24, in float lanes:
 * (float)(q * (1/s)) in double is the correctly rounded q/s here (its error, below 2^-52
 * relative, is smaller than the distance 1/(s M) >= 2^-48 of q/s from any float midpoint
 * M 2^-t, M < 2^25, and q/s is no midpoint itself), and so is Markstein's correction of
 * y = q r, r = 1/s in float: y + r (q - s y), the residual exact by FMA. test_batch checks it
 * for every q <= s of every N the 32-bit lanes take.
 */
SP_INLINE SIMD_FN void store_weights32(const nint* q, uint32_t k, double scale, const simd_layout* layout, float* out)
{
    __m256 w[SP_MAX_INFLUENCES], s = _mm256_set1_ps((float)scale), r = _mm256_set1_ps(1.0f / (float)scale);
    SP_UNROLL
    for (uint32_t i = 0; i < k; ++i) {
        __m256 x = _mm256_cvtepi32_ps(q[i]), y = _mm256_mul_ps(x, r);
        w[i] = _mm256_fmadd_ps(_mm256_fnmadd_ps(y, s, x), r, y);
    }
    store_floats8(w, k, layout, out);
}

/* store_weights32 for 0 <= q <= s < 2^24 by division: the correctly rounded q/s for every such
 * s, which the scalar's double product is too (store_weights32's argument holds for s < 2^24: q/s
 * is no float midpoint and lies at least 2^-49 of itself from every one). Markstein's correction
 * is proven by test_batch only up to the split lanes' s; the divisions also ran the wide lanes
 * ~3% faster than it on AVX2 (Zen 4: off the FMA pipes). */
SP_INLINE SIMD_FN void store_quotients32(const nint* q, uint32_t k, double scale, const simd_layout* layout, float* out)
{
    __m256 w[SP_MAX_INFLUENCES], s = _mm256_set1_ps((float)scale);
    SP_UNROLL
    for (uint32_t i = 0; i < k; ++i) w[i] = _mm256_div_ps(_mm256_cvtepi32_ps(q[i]), s);
    store_floats8(w, k, layout, out);
}

/* u64 < 2^52 <-> double by placing it in the mantissa of 2^52 (AVX2 has no 64-bit conversion);
 * lanes outside that range are garbage, and only lanes the scalar code redoes get there. */
SP_INLINE SIMD_FN vec load_codes(const uint64_t* codes, code_check* check)
{
    __m256d magic = v_splat(4503599627370496.0);
    __m256i raw = _mm256_loadu_si256((const __m256i*)codes);
    check->over = _mm256_or_si256(check->over, _mm256_cmpgt_epi64(_mm256_xor_si256(raw, _mm256_set1_epi64x(INT64_MIN)), check->top64));
    return _mm256_sub_pd(_mm256_castsi256_pd(_mm256_or_si256(raw, _mm256_castpd_si256(magic))), magic);
}

SP_INLINE SIMD_FN void store_codes(uint64_t* codes, vec x)
{
    __m256d magic = v_splat(4503599627370496.0);
    _mm256_storeu_si256((__m256i*)codes,
                        _mm256_xor_si256(_mm256_castpd_si256(_mm256_add_pd(x, magic)), _mm256_castpd_si256(magic)));
}

/* Lanes ROUNDING_MAGIC + code (codec_oss_simd.h: 1.5 2^52 plus an integer of magnitude below
 * 2^51) as the u64 codes: the difference of the bits. */
SP_INLINE SIMD_FN void store_biased_codes(uint64_t* codes, vec x)
{
    _mm256_storeu_si256((__m256i*)codes, _mm256_sub_epi64(_mm256_castpd_si256(x), _mm256_castpd_si256(v_splat(0x1.8p52))));
}

/* Small integral lanes as four bytes. */
SP_INLINE SIMD_FN void store_counts(vec count, uint8_t* out)
{
    __m128i bytes = _mm_shuffle_epi8(_mm256_cvtpd_epi32(count), _mm_setr_epi8(0, 4, 8, 12, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1));
    int32_t packed = _mm_cvtsi128_si32(bytes);
    memcpy(out, &packed, sizeof(packed));
}

SP_INLINE SIMD_FN int codes_valid(const uint64_t* codes, uint64_t max_code)
{
    code_check check = check_start(max_code);
    load_codes(codes, &check);
    return check_passed(&check);
}

/*
 * cbrt(x) + 1/cbrt(x) for the layer estimate without a division or square root (AVX2 has no
 * rcp14 for doubles), through z ~ 1/c: the exponent/3 bit trick for x^(-1/3) (3.4%) and a
 * third-order step z (1 + r/3 + 2r^2/9) with r = 1 - x z^3, in float (~1e-4); then, in double,
 * what a Newton step z' = z (1 + r/3), c' = x z'^2 would give: c' + z' = c + z + r (2c + z) / 3
 * up to r^2 terms (c = x z^2), one FMA after r, to ~1e-8. That puts ~1e-5 of random codes at 22
 * bits (~5e-4 at the largest N) in the wrong layer; the scalar code redoes them.
 */
SP_INLINE SIMD_FN root root_start(vec x)
{
    __m128 xf = _mm256_cvtpd_ps(x);
    __m128i third = _mm_cvttps_epi32(_mm_mul_ps(_mm_cvtepi32_ps(_mm_castps_si128(xf)), _mm_set1_ps(1.0f / 3.0f)));
    __m128 z = _mm_castsi128_ps(_mm_sub_epi32(_mm_set1_epi32(1419916032), third));
    __m128 r = _mm_fnmadd_ps(_mm_mul_ps(xf, z), _mm_mul_ps(z, z), _mm_set1_ps(1.0f)); /* x z and z^2 side by side */
    return _mm_fmadd_ps(_mm_mul_ps(z, r), _mm_fmadd_ps(r, _mm_set1_ps(2.0f / 9.0f), _mm_set1_ps(1.0f / 3.0f)), z);
}

/* root_start of two blocks in one pass of eight float lanes (the same operations, lane by lane). */
SP_INLINE SIMD_FN void root_start_pair(vec a, vec b, root* first, root* second)
{
    __m256 xf = _mm256_set_m128(_mm256_cvtpd_ps(b), _mm256_cvtpd_ps(a));
    __m256i third = _mm256_cvttps_epi32(_mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_castps_si256(xf)), _mm256_set1_ps(1.0f / 3.0f)));
    __m256 z = _mm256_castsi256_ps(_mm256_sub_epi32(_mm256_set1_epi32(1419916032), third));
    __m256 r = _mm256_fnmadd_ps(_mm256_mul_ps(xf, z), _mm256_mul_ps(z, z), _mm256_set1_ps(1.0f));
    __m256 y = _mm256_fmadd_ps(_mm256_mul_ps(z, r), _mm256_fmadd_ps(r, _mm256_set1_ps(2.0f / 9.0f), _mm256_set1_ps(1.0f / 3.0f)), z);
    *first = _mm256_castps256_ps128(y), *second = _mm256_extractf128_ps(y, 1);
}

SP_INLINE SIMD_FN vec root_finish(vec x, root zf)
{
    __m256d z = _mm256_cvtps_pd(zf), xz = _mm256_mul_pd(x, z);
    __m256d r = _mm256_fnmadd_pd(xz, _mm256_mul_pd(z, z), v_splat(1.0));
    __m256d c = _mm256_mul_pd(xz, z);
    __m256d slope = _mm256_fmadd_pd(c, v_splat(2.0 / 3.0), _mm256_mul_pd(z, v_splat(1.0 / 3.0)));
    return _mm256_fmadd_pd(r, slope, _mm256_add_pd(c, z));
}

/* root_finish to third order in r for the wide lanes, whose t reaches 2^24 (root_finish's
 * ~1e-8 is up to 0.3 of t there), without the division of a Newton step: with x z^3 = 1 - r,
 * x^(1/3) = c (1 - r)^(-2/3) = c (1 + 2r/3 + 5r^2/9 + 40r^3/81 + O(r^4)). r stays below ~6e-4
 * after root_start, so that is good to ~1e-13 relative (~1e-6 of t, 3e-7 of a layer: the
 * Newton step's accuracy for every code but those next to a layer start, ~2 rows of the
 * largest layers; a second-order series left ~700); 1/cbrt(x) = z (1 + r/3 + ...) is taken
 * as z, off by r z / 3 <= 2e-4 of t, 2e-10 where t is large (z ~ 1/t). */
SP_INLINE SIMD_FN vec root_finish_fine(vec x, root zf)
{
    __m256d z = _mm256_cvtps_pd(zf), xz = _mm256_mul_pd(x, z);
    __m256d r = _mm256_fnmadd_pd(xz, _mm256_mul_pd(z, z), v_splat(1.0));
    __m256d c = _mm256_mul_pd(xz, z);
    __m256d series = _mm256_fmadd_pd(_mm256_fmadd_pd(r, v_splat(40.0 / 81.0), v_splat(5.0 / 9.0)), r, v_splat(2.0 / 3.0));
    return _mm256_fmadd_pd(_mm256_mul_pd(c, r), series, _mm256_add_pd(c, z));
}

/* The 64-bit integer lanes of the wide driver (codec_oss_wide_simd.h). AVX2 has no 64-bit
 * multiply or unsigned compare: products come from 32-bit pieces (_mm256_mul_epu32), compares
 * are signed ones with the sign bits flipped. */

#define WIDE_NAME(name) sp_oss_wide_##name##_avx2

typedef __m256i uvec;

#define u_srl(a, n) _mm256_srli_epi64(a, n)
#define u_sll(a, n) _mm256_slli_epi64(a, n)
SP_INLINE SIMD_FN uvec u_splat(uint64_t x) { return _mm256_set1_epi64x((int64_t)x); }
SP_INLINE SIMD_FN uvec u_load(const uint64_t* p) { return _mm256_loadu_si256((const __m256i*)p); }
SP_INLINE SIMD_FN void u_store(uint64_t* p, uvec a) { _mm256_storeu_si256((__m256i*)p, a); }
SP_INLINE SIMD_FN uvec u_add(uvec a, uvec b) { return _mm256_add_epi64(a, b); }
SP_INLINE SIMD_FN uvec u_sub(uvec a, uvec b) { return _mm256_sub_epi64(a, b); }
SP_INLINE SIMD_FN uvec u_and(uvec a, uvec b) { return _mm256_and_si256(a, b); }
SP_INLINE SIMD_FN uvec u_mul32(uvec a, uvec b) { return _mm256_mul_epu32(a, b); }
#define WIDE_INTEGER_PRODUCT 0 /* codec_oss_wide_simd.h's wide_product: by FMAs */
SP_INLINE SIMD_FN uvec u_mul(uvec a, uvec b)
{
    uvec cross = u_add(u_mul32(u_srl(a, 32), b), u_mul32(a, u_srl(b, 32)));
    return u_add(u_mul32(a, b), u_sll(cross, 32));
}
SP_INLINE SIMD_FN uvec u_unbias(vec x) /* ROUNDING_MAGIC + m -> m */
{
    return u_sub(_mm256_castpd_si256(x), _mm256_castpd_si256(v_splat(0x1.8p52)));
}

/* Below 2^52 through the mantissa of 2^52, both ways (garbage elsewhere, as load_codes). */
SP_INLINE SIMD_FN vec v_from_u(uvec a)
{
    vec magic = v_splat(0x1p52);
    return _mm256_sub_pd(_mm256_castsi256_pd(_mm256_or_si256(a, _mm256_castpd_si256(magic))), magic);
}

SP_INLINE SIMD_FN uvec u_from_v(vec x)
{
    vec magic = v_splat(0x1p52);
    return _mm256_xor_si256(_mm256_castpd_si256(_mm256_add_pd(x, magic)), _mm256_castpd_si256(magic));
}

/* The two 32-bit halves: the low one in the mantissa of 2^52 (no masking: the blend puts 2^52's
 * high half over it). */
SP_INLINE SIMD_FN void v_halves(uvec a, vec* high, vec* low)
{
    vec magic = v_splat(0x1p52);
    *high = v_from_u(u_srl(a, 32));
    *low = v_sub(_mm256_castsi256_pd(_mm256_blend_epi32(a, _mm256_castpd_si256(magic), 0xAA)), magic);
}

/* Any u64, rounded to nearest: 2^84 + 2^32 hi and 2^52 + lo are exact doubles, so is
 * 2^32 hi - 2^52 (a multiple of 2^32 below 2^64), and the one rounding is the final sum's. */
SP_INLINE SIMD_FN vec v_from_u_rounded(uvec a)
{
    uvec high = _mm256_or_si256(u_srl(a, 32), _mm256_castpd_si256(v_splat(0x1p84)));
    uvec low = _mm256_blend_epi32(a, _mm256_castpd_si256(v_splat(0x1p52)), 0xAA);
    return v_add(v_sub(_mm256_castsi256_pd(high), v_splat(0x1p84 + 0x1p52)), _mm256_castsi256_pd(low));
}

/* K = 2 weights, as sp_grid_to_weights rounds them, stored as four vertices by one interleave
 * (codec_oss_simd.h's store goes through memory for K < 4: for K = 2 slower than the scalar
 * loop). */
SP_INLINE SIMD_FN void store_pairs(vec q0, vec q1, double inverse, const simd_layout* layout, float* out)
{
    __m128 first = _mm256_cvtpd_ps(v_mul(q0, v_splat(inverse))), second = _mm256_cvtpd_ps(v_mul(q1, v_splat(inverse)));
    put4(layout, out, _mm_unpacklo_ps(first, second));
    put4(layout, out + 4, _mm_unpackhi_ps(first, second));
}

/* K = 2 encode past 2^50 grids in double lanes (codec_oss_wide_simd.h's wide_pair_start):
 * the two weights of four vertices as two component vectors (exact), by one permute of the eight
 * floats (store_pairs backwards); the other primitives it needs. */
SP_INLINE SIMD_FN void load_pairs(const float* w, vec* first, vec* second)
{
    __m256 split = _mm256_permutevar8x32_ps(_mm256_loadu_ps(w), _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7));
    *first = _mm256_cvtps_pd(_mm256_castps256_ps128(split));
    *second = _mm256_cvtps_pd(_mm256_extractf128_ps(split, 1));
}
SP_INLINE SIMD_FN mask m_eq(vec a, vec b) { return _mm256_cmp_pd(a, b, _CMP_EQ_OQ); }
SP_INLINE SIMD_FN vec v_keep_where(vec x, mask m) { return _mm256_and_pd(x, m); } /* m ? x : +0 */
/* The double just below x > 0 where m (x elsewhere): its bits less one, by adding the -1 lanes. */
SP_INLINE SIMD_FN vec v_below_where(vec x, mask m)
{
    return _mm256_castsi256_pd(_mm256_add_epi64(_mm256_castpd_si256(x), _mm256_castpd_si256(m)));
}
SP_INLINE SIMD_FN uvec u_bits(vec x) { return _mm256_castpd_si256(x); } /* the bits, as they are */

/* K = 3 weights likewise, as four vertices: components 0, 1 through one permute, 2 through
 * another, blended; then the last vertex and a half the same way. */
SP_INLINE SIMD_FN void store_triples(const vec* q, double inverse, const simd_layout* layout, float* out)
{
    __m128 w0 = _mm256_cvtpd_ps(v_mul(q[0], v_splat(inverse))), w1 = _mm256_cvtpd_ps(v_mul(q[1], v_splat(inverse)));
    __m128 w2 = _mm256_cvtpd_ps(v_mul(q[2], v_splat(inverse)));
    __m256 pairs = _mm256_insertf128_ps(_mm256_castps128_ps256(w0), w1, 1), thirds = _mm256_castps128_ps256(w2);
    __m256 head = _mm256_blend_ps(_mm256_permutevar8x32_ps(pairs, _mm256_setr_epi32(0, 4, 0, 1, 5, 0, 2, 6)),
                                  _mm256_permutevar8x32_ps(thirds, _mm256_setr_epi32(0, 0, 0, 0, 0, 1, 0, 0)), 0x24);
    __m256 tail = _mm256_blend_ps(_mm256_permutevar8x32_ps(pairs, _mm256_setr_epi32(0, 3, 7, 0, 0, 0, 0, 0)),
                                  _mm256_permutevar8x32_ps(thirds, _mm256_setr_epi32(2, 0, 0, 3, 0, 0, 0, 0)), 0x09);
    put8(layout, out, head);
    put4(layout, out + 8, _mm256_castps256_ps128(tail));
}

/* ---- the edge codes (codec_oss_simd.h's edge_decode) ------------------------------------ */

/* u_at_least's bound for n (n - 1, biased: the compare is signed and strict; n >= 1). */
SP_INLINE SIMD_FN uvec u_bound(uint64_t n) { return _mm256_set1_epi64x((int64_t)((n - 1) ^ (uint64_t)INT64_MIN)); }

/* The lanes of a at least n (u_bound(n)), unsigned, as bits. */
SP_INLINE SIMD_FN unsigned u_at_least(uvec a, uvec bound)
{
    __m256i biased = _mm256_xor_si256(a, _mm256_set1_epi64x(INT64_MIN));
    return (unsigned)_mm256_movemask_pd(_mm256_castsi256_pd(_mm256_cmpgt_epi64(biased, bound)));
}

/* The lanes of a set in keep, in order, to the front of out (a whole block written). The
 * permutes come from a table of the 16 lane sets: lane l of the result takes the 32-bit halves
 * 2m, 2m + 1 of the l-th lane kept. */
SP_INLINE SIMD_FN void u_compact(uvec a, unsigned keep, uint64_t* out)
{
    static const int32_t order[16][8] = {
        {0, 1, 0, 1, 0, 1, 0, 1}, {0, 1, 0, 1, 0, 1, 0, 1}, {2, 3, 0, 1, 0, 1, 0, 1}, {0, 1, 2, 3, 0, 1, 0, 1},
        {4, 5, 0, 1, 0, 1, 0, 1}, {0, 1, 4, 5, 0, 1, 0, 1}, {2, 3, 4, 5, 0, 1, 0, 1}, {0, 1, 2, 3, 4, 5, 0, 1},
        {6, 7, 0, 1, 0, 1, 0, 1}, {0, 1, 6, 7, 0, 1, 0, 1}, {2, 3, 6, 7, 0, 1, 0, 1}, {0, 1, 2, 3, 6, 7, 0, 1},
        {4, 5, 6, 7, 0, 1, 0, 1}, {0, 1, 4, 5, 6, 7, 0, 1}, {2, 3, 4, 5, 6, 7, 0, 1}, {0, 1, 2, 3, 4, 5, 6, 7}};
    __m256i permute = _mm256_loadu_si256((const __m256i*)order[keep & 15]);
    _mm256_storeu_si256((__m256i*)out, _mm256_permutevar8x32_epi32(a, permute));
}

/* Four whole rows of k floats, each the first two weights (the doubles' roundings to float) and
 * zeros, permuted from both weights in one register (a's in lanes 0-3, b's in 4-7): K = 4 as the
 * (w0, w1) pairs of vertices 0, 2 | 1, 3, each unpacked with a zero pair; K = 3 into the rows'
 * places (float p is vertex p / 3's weight p % 3), the zeros blended in. */
SP_INLINE SIMD_FN void store_edge_pairs(vec first, vec second, uint32_t k, float* out)
{
    __m128 a = _mm256_cvtpd_ps(first), b = _mm256_cvtpd_ps(second);
    __m256 both = _mm256_insertf128_ps(_mm256_castps128_ps256(a), b, 1), zero = _mm256_setzero_ps();
    if (k == 4) {
        __m256d pairs = _mm256_castps_pd(_mm256_permutevar8x32_ps(both, _mm256_setr_epi32(0, 4, 2, 6, 1, 5, 3, 7)));
        _mm256_storeu_pd((double*)out, _mm256_unpacklo_pd(pairs, _mm256_castps_pd(zero)));       /* vertices 0, 1 */
        _mm256_storeu_pd((double*)(out + 8), _mm256_unpackhi_pd(pairs, _mm256_castps_pd(zero))); /* 2, 3 */
    } else {
        __m256 head = _mm256_permutevar8x32_ps(both, _mm256_setr_epi32(0, 4, 0, 1, 5, 0, 2, 6));
        __m256 tail = _mm256_permutevar8x32_ps(both, _mm256_setr_epi32(0, 3, 7, 0, 0, 0, 0, 0));
        _mm256_storeu_ps(out, _mm256_blend_ps(head, zero, 0x24));
        _mm_storeu_ps(out + 8, _mm256_castps256_ps128(_mm256_blend_ps(tail, zero, 0x09)));
    }
}

/* A block's vertex numbers in 32-bit lanes: 0, 1, ... BLOCK - 1, each BLOCK more, and those
 * kept, in order, to the front of out (a whole block written; the permutes from a table of the
 * 16 lane sets). */
typedef __m128i vertex_lanes;
SP_INLINE SIMD_FN vertex_lanes vertex_numbers(void) { return _mm_setr_epi32(0, 1, 2, 3); }
SP_INLINE SIMD_FN vertex_lanes vertex_numbers_next(vertex_lanes a) { return _mm_add_epi32(a, _mm_set1_epi32(BLOCK)); }
SP_INLINE SIMD_FN void vertex_compact(vertex_lanes a, unsigned keep, uint32_t* out)
{
    static const int32_t order[16][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}, {1, 0, 0, 0}, {0, 1, 0, 0}, {2, 0, 0, 0}, {0, 2, 0, 0},
                                         {1, 2, 0, 0}, {0, 1, 2, 0}, {3, 0, 0, 0}, {0, 3, 0, 0}, {1, 3, 0, 0}, {0, 1, 3, 0},
                                         {2, 3, 0, 0}, {0, 2, 3, 0}, {1, 2, 3, 0}, {0, 1, 2, 3}};
    __m128i permute = _mm_loadu_si128((const __m128i*)order[keep & 15]);
    _mm_storeu_si128((__m128i*)out, _mm_castps_si128(_mm_permutevar_ps(_mm_castsi128_ps(a), permute)));
}
#endif
#endif
