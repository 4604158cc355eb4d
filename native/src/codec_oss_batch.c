/*
 * Vectorised batch encode and decode of OSS for K = 2..4 (AVX2, four vertices per step), and
 * the dispatch between it and the AVX-512 path (codec_oss_batch_avx512.c, eight per step).
 *
 * Results are bit-identical to the scalar path (sp_grid_quantize + sp_oss_pack, and
 * sp_oss_unpack + the double-to-float conversion of sp_decode_weights): the rounding runs in
 * double lanes with the scalar's exact operation order, and the OSS index arithmetic runs in
 * double lanes too, where every intermediate is an integer or a quarter below 2^50 and thus
 * exact in any order (Horner forms, explicit FMAs). Decode's layer and row *estimates* differ
 * from the scalar ones (no layer square root, no divisions, shifted arguments): exact integer
 * checks decide every lane. A lane whose inputs leave that exact regime (odd weights, a code
 * the estimate misses) is redone by the scalar code, so the fast path only ever has to be
 * right where it claims to be.
 *
 * The functions return how many leading vertices they handled (a multiple of the block size);
 * the caller's scalar loop does the rest, and all of it when the CPU has no AVX2 or the codec
 * is outside the exact range.
 */
#include <string.h>

#include "codec_internal.h"

/* Largest N per K for which every intermediate (numerators of u(k) and s_N(j), V of the layer
 * root, codes) stays below 2^50: K = 4 numerators are < 3N^3/8 + N^3/2, K = 3 ones < 3N^2. */
#define BATCH_MAX_N2 ((uint64_t)1 << 48)
#define BATCH_MAX_N3 ((uint64_t)1 << 23)
#define BATCH_MAX_N4 ((uint64_t)1 << 15)

/* Which configurations the vector path is exact for (shared by encode and decode). */
static int batch_supported(const sp_codec* codec)
{
    uint32_t k = codec->influences;
    if (codec->method != SP_METHOD_OSS || k < 2 || k > 4) return 0;
    uint64_t limit = k == 2 ? BATCH_MAX_N2 : (k == 3 ? BATCH_MAX_N3 : BATCH_MAX_N4);
    return codec->n >= 2 && codec->n <= limit;
}

#if (defined(__x86_64__) || defined(__i386__)) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#endif

/* The scalar encode of one vertex, as the batch loop in codec.c does it: the reference the
 * vector lanes fall back to. */
uint64_t sp_oss_encode_one(const sp_codec* codec, const float* weights, uint8_t* significant)
{
    uint64_t q[SP_MAX_INFLUENCES] = {0};
    uint32_t k = codec->influences;
    sp_grid_quantize(weights, k, codec->scale, q);
    if (significant) *significant = sp_grid_significant(q, k);
    return sp_oss_pack(codec->n, k, q);
}

#if (defined(__x86_64__) || defined(__i386__)) && (defined(__GNUC__) || defined(__clang__))

/* FMA3 comes with every AVX2 CPU but is a flag of its own (has_avx2 checks both). With it, both
 * compilers may fuse some multiplies and adds (GCC's gnu11 default contracts across
 * statements), which round differently from the scalar code: keep every product and sum
 * rounded on its own. Explicit FMA intrinsics appear only where the result is exact (the OSS
 * index arithmetic: integers and quarters below 2^50) or an estimate. */
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#else
#pragma GCC optimize("fp-contract=off")
#endif
#define SP_AVX2 __attribute__((target("avx2,fma")))
#define BLOCK 4
/* Blocks per stage. A block's whole encode or decode is one long dependency chain, and the
 * core keeps only a few blocks' worth of waiting operations in flight (on the Zen 5 EPYC
 * measured, a loop of independent 8-FMA chains runs at half the rate of the same FMAs in four
 * chains of two), so the work runs in stages of short chains, each over all blocks of a chunk
 * before the next: the blocks of one stage are independent, and the core overlaps them.
 * Splitting stages where chains are long paid: K = 4 encode ~1.5x (division, floors and
 * rounding apart, the scalar redo after them all), decode ~1.1x (see layer_estimate4). */
#define CHUNK 8
/* Decode's stages measured ~10% faster with 16 blocks than with 8 for K = 4, 32 no faster;
 * encode's no faster with 16. */
#define DECODE_CHUNK 16
/* Loops over the K components and the lanes: fully unrolled so the vectors stay in registers. */
#define UNROLL _Pragma("GCC unroll 4")

static inline SP_AVX2 __m256d splat(double x)
{
    return _mm256_set1_pd(x);
}

/* 0 <= x < 2^52, integral: to u64 by placing it in the mantissa of 2^52. */
static inline SP_AVX2 __m256i to_u64(__m256d x)
{
    __m256d magic = splat(4503599627370496.0);
    return _mm256_xor_si256(_mm256_castpd_si256(_mm256_add_pd(x, magic)), _mm256_castpd_si256(magic));
}

/* u64 < 2^52 to double, the inverse trick. */
static inline SP_AVX2 __m256d from_u64(__m256i x)
{
    __m256d magic = splat(4503599627370496.0);
    return _mm256_sub_pd(_mm256_castsi256_pd(_mm256_or_si256(x, _mm256_castpd_si256(magic))), magic);
}

/* s_B(j) = floor(((4B + 2 - 3j) j + 1) / 4) for rows inside the triangle (positive), as
 * floor((B + 1/2 - 3j/4) j + 1/4): every exact intermediate is a multiple of 1/4 below 2^50, so
 * each step, fused or not, is exact. */
static inline SP_AVX2 __m256d row_base4(__m256d b, __m256d j)
{
    __m256d quarter = _mm256_fnmadd_pd(j, splat(0.75), _mm256_add_pd(b, splat(0.5))); /* (4B + 2 - 3j) / 4 */
    return _mm256_floor_pd(_mm256_fmadd_pd(quarter, j, splat(0.25)));
}

/* u(k) = floor((3Nk(N - 2k + 3) + k((4k - 9)k + 6) + 2) / 9), for k <= (N + 1)/2, with the
 * numerator a in Horner form ((4k - 6N - 9) k + 3N^2 + 9N + 6) k + 2: integers below 2^50, so
 * exact, and the last step adds 1/2 as well: a = 9m + r with 0 <= r < 9 puts (a + 1/2) / 9 at
 * least 1/18 away from an integer, while the product with the rounded 1/9 is within
 * (a/9) 2^-52 < 1/36 of it, so its floor is the exact quotient m. */
static inline SP_AVX2 __m256d layer_base4(double n, __m256d k)
{
    __m256d a = _mm256_fmadd_pd(k, splat(4.0), splat(-(6 * n + 9)));
    __m256d b = _mm256_fmadd_pd(a, k, splat(3 * n * n + 9 * n + 6));
    return _mm256_floor_pd(_mm256_mul_pd(_mm256_fmadd_pd(b, k, splat(2.5)), splat(1.0 / 9.0)));
}

/* ---- encode ----------------------------------------------------------------------------- */

/* Component i of four consecutive vertices of k weights, widened to double (exact). */
static inline SP_AVX2 void load_block(const float* w, uint32_t k, __m256d* x)
{
    if (k == 4) {
        __m128 r0 = _mm_loadu_ps(w), r1 = _mm_loadu_ps(w + 4), r2 = _mm_loadu_ps(w + 8), r3 = _mm_loadu_ps(w + 12);
        _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
        x[0] = _mm256_cvtps_pd(r0);
        x[1] = _mm256_cvtps_pd(r1);
        x[2] = _mm256_cvtps_pd(r2);
        x[3] = _mm256_cvtps_pd(r3);
        return;
    }
    UNROLL
    for (uint32_t i = 0; i < k; ++i) x[i] = _mm256_cvtps_pd(_mm_setr_ps(w[i], w[k + i], w[2 * k + i], w[3 * k + i]));
}

/* sp_grid_quantize's s / sum of the weights, the first step of its fast path, for four lanes:
 * a stage of its own (see CHUNK), as the division ends a long chain. */
static inline SP_AVX2 __m256d quantize_scale(const __m256d* w, uint32_t k, double s)
{
    __m256d sum = _mm256_setzero_pd();
    UNROLL
    for (uint32_t i = 0; i < k; ++i) sum = _mm256_add_pd(sum, w[i]); /* 0 + w0 first: keeps -0 as the scalar does */
    return _mm256_div_pd(splat(s), sum);
}

/* sp_grid_quantize's floors x = max(w s / sum, 0) -> q = trunc(x), remainder = x - q, same
 * operations in the same order; returns the deficit s - sum of q. */
static inline SP_AVX2 __m256d quantize_floor(const __m256d* w, uint32_t k, double s, __m256d scale, __m256d* q,
                                             __m256d* remainder)
{
    __m256d deficit = splat(s);
    UNROLL
    for (uint32_t i = 0; i < k; ++i) {
        /* max(x, 0) returns its second operand for NaN: x > 0 ? x : 0, as in the scalar */
        __m256d x = _mm256_max_pd(_mm256_mul_pd(w[i], scale), _mm256_setzero_pd());
        q[i] = _mm256_round_pd(x, _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC);
        remainder[i] = _mm256_sub_pd(x, q[i]);
        deficit = _mm256_sub_pd(deficit, q[i]);
    }
    return deficit;
}

/*
 * sp_grid_quantize's last step in four lanes: the deficit goes, one each, to the components
 * with the largest remainders (ties to the lower index). Returns the mask of lanes the fast
 * path is exact for: a deficit in [0, k), where the scalar takes the same path. That also
 * bounds every x by s + 1, so floors and deficit are exact: an x past that makes the deficit
 * negative, and one past 2^53 (or infinite) keeps it so under rounding.
 */
static inline SP_AVX2 __m256d quantize_round(uint32_t k, __m256d deficit, const __m256d* remainder, __m256d* q)
{
    __m256i rank[SP_MAX_INFLUENCES];
    UNROLL
    for (uint32_t i = 0; i < k; ++i) rank[i] = _mm256_set1_epi64x((int64_t)(k - 1 - i)); /* every later slot beats i ... */
    /* ... unless i wins against it; and an earlier slot beats i when it wins. A compare mask is
     * -1 where a wins, so rank[a] adds it and rank[b] subtracts it. */
    UNROLL
    for (uint32_t a = 0; a < k; ++a) {
        UNROLL
        for (uint32_t b = a + 1; b < k; ++b) {
            __m256i a_wins = _mm256_castpd_si256(_mm256_cmp_pd(remainder[a], remainder[b], _CMP_GE_OQ));
            rank[a] = _mm256_add_epi64(rank[a], a_wins);
            rank[b] = _mm256_sub_epi64(rank[b], a_wins);
        }
    }
    __m256d ok = _mm256_and_pd(_mm256_cmp_pd(deficit, _mm256_setzero_pd(), _CMP_GE_OQ),
                               _mm256_cmp_pd(deficit, splat((double)k), _CMP_LT_OQ));
    __m256i bumps = to_u64(_mm256_and_pd(deficit, ok)); /* 0..k-1 where ok */
    UNROLL
    for (uint32_t i = 0; i < k; ++i)
        q[i] = _mm256_add_pd(q[i], _mm256_and_pd(_mm256_castsi256_pd(_mm256_cmpgt_epi64(bumps, rank[i])), splat(1.0)));
    return ok;
}

/* sp_oss_pack on sorted lanes (the caller masks unsorted ones: the scalar wraps around there). */
static inline SP_AVX2 __m256d pack_block(const __m256d* q, uint32_t k, double n)
{
    if (k == 2) return q[1];
    if (k == 3) return _mm256_add_pd(row_base4(splat(n), q[2]), _mm256_sub_pd(q[1], q[2]));
    __m256d layer = q[3], bottom = _mm256_fnmadd_pd(layer, splat(2.0), splat(n));
    __m256d row = row_base4(bottom, _mm256_sub_pd(q[2], q[3]));
    return _mm256_add_pd(_mm256_add_pd(layer_base4(n, layer), row), _mm256_sub_pd(q[1], q[2]));
}

/* Significant counts of four sorted lanes: 1 + the non-zero components after the first. */
static inline SP_AVX2 void store_significant(const __m256d* q, uint32_t k, uint8_t* out)
{
    __m256d count = splat(1.0);
    UNROLL
    for (uint32_t i = 1; i < k; ++i)
        count = _mm256_add_pd(count, _mm256_and_pd(_mm256_cmp_pd(q[i], _mm256_setzero_pd(), _CMP_GT_OQ), splat(1.0)));
    __m128i bytes = _mm_shuffle_epi8(_mm256_cvtpd_epi32(count), _mm_setr_epi8(0, 4, 8, 12, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1));
    int32_t packed = _mm_cvtsi128_si32(bytes);
    memcpy(out, &packed, sizeof(packed));
}

/* Encodes `blocks` (<= CHUNK) blocks in stages (see CHUNK): the quantisation's division,
 * its rest, the indices, and the scalar redo of the lanes the vector code cannot prove exact. */
static inline __attribute__((always_inline)) SP_AVX2 void encode_chunk(const sp_codec* codec, const float* weights,
                                                                       size_t blocks, uint64_t* codes,
                                                                       uint8_t* significant, uint32_t k)
{
    double s = (double)codec->scale, n = (double)codec->n;
    __m256d w[CHUNK][SP_MAX_INFLUENCES], scale[CHUNK], deficit[CHUNK];
    __m256d q[CHUNK][SP_MAX_INFLUENCES], remainder[CHUNK][SP_MAX_INFLUENCES];
    int missed[CHUNK]; /* lanes as bits */
    for (size_t b = 0; b < blocks; ++b) {
        load_block(weights + b * BLOCK * k, k, w[b]);
        scale[b] = quantize_scale(w[b], k, s);
    }
    for (size_t b = 0; b < blocks; ++b) deficit[b] = quantize_floor(w[b], k, s, scale[b], q[b], remainder[b]);
    for (size_t b = 0; b < blocks; ++b) {
        __m256d ok = quantize_round(k, deficit[b], remainder[b], q[b]);
        UNROLL
        for (uint32_t i = 1; i < k; ++i) ok = _mm256_and_pd(ok, _mm256_cmp_pd(q[b][i - 1], q[b][i], _CMP_GE_OQ));
        missed[b] = ~_mm256_movemask_pd(ok) & 15;
    }
    for (size_t b = 0; b < blocks; ++b) {
        _mm256_storeu_si256((__m256i*)(codes + b * BLOCK), to_u64(pack_block(q[b], k, n)));
        if (significant) store_significant(q[b], k, significant + b * BLOCK);
    }
    /* The scalar redo in a pass of its own, as in decode_chunk. */
    for (size_t b = 0; b < blocks; ++b) {
        int slow = missed[b];
        for (size_t lane = b * BLOCK; slow; ++lane, slow >>= 1)
            if (slow & 1) codes[lane] = sp_oss_encode_one(codec, weights + lane * k, significant ? significant + lane : NULL);
    }
}

static inline __attribute__((always_inline)) SP_AVX2 size_t encode_blocks(const sp_codec* codec, const float* weights,
                                                                          size_t count, uint64_t* codes,
                                                                          uint8_t* significant, uint32_t k)
{
    size_t v = 0;
    for (; v + CHUNK * BLOCK <= count; v += CHUNK * BLOCK)
        encode_chunk(codec, weights + v * k, CHUNK, codes + v, significant ? significant + v : NULL, k);
    size_t blocks = (count - v) / BLOCK;
    if (blocks) encode_chunk(codec, weights + v * k, blocks, codes + v, significant ? significant + v : NULL, k);
    return v + blocks * BLOCK;
}

static SP_AVX2 size_t encode_avx2(const sp_codec* codec, const float* weights, size_t count, uint64_t* codes,
                                  uint8_t* significant)
{
    switch (codec->influences) { /* constant k: unrolled lanes */
    case 2: return encode_blocks(codec, weights, count, codes, significant, 2);
    case 3: return encode_blocks(codec, weights, count, codes, significant, 3);
    default: return encode_blocks(codec, weights, count, codes, significant, 4);
    }
}

/* ---- decode ----------------------------------------------------------------------------- */

/*
 * The layer estimate, oss_find_layer's (2N + 3 - t) / 4 with t = c + 1/c,
 * c = cbrt(V - 1 + sqrt(V (V - 2))), for code + 17/18 instead of code, floored and clamped to
 * the layers. V = 72 (u~(k0) - code) with k0 = (N + 1)/2 and u~ the unfloored u
 * (u~(k) - u(k) in [0, 8/9]), which increases up to k0, so every code of layer k plus 17/18 lies
 * strictly between u~(k) and u~(k + 1) (the same shift as the row estimate's 7/8) and in exact
 * arithmetic the estimate is the layer; it also keeps V >= 4 for valid codes.
 * c^3 + 1/c^3 = 2(V - 1) = x, so t is the root t >= 2 of t^3 - 3t = x, and cbrt(x) + 1/cbrt(x)
 * is within c^-5/3 of it (below 1e-6 but for the last few codes, where x < 2000), which skips
 * oss_find_layer's square root. (The AVX-512 path computes the same estimate, another way.)
 *
 * cbrt comes without a division or square root (AVX2 has no rcp14 for doubles), as z ~ 1/c:
 * the exponent/3 bit trick for x^(-1/3) (3.4%) and a third-order step z (1 + r/3 + 2r^2/9)
 * with r = 1 - x z^3, in float (~1e-4); then, in double, what a Newton step z' = z (1 + r/3),
 * c' = x z'^2 would give: c' + z' = c + z + r (2c + z) / 3 up to r^2 terms (c = x z^2), one
 * FMA after r, to ~1e-8. That puts ~1e-5 of random codes at 22 bits (~5e-4 at the largest N)
 * in the wrong layer, codes within that error of a layer boundary, and the scalar code redoes
 * them. The float part and the double part are stages of their own over the blocks of a chunk
 * (see CHUNK): ~10% faster than one stage of the whole chain.
 */

/* x = 2(V - 1) for code + 17/18: an integer below 2^49, so the fused product is exact. */
static inline SP_AVX2 __m256d layer_argument4(double n, __m256d code)
{
    double m = n + 1;
    return _mm256_fnmadd_pd(code, splat(144.0), splat(8 * m * m * m + 12 * m * m - 106));
}

/* z ~ x^(-1/3) to ~1e-4 in float: the bit trick and the third-order step. */
static inline SP_AVX2 __m128 inverse_cube_root4(__m256d x)
{
    __m128 xf = _mm256_cvtpd_ps(x);
    __m128i third = _mm_cvttps_epi32(_mm_mul_ps(_mm_cvtepi32_ps(_mm_castps_si128(xf)), _mm_set1_ps(1.0f / 3.0f)));
    __m128 z = _mm_castsi128_ps(_mm_sub_epi32(_mm_set1_epi32(1419916032), third));
    __m128 r = _mm_fnmadd_ps(_mm_mul_ps(xf, z), _mm_mul_ps(z, z), _mm_set1_ps(1.0f)); /* x z and z^2 side by side */
    return _mm_fmadd_ps(_mm_mul_ps(z, r), _mm_fmadd_ps(r, _mm_set1_ps(2.0f / 9.0f), _mm_set1_ps(1.0f / 3.0f)), z);
}

/* floor(e) clamped to [0, top]; NaN becomes 0 (max returns its second operand). */
static inline SP_AVX2 __m256d clamp_floor(__m256d e, __m256d top)
{
    return _mm256_min_pd(_mm256_max_pd(_mm256_floor_pd(e), _mm256_setzero_pd()), top);
}

/* The layer from x and z ~ x^(-1/3): the Newton-corrected c + z, then (2N + 3 - t) / 4. */
static inline SP_AVX2 __m256d layer_estimate4(double n, __m256d x, __m128 zf)
{
    __m256d z = _mm256_cvtps_pd(zf), xz = _mm256_mul_pd(x, z);
    __m256d r = _mm256_fnmadd_pd(xz, _mm256_mul_pd(z, z), splat(1.0));
    __m256d c = _mm256_mul_pd(xz, z);
    __m256d slope = _mm256_fmadd_pd(c, splat(2.0 / 3.0), _mm256_mul_pd(z, splat(1.0 / 3.0)));
    __m256d t = _mm256_fmadd_pd(r, slope, _mm256_add_pd(c, z));
    __m256d estimate = _mm256_fnmadd_pd(t, splat(0.25), splat((2 * n + 3) / 4));
    return clamp_floor(estimate, splat((double)(((uint64_t)n + 1) / 2 - 1)));
}

/* oss_find_row's mirrored square root estimate for w + 7/8 instead of w in the triangle with
 * B = `bottom` samples along its bottom edge, floored and clamped to j >= 0. s(j) = floor(s~(j))
 * with s~(j) - s(j) in {0, 1/4, 1/2, 3/4}, so w + 7/8 lies strictly between s~(j) and
 * s~(j + 1) for every w of row j, and in exact arithmetic the estimate is the row. With
 * apex = 2B + 1, 12 (w + 7/8) = 12 w + 10.5: mirrored = apex^2 + 3 - 10.5 - 12 w. The correctly
 * rounded sqrt keeps the rounding error far below the 1/8 margin up to the largest N. No clamp
 * to the last row: the estimate is at most apex / 3 < rows + 1, and row_offset4 rejects
 * j = rows (a row of no codes). */
static inline SP_AVX2 __m256d row_estimate4(__m256d bottom, __m256d w)
{
    __m256d apex = _mm256_fmadd_pd(bottom, splat(2.0), splat(1.0));
    __m256d mirrored = _mm256_fnmadd_pd(w, splat(12.0), _mm256_fmsub_pd(apex, apex, splat(7.5)));
    __m256d estimate = _mm256_mul_pd(_mm256_sub_pd(apex, _mm256_sqrt_pd(mirrored)), splat(1.0 / 3.0));
    return _mm256_max_pd(_mm256_floor_pd(estimate), _mm256_setzero_pd());
}

/* i = w - s(j), with *missed the lanes (as bits) where j is not w's row, that is where i is
 * not in [0, floor((2B - 3j) / 2)), the length of row j (none for j >= rows): for integral i
 * that is 0 <= i <= B - 1 - 3j/2. Exact: integers and halves below 2^50, and x - x is +0, so
 * the sign bits of i and of (B - 1 - 3j/2) - i flag the misses. */
static inline SP_AVX2 __m256d row_offset4(__m256d bottom, __m256d j, __m256d w, int* missed)
{
    __m256d i = _mm256_sub_pd(w, row_base4(bottom, j));
    __m256d last = _mm256_fnmadd_pd(j, splat(1.5), _mm256_sub_pd(bottom, splat(1.0)));
    *missed = _mm256_movemask_pd(_mm256_or_pd(i, _mm256_sub_pd(last, i)));
    return i;
}

/* (float)(q * (1/s)) per component, as grid_to_weights does, stored as four vertices. */
static inline SP_AVX2 void store_block(const __m256d* q, uint32_t k, double inverse, float* out)
{
    __m128 w[SP_MAX_INFLUENCES];
    UNROLL
    for (uint32_t i = 0; i < k; ++i) w[i] = _mm256_cvtpd_ps(_mm256_mul_pd(q[i], splat(inverse)));
    if (k == 4) { /* a 4x4 transpose in two registers: six shuffles, not eight, and two stores */
        __m256 even = _mm256_insertf128_ps(_mm256_castps128_ps256(w[0]), w[2], 1); /* components 0 | 2 */
        __m256 odd = _mm256_insertf128_ps(_mm256_castps128_ps256(w[1]), w[3], 1);  /* components 1 | 3 */
        /* pairs (c0, c1) of vertices 0, 1 | (c2, c3) of vertices 0, 1, then the same for 2, 3 */
        __m256d lo = _mm256_castps_pd(_mm256_unpacklo_ps(even, odd)), hi = _mm256_castps_pd(_mm256_unpackhi_ps(even, odd));
        _mm256_storeu_ps(out, _mm256_castpd_ps(_mm256_permute4x64_pd(lo, 0xD8)));     /* vertices 0, 1 */
        _mm256_storeu_ps(out + 8, _mm256_castpd_ps(_mm256_permute4x64_pd(hi, 0xD8))); /* vertices 2, 3 */
        return;
    }
    float lanes[SP_MAX_INFLUENCES][BLOCK];
    UNROLL
    for (uint32_t i = 0; i < k; ++i) _mm_storeu_ps(lanes[i], w[i]);
    UNROLL
    for (uint32_t lane = 0; lane < BLOCK; ++lane) {
        UNROLL
        for (uint32_t i = 0; i < k; ++i) out[lane * k + i] = lanes[i][lane];
    }
}

/* The layer stages of decode_chunk for `blocks` blocks of codes (as doubles). */
static inline __attribute__((always_inline)) SP_AVX2 void decode_layers(double n, const __m256d* code, size_t blocks,
                                                                        __m256d* layer)
{
    __m256d x[DECODE_CHUNK];
    __m128 z[DECODE_CHUNK];
    for (size_t b = 0; b < blocks; ++b) {
        x[b] = layer_argument4(n, code[b]);
        z[b] = inverse_cube_root4(x[b]);
    }
    for (size_t b = 0; b < blocks; ++b) layer[b] = layer_estimate4(n, x[b], z[b]);
}

/* sp_oss_unpack's sorted grid components for K = 3, 4 from the layer (0 for K = 3), row j and
 * offset i: integers below 2^50, so exact in any order. */
static inline SP_AVX2 void unpacked_block(double n, uint32_t k, __m256d layer, __m256d row, __m256d i, __m256d* q)
{
    __m256d grid = splat(2 * (n - 1));
    if (k == 4) q[3] = layer;
    q[2] = _mm256_add_pd(row, layer);
    q[1] = _mm256_add_pd(i, q[2]);
    __m256d sum = _mm256_add_pd(q[1], q[2]);
    q[0] = _mm256_sub_pd(grid, k == 4 ? _mm256_add_pd(sum, layer) : sum);
}

/* The scalar redo of the lanes the vector code could not prove exact (bits of missed[b]), in a
 * pass of its own after the vector ones: a call inside those would clobber every vector
 * register, and the loop would reload its constants on each block. */
static void decode_missed(const sp_codec* codec, const uint64_t* codes, const int* missed, size_t blocks,
                          float* weights)
{
    uint32_t k = codec->influences;
    for (size_t b = 0; b < blocks; ++b)
        for (size_t lane = b * BLOCK, slow = (size_t)missed[b]; slow; ++lane, slow >>= 1)
            if (slow & 1) sp_decode_weights(codec, codes[lane], weights + lane * k);
}

/* sp_oss_unpack and grid_to_weights for `blocks` blocks of codes <= max_code, in stages, each
 * run over all blocks of a chunk before the next (see CHUNK). Every array entry is written in
 * a stage before a later one reads it (initialising them up front cost a block fill a chunk).
 *
 * The layer needs no check of its own: with k clamped to the layers, the row check accepts
 * only a rest = code - u(k) inside layer k's triangle (a negative rest fails s(j) <= rest, one
 * past the triangle fails rest < s(j + 1) for every row, row j >= rows has s(j + 1) <= s(j)),
 * and then (k, row, i) is the one tuple whose index is code. */
static inline __attribute__((always_inline)) SP_AVX2 void decode_chunk(const sp_codec* codec, const uint64_t* codes,
                                                                       size_t blocks, float* weights, uint32_t k)
{
    double n = (double)codec->n, inverse = 1.0 / (double)codec->scale;
    __m256d layer[DECODE_CHUNK], rest[DECODE_CHUNK], bottom[DECODE_CHUNK], row[DECODE_CHUNK];
    int missed[DECODE_CHUNK] = {0}; /* lanes as bits */
    for (size_t b = 0; b < blocks; ++b) rest[b] = from_u64(_mm256_loadu_si256((const __m256i*)(codes + b * BLOCK)));
    if (k == 4) decode_layers(n, rest, blocks, layer);
    if (k > 2)
        for (size_t b = 0; b < blocks; ++b) {
            if (k == 4) {
                rest[b] = _mm256_sub_pd(rest[b], layer_base4(n, layer[b]));
                bottom[b] = _mm256_fnmadd_pd(layer[b], splat(2.0), splat(n));
            } else {
                layer[b] = _mm256_setzero_pd();
                bottom[b] = splat(n);
            }
            row[b] = row_estimate4(bottom[b], rest[b]);
        }
    for (size_t b = 0; b < blocks; ++b) {
        __m256d q[SP_MAX_INFLUENCES];
        if (k == 2) {
            q[1] = rest[b];
            q[0] = _mm256_sub_pd(splat(2 * (n - 1)), rest[b]);
        } else {
            __m256d i = row_offset4(bottom[b], row[b], rest[b], &missed[b]);
            unpacked_block(n, k, layer[b], row[b], i, q);
        }
        store_block(q, k, inverse, weights + b * BLOCK * k);
    }
    decode_missed(codec, codes, missed, blocks, weights);
}

/* How many of the first `blocks` blocks hold only codes <= max_code. */
static inline SP_AVX2 size_t valid_blocks(const sp_codec* codec, const uint64_t* codes, size_t blocks)
{
    /* unsigned code <= max_code as a signed compare of both with the sign bit flipped */
    __m256i flip = _mm256_set1_epi64x(INT64_MIN), top = _mm256_set1_epi64x((int64_t)(codec->max_code ^ (uint64_t)INT64_MIN));
    for (size_t b = 0; b < blocks; ++b) {
        __m256i raw = _mm256_loadu_si256((const __m256i*)(codes + b * BLOCK));
        if (!_mm256_testz_si256(_mm256_cmpgt_epi64(_mm256_xor_si256(raw, flip), top), _mm256_set1_epi64x(-1))) return b;
    }
    return blocks;
}

static inline __attribute__((always_inline)) SP_AVX2 size_t decode_blocks(const sp_codec* codec, const uint64_t* codes,
                                                                          size_t count, float* weights, uint32_t k)
{
    size_t v = 0;
    while (v + BLOCK <= count) {
        size_t blocks = (count - v) / BLOCK;
        blocks = valid_blocks(codec, codes + v, blocks < DECODE_CHUNK ? blocks : DECODE_CHUNK);
        if (blocks == 0) break; /* an invalid code: the scalar loop reports the first one */
        decode_chunk(codec, codes + v, blocks, weights + v * k, k);
        v += blocks * BLOCK;
    }
    return v;
}

static SP_AVX2 size_t decode_avx2(const sp_codec* codec, const uint64_t* codes, size_t count, float* weights)
{
    switch (codec->influences) {
    case 2: return decode_blocks(codec, codes, count, weights, 2);
    case 3: return decode_blocks(codec, codes, count, weights, 3);
    default: return decode_blocks(codec, codes, count, weights, 4);
    }
}

/* AVX2 and FMA3: the path uses explicit FMAs (see SP_AVX2). */
static int has_avx2(void)
{
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}
#else
static size_t encode_avx2(const sp_codec* codec, const float* weights, size_t count, uint64_t* codes,
                          uint8_t* significant)
{
    (void)codec, (void)weights, (void)count, (void)codes, (void)significant;
    return 0;
}
static size_t decode_avx2(const sp_codec* codec, const uint64_t* codes, size_t count, float* weights)
{
    (void)codec, (void)codes, (void)count, (void)weights;
    return 0;
}
static int has_avx2(void)
{
    return 0;
}
#endif

/* The widest path this CPU and the caller allow (__builtin_cpu_supports reads a cached word). */
static sp_oss_isa batch_isa(sp_oss_isa widest)
{
    sp_oss_isa cpu = sp_oss_has_avx512() ? SP_OSS_ISA_AVX512 : (has_avx2() ? SP_OSS_ISA_AVX2 : SP_OSS_ISA_SCALAR);
    return cpu < widest ? cpu : widest;
}

/* AVX-512 takes blocks of 8, AVX2 what is left in blocks of 4 (the tail, or the rest after a
 * block the AVX-512 loop stopped at), the scalar loop in codec.c the remainder. Nothing left:
 * no AVX2 call, whose pointer arithmetic on the null arrays of an empty batch is undefined. */
size_t sp_oss_encode_batch(const sp_codec* codec, const float* weights, size_t count, uint64_t* codes,
                           uint8_t* significant, sp_oss_isa widest)
{
    sp_oss_isa isa = batch_supported(codec) ? batch_isa(widest) : SP_OSS_ISA_SCALAR;
    size_t done = 0;
    if (isa >= SP_OSS_ISA_AVX512) done = sp_oss_encode_avx512(codec, weights, count, codes, significant);
    if (isa >= SP_OSS_ISA_AVX2 && done < count)
        done += encode_avx2(codec, weights + done * codec->influences, count - done, codes + done,
                            significant ? significant + done : NULL);
    return done;
}

size_t sp_oss_decode_batch(const sp_codec* codec, const uint64_t* codes, size_t count, float* weights,
                           sp_oss_isa widest)
{
    sp_oss_isa isa = batch_supported(codec) ? batch_isa(widest) : SP_OSS_ISA_SCALAR;
    size_t done = 0;
    if (isa >= SP_OSS_ISA_AVX512) done = sp_oss_decode_avx512(codec, codes, count, weights);
    if (isa >= SP_OSS_ISA_AVX2 && done < count)
        done += decode_avx2(codec, codes + done, count - done, weights + done * codec->influences);
    return done;
}
