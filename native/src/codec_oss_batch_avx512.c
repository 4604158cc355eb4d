/*
 * AVX-512 batch encode and decode of OSS for K = 2..4: codec_oss_batch.c's AVX2 path with
 * eight double lanes, compare masks in mask registers, and the AoS weights moved in and out
 * with two-source permutes instead of per-lane inserts and extracts.
 *
 * Same rounding steps in the same order as the AVX2 path (and so as the scalar code) for every
 * value that reaches the output, the same exactness argument (integers below 2^50 in double
 * lanes) and the same rule: a lane the vector code cannot prove exact is redone by the scalar
 * code. See codec_oss_batch.c. The OSS index arithmetic may take other forms (Horner, explicit
 * FMAs): its every intermediate is an integer or a quarter below 2^50, exact in any order. And
 * decode's layer and row *estimates* differ (rcp14, shifted arguments, no layer square root):
 * the exact integer checks decide every lane.
 */
#include "codec_internal.h"

#if (defined(__x86_64__) || defined(__i386__)) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>

/* avx512f implies fma, and both compilers then fuse some multiplies and adds (GCC's gnu11
 * default contracts across statements), which round differently from the scalar code: keep
 * every product and sum rounded on its own. Explicit FMA intrinsics appear only where the
 * result is exact or an estimate. */
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#else
#pragma GCC optimize("fp-contract=off")
#endif
#define SP_AVX512 __attribute__((target("avx512f,avx512dq,avx512vl")))
#define BLOCK 8
/* Blocks per stage (see CHUNK in codec_oss_batch.c): enough independent blocks per stage for
 * the core to overlap the long dependency chains (division, root estimates) of one block with
 * the others; 4 was ~20% slower for K = 4 decode on Zen 4, 16 no faster than 8. */
#define CHUNK 8
#define UNROLL _Pragma("GCC unroll 4")

static inline SP_AVX512 __m512d splat(double x)
{
    return _mm512_set1_pd(x);
}

static inline SP_AVX512 __m512d floor8(__m512d x)
{
    return _mm512_roundscale_pd(x, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
}

/* s_B(j) = floor(((4B + 2 - 3j) j + 1) / 4) for rows inside the triangle (positive), as
 * floor((B + 1/2 - 3j/4) j + 1/4): every exact intermediate is a multiple of 1/4 below 2^50, so
 * each step, fused or not, is exact. */
static inline SP_AVX512 __m512d row_base8(__m512d b, __m512d j)
{
    __m512d quarter = _mm512_fnmadd_pd(j, splat(0.75), _mm512_add_pd(b, splat(0.5))); /* (4B + 2 - 3j) / 4 */
    return floor8(_mm512_fmadd_pd(quarter, j, splat(0.25)));
}

/* u(k) = floor((3Nk(N - 2k + 3) + k((4k - 9)k + 6) + 2) / 9), for k <= (N + 1)/2, with the
 * numerator a in Horner form ((4k - 6N - 9) k + 3N^2 + 9N + 6) k + 2: integers below 2^50, so
 * exact, and the last step adds 1/2 as well for floor((a + 1/2) / 9) (exact: see layer_base4 in
 * the AVX2 path). */
static inline SP_AVX512 __m512d layer_base8(double n, __m512d k)
{
    __m512d a = _mm512_fmadd_pd(k, splat(4.0), splat(-(6 * n + 9)));
    __m512d b = _mm512_fmadd_pd(a, k, splat(3 * n * n + 9 * n + 6));
    return floor8(_mm512_mul_pd(_mm512_fmadd_pd(b, k, splat(2.5)), splat(1.0 / 9.0)));
}

/* ---- AoS <-> SoA ------------------------------------------------------------------------ */

/* Permute indices between 8 vertices of k floats (AoS, as two 16-float registers: floats
 * 0..15 and floats 8k-16..8k-1, overlapping for k < 4) and component pairs (c, c + 1) of the
 * 8 vertices (SoA, one register per pair: component c in the low half). */
static inline SP_AVX512 __m512i soa_index(uint32_t k, uint32_t pair)
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
static inline SP_AVX512 __m512i aos_index(uint32_t k, uint32_t half)
{
    int32_t index[16];
    for (uint32_t lane = 0; lane < 16; ++lane) {
        uint32_t f = 16 * half + lane, v = f / k, c = f % k;
        index[lane] = (int32_t)(v < 8 ? (c / 2) * 16 + (c % 2) * 8 + v : 0);
    }
    return _mm512_loadu_si512(index);
}

/* Component i of eight consecutive vertices of k weights, widened to double (exact). */
static inline SP_AVX512 void load_block8(const float* w, uint32_t k, const __m512i* index, __m512d* x)
{
    __m512 lo = _mm512_loadu_ps(w), hi = _mm512_loadu_ps(w + 8 * k - 16);
    UNROLL
    for (uint32_t pair = 0; 2 * pair < k; ++pair) {
        __m512 p = _mm512_permutex2var_ps(lo, index[pair], hi);
        x[2 * pair] = _mm512_cvtps_pd(_mm512_castps512_ps256(p));
        if (2 * pair + 1 < k) x[2 * pair + 1] = _mm512_cvtps_pd(_mm512_extractf32x8_ps(p, 1));
    }
}

/* (float)(q * (1/s)) per component, as grid_to_weights does, stored as eight vertices. */
static inline SP_AVX512 void store_block8(const __m512d* q, uint32_t k, double inverse, const __m512i* index,
                                          float* out)
{
    __m512 pair[2] = {_mm512_setzero_ps(), _mm512_setzero_ps()};
    UNROLL
    for (uint32_t i = 0; i < k; ++i) {
        __m256 w = _mm512_cvtpd_ps(_mm512_mul_pd(q[i], splat(inverse)));
        pair[i / 2] = i % 2 ? _mm512_insertf32x8(pair[i / 2], w, 1) : _mm512_castps256_ps512(w);
    }
    _mm512_storeu_ps(out, _mm512_permutex2var_ps(pair[0], index[0], pair[1]));
    if (k > 2) _mm512_mask_storeu_ps(out + 16, (__mmask16)(k == 4 ? 0xFFFF : 0x00FF), _mm512_permutex2var_ps(pair[0], index[1], pair[1]));
}

/* ---- encode ----------------------------------------------------------------------------- */

/* sp_grid_quantize's fast path in eight lanes, same operations in the same order; returns the
 * mask of lanes with a deficit in [0, k), where the scalar takes the same path (see
 * quantize_round in the AVX2 path for why that also makes every step exact). */
static inline SP_AVX512 __mmask8 quantize_block8(const __m512d* w, uint32_t k, double s, __m512d* q)
{
    __m512d zero = _mm512_setzero_pd(), grid = splat(s), one = splat(1.0);
    __m512d sum = zero, remainder[SP_MAX_INFLUENCES];
    __m512i rank[SP_MAX_INFLUENCES], step = _mm512_set1_epi64(1);
    UNROLL
    for (uint32_t i = 0; i < k; ++i) sum = _mm512_add_pd(sum, w[i]); /* 0 + w0 first: keeps -0 as the scalar does */
    __m512d scale = _mm512_div_pd(grid, sum);
    __m512d deficit = grid;
    UNROLL
    for (uint32_t i = 0; i < k; ++i) {
        /* max(x, 0) returns its second operand for NaN: x > 0 ? x : 0, as in the scalar */
        __m512d x = _mm512_max_pd(_mm512_mul_pd(w[i], scale), zero);
        q[i] = _mm512_roundscale_pd(x, _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC);
        remainder[i] = _mm512_sub_pd(x, q[i]);
        deficit = _mm512_sub_pd(deficit, q[i]);
        rank[i] = _mm512_set1_epi64((int64_t)(k - 1 - i)); /* every later slot beats i ... */
    }
    /* ... unless i wins against it; an earlier slot a beats b when it wins. */
    UNROLL
    for (uint32_t a = 0; a < k; ++a) {
        UNROLL
        for (uint32_t b = a + 1; b < k; ++b) {
            __mmask8 a_wins = _mm512_cmp_pd_mask(remainder[a], remainder[b], _CMP_GE_OQ);
            rank[a] = _mm512_mask_sub_epi64(rank[a], a_wins, rank[a], step);
            rank[b] = _mm512_mask_add_epi64(rank[b], a_wins, rank[b], step);
        }
    }
    __mmask8 ok = _mm512_cmp_pd_mask(deficit, zero, _CMP_GE_OQ) & _mm512_cmp_pd_mask(deficit, splat((double)k), _CMP_LT_OQ);
    __m512i bumps = _mm512_cvttpd_epu64(_mm512_maskz_mov_pd(ok, deficit)); /* 0..k-1 where ok */
    UNROLL
    for (uint32_t i = 0; i < k; ++i) q[i] = _mm512_mask_add_pd(q[i], _mm512_cmpgt_epi64_mask(bumps, rank[i]), q[i], one);
    return ok;
}

/* sp_oss_pack on sorted lanes (the caller masks unsorted ones: the scalar wraps around there). */
static inline SP_AVX512 __m512d pack_block8(const __m512d* q, uint32_t k, double n)
{
    if (k == 2) return q[1];
    if (k == 3) return _mm512_add_pd(row_base8(splat(n), q[2]), _mm512_sub_pd(q[1], q[2]));
    __m512d layer = q[3], bottom = _mm512_fnmadd_pd(layer, splat(2.0), splat(n));
    __m512d row = row_base8(bottom, _mm512_sub_pd(q[2], q[3]));
    return _mm512_add_pd(_mm512_add_pd(layer_base8(n, layer), row), _mm512_sub_pd(q[1], q[2]));
}

/* Significant counts of eight sorted lanes: 1 + the non-zero components after the first. */
static inline SP_AVX512 void store_significant8(const __m512d* q, uint32_t k, uint8_t* out)
{
    __m512i count = _mm512_set1_epi64(1), step = _mm512_set1_epi64(1);
    UNROLL
    for (uint32_t i = 1; i < k; ++i)
        count = _mm512_mask_add_epi64(count, _mm512_cmp_pd_mask(q[i], _mm512_setzero_pd(), _CMP_GT_OQ), count, step);
    _mm_storel_epi64((__m128i*)out, _mm512_cvtepi64_epi8(count));
}

static inline __attribute__((always_inline)) SP_AVX512 void encode_chunk8(const sp_codec* codec, const float* weights,
                                                                          size_t blocks, uint64_t* codes,
                                                                          uint8_t* significant, uint32_t k)
{
    double s = (double)codec->scale, n = (double)codec->n;
    __m512i index[2] = {soa_index(k, 0), soa_index(k, 1)};
    __m512d q[CHUNK][SP_MAX_INFLUENCES];
    __mmask8 ok[CHUNK];
    for (size_t b = 0; b < blocks; ++b) {
        __m512d w[SP_MAX_INFLUENCES];
        load_block8(weights + b * BLOCK * k, k, index, w);
        ok[b] = quantize_block8(w, k, s, q[b]);
        UNROLL
        for (uint32_t i = 1; i < k; ++i) ok[b] &= _mm512_cmp_pd_mask(q[b][i - 1], q[b][i], _CMP_GE_OQ);
    }
    for (size_t b = 0; b < blocks; ++b) {
        size_t v = b * BLOCK;
        _mm512_storeu_si512(codes + v, _mm512_cvttpd_epu64(pack_block8(q[b], k, n)));
        if (significant) store_significant8(q[b], k, significant + v);
        unsigned slow = ~(unsigned)ok[b] & 0xFF;
        for (size_t lane = v; slow; ++lane, slow >>= 1)
            if (slow & 1) codes[lane] = sp_oss_encode_one(codec, weights + lane * k, significant ? significant + lane : NULL);
    }
}

static inline __attribute__((always_inline)) SP_AVX512 size_t encode_blocks8(const sp_codec* codec,
                                                                             const float* weights, size_t count,
                                                                             uint64_t* codes, uint8_t* significant,
                                                                             uint32_t k)
{
    size_t v = 0;
    for (; v + CHUNK * BLOCK <= count; v += CHUNK * BLOCK)
        encode_chunk8(codec, weights + v * k, CHUNK, codes + v, significant ? significant + v : NULL, k);
    size_t blocks = (count - v) / BLOCK;
    if (blocks) encode_chunk8(codec, weights + v * k, blocks, codes + v, significant ? significant + v : NULL, k);
    return v + blocks * BLOCK;
}

SP_AVX512 size_t sp_oss_encode_avx512(const sp_codec* codec, const float* weights, size_t count, uint64_t* codes,
                                      uint8_t* significant)
{
    switch (codec->influences) { /* constant k: unrolled lanes */
    case 2: return encode_blocks8(codec, weights, count, codes, significant, 2);
    case 3: return encode_blocks8(codec, weights, count, codes, significant, 3);
    default: return encode_blocks8(codec, weights, count, codes, significant, 4);
    }
}

/* ---- decode ----------------------------------------------------------------------------- */

static inline SP_AVX512 __m256 splatf(float x)
{
    return _mm256_set1_ps(x);
}

/* floor(e) clamped to [0, top]; NaN becomes 0 (max returns its second operand). */
static inline SP_AVX512 __m512d clamp_floor8(__m512d e, __m512d top)
{
    return _mm512_min_pd(_mm512_max_pd(floor8(e), _mm512_setzero_pd()), top);
}

/* cbrt(x) for x >= 1 to ~1e-8 relative: the float exponent/3 bit trick (3.2%), a Halley step in
 * float with rcp14 for its division (~1e-4), then one Newton step in double whose 1/(3y^2)
 * comes from rcp14 (its 2^-14 error only scales the already small correction). An estimate
 * only: no division or zmm square root (those were the bottleneck of an earlier double Halley
 * step; the float division, too, cost more than its precision is worth here). */
static inline SP_AVX512 __m512d cube_root8(__m512d x)
{
    __m256 xf = _mm512_cvtpd_ps(x);
    __m256i third = _mm256_cvttps_epi32(_mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_castps_si256(xf)), splatf(1.0f / 3.0f)));
    __m256 yf = _mm256_castsi256_ps(_mm256_add_epi32(third, _mm256_set1_epi32(709958130)));
    __m256 yf3 = _mm256_mul_ps(_mm256_mul_ps(yf, yf), yf);
    __m256 inverse = _mm256_rcp14_ps(_mm256_add_ps(_mm256_add_ps(yf3, yf3), xf));
    yf = _mm256_mul_ps(_mm256_mul_ps(yf, _mm256_add_ps(yf3, _mm256_add_ps(xf, xf))), inverse); /* y (y^3 + 2x) / (2y^3 + x) */
    __m512d y = _mm512_cvtps_pd(yf);
    __m512d y2 = _mm512_mul_pd(y, y);
    __m512d r = _mm512_rcp14_pd(_mm512_mul_pd(y2, splat(3.0)));
    return _mm512_fnmadd_pd(_mm512_fmsub_pd(y2, y, x), r, y); /* y - (y^3 - x) / (3y^2) */
}

/* oss_find_layer's estimate (2N + 3 - t) / 4 with t = c + 1/c, c = cbrt(V - 1 + sqrt(V (V - 2))),
 * for code + 17/18 instead of code, floored and clamped to the layers. V = 72 (u~(k0) - code)
 * with k0 = (N + 1)/2 and u~ the unfloored u (u~(k) - u(k) in [0, 8/9]), which increases up to
 * k0, so every code of layer k plus 17/18 lies strictly between u~(k) and u~(k + 1) (the same
 * shift as the row estimate's 7/8) and in exact arithmetic the estimate is the layer; it also
 * keeps V >= 4 for valid codes. c^3 + 1/c^3 = 2(V - 1) = b, so t is the root t >= 2 of
 * t^3 - 3t = b, and cbrt(b) + 1/cbrt(b) is within c^-5/3 of it (below 1e-6 but for the last
 * few codes, where b < 2000), which skips oss_find_layer's square root; 1/c comes from rcp14.
 * b is an integer below 2^49, so the fused product is exact. */
static inline SP_AVX512 __m512d layer_estimate8(double n, __m512d code)
{
    double m = n + 1;
    __m512d b = _mm512_fnmadd_pd(code, splat(144.0), splat(8 * m * m * m + 12 * m * m - 106)); /* 2(V - 1) */
    __m512d c = cube_root8(b);
    __m512d estimate = _mm512_fnmadd_pd(_mm512_add_pd(c, _mm512_rcp14_pd(c)), splat(0.25), splat((2 * n + 3) / 4));
    return clamp_floor8(estimate, splat((double)(((uint64_t)n + 1) / 2 - 1)));
}

/* oss_find_row's mirrored square root estimate for w + 7/8 instead of w in the triangle with
 * B = `bottom` samples along its bottom edge, floored and clamped to j >= 0. s(j) = floor(s~(j))
 * with s~(j) - s(j) in {0, 1/4, 1/2, 3/4}, so w = s(j) lies up to 3/4 below the smooth s~(j)
 * and the unshifted estimate floors to j - 1 there (the ~0.2% of lanes the scalar code used to
 * redo); w + 7/8 lies strictly between s~(j) and s~(j + 1) for every w of row j, so in exact
 * arithmetic the estimate is the row. With apex = 2B + 1, 12 (w + 7/8) = 12 w + 10.5:
 * mirrored = apex^2 + 3 - 10.5 - 12 w. The exact check still decides; the correctly rounded
 * sqrt keeps the rounding error far below the 1/8 margin (an rsqrt14 estimate measured slower
 * and missed more for large N). No clamp to the last row: the estimate is at most
 * apex / 3 < rows + 1, and row_offset8 rejects j = rows (a row of no codes). */
static inline SP_AVX512 __m512d row_estimate8(__m512d bottom, __m512d w)
{
    __m512d apex = _mm512_fmadd_pd(bottom, splat(2.0), splat(1.0));
    __m512d mirrored = _mm512_fnmadd_pd(w, splat(12.0), _mm512_fmsub_pd(apex, apex, splat(7.5)));
    __m512d estimate = _mm512_mul_pd(_mm512_sub_pd(apex, _mm512_sqrt_pd(mirrored)), splat(1.0 / 3.0));
    return _mm512_max_pd(floor8(estimate), _mm512_setzero_pd());
}

/* i = w - s(j), clearing the lanes of *ok where j is not w's row, that is where i is not in
 * [0, floor((2B - 3j) / 2)), the length of row j (none for j >= rows): for integral i that is
 * 0 <= i <= B - 1 - 3j/2. Exact: integers and halves below 2^50. */
static inline SP_AVX512 __m512d row_offset8(__m512d bottom, __m512d j, __m512d w, __mmask8* ok)
{
    __m512d i = _mm512_sub_pd(w, row_base8(bottom, j));
    __m512d last = _mm512_fnmadd_pd(j, splat(1.5), _mm512_sub_pd(bottom, splat(1.0)));
    *ok = _mm512_mask_cmp_pd_mask(_mm512_cmp_pd_mask(i, _mm512_setzero_pd(), _CMP_GE_OQ) & *ok, i, last, _CMP_LE_OQ);
    return i;
}

/* sp_oss_unpack and grid_to_weights for `blocks` blocks of codes <= max_code. */
static inline __attribute__((always_inline)) SP_AVX512 void decode_chunk8(const sp_codec* codec, const uint64_t* codes,
                                                                          size_t blocks, float* weights, uint32_t k)
{
    double n = (double)codec->n, inverse = 1.0 / (double)codec->scale;
    __m512i index[2] = {aos_index(k, 0), aos_index(k, 1)};
    __m512d layer[CHUNK], rest[CHUNK], bottom[CHUNK], row[CHUNK];
    __mmask8 ok[CHUNK];
    for (size_t b = 0; b < blocks; ++b) {
        rest[b] = _mm512_cvtepu64_pd(_mm512_loadu_si512(codes + b * BLOCK)); /* < 2^50: exact */
        layer[b] = _mm512_setzero_pd();
        bottom[b] = splat(n);
        ok[b] = 0xFF;
    }
    if (k == 4)
        for (size_t b = 0; b < blocks; ++b) layer[b] = layer_estimate8(n, rest[b]);
    /* The layer needs no check of its own: with k clamped to the layers, the row check
     * accepts only a rest = code - u(k) inside layer k's triangle (a negative rest fails
     * s(j) <= rest, one past the triangle fails rest < s(j + 1) for every row, row
     * j >= rows has s(j + 1) <= s(j)), and then (k, row, i) is the one tuple whose index
     * is code. */
    if (k > 2)
        for (size_t b = 0; b < blocks; ++b) {
            if (k == 4) {
                rest[b] = _mm512_sub_pd(rest[b], layer_base8(n, layer[b]));
                bottom[b] = _mm512_fnmadd_pd(layer[b], splat(2.0), splat(n));
            }
            row[b] = row_estimate8(bottom[b], rest[b]);
        }
    for (size_t b = 0; b < blocks; ++b) {
        __m512d q[SP_MAX_INFLUENCES], grid = splat(2 * (n - 1));
        if (k == 2) {
            q[1] = rest[b];
            q[0] = _mm512_sub_pd(grid, rest[b]);
        } else {
            __m512d i = row_offset8(bottom[b], row[b], rest[b], &ok[b]);
            if (k == 4) q[3] = layer[b];
            q[2] = _mm512_add_pd(row[b], layer[b]);
            q[1] = _mm512_add_pd(i, q[2]);
            __m512d sum = _mm512_add_pd(q[1], q[2]);
            q[0] = _mm512_sub_pd(grid, k == 4 ? _mm512_add_pd(sum, layer[b]) : sum);
        }
        store_block8(q, k, inverse, index, weights + b * BLOCK * k);
    }
    /* The scalar redo in a pass of its own: a call inside the loop above would clobber every
     * vector register, and the loop would reload its constants on each block. */
    for (size_t b = 0; b < blocks; ++b) {
        unsigned slow = ~(unsigned)ok[b] & 0xFF;
        for (size_t lane = b * BLOCK; slow; ++lane, slow >>= 1)
            if (slow & 1) sp_decode_weights(codec, codes[lane], weights + lane * k);
    }
}

/* How many of the first `blocks` blocks hold only codes <= max_code. */
static inline SP_AVX512 size_t valid_blocks8(const sp_codec* codec, const uint64_t* codes, size_t blocks)
{
    __m512i top = _mm512_set1_epi64((int64_t)codec->max_code);
    for (size_t b = 0; b < blocks; ++b)
        if (_mm512_cmpgt_epu64_mask(_mm512_loadu_si512(codes + b * BLOCK), top)) return b;
    return blocks;
}

static inline __attribute__((always_inline)) SP_AVX512 size_t decode_blocks8(const sp_codec* codec,
                                                                             const uint64_t* codes, size_t count,
                                                                             float* weights, uint32_t k)
{
    size_t v = 0;
    while (v + BLOCK <= count) {
        size_t blocks = (count - v) / BLOCK;
        blocks = valid_blocks8(codec, codes + v, blocks < CHUNK ? blocks : CHUNK);
        if (blocks == 0) break; /* an invalid code: the AVX2 and scalar loops take it from here */
        decode_chunk8(codec, codes + v, blocks, weights + v * k, k);
        v += blocks * BLOCK;
    }
    return v;
}

SP_AVX512 size_t sp_oss_decode_avx512(const sp_codec* codec, const uint64_t* codes, size_t count, float* weights)
{
    switch (codec->influences) {
    case 2: return decode_blocks8(codec, codes, count, weights, 2);
    case 3: return decode_blocks8(codec, codes, count, weights, 3);
    default: return decode_blocks8(codec, codes, count, weights, 4);
    }
}

int sp_oss_has_avx512(void)
{
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
}
#else
size_t sp_oss_encode_avx512(const sp_codec* codec, const float* weights, size_t count, uint64_t* codes,
                            uint8_t* significant)
{
    (void)codec, (void)weights, (void)count, (void)codes, (void)significant;
    return 0;
}
size_t sp_oss_decode_avx512(const sp_codec* codec, const uint64_t* codes, size_t count, float* weights)
{
    (void)codec, (void)codes, (void)count, (void)weights;
    return 0;
}
int sp_oss_has_avx512(void)
{
    return 0;
}
#endif
