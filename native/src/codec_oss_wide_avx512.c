/*
 * The AVX-512 (F, DQ, VL) OSS batch paths: the double-lane ones (codec_oss_batch_avx512.c,
 * included here so that its primitives, rounding and root estimates serve the wide driver too;
 * this file is its one translation unit) and the 64-bit integer lanes of the wide driver
 * (codec_oss_wide_simd.h): vpmullq products, unsigned compares into mask registers, 64-bit
 * conversions.
 */
#include "codec_oss_batch_avx512.c"

#if SP_X86_SIMD
#include "codec_oss_wide.h"

#define WIDE_NAME(name) sp_oss_wide_##name##_avx512

#define WIDE_ROOT_NEWTON 0 /* its root (a double Newton step) is good to far below half a layer */

typedef __m512i uvec;
typedef __mmask8 umask;

#define u_srl(a, n) _mm512_srli_epi64(a, n)
#define u_sll(a, n) _mm512_slli_epi64(a, n)
SP_INLINE SIMD_FN uvec u_splat(uint64_t x) { return _mm512_set1_epi64((int64_t)x); }
SP_INLINE SIMD_FN uvec u_load(const uint64_t* p) { return _mm512_loadu_si512(p); }
SP_INLINE SIMD_FN void u_store(uint64_t* p, uvec a) { _mm512_storeu_si512(p, a); }
SP_INLINE SIMD_FN uvec u_add(uvec a, uvec b) { return _mm512_add_epi64(a, b); }
SP_INLINE SIMD_FN uvec u_sub(uvec a, uvec b) { return _mm512_sub_epi64(a, b); }
SP_INLINE SIMD_FN uvec u_and(uvec a, uvec b) { return _mm512_and_si512(a, b); }
SP_INLINE SIMD_FN uvec u_srlv(uvec a, uvec count) { return _mm512_srlv_epi64(a, count); }
SP_INLINE SIMD_FN uvec u_mul32(uvec a, uvec b) { return _mm512_mul_epu32(a, b); }
SP_INLINE SIMD_FN uvec u_mul(uvec a, uvec b) { return _mm512_mullo_epi64(a, b); }
SP_INLINE SIMD_FN uvec u_mul_u32(uvec a, uvec b) { return u_mul(a, b); }
SP_INLINE SIMD_FN umask u_lt(uvec a, uvec b) { return _mm512_cmplt_epu64_mask(a, b); }
SP_INLINE SIMD_FN umask u_lt_small(uvec a, uvec b) { return _mm512_cmplt_epi64_mask(a, b); }
SP_INLINE SIMD_FN uvec u_select(umask m, uvec a, uvec b) { return _mm512_mask_blend_epi64(m, b, a); }
SP_INLINE SIMD_FN unsigned um_bits(umask m) { return m; }
SP_INLINE SIMD_FN vec v_from_u(uvec a) { return _mm512_cvtepu64_pd(a); }
SP_INLINE SIMD_FN vec v_from_u_rounded(uvec a) { return _mm512_cvtepu64_pd(a); } /* rounded to nearest */
SP_INLINE SIMD_FN void v_halves(uvec a, vec* high, vec* low)
{
    *high = _mm512_cvtepu64_pd(u_srl(a, 32));
    *low = _mm512_cvtepu64_pd(u_and(a, u_splat(0xFFFFFFFFu)));
}
SP_INLINE SIMD_FN uvec u_from_v(vec x) { return _mm512_cvttpd_epu64(x); }

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

#include "codec_oss_wide_simd.h"
#endif
