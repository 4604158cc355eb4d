/*
 * Batch encode/decode against the single-vertex path, bit for bit. The batch functions take a
 * vector path for OSS (codec_oss_batch.c: AVX-512 blocks of 8, AVX2 blocks of 4) on blocks of
 * vertices and leave the tail and any odd lane to the scalar code; a batch of one vertex is
 * always scalar, so it is the reference. Every check runs once per vector path the CPU has.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../../native/src/codec_internal.h" /* the *_isa batch forms: one path at a time */
#include "../../native/src/codec_oss_wide.h"     /* the double lanes' limits */
#include "check.h"
#include "skinpack.h"

#include "batch_compare.h"

/* Every code of small N: decode them all in one batch, then encode the decoded weights and
 * the same weights nudged by one float step both ways (remainders near 0 and 1). */
static void exhaustive_small(void)
{
    for (uint32_t k = 2; k <= 4; ++k)
        for (uint64_t n = 2; n <= (k == 4 ? 60u : 120u); ++n) {
            sp_codec c = oss(k, n);
            size_t count = (size_t)c.max_code + 1;
            uint64_t* codes = malloc(count * sizeof(uint64_t));
            float* w = malloc(count * k * sizeof(float));
            for (size_t v = 0; v < count; ++v) codes[v] = v;
            if (compare_decode(&c, codes, count, "exhaustive decode")) return;
            CHECK(decode_batch(&c, codes, count, w, NULL) == SP_OK);
            if (compare_encode(&c, w, count, "exhaustive encode")) return;
            for (int dir = -1; dir <= 1; dir += 2) {
                for (size_t i = 0; i < count * k; ++i) w[i] = nextafterf(w[i], dir < 0 ? 0.0f : 1.0f);
                if (compare_encode(&c, w, count, "nudged encode")) return;
            }
            free(codes), free(w);
        }
}

/* A sorted random tuple summing to ~1, drawn from shapes that stress the rounding: plain,
 * ties, zeros, one-hot, grid points (ties of remainders), and values just off grid points. */
static void random_tuple(uint32_t k, uint64_t s, float* w)
{
    double raw[4] = {0, 0, 0, 0}, sum = 0;
    uint64_t shape = rng_next() % 8;
    for (uint32_t i = 0; i < k; ++i) raw[i] = rng_unit();
    if (shape == 1) raw[1] = raw[0];                                   /* a tie */
    if (shape == 2) for (uint32_t i = 1 + (uint32_t)(rng_next() % (k - 1)); i < k; ++i) raw[i] = 0; /* zeros */
    if (shape == 3) for (uint32_t i = 1; i < k; ++i) raw[i] = 0;        /* one-hot */
    if (shape == 4) for (uint32_t i = 0; i < k; ++i) raw[i] = 1;        /* all equal */
    if (shape == 5 || shape == 6) /* on the grid (shape 6: half a step off) */
        for (uint32_t i = 0; i < k; ++i) raw[i] = floor(raw[i] * (double)s / k) + (shape == 6 ? 0.5 : 0);
    for (uint32_t i = 0; i < k; ++i) sum += raw[i];
    if (!(sum > 0)) raw[0] = sum = 1;
    for (uint32_t i = 1; i < k; ++i) /* descending */
        for (uint32_t j = i; j > 0 && raw[j - 1] < raw[j]; --j) {
            double t = raw[j];
            raw[j] = raw[j - 1];
            raw[j - 1] = t;
        }
    for (uint32_t i = 0; i < k; ++i) w[i] = (float)(raw[i] / sum);
    if (shape == 7) w[rng_next() % k] = nextafterf(w[0], 2.0f); /* off by one float step, maybe unsorted */
}

/* Millions of random tuples on the bench budgets and at the edges of the vector path. */
static void random_tuples(void)
{
    static const uint32_t budgets[] = {8, 16, 22, 26, 30, 38, 44, 45, 46, 52, 64};
    size_t count = 300000;
    float* w = malloc(count * 4 * sizeof(float));
    uint64_t* codes = malloc(count * sizeof(uint64_t));
    for (uint32_t k = 2; k <= 4; ++k)
        for (size_t b = 0; b < sizeof(budgets) / sizeof(budgets[0]); ++b) {
            sp_codec c;
            if (sp_codec_from_bits(SP_METHOD_OSS, k, budgets[b], &c) != SP_OK) continue;
            for (size_t v = 0; v < count; ++v) random_tuple(k, c.scale, w + v * k);
            if (compare_encode(&c, w, count, "random encode")) return;
            for (size_t v = 0; v < count; ++v) codes[v] = rng_next() % (c.max_code + 1 ? c.max_code + 1 : UINT64_MAX);
            if (compare_decode(&c, codes, count, "random decode")) return;
        }
    free(w), free(codes);
}

/* The grid points of `count` codes (scalar decode into w, count * K floats) encoded: at layer
 * and row starts the encode's floors (rounding FMAs, codec_oss_simd.h's pack_block) are nearest
 * integers of values 1/4 (odd rows) and 1/18 (layer bases) from a half-integer. */
static int compare_encode_decoded(const sp_codec* c, const uint64_t* codes, size_t count, float* w, const char* what)
{
    CHECK(sp_decode_weights_batch_isa(c, codes, count, w, NULL, SP_ISA_SCALAR) == SP_OK);
    return compare_encode(c, w, count, what);
}

/* N at and just past the largest the vector paths accept (exact there, scalar beyond), and the
 * largest their 32-bit lanes decode (K = 3: NARROW_MAX_N3, K = 4: NARROW_MAX_N4, and K = 4 with
 * the rows in 32-bit lanes: SPLIT_MAX_N4; double lanes beyond), and
 * codes at every layer and row start/end there, where the root estimates are off by one, and
 * the last codes, where the layer estimate's cube root argument is smallest. */
static void range_edges(void)
{
    static const struct { uint32_t k; uint64_t n; } edges[] = {
        {2, BATCH_MAX_N2}, {3, BATCH_MAX_N3}, {4, BATCH_MAX_N4}, {3, NARROW_MAX_N3}, {4, NARROW_MAX_N4},
        {4, SPLIT_MAX_N4}};
    size_t count = 200000;
    float* w = malloc(count * 4 * sizeof(float));
    uint64_t* codes = malloc(count * sizeof(uint64_t));
    for (size_t e = 0; e < sizeof(edges) / sizeof(edges[0]); ++e)
        for (uint64_t n = edges[e].n - 1; n <= edges[e].n + 1; ++n) {
            uint32_t k = edges[e].k;
            sp_codec c = oss(k, n);
            for (size_t v = 0; v < count; ++v) random_tuple(k, c.scale, w + v * k);
            if (compare_encode(&c, w, count, "edge encode")) return;
            for (size_t v = 0; v < count; ++v) {
                uint64_t layer = k == 4 ? rng_next() % ((n + 1) / 2) : 0, bottom = n - 2 * layer;
                uint64_t base = k == 4 ? sp_oss_layer_base(n, layer) : 0;
                uint64_t row = rng_next() % ((2 * bottom + 1) / 3), code = rng_next() % (c.max_code + 1);
                if (k > 2 && v % 3 == 0) code = base + sp_oss_row_base(bottom, row);  /* row start */
                if (k > 2 && v % 3 == 1) code = base + sp_oss_row_base(bottom, row + 1) - 1; /* row end */
                if (k == 4 && v % 7 == 0) code = base - (layer > 0);                  /* layer end */
                if (k == 4 && v % 11 == 0) code = base;                               /* layer start */
                if (k == 4 && v % 13 == 0) code = c.max_code - rng_next() % 64;       /* the last layers */
                codes[v] = code;
            }
            if (compare_decode(&c, codes, count, "edge decode")) return;
            if (compare_encode_decoded(&c, codes, count, w, "edge grid encode")) return;
        }
    free(w), free(codes);
}

/* Every layer's first and last codes (and their neighbours) for K = 4, every row's for K = 3,
 * from small budgets to the large ones: where the layer and row estimates are closest to
 * wrong (the AVX2 layer estimate's float cube root is good to ~1e-8, so its misses gather
 * there for large N; the 32-bit lanes' float roots, to 24 and 25 bits, miss more), each lane
 * decoded or redone as the scalar code decodes it. */
static void estimate_boundaries(void)
{
    static const struct { uint32_t k, bits; } cases[] = {{3, 12}, {3, 22}, {3, 24}, {3, 32}, {4, 12}, {4, 22},
                                                          {4, 25}, {4, 32}, {4, 40}, {4, 44}, {4, 45}};
    for (size_t e = 0; e < sizeof(cases) / sizeof(cases[0]); ++e) {
        sp_codec c;
        uint32_t k = cases[e].k;
        CHECK(sp_codec_from_bits(SP_METHOD_OSS, k, cases[e].bits, &c) == SP_OK);
        uint64_t n = c.n, parts = k == 4 ? (n + 1) / 2 : (2 * n + 1) / 3; /* layers or rows */
        uint64_t* codes = malloc(parts * 4 * sizeof(uint64_t));
        size_t count = 0;
        for (uint64_t p = 0; p < parts; ++p) {
            uint64_t start = k == 4 ? sp_oss_layer_base(n, p) : sp_oss_row_base(n, p);
            for (uint64_t d = 0; d < 4; ++d) /* start - 2 .. start + 1 */
                if (start + d >= 2 && start + d - 2 <= c.max_code) codes[count++] = start + d - 2;
        }
        compare_decode(&c, codes, count, "boundary decode");
        float* w = malloc(count * k * sizeof(float) + 1);
        compare_encode_decoded(&c, codes, count, w, "boundary encode"); /* every layer base's residue mod 9 */
        free(codes), free(w);
    }
}

/* K = 4 with the rows in 32-bit lanes (N past NARROW_MAX_N4 up to SPLIT_MAX_N4): every row's
 * first and last codes (and their neighbours) in the first layers, one in the middle and the
 * last ones, where the float row estimate, taken half a row low, is closest to two rows off,
 * and the int32 row bases and offsets are largest (layer 0 of N = SPLIT_MAX_N4 = 80264:
 * S = 2^31 - 1.8e5). */
static void split_row_boundaries(void)
{
    static const uint64_t ns[] = {NARROW_MAX_N4 + 1, 4258, 17038, 68158, SPLIT_MAX_N4};
    for (size_t e = 0; e < sizeof(ns) / sizeof(ns[0]); ++e) {
        uint64_t n = ns[e], last_layer = (n + 1) / 2 - 1;
        const uint64_t layers[] = {0, 1, 2, last_layer / 2, last_layer - 2, last_layer - 1, last_layer};
        sp_codec c = oss(4, n);
        uint64_t* codes = malloc(((2 * n + 1) / 3 + 1) * 4 * sizeof(uint64_t));
        for (size_t l = 0; l < sizeof(layers) / sizeof(layers[0]); ++l) {
            uint64_t base = sp_oss_layer_base(n, layers[l]), bottom = n - 2 * layers[l], rows = (2 * bottom + 1) / 3;
            size_t count = 0;
            for (uint64_t j = 0; j <= rows; ++j) {
                uint64_t start = base + sp_oss_row_base(bottom, j);
                for (uint64_t d = 0; d < 4; ++d) /* start - 2 .. start + 1 */
                    if (start + d >= 2 && start + d - 2 <= c.max_code) codes[count++] = start + d - 2;
            }
            if (compare_decode(&c, codes, count, "split row boundary decode")) break;
            float* w = malloc(count * 4 * sizeof(float) + 1);
            int failed = compare_encode_decoded(&c, codes, count, w, "row boundary encode"); /* rows of both parities */
            free(w);
            if (failed) break;
        }
        free(codes);
    }
}

/* Every weight q / s the 32-bit lanes compute (every q <= s = 2(N - 1) of every N they take,
 * K = 3 up to NARROW_MAX_N3, K = 4 up to NARROW_MAX_N4; with the rows in 32-bit lanes, K = 4 up
 * to SPLIT_MAX_N4, every q of the first N past the narrow lanes, of the bench's 32/38/44-bit N,
 * of the largest and of 200 random N between): the first row of the first layer, codes
 * 0..N - 1, holds q1 = 0..N - 1 and q0 = N - 1..s, so it reaches every q. */
static void narrow_weights(void)
{
    uint64_t* codes = malloc(SPLIT_MAX_N4 * sizeof(uint64_t));
    for (uint64_t v = 0; v < SPLIT_MAX_N4; ++v) codes[v] = v;
    for (uint32_t k = 3; k <= 4; ++k)
        for (uint64_t n = 2; n <= (k == 3 ? NARROW_MAX_N3 : NARROW_MAX_N4); ++n) {
            sp_codec c = oss(k, n);
            if (compare_decode(&c, codes, (size_t)n, "narrow weights")) break;
        }
    static const uint64_t split[] = {NARROW_MAX_N4 + 1, NARROW_MAX_N4 + 2, 4258, 17038, 68158, SPLIT_MAX_N4 - 1,
                                     SPLIT_MAX_N4};
    size_t listed = sizeof(split) / sizeof(split[0]);
    for (size_t i = 0; i < listed + 200; ++i) {
        uint64_t n = i < listed ? split[i] : NARROW_MAX_N4 + 1 + rng_next() % (SPLIT_MAX_N4 - NARROW_MAX_N4);
        sp_codec c = oss(4, n);
        if (compare_decode(&c, codes, (size_t)n, "split weights")) break;
    }
    free(codes);
}

/* Weights the scalar rounding sends down its general path (negative, NaN, infinite, zero,
 * not summing to 1): the vector lanes must hand them to the scalar code. Not here: sums near 0
 * (denormal weights, w and -w), which scale x past 2^63, where the scalar fast path is
 * undefined (the int64 conversion overflows). */
static void odd_weights(void)
{
    const float odd[] = {-1e-3f, -0.0f, 0.0f, NAN, INFINITY, -INFINITY, 0.5f, 2.0f, 1.0f, 0.75f};
    size_t count = 40000;
    float* w = malloc(count * 4 * sizeof(float));
    for (uint32_t k = 2; k <= 4; ++k) {
        sp_codec c;
        /* a small grid: the scalar general path spends O(s) on weights that sum to 0 or NaN */
        CHECK(sp_codec_from_bits(SP_METHOD_OSS, k, 10, &c) == SP_OK);
        for (size_t v = 0; v < count; ++v) {
            random_tuple(k, c.scale, w + v * k);
            for (uint32_t i = 0; i < k; ++i)
                if (rng_next() % 4 == 0) w[v * k + i] = odd[rng_next() % (sizeof(odd) / sizeof(odd[0]))];
        }
        compare_encode(&c, w, count, "odd encode");
    }
    free(w);
}

/* Sorted tuples scaled down by 2^-e, e from 0 to 149 (the scale s / sum up to ~2^150), and
 * sorted tuples with subnormal trailing weights under a normal first one: exact in whichever
 * lanes take them. */
static void tiny_weights(void)
{
    size_t count = 150 * 8 * 4;
    float* w = malloc(count * 4 * sizeof(float));
    for (uint32_t k = 2; k <= 4; ++k) {
        static const uint32_t budgets[] = {16, 44, 64};
        for (size_t b = 0; b < sizeof(budgets) / sizeof(budgets[0]); ++b) {
            sp_codec c;
            CHECK(sp_codec_from_bits(SP_METHOD_OSS, k, budgets[b] - (k == 2 && budgets[b] == 64), &c) == SP_OK);
            for (size_t v = 0; v < count; ++v) {
                float* x = w + v * k;
                random_tuple(k, c.scale, x);
                if (v % 4 == 3) /* subnormal trailing weights under a normal first one */
                    for (uint32_t i = 1; i < k; ++i) x[i] = ldexpf(x[i], -126 - (int)(rng_next() % 24));
                else
                    for (uint32_t i = 0; i < k; ++i) x[i] = ldexpf(x[i], -(int)(v / 32 % 150));
            }
            if (compare_encode(&c, w, count, "tiny weights encode")) break;
        }
    }
    free(w);
}

/* One lane of a batch of sorted tuples made unsorted (each neighbouring pair swapped, a negative
 * or NaN weight at each place) or kept sorted by a zero or -0 last weight, in each lane of the
 * first three AVX-512 / six AVX2 blocks: each lane's order check alone (for K = 4 on AVX2 in float
 * lanes, two compares covering two pairs each) decides whether the lane is redone. */
static void unsorted_lanes(void)
{
    enum { COUNT = 26 };
    static const uint32_t budgets[] = {16, 38, 52};
    float w[COUNT * 4];
    for (uint32_t k = 2; k <= 4; ++k)
        for (size_t b = 0; b < sizeof(budgets) / sizeof(budgets[0]); ++b) {
            sp_codec c;
            CHECK(sp_codec_from_bits(SP_METHOD_OSS, k, budgets[b], &c) == SP_OK);
            for (size_t lane = 0; lane < 24; ++lane)
                for (uint32_t change = 0; change < 2 * k + 2; ++change) {
                    for (size_t v = 0; v < COUNT; ++v) /* distinct weights: 4/10, 3/10, 2/10, 1/10 for K = 4 */
                        for (uint32_t i = 0; i < k; ++i) w[v * k + i] = (float)(k - i) / (float)(k * (k + 1) / 2);
                    float* x = w + lane * k;
                    if (change < k - 1) { /* places change and change + 1 swapped */
                        float t = x[change];
                        x[change] = x[change + 1], x[change + 1] = t;
                    } else if (change < 2 * k - 1) {
                        x[change - (k - 1)] = NAN;
                    } else {
                        const float last[] = {-1e-3f, -0.0f, 0.0f};
                        x[k - 1] = last[change - (2 * k - 1)];
                    }
                    if (compare_encode(&c, w, COUNT, "unsorted lane encode")) return;
                }
        }
}

/* Counts around the block size and pointers off 16/32-byte alignment. */
static void counts_and_alignment(void)
{
    float w[4 * 72 + 4];
    uint64_t codes[72 + 2];
    for (uint32_t k = 2; k <= 4; ++k) {
        sp_codec c;
        CHECK(sp_codec_from_bits(SP_METHOD_OSS, k, 22, &c) == SP_OK);
        for (size_t offset = 0; offset < 3; ++offset)
            for (size_t count = 0; count <= 70; ++count) { /* chunks, blocks of 8 and 4, tails */
                for (size_t v = 0; v < count; ++v) random_tuple(k, c.scale, w + offset + v * k);
                compare_encode(&c, w + offset, count, "count encode");
                for (size_t v = 0; v < count; ++v) codes[offset + v] = rng_next() % (c.max_code + 1);
                compare_decode(&c, codes + offset, count, "count decode");
            }
        /* a zero count with null pointers is fine */
        CHECK(encode_batch(&c, NULL, 0, NULL, NULL) == SP_OK);
        CHECK(decode_batch(&c, NULL, 0, NULL, NULL) == SP_OK);
    }
}

/* An invalid code anywhere in a block: the first one is reported, every vertex before it is
 * decoded as the scalar path decodes it, and none after it is written. */
static void invalid_codes(void)
{
    enum { COUNT = 44 }; /* past an AVX-512 chunk, into blocks of 8 and 4 */
    for (uint32_t k = 2; k <= 4; ++k) {
        sp_codec c;
        CHECK(sp_codec_from_bits(SP_METHOD_OSS, k, 22, &c) == SP_OK);
        for (size_t at = 0; at < COUNT; ++at)
            for (int pass = 0; pass < 3; ++pass) {
                uint64_t codes[COUNT];
                float w[COUNT * 4], ref[4];
                /* just past the range, all ones, and a code whose low 32 bits are negative as int32 */
                const uint64_t invalid[3] = {c.max_code + 1, UINT64_MAX, ((uint64_t)1 << 31) + 5};
                for (size_t v = 0; v < COUNT; ++v) codes[v] = rng_next() % (c.max_code + 1);
                codes[at] = invalid[pass];
                if (at + 3 < COUNT) codes[at + 3] = c.max_code + 7; /* a later one is not reported */
                for (size_t i = 0; i < COUNT * 4; ++i) w[i] = -7.0f;
                size_t bad = (size_t)-1;
                CHECK(decode_batch(&c, codes, COUNT, w, &bad) == SP_ERR_CODE_OUT_OF_RANGE);
                CHECK_MSG(bad == at, "K=%u invalid at %zu reported at %zu", k, at, bad);
                for (size_t v = 0; v < COUNT; ++v) {
                    if (v < at) {
                        sp_decode_weights(&c, codes[v], ref);
                        CHECK(memcmp(w + v * k, ref, k * sizeof(float)) == 0);
                    } else {
                        for (uint32_t i = 0; i < k; ++i) CHECK(w[v * k + i] == -7.0f);
                    }
                }
            }
    }
}

/* The vertices each path takes in a batch of 23 (the scalar loop does the rest): a path that
 * silently did nothing would pass every comparison above. K = 4 at 32 bits: the rows in 32-bit
 * lanes (one NBLOCK block, then the double lanes). */
static void path_coverage(sp_isa isa)
{
    static const struct { uint32_t k, bits; } cases[] = {{2, 22}, {3, 22}, {4, 22}, {4, 32}};
    float w[23 * 4];
    uint64_t codes[23];
    for (size_t e = 0; e < sizeof(cases) / sizeof(cases[0]); ++e) {
        sp_codec c;
        uint32_t k = cases[e].k;
        CHECK(sp_codec_from_bits(SP_METHOD_OSS, k, cases[e].bits, &c) == SP_OK);
        for (size_t v = 0; v < 23; ++v) random_tuple(k, c.scale, w + v * k);
        size_t expected = 0;
        sp_isa cpu = sp_cpu_isa();
        if (isa >= SP_ISA_AVX512 && cpu >= SP_ISA_AVX512) expected = 16 + 4; /* two blocks of 8, one of 4 */
        else if (isa >= SP_ISA_AVX2 && cpu >= SP_ISA_AVX2) expected = 20;
        CHECK_MSG(sp_oss_encode_batch(&c, w, 23, codes, NULL, isa) == expected, "K=%u isa %d encode prefix", k, (int)isa);
        /* valid codes (an unsorted random tuple may have encoded past max_code) */
        for (size_t v = 0; v < 23; ++v) codes[v] = rng_next() % (c.max_code + 1);
        CHECK_MSG(sp_oss_decode_batch(&c, codes, 23, w, isa) == expected, "K=%u isa %d decode prefix", k, (int)isa);
    }
}

/* The cached CPU answer is the detected one and agrees with the compiler's own feature test
 * (which also checks the OS state): a wrong answer would run an ISA the CPU lacks, or skip
 * every vector path and let the comparisons above pass on scalar code alone. */
static void cpu_features(void)
{
    sp_isa cached = sp_cpu_isa();
    CHECK(cached == sp_cpu_isa_detect());
    CHECK(sp_cpu_isa() == cached);
#if (defined(__x86_64__) || defined(__i386__)) && (defined(__GNUC__) || defined(__clang__))
    int avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    int avx512 = avx2 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
                 __builtin_cpu_supports("avx512vl");
    CHECK_MSG(cached == (avx512 ? SP_ISA_AVX512 : avx2 ? SP_ISA_AVX2 : SP_ISA_SCALAR), "sp_cpu_isa %d", (int)cached);
#endif
}

int main(void)
{
    cpu_features();
    /* AVX-512 (with AVX2 on its tail) first, then AVX2 alone; each falls to the next on CPUs
     * without it, so the checks then merely repeat. */
    static const sp_isa paths[] = {SP_ISA_AVX512, SP_ISA_AVX2};
    for (size_t p = 0; p < sizeof(paths) / sizeof(paths[0]); ++p) {
        widest = paths[p];
        path_coverage(paths[p]);
        exhaustive_small();
        counts_and_alignment();
        invalid_codes();
        odd_weights();
        tiny_weights();
        unsorted_lanes();
        range_edges();
        estimate_boundaries();
        split_row_boundaries();
        narrow_weights();
        random_tuples();
    }
    return check_report("test_batch");
}
