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

typedef __m512i ivec;
typedef __mmask8 imask;

#define i_srl(a, n) _mm512_srli_epi64(a, n)
#define i_sll(a, n) _mm512_slli_epi64(a, n)
SP_INLINE SIMD_FN ivec i_splat(uint64_t x) { return _mm512_set1_epi64((int64_t)x); }
SP_INLINE SIMD_FN ivec i_load(const uint64_t* p) { return _mm512_loadu_si512(p); }
SP_INLINE SIMD_FN void i_store(uint64_t* p, ivec a) { _mm512_storeu_si512(p, a); }
SP_INLINE SIMD_FN ivec i_add(ivec a, ivec b) { return _mm512_add_epi64(a, b); }
SP_INLINE SIMD_FN ivec i_sub(ivec a, ivec b) { return _mm512_sub_epi64(a, b); }
SP_INLINE SIMD_FN ivec i_and(ivec a, ivec b) { return _mm512_and_si512(a, b); }
SP_INLINE SIMD_FN ivec i_srlv(ivec a, ivec count) { return _mm512_srlv_epi64(a, count); }
SP_INLINE SIMD_FN ivec i_mul32(ivec a, ivec b) { return _mm512_mul_epu32(a, b); }
SP_INLINE SIMD_FN ivec i_mul(ivec a, ivec b) { return _mm512_mullo_epi64(a, b); }
SP_INLINE SIMD_FN ivec i_mul_u32(ivec a, ivec b) { return i_mul(a, b); }
SP_INLINE SIMD_FN imask i_lt(ivec a, ivec b) { return _mm512_cmplt_epu64_mask(a, b); }
SP_INLINE SIMD_FN imask i_lt_small(ivec a, ivec b) { return _mm512_cmplt_epi64_mask(a, b); }
SP_INLINE SIMD_FN ivec i_select(imask m, ivec a, ivec b) { return _mm512_mask_blend_epi64(m, b, a); }
SP_INLINE SIMD_FN unsigned im_bits(imask m) { return m; }
SP_INLINE SIMD_FN vec v_from_i(ivec a) { return _mm512_cvtepu64_pd(a); }
SP_INLINE SIMD_FN vec v_from_i_rounded(ivec a) { return _mm512_cvtepu64_pd(a); } /* rounded to nearest */
SP_INLINE SIMD_FN void v_halves(ivec a, vec* high, vec* low)
{
    *high = _mm512_cvtepu64_pd(i_srl(a, 32));
    *low = _mm512_cvtepu64_pd(i_and(a, i_splat(0xFFFFFFFFu)));
}
SP_INLINE SIMD_FN ivec i_from_v(vec x) { return _mm512_cvttpd_epu64(x); }

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
