/*
 * The wide OSS vector paths (codec_oss_wide_simd.h: 64-bit integer lanes for K = 3 past
 * N = 2^24, K = 4 past N = 3 * 2^15, K = 2 past N = 2^48) against the scalar code, bit
 * for bit, once per vector path the CPU has: codes around every layer start (K = 4) and around
 * row starts (every row of sampled layers; for K = 3 every row just past the double lanes, and
 * the first, last and sampled rows of wider codes, where the root arguments stop being exact),
 * the last codes, random codes and weights from 46 to 64 bits, odd weights, counts and
 * alignments, invalid codes, which stop the batch where the scalar code stops, the grid points of
 * the boundary codes encoded (K = 4: the layer base of every layer), and for K = 2
 * past N = 2^49 (the exact pair rounding) adversarial pairs at 51..63 bits.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../../native/src/codec_internal.h" /* the *_isa batch forms: one path at a time */
#include "../../native/src/codec_oss_wide.h"     /* the double lanes' limits */
#include "check.h"
#include "skinpack.h"

#include "batch_compare.h"

static sp_codec oss_bits(uint32_t k, uint32_t bits)
{
    sp_codec c;
    CHECK(sp_codec_from_bits(SP_METHOD_OSS, k, bits, &c) == SP_OK);
    return c;
}

/* The codes start - 2 .. start + 1 of a base, those in range. */
static size_t push_around(const sp_codec* c, uint64_t start, uint64_t* codes, size_t count)
{
    for (uint64_t d = 0; d < 4; ++d)
        if (start + d >= 2 && start + d - 2 <= c->max_code) codes[count++] = start + d - 2;
    return count;
}

/* K = 3 rows (first, last, random, and around the rows where the root argument apex^2 + 3 - 12w
 * crosses 2^62) or the rows of one K = 4 layer (all of them when `every`). */
static size_t push_rows(const sp_codec* c, uint64_t base, uint64_t bottom, int every, uint64_t* codes, size_t count)
{
    uint64_t rows = (2 * bottom + 1) / 3, apex = 2 * bottom + 1, cross = apex > 0x80000000ull ? (apex - 0x80000000ull) / 3 : 0;
    if (every)
        for (uint64_t j = 0; j <= rows; ++j) count = push_around(c, base + sp_oss_row_base(bottom, j), codes, count);
    else
        for (uint64_t s = 0; s < 6000; ++s) {
            uint64_t j = s < 1000 ? s : s < 2000 ? rows - (s - 1000) : s < 3000 ? cross + s - 2500 : rng_next() % rows;
            if (j <= rows) count = push_around(c, base + sp_oss_row_base(bottom, j), codes, count);
        }
    return count;
}

/* Codes around every layer start of K = 4 (and every row of a few layers), around sampled row
 * starts of K = 3, around powers of two for K = 2, and the last 64 codes. */
static void boundaries(const sp_codec* c)
{
    uint64_t n = c->n, layers = c->influences == 4 ? (n + 1) / 2 : 1;
    size_t cap = (size_t)layers * 4 + 6000 * 4 * 8 + 64 + (c->influences == 4 && n < 200000 ? 8 * n : 0);
    uint64_t* codes = malloc(cap * sizeof(uint64_t));
    size_t count = 0;
    if (c->influences == 4) {
        for (uint64_t k = 0; k <= layers; ++k) count = push_around(c, sp_oss_layer_base(n, k), codes, count);
        uint64_t sampled[] = {0, 1, layers / 3, layers - 2, rng_next() % layers};
        for (size_t s = 0; s < 5; ++s)
            count = push_rows(c, sp_oss_layer_base(n, sampled[s]), n - 2 * sampled[s], n < 200000 && s == 2, codes, count);
    } else if (c->influences == 3) {
        count = push_rows(c, 0, n, 0, codes, count);
    } else { /* K = 2: around the powers of two, where the conversions to double start rounding */
        for (uint32_t bit = 1; bit < 64; ++bit) count = push_around(c, (uint64_t)1 << bit, codes, count);
        for (uint32_t bit = 1; bit < 64; ++bit) count = push_around(c, c->scale - ((uint64_t)1 << bit), codes, count);
    }
    for (uint64_t d = 0; d < 64; ++d) codes[count++] = c->max_code - d;
    compare_decode(c, codes, count, "boundary decode");
    float* w = malloc(count * c->influences * sizeof(float)); /* their grid points: for K = 4 every layer's, */
    CHECK(sp_decode_weights_batch_isa(c, codes, count, w, NULL, SP_ISA_SCALAR) == SP_OK); /* each k mod 3 and */
    compare_encode(c, w, count, "boundary encode"); /* layer numerator mod 9 of wide_layer_split */
    free(codes), free(w);
}

/* K = 3 just past the double lanes (N = 2^24 + 1): codes around every row start, in batches. */
static void every_row_start(void)
{
    sp_codec c = oss(3, BATCH_MAX_N3 + 1);
    uint64_t rows = (2 * c.n + 1) / 3, batch = 1 << 18;
    uint64_t* codes = malloc(batch * 4 * sizeof(uint64_t));
    for (uint64_t first = 0; first <= rows; first += batch) {
        size_t count = 0;
        for (uint64_t j = first; j < first + batch && j <= rows; ++j) count = push_around(&c, sp_oss_row_base(c.n, j), codes, count);
        compare_decode(&c, codes, count, "row start decode");
    }
    free(codes);
}

/* Random sorted weights of several shapes (ties, zeros, one-hot), some off by a float step. */
static void random_weights(uint32_t k, float* w)
{
    double raw[SP_MAX_INFLUENCES] = {0, 0, 0, 0}, sum = 0;
    uint64_t shape = rng_next() % 6;
    for (uint32_t i = 0; i < k; ++i) raw[i] = shape == 3 && i > 0 ? 0 : rng_unit();
    if (shape == 1) raw[1] = raw[0];
    if (shape == 2) raw[k - 1] = 0;
    for (uint32_t i = 1; i < k; ++i)
        for (uint32_t j = i; j > 0 && raw[j - 1] < raw[j]; --j) {
            double t = raw[j];
            raw[j] = raw[j - 1], raw[j - 1] = t;
        }
    for (uint32_t i = 0; i < k; ++i) sum += raw[i];
    for (uint32_t i = 0; i < k; ++i) w[i] = (float)(raw[i] / sum);
    if (shape == 4) w[rng_next() % k] = nextafterf(w[0], 1.0f); /* maybe unsorted */
}

/* Random codes, their decoded weights re-encoded (grid points) and nudged by a float step, and
 * random weights. */
static void random_round_trips(const sp_codec* c)
{
    uint32_t k = c->influences;
    size_t count = 100000;
    uint64_t* codes = malloc(count * sizeof(uint64_t));
    float* w = malloc(count * k * sizeof(float));
    for (size_t v = 0; v < count; ++v) codes[v] = c->max_code == UINT64_MAX ? rng_next() : rng_next() % (c->max_code + 1);
    compare_decode(c, codes, count, "random decode");
    CHECK(sp_decode_weights_batch_isa(c, codes, count, w, NULL, SP_ISA_SCALAR) == SP_OK);
    compare_encode(c, w, count, "decoded encode");
    for (size_t i = 0; i < count * k; ++i) w[i] = nextafterf(w[i], (i & 1) ? 0.0f : 1.0f);
    compare_encode(c, w, count, "nudged encode");
    for (size_t v = 0; v < count; ++v) random_weights(k, w + v * k);
    compare_encode(c, w, count, "random encode");
    free(codes), free(w);
}

/* An invalid code anywhere in a batch: the first one is reported, every vertex before it is
 * decoded as the scalar path decodes it, and none after it is written. */
static void invalid_codes(const sp_codec* c)
{
    enum { COUNT = 44 }; /* past an AVX-512 chunk, into blocks of 8 and 4 */
    uint32_t k = c->influences;
    if (c->max_code == UINT64_MAX) return; /* every code is valid */
    for (size_t at = 0; at < COUNT; ++at) {
        uint64_t codes[COUNT];
        float w[COUNT * 4], ref[COUNT * 4];
        for (size_t v = 0; v < COUNT; ++v) codes[v] = rng_next() % (c->max_code + 1);
        codes[at] = at % 2 ? UINT64_MAX : c->max_code + 1;
        if (at + 3 < COUNT) codes[at + 3] = c->max_code + 7; /* a later one is not reported */
        for (size_t i = 0; i < COUNT * 4; ++i) w[i] = ref[i] = -7.0f;
        size_t bad = (size_t)-1, ref_bad = (size_t)-2;
        CHECK(sp_decode_weights_batch_isa(c, codes, COUNT, w, &bad, widest) == SP_ERR_CODE_OUT_OF_RANGE);
        CHECK(sp_decode_weights_batch_isa(c, codes, COUNT, ref, &ref_bad, SP_ISA_SCALAR) == SP_ERR_CODE_OUT_OF_RANGE);
        CHECK_MSG(bad == at && ref_bad == at, "K=%u invalid at %zu reported at %zu", k, at, bad);
        CHECK(memcmp(w, ref, sizeof(w)) == 0); /* the same decoded prefix, the same untouched rest */
    }
}

/* The vertices the vector paths take in a batch of 23 (the scalar loop does the rest): a path
 * that silently did nothing would pass every comparison above. */
static void path_coverage(const sp_codec* c)
{
    float w[23 * 4];
    uint64_t codes[23];
    sp_isa cpu = sp_cpu_isa(), isa = cpu < widest ? cpu : widest;
    /* AVX-512: two blocks of 8 and one of 4; both ways, K = 2 encode past 2^50 grids too; K = 4
     * decode in pairs of blocks (its rows in 32-bit lanes): 16 of AVX-512 or AVX2, then none */
    size_t expected = isa >= SP_ISA_AVX2 ? 20 : 0, decoded = isa >= SP_ISA_AVX2 && c->influences == 4 ? 16 : expected;
    for (size_t v = 0; v < 23; ++v) random_weights(c->influences, w + v * c->influences);
    CHECK_MSG(sp_oss_encode_batch(c, w, 23, codes, NULL, widest) == expected, "K=%u N=%llu encode prefix",
              c->influences, (unsigned long long)c->n);
    for (size_t v = 0; v < 23; ++v) codes[v] = rng_next() % (c->max_code + 1);
    CHECK_MSG(sp_oss_decode_batch(c, codes, 23, w, widest) == decoded, "K=%u N=%llu decode prefix", c->influences,
              (unsigned long long)c->n);
    CHECK(sp_oss_batch_supported(c, widest) == (expected > 0));
}

/* Weights the scalar rounding sends down its general path (negative, NaN, infinite, zero, not
 * summing to 1): the vector lanes must hand them to the scalar code. */
static void odd_weights(const sp_codec* c)
{
    static const float odd[] = {-1e-3f, -0.0f, 0.0f, NAN, INFINITY, -INFINITY, 0.5f, 2.0f, 1.0f, 0.75f};
    uint32_t k = c->influences;
    size_t count = 4000;
    float* w = malloc(count * k * sizeof(float));
    for (size_t v = 0; v < count; ++v) {
        random_weights(k, w + v * k);
        for (uint32_t i = 0; i < k; ++i)
            if (rng_next() % 4 == 0) w[v * k + i] = odd[rng_next() % (sizeof(odd) / sizeof(odd[0]))];
    }
    compare_encode(c, w, count, "odd encode");
    free(w);
}

/* Counts around the block sizes (chunks, blocks of 8 and 4, tails) and pointers off the
 * vectors' alignment; a zero count with null pointers is fine. */
static void counts_and_alignment(const sp_codec* c)
{
    float w[4 * 72 + 4];
    uint64_t codes[72 + 2];
    uint32_t k = c->influences;
    for (size_t offset = 0; offset < 3; ++offset)
        for (size_t count = 0; count <= 70; count += 1 + count / 8) {
            for (size_t v = 0; v < count; ++v) random_weights(k, w + offset + v * k);
            compare_encode(c, w + offset, count, "count encode");
            for (size_t v = 0; v < count; ++v) codes[offset + v] = rng_next() % (c->max_code + 1);
            compare_decode(c, codes + offset, count, "count decode");
        }
    CHECK(sp_encode_weights_batch_isa(c, NULL, 0, NULL, NULL, widest) == SP_OK);
    CHECK(sp_decode_weights_batch_isa(c, NULL, 0, NULL, NULL, widest) == SP_OK);
}

/* K = 2 pairs for the lanes' exact rounding (grids past 2^50): every exponent gap 0..70 with
 * random significands in both slot orders, denormals, zeros, equal weights, the edges of the
 * plain test (-0, the smallest negative, the largest float, infinity, NaN), near ties (the
 * smaller weight picked so that x = s small / D is near m + 1/2, as near as a float allows) and
 * exact ties +-1 step. */
static void adversarial_pairs(const sp_codec* c)
{
    static const uint32_t edges[] = {0x00000000u, 0x80000000u, 0x80000001u, 0x00000001u, 0x007FFFFFu,
                                     0x00800000u, 0x7F7FFFFFu, 0x7F800000u, 0x7FC00000u, 0x3F800000u};
    size_t count = 60000, ties = 0;
    uint32_t tie[64][2]; /* B < 2^k with s B = 2^(k-1) mod 2^k: x = s B / 2^k is exactly m + 1/2 */
    for (uint32_t k = 8; k <= 16 && ties < 64; ++k)
        for (uint64_t b = 1; b < ((uint64_t)1 << k) && ties < 64; ++b)
            if (((c->scale * b) & (((uint64_t)1 << k) - 1)) == (uint64_t)1 << (k - 1)) tie[ties][0] = (uint32_t)b, tie[ties++][1] = k;
    float* w = malloc(count * 2 * sizeof(float));
    for (size_t v = 0; v < count; ++v) {
        uint32_t gap = (uint32_t)(rng_next() % 71), kind = (uint32_t)(rng_next() % 7), bits[2];
        int exponent = -(int)(rng_next() % 60);
        float large = ldexpf((float)((rng_next() & 0x7FFFFF) | 0x800000), exponent - 23);
        float small = ldexpf((float)((rng_next() & 0x7FFFFF) | 0x800000), exponent - 23 - (int)gap);
        if (kind == 1) small = ldexpf((float)(rng_next() % 0x800000), -149);
        if (kind == 2) small = v % 2 ? 0.0f : large;
        if (kind == 3) { /* near a tie: D ~ large, x = s small / D, small moved so x is m + 1/2 */
            long double d = (long double)large, x = (long double)c->scale * small / (d + small);
            long double target = floorl(x) + 0.5L, b = target * d / ((long double)c->scale - target);
            small = (float)b;
        }
        if (kind == 5 && ties) { /* an exact tie, or 1/2^k off it (D = 2^(exponent - k) exactly) */
            const uint32_t* t = tie[rng_next() % ties];
            int64_t b = (int64_t)t[0] + (int64_t)(rng_next() % 3) - 1;
            small = ldexpf((float)b, exponent - (int)t[1]);
            large = ldexpf((float)(((int64_t)1 << t[1]) - b), exponent - (int)t[1]);
        }
        memcpy(&bits[0], &large, 4), memcpy(&bits[1], &small, 4);
        if (kind == 4) bits[rng_next() % 2] = edges[rng_next() % (sizeof(edges) / sizeof(edges[0]))];
        int swap = (int)(rng_next() % 2);
        memcpy(&w[v * 2 + swap], &bits[0], 4), memcpy(&w[v * 2 + 1 - swap], &bits[1], 4);
    }
    compare_encode(c, w, count, "adversarial pair encode");
    free(w);
}

static void check_codec(const sp_codec* c)
{
    counts_and_alignment(c);
    odd_weights(c);
    path_coverage(c);
    boundaries(c);
    random_round_trips(c);
    invalid_codes(c);
}

int main(void)
{
    static const uint32_t widths[] = {46, 48, 52, 56, 60, 64};
    static const sp_isa paths[] = {SP_ISA_AVX512, SP_ISA_AVX2};
    for (size_t p = 0; p < sizeof(paths) / sizeof(paths[0]); ++p) {
        widest = paths[p];
        for (uint32_t k = 3; k <= 4; ++k)
            for (size_t i = 0; i < sizeof(widths) / sizeof(widths[0]); ++i) {
                sp_codec c = oss_bits(k, widths[i]);
                if (sp_oss_lanes_for(&c) == SP_LANES_WIDE) check_codec(&c);
            }
        /* just past the double lanes, and the largest N of each K */
        sp_codec edges[] = {oss(3, BATCH_MAX_N3 + 1), oss(4, BATCH_MAX_N4 + 1), oss(2, BATCH_MAX_N2 + 1),
                            oss(2, (uint64_t)1 << 49)};
        for (size_t e = 0; e < sizeof(edges) / sizeof(edges[0]); ++e) check_codec(&edges[e]);
        /* K = 2 past 2^49: the exact pair rounding in the lanes */
        sp_codec k2_52 = oss_bits(2, 52), k2_64 = oss_bits(2, 64), k2_past = oss(2, ((uint64_t)1 << 49) + 1);
        check_codec(&k2_52);
        check_codec(&k2_64);
        check_codec(&k2_past);
        static const uint32_t pair_widths[] = {51, 52, 56, 60, 63};
        for (size_t i = 0; i < sizeof(pair_widths) / sizeof(pair_widths[0]); ++i) {
            sp_codec c = oss_bits(2, pair_widths[i]);
            adversarial_pairs(&c);
        }
        every_row_start();
    }
    return check_report("test_batch_wide");
}
