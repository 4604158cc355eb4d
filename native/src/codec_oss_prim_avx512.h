/*
 * AVX-512 (F, DQ, VL) primitives of the OSS batch drivers (codec_oss_simd.h,
 * codec_oss_wide_simd.h), included by codec_oss_batch_avx512.c only: eight double lanes
 * (sixteen float / int32 lanes for narrow decode), compare masks in mask registers, the AoS
 * weights moved in and out with two-source permutes, and rcp14 estimates in the layer root.
 */
#ifndef SKINPACK_CODEC_OSS_PRIM_AVX512_H
#define SKINPACK_CODEC_OSS_PRIM_AVX512_H

#include "codec_internal.h"

#if SP_X86_SIMD
#include <immintrin.h>

SP_FP_CONTRACT_OFF /* avx512f implies fma */
#define SIMD_FN SP_TARGET("avx512f,avx512dq,avx512vl")
#define SIMD_NAME(name) sp_oss_##name##_avx512
#define BLOCK 8
#define ENCODE_CHUNK 16 /* blocks per stage: on Zen 5, 8 is ~3% slower for K = 3, 4, 32 no faster */
#define DECODE_CHUNK 16 /* on Zen 5, 8 is ~5% slower for K = 3, 4 decode (4 was ~20% slower on Zen 4) */
#define ENCODE_FUSED 1  /* K = 2, 3 encode in one stage (encode_fused); K = 3 ~15% faster on Zen 5 than in three */

typedef __m512d vec;
typedef __mmask8 mask;
typedef __m256 root;
/* Permute indices between 8 vertices of k floats and component pairs (see soa_index); stream:
 * the decode's weights go by streaming stores (put16, put8; codec_oss_simd.h). */
typedef struct simd_layout {
    __m512i soa[2], aos[2];
    int stream;
} simd_layout;

SP_INLINE SIMD_FN vec v_splat(double x) { return _mm512_set1_pd(x); }
SP_INLINE SIMD_FN vec v_zero(void) { return _mm512_setzero_pd(); }
SP_INLINE SIMD_FN vec v_add(vec a, vec b) { return _mm512_add_pd(a, b); }
SP_INLINE SIMD_FN vec v_sub(vec a, vec b) { return _mm512_sub_pd(a, b); }
SP_INLINE SIMD_FN vec v_mul(vec a, vec b) { return _mm512_mul_pd(a, b); }
SP_INLINE SIMD_FN vec v_div(vec a, vec b) { return _mm512_div_pd(a, b); }
SP_INLINE SIMD_FN vec v_sqrt(vec a) { return _mm512_sqrt_pd(a); }
SP_INLINE SIMD_FN vec v_max(vec a, vec b) { return _mm512_max_pd(a, b); }
SP_INLINE SIMD_FN vec v_min(vec a, vec b) { return _mm512_min_pd(a, b); }
SP_INLINE SIMD_FN vec v_floor(vec a) { return _mm512_roundscale_pd(a, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC); }
SP_INLINE SIMD_FN vec v_trunc(vec a) { return _mm512_roundscale_pd(a, _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC); }
SP_INLINE SIMD_FN vec v_fmadd(vec a, vec b, vec c) { return _mm512_fmadd_pd(a, b, c); }
SP_INLINE SIMD_FN vec v_fnmadd(vec a, vec b, vec c) { return _mm512_fnmadd_pd(a, b, c); }
SP_INLINE SIMD_FN vec v_fmsub(vec a, vec b, vec c) { return _mm512_fmsub_pd(a, b, c); }
SP_INLINE SIMD_FN mask m_ge(vec a, vec b) { return _mm512_cmp_pd_mask(a, b, _CMP_GE_OQ); }
SP_INLINE SIMD_FN mask m_gt(vec a, vec b) { return _mm512_cmp_pd_mask(a, b, _CMP_GT_OQ); }
SP_INLINE SIMD_FN mask m_lt(vec a, vec b) { return _mm512_cmp_pd_mask(a, b, _CMP_LT_OQ); }
SP_INLINE SIMD_FN mask m_and(mask a, mask b) { return (mask)(a & b); }
SP_INLINE SIMD_FN unsigned m_bits(mask a) { return a; }
SP_INLINE SIMD_FN vec v_add_where(vec x, mask m, vec y) { return _mm512_mask_add_pd(x, m, x, y); }

/* Counters as plain doubles: a masked add is one instruction already. */
#define COUNTER_BIAS 0.0
typedef __m512d counter;
SP_INLINE SIMD_FN counter c_splat(uint32_t c) { return v_splat(c); }
SP_INLINE SIMD_FN counter c_inc_where(counter c, mask m) { return v_add_where(c, m, v_splat(1.0)); }
SP_INLINE SIMD_FN counter c_dec_where(counter c, mask m) { return v_add_where(c, m, v_splat(-1.0)); }
SP_INLINE SIMD_FN mask c_below(counter c, vec threshold) { return m_gt(threshold, c); }
SP_INLINE SIMD_FN mask c_deficit_fits(vec threshold, uint32_t k)
{
    return m_and(m_ge(threshold, v_zero()), m_lt(threshold, v_splat((double)k)));
}
/* Each slot starts beaten by every later one (the last from 0: a masked add into zeros, which
 * the compiler makes a masked move), and an earlier slot a that beats b takes that back. */
SP_INLINE SIMD_FN counter rank_start(uint32_t i, uint32_t k) { return c_splat(k - 1 - i); }
SP_INLINE SIMD_FN void rank_pair(vec ra, vec rb, counter* rank_a, counter* rank_b)
{
    mask a_wins = m_ge(ra, rb);
    *rank_a = c_dec_where(*rank_a, a_wins);
    *rank_b = c_inc_where(*rank_b, a_wins);
}

/* Sixteen float or int32 lanes for decode in 32-bit lanes. */
#define NBLOCK 16
#define NARROW_CHUNK 16 /* blocks a stage (256 vertices): K = 4 ~3% faster than 8 */
typedef __m512 nvec;
typedef __m512i nint;
typedef __mmask16 nmask;
SP_INLINE SIMD_FN nvec f_splat(float x) { return _mm512_set1_ps(x); }
SP_INLINE SIMD_FN nvec f_add(nvec a, nvec b) { return _mm512_add_ps(a, b); }
SP_INLINE SIMD_FN nvec f_sub(nvec a, nvec b) { return _mm512_sub_ps(a, b); }
SP_INLINE SIMD_FN nvec f_mul(nvec a, nvec b) { return _mm512_mul_ps(a, b); }
SP_INLINE SIMD_FN nvec f_sqrt(nvec a) { return _mm512_sqrt_ps(a); }
SP_INLINE SIMD_FN nvec f_fmadd(nvec a, nvec b, nvec c) { return _mm512_fmadd_ps(a, b, c); }
SP_INLINE SIMD_FN nvec f_fnmadd(nvec a, nvec b, nvec c) { return _mm512_fnmadd_ps(a, b, c); }
SP_INLINE SIMD_FN nint i_splat(int32_t x) { return _mm512_set1_epi32(x); }
SP_INLINE SIMD_FN nint i_add(nint a, nint b) { return _mm512_add_epi32(a, b); }
SP_INLINE SIMD_FN nint i_sub(nint a, nint b) { return _mm512_sub_epi32(a, b); }
SP_INLINE SIMD_FN nint i_mullo(nint a, nint b) { return _mm512_mullo_epi32(a, b); }
SP_INLINE SIMD_FN nint i_max(nint a, nint b) { return _mm512_max_epi32(a, b); }
SP_INLINE SIMD_FN nint i_min(nint a, nint b) { return _mm512_min_epi32(a, b); }
SP_INLINE SIMD_FN nint i_shr2(nint a) { return _mm512_srai_epi32(a, 2); }
SP_INLINE SIMD_FN nmask i_gt(nint a, nint b) { return _mm512_cmpgt_epi32_mask(a, b); }
SP_INLINE SIMD_FN nmask n_or(nmask a, nmask b) { return (nmask)(a | b); }
SP_INLINE SIMD_FN unsigned n_bits(nmask a) { return a; }
SP_INLINE SIMD_FN nvec i_to_f(nint a) { return _mm512_cvtepi32_ps(a); }
SP_INLINE SIMD_FN nint i_trunc(nvec a) { return _mm512_cvttps_epi32(a); } /* NaN and overflow: INT32_MIN */
SP_INLINE SIMD_FN nint f_as_i(nvec a) { return _mm512_castps_si512(a); }
SP_INLINE SIMD_FN nvec i_as_f(nint a) { return _mm512_castsi512_ps(a); }
SP_INLINE SIMD_FN nint i_shr1(nint a) { return _mm512_srai_epi32(a, 1); }
SP_INLINE SIMD_FN nint i_add_where(nint a, nmask m, nint b) { return _mm512_mask_add_epi32(a, m, a, b); }
SP_INLINE SIMD_FN nint i_sub_where(nint a, nmask m, nint b) { return _mm512_mask_sub_epi32(a, m, a, b); }
/* Two blocks of double lanes as NBLOCK int32 (integral, in range) or floats (rounded). */
SP_INLINE SIMD_FN nint i_from_pair(vec a, vec b)
{
    return _mm512_inserti64x4(_mm512_castsi256_si512(_mm512_cvttpd_epi32(a)), _mm512_cvttpd_epi32(b), 1);
}
SP_INLINE SIMD_FN nvec f_from_pair(vec a, vec b)
{
    return _mm512_insertf32x8(_mm512_castps256_ps512(_mm512_cvtpd_ps(a)), _mm512_cvtpd_ps(b), 1);
}
/* The low 32 bits of each lane of two blocks (as bits), as NBLOCK int32 lanes in order. */
SP_INLINE SIMD_FN nint i_low_pair(vec a, vec b)
{
    __m512i even = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
    return _mm512_permutex2var_epi32(_mm512_castpd_si512(a), even, _mm512_castpd_si512(b));
}
/* The inverse for int32: NBLOCK int32 lanes as two blocks of doubles (exact). */
SP_INLINE SIMD_FN void v_from_i_pair(nint a, vec* first, vec* second)
{
    *first = _mm512_cvtepi32_pd(_mm512_castsi512_si256(a));
    *second = _mm512_cvtepi32_pd(_mm512_extracti64x4_epi64(a, 1));
}

/* floor(a / 9) for 0 <= a < 2^33, as the AVX2 path (codec_oss_prim_avx2.h). */
SP_INLINE SIMD_FN nint i_div9(nint a)
{
    __m512i m = _mm512_set1_epi32(954437177);
    __m512i even = _mm512_srli_epi64(_mm512_mul_epu32(a, m), 33);
    __m512i odd = _mm512_srli_epi64(_mm512_mul_epu32(_mm512_srli_epi64(a, 32), m), 1);
    return _mm512_mask_blend_epi32((__mmask16)0xAAAA, even, odd);
}

/* Indices between 8 vertices of k floats (AoS, as two 16-float registers: floats 0..15 and
 * floats 8k-16..8k-1, overlapping for k < 4) and component pairs (c, c + 1) of the 8 vertices
 * (SoA, one register per pair: component c in the low half). */
SP_INLINE SIMD_FN __m512i soa_index(uint32_t k, uint32_t pair)
{
    int32_t index[16];
    for (uint32_t lane = 0; lane < 16; ++lane) {
        uint32_t c = 2 * pair + lane / 8, f = (lane % 8) * k + (c < k ? c : 0);
        index[lane] = (int32_t)(f < 16 ? f : 16 + f - (8 * k - 16));
    }
    return _mm512_loadu_si512(index);
}

/* The inverse: output float f (of 16 starting at float 16 * half) from the pair registers
 * (pair 0 as indices 0..15, pair 1 as 16..31). */
SP_INLINE SIMD_FN __m512i aos_index(uint32_t k, uint32_t half)
{
    int32_t index[16];
    for (uint32_t lane = 0; lane < 16; ++lane) {
        uint32_t f = 16 * half + lane, v = f / k, c = f % k;
        index[lane] = (int32_t)(v < 8 ? (c / 2) * 16 + (c % 2) * 8 + v : 0);
    }
    return _mm512_loadu_si512(index);
}

SP_INLINE SIMD_FN simd_layout layout_for(uint32_t k)
{
    simd_layout layout = {{soa_index(k, 0), soa_index(k, 1)}, {aos_index(k, 0), aos_index(k, 1)}, 0};
    return layout;
}

#define LOAD_ORDERED 0 /* the driver's load_weights and weights_ordered serve */

/* Component i of eight consecutive vertices of k weights, widened to double (exact). */
SP_INLINE SIMD_FN void load_weights(const float* w, uint32_t k, const simd_layout* layout, vec* x)
{
    __m512 lo = _mm512_loadu_ps(w), hi = _mm512_loadu_ps(w + 8 * k - 16);
    SP_UNROLL
    for (uint32_t pair = 0; 2 * pair < k; ++pair) {
        __m512 p = _mm512_permutex2var_ps(lo, layout->soa[pair], hi);
        x[2 * pair] = _mm512_cvtps_pd(_mm512_castps512_ps256(p));
        if (2 * pair + 1 < k) x[2 * pair + 1] = _mm512_cvtps_pd(_mm512_extractf32x8_ps(p, 1));
    }
}

/*
 * The weights' stores, streaming (non-temporal) ones where layout->stream (see put8 in
 * codec_oss_prim_avx2.h). p is 32-byte aligned there (the decode entry streams only from such a
 * start, and every store here lies a multiple of 32 bytes past it: K = 3's blocks of 96), and
 * put16's stores half-way into a line go as two of 32 bytes.
 */
#define STREAM_ALIGN 32

SP_INLINE SIMD_FN void put8(const simd_layout* layout, float* p, __m256 v)
{
    if (layout->stream) _mm256_stream_ps(p, v);
    else _mm256_storeu_ps(p, v);
}

SP_INLINE SIMD_FN void put16(const simd_layout* layout, float* p, __m512 v)
{
    if (!layout->stream) _mm512_storeu_ps(p, v);
    else if (!((uintptr_t)p & 63)) _mm512_stream_ps(p, v);
    else {
        _mm256_stream_ps(p, _mm512_castps512_ps256(v));
        _mm256_stream_ps(p + 8, _mm512_extractf32x8_ps(v, 1));
    }
}

/* The floats of eight vertices, 2k of them, from the two component pairs (a = 0, 1 | 2, 3). */
SP_INLINE SIMD_FN void store_vertices8(const __m512* pair, uint32_t k, const simd_layout* layout, float* out)
{
    put16(layout, out, _mm512_permutex2var_ps(pair[0], layout->aos[0], pair[1]));
    if (k == 4) put16(layout, out + 16, _mm512_permutex2var_ps(pair[0], layout->aos[1], pair[1]));
    if (k == 3) put8(layout, out + 16, _mm512_castps512_ps256(_mm512_permutex2var_ps(pair[0], layout->aos[1], pair[1])));
}

/* (float)(q * (1/s)) per component, as sp_grid_to_weights does, stored as eight vertices. */
SP_INLINE SIMD_FN void store_weights(const vec* q, uint32_t k, double inverse, const simd_layout* layout, float* out)
{
    __m512 pair[2] = {_mm512_setzero_ps(), _mm512_setzero_ps()};
    SP_UNROLL
    for (uint32_t i = 0; i < k; ++i) {
        __m256 w = _mm512_cvtpd_ps(_mm512_mul_pd(q[i], v_splat(inverse)));
        pair[i / 2] = i % 2 ? _mm512_insertf32x8(pair[i / 2], w, 1) : _mm512_castps256_ps512(w);
    }
    store_vertices8(pair, k, layout, out);
}

/* Codes <= max_code: the largest code seen, compared once. */
typedef struct code_check {
    __m512i high;
    uint64_t max_code;
} code_check;

SP_INLINE SIMD_FN code_check check_start(uint64_t max_code)
{
    code_check check = {_mm512_setzero_si512(), max_code};
    return check;
}

SP_INLINE SIMD_FN int check_passed(const code_check* check)
{
    return !_mm512_cmpgt_epu64_mask(check->high, _mm512_set1_epi64((int64_t)check->max_code));
}

/* The low halves of sixteen codes, in order. */
SP_INLINE SIMD_FN nint load_codes32(const uint64_t* codes, code_check* check)
{
    __m512i first = _mm512_loadu_si512(codes), second = _mm512_loadu_si512(codes + 8);
    check->high = _mm512_max_epu64(check->high, _mm512_max_epu64(first, second));
    return _mm512_inserti64x4(_mm512_castsi256_si512(_mm512_cvtepi64_epi32(first)), _mm512_cvtepi64_epi32(second), 1);
}

/* store_weights of two blocks, one after the other. */
SP_INLINE SIMD_FN void store_pair(const vec* first, const vec* second, uint32_t k, double inverse,
                                  const simd_layout* layout, float* out)
{
    store_weights(first, k, inverse, layout, out);
    store_weights(second, k, inverse, layout, out + BLOCK * k);
}

/* Sixteen vertices of k floats from k component vectors (w[3] overwritten for k = 3): each half
 * as store_weights stores it. */
SP_INLINE SIMD_FN void store_floats16(__m512* w, uint32_t k, const simd_layout* layout, float* out)
{
    if (k == 3) w[3] = w[2]; /* the unused pair half */
    /* pairs (c, c + 1) of vertices 0..7 (the low halves: 0x44) and 8..15 (the high ones: 0xEE) */
    __m512 pairs[2][2] = {{_mm512_shuffle_f32x4(w[0], w[1], 0x44)}, {_mm512_shuffle_f32x4(w[0], w[1], 0xEE)}};
    pairs[0][1] = k > 2 ? _mm512_shuffle_f32x4(w[2], w[3], 0x44) : pairs[0][0];
    pairs[1][1] = k > 2 ? _mm512_shuffle_f32x4(w[2], w[3], 0xEE) : pairs[1][0];
    SP_UNROLL
    for (uint32_t half = 0; half < 2; ++half) store_vertices8(pairs[half], k, layout, out + half * BLOCK * k);
}

/* store_weights of sixteen vertices from int32 components 0 <= q <= s < 2^24: in float lanes
 * by Markstein's correction of q r, the correctly rounded q/s as the double product (see
 * store_weights32 in codec_oss_prim_avx2.h). */
SP_INLINE SIMD_FN void store_weights32(const nint* q, uint32_t k, double scale, const simd_layout* layout, float* out)
{
    __m512 w[SP_MAX_INFLUENCES], s = _mm512_set1_ps((float)scale), r = _mm512_set1_ps(1.0f / (float)scale);
    SP_UNROLL
    for (uint32_t i = 0; i < k; ++i) {
        __m512 x = _mm512_cvtepi32_ps(q[i]), y = _mm512_mul_ps(x, r);
        w[i] = _mm512_fmadd_ps(_mm512_fnmadd_ps(y, s, x), r, y);
    }
    store_floats16(w, k, layout, out);
}

/* store_weights32 by division, for every s < 2^24 (store_quotients32 in codec_oss_prim_avx2.h). */
SP_INLINE SIMD_FN void store_quotients32(const nint* q, uint32_t k, double scale, const simd_layout* layout, float* out)
{
    __m512 w[SP_MAX_INFLUENCES], s = _mm512_set1_ps((float)scale);
    SP_UNROLL
    for (uint32_t i = 0; i < k; ++i) w[i] = _mm512_div_ps(_mm512_cvtepi32_ps(q[i]), s);
    store_floats16(w, k, layout, out);
}

SP_INLINE SIMD_FN vec load_codes(const uint64_t* codes, code_check* check)
{
    __m512i raw = _mm512_loadu_si512(codes);
    check->high = _mm512_max_epu64(check->high, raw);
    return _mm512_cvtepu64_pd(raw); /* exact below 2^53 */
}

SP_INLINE SIMD_FN void store_codes(uint64_t* codes, vec x)
{
    _mm512_storeu_si512(codes, _mm512_cvttpd_epu64(x));
}

/* Lanes ROUNDING_MAGIC + code (codec_oss_simd.h: 1.5 2^52 plus an integer of magnitude below
 * 2^51) as the u64 codes: the difference of the bits. */
SP_INLINE SIMD_FN void store_biased_codes(uint64_t* codes, vec x)
{
    _mm512_storeu_si512(codes, _mm512_sub_epi64(_mm512_castpd_si512(x), _mm512_castpd_si512(v_splat(0x1.8p52))));
}

SP_INLINE SIMD_FN void store_counts(vec count, uint8_t* out)
{
    _mm_storel_epi64((__m128i*)out, _mm512_cvtepi64_epi8(_mm512_cvttpd_epi64(count)));
}

SP_INLINE SIMD_FN int codes_valid(const uint64_t* codes, uint64_t max_code)
{
    return !_mm512_cmpgt_epu64_mask(_mm512_loadu_si512(codes), _mm512_set1_epi64((int64_t)max_code));
}

/*
 * cbrt(x) + 1/cbrt(x) for the layer estimate, x >= 1: the float exponent/3 bit trick (3.2%), a
 * Halley step in float with rcp14 for its division (~1e-4), then one Newton step in double whose
 * 1/(3y^2) comes from rcp14 (its 2^-14 error only scales the already small correction), and 1/c
 * from rcp14. An estimate only: no division or zmm square root (those were the bottleneck of an
 * earlier double Halley step).
 */
SP_INLINE SIMD_FN root root_start(vec x)
{
    __m256 xf = _mm512_cvtpd_ps(x);
    __m256i third = _mm256_cvttps_epi32(_mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_castps_si256(xf)), _mm256_set1_ps(1.0f / 3.0f)));
    __m256 yf = _mm256_castsi256_ps(_mm256_add_epi32(third, _mm256_set1_epi32(709958130)));
    __m256 yf3 = _mm256_mul_ps(_mm256_mul_ps(yf, yf), yf);
    __m256 inverse = _mm256_rcp14_ps(_mm256_add_ps(_mm256_add_ps(yf3, yf3), xf));
    return _mm256_mul_ps(_mm256_mul_ps(yf, _mm256_add_ps(yf3, _mm256_add_ps(xf, xf))), inverse); /* y (y^3 + 2x) / (2y^3 + x) */
}

SP_INLINE SIMD_FN vec root_finish(vec x, root yf)
{
    __m512d y = _mm512_cvtps_pd(yf);
    __m512d y2 = _mm512_mul_pd(y, y);
    __m512d r = _mm512_rcp14_pd(_mm512_mul_pd(y2, v_splat(3.0)));
    __m512d c = _mm512_fnmadd_pd(_mm512_fmsub_pd(y2, y, x), r, y); /* y - (y^3 - x) / (3y^2) */
    return _mm512_add_pd(c, _mm512_rcp14_pd(c));
}

/* The 64-bit integer lanes of the wide driver (codec_oss_wide_simd.h): vpmullq products,
 * unsigned compares into mask registers, 64-bit conversions. */

#define WIDE_NAME(name) sp_oss_wide_##name##_avx512

/* Its root_start already fills eight float lanes a block (a sixteen-lane pass ran ~1% faster). */
SP_INLINE SIMD_FN void root_start_pair(vec a, vec b, root* first, root* second)
{
    *first = root_start(a), *second = root_start(b);
}

/* Its root (a double Newton step) is good to far below half a layer at the wide lanes' t. */
SP_INLINE SIMD_FN vec root_finish_fine(vec x, root yf) { return root_finish(x, yf); }

typedef __m512i uvec;

#define u_srl(a, n) _mm512_srli_epi64(a, n)
#define u_sll(a, n) _mm512_slli_epi64(a, n)
SP_INLINE SIMD_FN uvec u_splat(uint64_t x) { return _mm512_set1_epi64((int64_t)x); }
SP_INLINE SIMD_FN uvec u_load(const uint64_t* p) { return _mm512_loadu_si512(p); }
SP_INLINE SIMD_FN void u_store(uint64_t* p, uvec a) { _mm512_storeu_si512(p, a); }
SP_INLINE SIMD_FN uvec u_add(uvec a, uvec b) { return _mm512_add_epi64(a, b); }
SP_INLINE SIMD_FN uvec u_sub(uvec a, uvec b) { return _mm512_sub_epi64(a, b); }
SP_INLINE SIMD_FN uvec u_and(uvec a, uvec b) { return _mm512_and_si512(a, b); }
SP_INLINE SIMD_FN uvec u_mul32(uvec a, uvec b) { return _mm512_mul_epu32(a, b); }
SP_INLINE SIMD_FN uvec u_mul(uvec a, uvec b) { return _mm512_mullo_epi64(a, b); }
#define WIDE_INTEGER_PRODUCT 1 /* codec_oss_wide_simd.h's wide_product: vpmullq */
SP_INLINE SIMD_FN uvec u_unbias(vec x) /* ROUNDING_MAGIC + m -> m */
{
    return u_sub(_mm512_castpd_si512(x), _mm512_castpd_si512(v_splat(0x1.8p52)));
}
SP_INLINE SIMD_FN vec v_from_u(uvec a) { return _mm512_cvtepu64_pd(a); }
SP_INLINE SIMD_FN vec v_from_u_rounded(uvec a) { return _mm512_cvtepu64_pd(a); } /* rounded to nearest */
SP_INLINE SIMD_FN void v_halves(uvec a, vec* high, vec* low)
{
    *high = _mm512_cvtepu64_pd(u_srl(a, 32));
    *low = _mm512_cvtepu64_pd(u_and(a, u_splat(0xFFFFFFFFu)));
}
SP_INLINE SIMD_FN uvec u_from_v(vec x) { return _mm512_cvttpd_epu64(x); }

/* K = 2 encode past 2^50 grids in double lanes (codec_oss_wide_simd.h's wide_pair_start):
 * the two weights of eight vertices as two component vectors (exact), by one permute of the 16
 * floats; the other primitives it needs. */
SP_INLINE SIMD_FN void load_pairs(const float* w, vec* first, vec* second)
{
    __m512 split = _mm512_permutexvar_ps(_mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 1, 3, 5, 7, 9, 11, 13, 15),
                                         _mm512_loadu_ps(w));
    *first = _mm512_cvtps_pd(_mm512_castps512_ps256(split));
    *second = _mm512_cvtps_pd(_mm256_castpd_ps(_mm512_extractf64x4_pd(_mm512_castps_pd(split), 1)));
}
SP_INLINE SIMD_FN mask m_eq(vec a, vec b) { return _mm512_cmp_pd_mask(a, b, _CMP_EQ_OQ); }
SP_INLINE SIMD_FN vec v_keep_where(vec x, mask m) { return _mm512_maskz_mov_pd(m, x); } /* m ? x : +0 */
/* The double just below x > 0 where m (x elsewhere): its bits less one. */
SP_INLINE SIMD_FN vec v_below_where(vec x, mask m)
{
    __m512i bits = _mm512_castpd_si512(x);
    return _mm512_castsi512_pd(_mm512_mask_sub_epi64(bits, m, bits, _mm512_set1_epi64(1)));
}
SP_INLINE SIMD_FN uvec u_bits(vec x) { return _mm512_castpd_si512(x); } /* the bits, as they are */

/* K = 2 and 3 weights: codec_oss_simd.h's store (two-source permutes) serves. */
SP_INLINE SIMD_FN void store_pairs(vec q0, vec q1, double inverse, const simd_layout* layout, float* out)
{
    vec q[2] = {q0, q1};
    store_weights(q, 2, inverse, layout, out);
}

SP_INLINE SIMD_FN void store_triples(const vec* q, double inverse, const simd_layout* layout, float* out)
{
    store_weights(q, 3, inverse, layout, out);
}

/* ---- the edge codes (codec_oss_simd.h's edge_decode) ------------------------------------ */

/* u_at_least's bound for n. */
SP_INLINE SIMD_FN uvec u_bound(uint64_t n) { return _mm512_set1_epi64((int64_t)n); }

/* The lanes of a at least n (u_bound(n)), unsigned, as bits. */
SP_INLINE SIMD_FN unsigned u_at_least(uvec a, uvec bound) { return _mm512_cmpge_epu64_mask(a, bound); }

/* The lanes of a set in keep, in order, to the front of out (a whole block written). */
SP_INLINE SIMD_FN void u_compact(uvec a, unsigned keep, uint64_t* out)
{
    _mm512_storeu_si512(out, _mm512_maskz_compress_epi64((__mmask8)keep, a));
}

/* Eight whole rows of k floats, each the first two weights (the doubles' roundings to float) and
 * zeros: two-source permutes into the rows' places, zero where masked off (K = 3: float p of
 * the rows is vertex p / 3's weight p % 3, zero where 2). */
SP_INLINE SIMD_FN void store_edge_pairs(vec first, vec second, uint32_t k, float* out)
{
    __m256 a = _mm512_cvtpd_ps(first), b = _mm512_cvtpd_ps(second);
    __m512 wide_a = _mm512_castps256_ps512(a), wide_b = _mm512_castps256_ps512(b);
    if (k == 4) {
        __m512i low = _mm512_setr_epi32(0, 16, 0, 0, 1, 17, 0, 0, 2, 18, 0, 0, 3, 19, 0, 0);
        __m512i high = _mm512_setr_epi32(4, 20, 0, 0, 5, 21, 0, 0, 6, 22, 0, 0, 7, 23, 0, 0);
        _mm512_storeu_ps(out, _mm512_maskz_permutex2var_ps(0x3333, wide_a, low, wide_b));
        _mm512_storeu_ps(out + 16, _mm512_maskz_permutex2var_ps(0x3333, wide_a, high, wide_b));
    } else {
        __m512i head = _mm512_setr_epi32(0, 16, 0, 1, 17, 0, 2, 18, 0, 3, 19, 0, 4, 20, 0, 5);
        __m256i tail = _mm256_setr_epi32(13, 0, 6, 14, 0, 7, 15, 0); /* floats 16-23: a's are 0-7, b's 8-15 */
        _mm512_storeu_ps(out, _mm512_maskz_permutex2var_ps(0xB6DB, wide_a, head, wide_b));
        _mm256_storeu_ps(out + 16, _mm256_maskz_permutex2var_ps(0x6D, a, tail, b));
    }
}

/* A block's vertex numbers in 32-bit lanes: 0, 1, ... BLOCK - 1, each BLOCK more, and those
 * kept, in order, to the front of out (a whole block written). */
typedef __m256i vertex_lanes;
SP_INLINE SIMD_FN vertex_lanes vertex_numbers(void) { return _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7); }
SP_INLINE SIMD_FN vertex_lanes vertex_numbers_next(vertex_lanes a) { return _mm256_add_epi32(a, _mm256_set1_epi32(BLOCK)); }
SP_INLINE SIMD_FN void vertex_compact(vertex_lanes a, unsigned keep, uint32_t* out)
{
    _mm256_storeu_si256((__m256i*)out, _mm256_maskz_compress_epi32((__mmask8)keep, a));
}
#endif
#endif
