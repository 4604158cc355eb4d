/*
 * The AVX2 + FMA3 OSS batch paths: the double-lane ones (codec_oss_batch_avx2.c, included here
 * so that its primitives, rounding and root estimates serve the wide driver too; this file is
 * its one translation unit) and the 64-bit integer lanes of the wide driver
 * (codec_oss_wide_simd.h). AVX2 has no 64-bit multiply or unsigned compare: products come from
 * 32-bit pieces (_mm256_mul_epu32), compares are signed ones with the sign bits flipped.
 */
#include "codec_oss_batch_avx2.c"

#if SP_X86_SIMD
#include "codec_oss_wide.h"

#define WIDE_NAME(name) sp_oss_wide_##name##_avx2

#define WIDE_ROOT_NEWTON 1 /* its cube root is ~4e-8 off in places */

typedef __m256i uvec;
typedef __m256i umask; /* all-ones lanes */

#define u_srl(a, n) _mm256_srli_epi64(a, n)
#define u_sll(a, n) _mm256_slli_epi64(a, n)
SP_INLINE SIMD_FN uvec u_splat(uint64_t x) { return _mm256_set1_epi64x((int64_t)x); }
SP_INLINE SIMD_FN uvec u_load(const uint64_t* p) { return _mm256_loadu_si256((const __m256i*)p); }
SP_INLINE SIMD_FN void u_store(uint64_t* p, uvec a) { _mm256_storeu_si256((__m256i*)p, a); }
SP_INLINE SIMD_FN uvec u_add(uvec a, uvec b) { return _mm256_add_epi64(a, b); }
SP_INLINE SIMD_FN uvec u_sub(uvec a, uvec b) { return _mm256_sub_epi64(a, b); }
SP_INLINE SIMD_FN uvec u_and(uvec a, uvec b) { return _mm256_and_si256(a, b); }
SP_INLINE SIMD_FN uvec u_srlv(uvec a, uvec count) { return _mm256_srlv_epi64(a, count); }
SP_INLINE SIMD_FN uvec u_mul32(uvec a, uvec b) { return _mm256_mul_epu32(a, b); }
SP_INLINE SIMD_FN uvec u_mul_u32(uvec a, uvec b) { return u_add(u_mul32(a, b), u_sll(u_mul32(u_srl(a, 32), b), 32)); }
SP_INLINE SIMD_FN uvec u_mul(uvec a, uvec b)
{
    uvec cross = u_add(u_mul32(u_srl(a, 32), b), u_mul32(a, u_srl(b, 32)));
    return u_add(u_mul32(a, b), u_sll(cross, 32));
}
SP_INLINE SIMD_FN umask u_lt(uvec a, uvec b)
{
    uvec flip = u_splat((uint64_t)1 << 63);
    return _mm256_cmpgt_epi64(_mm256_xor_si256(b, flip), _mm256_xor_si256(a, flip));
}
SP_INLINE SIMD_FN umask u_lt_small(uvec a, uvec b) { return _mm256_cmpgt_epi64(b, a); }
SP_INLINE SIMD_FN uvec u_select(umask m, uvec a, uvec b) { return _mm256_blendv_epi8(b, a, m); }
SP_INLINE SIMD_FN unsigned um_bits(umask m) { return (unsigned)_mm256_movemask_pd(_mm256_castsi256_pd(m)); }

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
    (void)layout;
    __m128 first = _mm256_cvtpd_ps(v_mul(q0, v_splat(inverse))), second = _mm256_cvtpd_ps(v_mul(q1, v_splat(inverse)));
    _mm_storeu_ps(out, _mm_unpacklo_ps(first, second));
    _mm_storeu_ps(out + 4, _mm_unpackhi_ps(first, second));
}

/* K = 3 weights likewise, as four vertices: components 0, 1 through one permute, 2 through
 * another, blended; then the last vertex and a half the same way. */
SP_INLINE SIMD_FN void store_triples(const vec* q, double inverse, const simd_layout* layout, float* out)
{
    (void)layout;
    __m128 w0 = _mm256_cvtpd_ps(v_mul(q[0], v_splat(inverse))), w1 = _mm256_cvtpd_ps(v_mul(q[1], v_splat(inverse)));
    __m128 w2 = _mm256_cvtpd_ps(v_mul(q[2], v_splat(inverse)));
    __m256 pairs = _mm256_insertf128_ps(_mm256_castps128_ps256(w0), w1, 1), thirds = _mm256_castps128_ps256(w2);
    __m256 head = _mm256_blend_ps(_mm256_permutevar8x32_ps(pairs, _mm256_setr_epi32(0, 4, 0, 1, 5, 0, 2, 6)),
                                  _mm256_permutevar8x32_ps(thirds, _mm256_setr_epi32(0, 0, 0, 0, 0, 1, 0, 0)), 0x24);
    __m256 tail = _mm256_blend_ps(_mm256_permutevar8x32_ps(pairs, _mm256_setr_epi32(0, 3, 7, 0, 0, 0, 0, 0)),
                                  _mm256_permutevar8x32_ps(thirds, _mm256_setr_epi32(2, 0, 0, 3, 0, 0, 0, 0)), 0x09);
    _mm256_storeu_ps(out, head);
    _mm_storeu_ps(out + 8, _mm256_castps256_ps128(tail));
}

#include "codec_oss_wide_simd.h"
#endif
