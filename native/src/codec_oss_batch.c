/*
 * Vectorised batch encode and decode of OSS for K = 2..4 (AVX2, four vertices per step), and
 * the dispatch between it and the AVX-512 path (codec_oss_batch_avx512.c, eight per step).
 *
 * Results are bit-identical to the scalar path (sp_grid_quantize + sp_oss_pack, and
 * sp_oss_unpack + the double-to-float conversion of sp_decode_weights): the rounding runs in
 * double lanes with the scalar's exact operation order, and the OSS index arithmetic runs in
 * double lanes too, where every intermediate is an integer below 2^53 and thus exact. A lane
 * whose inputs leave that exact regime (odd weights, a code the estimate misses) is redone by
 * the scalar code, so the fast path only ever has to be right where it claims to be.
 *
 * The functions return how many leading vertices they handled (a multiple of the block size);
 * the caller's scalar loop does the rest, and all of it when the CPU has no AVX2 or the codec
 * is outside the exact range.
 */
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
    if (significant) {
        uint8_t count = 1;
        while (count < k && q[count] > 0) ++count;
        *significant = count;
    }
    return sp_oss_pack(codec->n, k, q);
}

#if (defined(__x86_64__) || defined(__i386__)) && (defined(__GNUC__) || defined(__clang__))

/* No "fma": a fused multiply-add would round differently from the scalar code. */
#define SP_AVX2 __attribute__((target("avx2")))
#define BLOCK 4
/* Blocks per pass. A block's whole encode or decode is one dependency chain (a division, or
 * square roots and divisions) longer than what the core's reorder window holds of it, so the
 * work runs in stages, each over all blocks of a chunk before the next: the blocks of one
 * stage are independent, and the core overlaps them. */
#define CHUNK 8
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

/* floor(a / d) for integral 0 <= a < 2^50 and small d: a = d m + r with 0 <= r < d puts
 * (a + 1/2) / d at least 1/(2d) away from an integer, while the product with the rounded 1/d
 * is within (a/d) 2^-52 < 1/(4d) of it, so the floor is the exact integer quotient. */
static inline SP_AVX2 __m256d floor_div(__m256d a, double d)
{
    return _mm256_floor_pd(_mm256_mul_pd(_mm256_add_pd(a, splat(0.5)), splat(1.0 / d)));
}

/* s_N(j) = floor(((4N + 2 - 3j) j + 1) / 4), for rows inside the triangle (positive). */
static inline SP_AVX2 __m256d row_base4(__m256d n, __m256d j)
{
    __m256d t = _mm256_sub_pd(_mm256_add_pd(_mm256_mul_pd(n, splat(4.0)), splat(2.0)), _mm256_mul_pd(j, splat(3.0)));
    __m256d num = _mm256_add_pd(_mm256_mul_pd(t, j), splat(1.0));
    return _mm256_floor_pd(_mm256_mul_pd(num, splat(0.25))); /* /4 is exact in binary */
}

/* u(k) = floor((3Nk(N - 2k + 3) + k((4k - 9)k + 6) + 2) / 9), for k <= (N + 1)/2. */
static inline SP_AVX2 __m256d layer_base4(__m256d n, __m256d k)
{
    __m256d width = _mm256_add_pd(_mm256_sub_pd(n, _mm256_add_pd(k, k)), splat(3.0));
    __m256d a = _mm256_mul_pd(_mm256_mul_pd(_mm256_mul_pd(n, splat(3.0)), k), width);
    __m256d inner = _mm256_add_pd(_mm256_mul_pd(_mm256_sub_pd(_mm256_mul_pd(k, splat(4.0)), splat(9.0)), k), splat(6.0));
    __m256d num = _mm256_add_pd(_mm256_add_pd(a, _mm256_mul_pd(k, inner)), splat(2.0));
    return floor_div(num, 9.0);
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

/*
 * sp_grid_quantize's fast path in four lanes, same operations in the same order. Returns the
 * mask of lanes it is exact for: a deficit in [0, k), where the scalar takes the same path.
 * That also bounds every x by s + 1, so floors and deficit are exact: an x past that makes
 * the deficit negative, and one past 2^53 (or infinite) keeps it so under rounding.
 */
static inline SP_AVX2 __m256d quantize_block(const __m256d* w, uint32_t k, double s, __m256d* q)
{
    __m256d zero = _mm256_setzero_pd(), grid = splat(s);
    __m256d sum = zero, remainder[SP_MAX_INFLUENCES];
    __m256i rank[SP_MAX_INFLUENCES];
    UNROLL
    for (uint32_t i = 0; i < k; ++i) sum = _mm256_add_pd(sum, w[i]); /* 0 + w0 first: keeps -0 as the scalar does */
    __m256d scale = _mm256_div_pd(grid, sum);
    __m256d deficit = grid;
    UNROLL
    for (uint32_t i = 0; i < k; ++i) {
        /* max(x, 0) returns its second operand for NaN: x > 0 ? x : 0, as in the scalar */
        __m256d x = _mm256_max_pd(_mm256_mul_pd(w[i], scale), zero);
        q[i] = _mm256_round_pd(x, _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC);
        remainder[i] = _mm256_sub_pd(x, q[i]);
        deficit = _mm256_sub_pd(deficit, q[i]);
        rank[i] = _mm256_set1_epi64x((int64_t)(k - 1 - i)); /* every later slot beats i ... */
    }
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
    __m256d ok = _mm256_and_pd(_mm256_cmp_pd(deficit, zero, _CMP_GE_OQ),
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
    __m256d nn = splat(n);
    if (k == 2) return q[1];
    if (k == 3) return _mm256_add_pd(row_base4(nn, q[2]), _mm256_sub_pd(q[1], q[2]));
    __m256d layer = q[3], bottom = _mm256_sub_pd(nn, _mm256_add_pd(layer, layer));
    __m256d row = row_base4(bottom, _mm256_sub_pd(q[2], q[3]));
    return _mm256_add_pd(_mm256_add_pd(layer_base4(nn, layer), row), _mm256_sub_pd(q[1], q[2]));
}

/* Encodes `blocks` (<= CHUNK) blocks: quantisation of all of them, then their indices. */
static inline __attribute__((always_inline)) SP_AVX2 void encode_chunk(const sp_codec* codec, const float* weights,
                                                                       size_t blocks, uint64_t* codes,
                                                                       uint8_t* significant, uint32_t k)
{
    double s = (double)codec->scale, n = (double)codec->n;
    __m256d q[CHUNK][SP_MAX_INFLUENCES], ok[CHUNK];
    for (size_t b = 0; b < blocks; ++b) {
        __m256d w[SP_MAX_INFLUENCES];
        load_block(weights + b * BLOCK * k, k, w);
        ok[b] = quantize_block(w, k, s, q[b]);
        UNROLL
        for (uint32_t i = 1; i < k; ++i) ok[b] = _mm256_and_pd(ok[b], _mm256_cmp_pd(q[b][i - 1], q[b][i], _CMP_GE_OQ));
    }
    for (size_t b = 0; b < blocks; ++b) {
        size_t v = b * BLOCK;
        _mm256_storeu_si256((__m256i*)(codes + v), to_u64(pack_block(q[b], k, n)));
        if (significant) {
            int positive[SP_MAX_INFLUENCES] = {0, 0, 0, 0};
            UNROLL
            for (uint32_t i = 1; i < k; ++i)
                positive[i] = _mm256_movemask_pd(_mm256_cmp_pd(q[b][i], _mm256_setzero_pd(), _CMP_GT_OQ));
            UNROLL
            for (uint32_t lane = 0; lane < BLOCK; ++lane) { /* sorted, so the non-zero ones lead */
                uint8_t c = 1;
                UNROLL
                for (uint32_t i = 1; i < k; ++i) c = (uint8_t)(c + ((positive[i] >> lane) & 1));
                significant[v + lane] = c;
            }
        }
        int slow = ~_mm256_movemask_pd(ok[b]) & 15;
        for (size_t lane = v; slow; ++lane, slow >>= 1)
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
 * c + 1/c for c = cbrt(x), x >= 1, to ~1e-13: the float exponent/3 bit trick (Kahan's
 * constant, ~5 bits), a cubically converging Halley step in float (~15 bits), one in double.
 * The last step's division and the one of 1/c share a single division:
 * c = y n / d gives c + 1/c = (y^2 n^2 + d^2) / (y n d). Only an estimate: the layer is checked
 * against the exact bases afterwards.
 */
static inline SP_AVX2 __m256d cube_root_plus_inverse4(__m256d x)
{
    __m128 xf = _mm256_cvtpd_ps(x);
    __m128i third = _mm_cvttps_epi32(_mm_mul_ps(_mm_cvtepi32_ps(_mm_castps_si128(xf)), _mm_set1_ps(1.0f / 3.0f)));
    __m128 yf = _mm_castsi128_ps(_mm_add_epi32(third, _mm_set1_epi32(709958130)));
    __m128 yf3 = _mm_mul_ps(_mm_mul_ps(yf, yf), yf);
    yf = _mm_div_ps(_mm_mul_ps(yf, _mm_add_ps(yf3, _mm_add_ps(xf, xf))), _mm_add_ps(_mm_add_ps(yf3, yf3), xf));
    __m256d y = _mm256_cvtps_pd(yf);
    __m256d y3 = _mm256_mul_pd(_mm256_mul_pd(y, y), y);
    __m256d yn = _mm256_mul_pd(y, _mm256_add_pd(y3, _mm256_add_pd(x, x))), d = _mm256_add_pd(_mm256_add_pd(y3, y3), x);
    return _mm256_div_pd(_mm256_add_pd(_mm256_mul_pd(yn, yn), _mm256_mul_pd(d, d)), _mm256_mul_pd(yn, d));
}

/* floor(e) clamped to [0, top]; NaN becomes 0 (max returns its second operand). */
static inline SP_AVX2 __m256d clamp_floor(__m256d e, __m256d top)
{
    return _mm256_min_pd(_mm256_max_pd(_mm256_floor_pd(e), _mm256_setzero_pd()), top);
}

/* The unpack in stages, each run over all blocks of a chunk before the next (see CHUNK). */

/* Row estimate of w in a triangle with `bottom` samples: oss_find_row's mirrored square root,
 * floored and clamped to the triangle's rows. */
static inline SP_AVX2 __m256d row_estimate4(__m256d bottom, __m256d w)
{
    __m256d apex = _mm256_add_pd(_mm256_add_pd(bottom, bottom), splat(1.0));
    __m256d mirrored = _mm256_sub_pd(_mm256_add_pd(_mm256_mul_pd(apex, apex), splat(3.0)), _mm256_mul_pd(w, splat(12.0)));
    __m256d estimate = _mm256_mul_pd(_mm256_sub_pd(apex, _mm256_sqrt_pd(mirrored)), splat(1.0 / 3.0));
    __m256d last = _mm256_sub_pd(floor_div(apex, 3.0), splat(1.0)); /* rows - 1 */
    return clamp_floor(estimate, last);
}

/* s(j), clearing the lanes of *ok where s(j) <= w < s(j + 1) fails (j not the exact row).
 * Row j < rows holds floor((2N - 3j) / 2) codes, so s(j + 1) is that much past s(j). */
static inline SP_AVX2 __m256d row_check4(__m256d bottom, __m256d j, __m256d w, __m256d* ok)
{
    __m256d lo = row_base4(bottom, j);
    __m256d length = _mm256_sub_pd(_mm256_add_pd(bottom, bottom), _mm256_mul_pd(j, splat(3.0)));
    __m256d hi = _mm256_add_pd(lo, _mm256_floor_pd(_mm256_mul_pd(length, splat(0.5))));
    *ok = _mm256_and_pd(*ok, _mm256_and_pd(_mm256_cmp_pd(lo, w, _CMP_LE_OQ), _mm256_cmp_pd(w, hi, _CMP_LT_OQ)));
    return lo;
}

/* The argument of oss_find_layer's cube root: V - 1 + sqrt(V (V - 2)), the root 0 for V <= 2. */
static inline SP_AVX2 __m256d layer_root_argument4(double n, __m256d code)
{
    double m = n + 1;
    __m256d v = _mm256_sub_pd(splat(4 * m * m * m + 6 * m * m + 16), _mm256_mul_pd(code, splat(72.0)));
    __m256d root = _mm256_and_pd(_mm256_cmp_pd(v, splat(2.0), _CMP_GT_OQ),
                                 _mm256_sqrt_pd(_mm256_mul_pd(v, _mm256_sub_pd(v, splat(2.0)))));
    return _mm256_add_pd(_mm256_sub_pd(v, splat(1.0)), root);
}

/* The layer estimate (2N + 3 - (c + 1/c)) / 4, floored and clamped to the layers. The scalar
 * clamps c >= 1 first; c + 1/c is the same for c and 1/c, so that clamp is not needed. */
static inline SP_AVX2 __m256d layer_estimate4(double n, __m256d argument)
{
    __m256d estimate = _mm256_mul_pd(_mm256_sub_pd(splat(2 * n + 3), cube_root_plus_inverse4(argument)), splat(0.25));
    return clamp_floor(estimate, splat((double)(((uint64_t)n + 1) / 2 - 1)));
}

/* (float)(q * (1/s)) per component, as grid_to_weights does, stored as four vertices. */
static inline SP_AVX2 void store_block(const __m256d* q, uint32_t k, double inverse, float* out)
{
    __m128 w[SP_MAX_INFLUENCES];
    UNROLL
    for (uint32_t i = 0; i < k; ++i) w[i] = _mm256_cvtpd_ps(_mm256_mul_pd(q[i], splat(inverse)));
    if (k == 4) {
        _MM_TRANSPOSE4_PS(w[0], w[1], w[2], w[3]);
        UNROLL
        for (uint32_t lane = 0; lane < BLOCK; ++lane) _mm_storeu_ps(out + 4 * lane, w[lane]);
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

/* sp_oss_unpack and grid_to_weights for `blocks` blocks of codes <= max_code. */
static inline __attribute__((always_inline)) SP_AVX2 void decode_chunk(const sp_codec* codec, const uint64_t* codes,
                                                                       size_t blocks, float* weights, uint32_t k)
{
    double n = (double)codec->n, inverse = 1.0 / (double)codec->scale;
    __m256d code[CHUNK], layer[CHUNK], rest[CHUNK], row[CHUNK], ok[CHUNK];
    for (size_t b = 0; b < blocks; ++b) {
        code[b] = rest[b] = from_u64(_mm256_loadu_si256((const __m256i*)(codes + b * BLOCK)));
        layer[b] = _mm256_setzero_pd();
        ok[b] = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
    }
    if (k == 4) {
        for (size_t b = 0; b < blocks; ++b) layer[b] = layer_root_argument4(n, code[b]);
        for (size_t b = 0; b < blocks; ++b) layer[b] = layer_estimate4(n, layer[b]);
        /* The layer needs no check of its own: with k clamped to the layers, the row check
         * accepts only a rest = code - u(k) inside layer k's triangle (a negative rest fails
         * s(j) <= rest, one past the triangle fails rest < s(j + 1) for every row, row
         * j >= rows has s(j + 1) <= s(j)), and then (k, row, i) is the one tuple whose index
         * is code. */
        for (size_t b = 0; b < blocks; ++b) rest[b] = _mm256_sub_pd(code[b], layer_base4(splat(n), layer[b]));
    }
    if (k > 2)
        for (size_t b = 0; b < blocks; ++b)
            row[b] = row_estimate4(_mm256_sub_pd(splat(n), _mm256_add_pd(layer[b], layer[b])), rest[b]);
    for (size_t b = 0; b < blocks; ++b) {
        __m256d q[SP_MAX_INFLUENCES], grid = splat(2 * (n - 1));
        if (k == 2) {
            q[1] = rest[b];
            q[0] = _mm256_sub_pd(grid, rest[b]);
        } else {
            __m256d bottom = _mm256_sub_pd(splat(n), _mm256_add_pd(layer[b], layer[b]));
            __m256d base = row_check4(bottom, row[b], rest[b], &ok[b]);
            if (k == 4) q[3] = layer[b];
            q[2] = _mm256_add_pd(row[b], layer[b]);
            q[1] = _mm256_add_pd(_mm256_sub_pd(rest[b], base), q[2]);
            __m256d sum = _mm256_add_pd(q[1], q[2]);
            q[0] = _mm256_sub_pd(grid, k == 4 ? _mm256_add_pd(sum, layer[b]) : sum);
        }
        store_block(q, k, inverse, weights + b * BLOCK * k);
        int slow = ~_mm256_movemask_pd(ok[b]) & 15;
        for (size_t lane = b * BLOCK; slow; ++lane, slow >>= 1)
            if (slow & 1) sp_decode_weights(codec, codes[lane], weights + lane * k);
    }
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
        blocks = valid_blocks(codec, codes + v, blocks < CHUNK ? blocks : CHUNK);
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

static int has_avx2(void)
{
    return __builtin_cpu_supports("avx2");
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
