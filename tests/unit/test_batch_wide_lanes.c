/*
 * What the wide decode lanes decode themselves (codec_oss_wide_simd.h, K = 3 past N = 2^24 and
 * K = 4 past N = 3 * 2^15; AVX2, or AVX-512 where built with LANES_AVX512). test_batch_wide.c
 * compares their output with the scalar code, but a lane they reject is redone by the scalar
 * code, so a broken rest or row offset (one that rejected every lane) would pass it. Here the
 * ISA's driver is compiled into the test with the scalar redo counted: every output still
 * bit-identical, and the redone lanes few, for random codes and for the codes around row starts
 * (where K = 3's estimate, half a row low, must take the step up, and K = 4's rows sit deep
 * inside their layer) and layer starts, up to 64-bit codes; and K = 4's split lanes
 * (codec_oss_simd.h, N = 1025 to 80264) at their layers' ends.
 * The same for encode, double and wide lanes, K = 2 to 4, 16- to 64-bit codes: sorted weights of
 * the bench's mix (one to K of them non-zero) and random ones, which the lanes must take every
 * one of (a broken rank, deficit check or layer product that rejected lanes would pass
 * test_batch: the scalar redo gives the same codes).
 */
#include <stdlib.h>
#include <string.h>

#include "../../native/src/codec_internal.h"

#include "check.h"
#include "skinpack.h"

#if SP_X86_SIMD
/* The driver's scalar redo, counted. */
static size_t redone = 0;
static void counted_decode_one(const sp_codec* codec, uint64_t code, float* weights)
{
    ++redone;
    sp_oss_decode_one(codec, code, weights);
}
#define sp_oss_decode_one counted_decode_one
static uint64_t counted_encode_one(const sp_codec* codec, const float* weights, uint8_t* significant)
{
    ++redone;
    return sp_oss_encode_one(codec, weights, significant);
}
#define sp_oss_encode_one counted_encode_one

#include "../../native/src/codec_oss_wide.h"
#if LANES_AVX512
#include "../../native/src/codec_oss_prim_avx512.h"
#define LANES_ISA SP_ISA_AVX512
#define LANES_TEST "test_batch_wide_lanes_avx512"
#else
#include "../../native/src/codec_oss_prim_avx2.h"
#define LANES_ISA SP_ISA_AVX2
#define LANES_TEST "test_batch_wide_lanes"
#endif
#undef SIMD_NAME
#define SIMD_NAME(name) counted_##name /* not the library's entry points */
#undef WIDE_NAME
#define WIDE_NAME(name) counted_wide_##name
#include "../../native/src/codec_oss_simd.h"
#include "../../native/src/codec_oss_wide_simd.h"
#undef sp_oss_decode_one
#undef sp_oss_encode_one

static sp_codec oss(uint32_t k, uint64_t n)
{
    sp_codec c;
    CHECK(sp_codec_from_params(SP_METHOD_OSS, k, n, NULL, &c) == SP_OK);
    return c;
}

/* Decodes `count` codes through the counted lanes (the wide ones where sp_oss_lanes_for says so,
 * else the double and 32-bit ones): every vertex of the full blocks taken, each bit-identical to
 * sp_decode_weights; returns the lanes redone. */
static size_t decode_counted(const sp_codec* c, const uint64_t* codes, size_t count, const char* what)
{
    uint32_t k = c->influences;
    float* w = malloc(count * k * sizeof(float));
    float ref[SP_MAX_INFLUENCES];
    redone = 0;
    size_t done = sp_oss_lanes_for(c) == SP_LANES_WIDE ? counted_wide_decode(c, codes, count, w, 0)
                                                        : counted_decode(c, codes, count, w, 0);
    size_t lanes = k == 4 ? NBLOCK : BLOCK; /* K = 4 in pairs of blocks */
    CHECK_MSG(done == count / lanes * lanes, "%s K=%u N=%llu: %zu of %zu done", what, k, (unsigned long long)c->n, done, count);
    for (size_t v = 0, failures = 0; v < done && failures < 5; ++v) {
        sp_decode_weights(c, codes[v], ref);
        int same = memcmp(w + v * k, ref, k * sizeof(float)) == 0;
        CHECK_MSG(same, "%s K=%u N=%llu code %llu", what, k, (unsigned long long)c->n, (unsigned long long)codes[v]);
        failures += !same;
    }
    free(w);
    return redone;
}

/* Random valid codes: the estimates miss about one in 10^5 (none in these runs), so more than
 * one in 10^3 redone means the lanes reject what they should decode. */
static void random_codes(const sp_codec* c)
{
    size_t count = 40000;
    uint64_t* codes = malloc(count * sizeof(uint64_t));
    for (size_t v = 0; v < count; ++v) codes[v] = c->max_code == UINT64_MAX ? rng_next() : rng_next() % (c->max_code + 1);
    size_t redo = decode_counted(c, codes, count, "random");
    CHECK_MSG(redo <= count / 1000, "random K=%u N=%llu: %zu of %zu lanes redone", c->influences, (unsigned long long)c->n,
              redo, count);
    free(codes);
}

/* The codes s - 2 .. s + 1 around 4000 row starts s: K = 3 rows 2 .. 2001 and the last ones
 * but the last two (where the estimate, half a row low, must take the step up), K = 4 rows
 * spread over the middle of the triangle of layer `layer` (rests up to 2^44, away from its ends,
 * where a code may land in the next or previous layer and be redone). None may be redone: each
 * is the last code of a row or one of the first two, decided by the exact double forms. */
static void row_starts(const sp_codec* c, uint64_t layer)
{
    uint64_t bottom = c->n - 2 * layer, rows = (2 * bottom + 1) / 3;
    uint64_t base = c->influences == 4 ? sp_oss_layer_base(c->n, layer) : 0;
    size_t count = 0;
    uint64_t* codes = malloc(4 * 4000 * sizeof(uint64_t));
    for (uint64_t s = 0; s < 4000; ++s) {
        uint64_t j = c->influences == 4 ? rows / 3 + s * (rows / 2) / 4000 : s < 2000 ? s + 2 : rows - 2 - (s - 2000);
        for (uint64_t d = 0; d < 4; ++d) codes[count++] = base + sp_oss_row_base(bottom, j) + d - 2;
    }
    size_t redo = decode_counted(c, codes, count, "row starts");
    CHECK_MSG(redo == 0, "row starts K=%u N=%llu layer %llu: %zu of %zu lanes redone", c->influences,
              (unsigned long long)c->n, (unsigned long long)layer, redo, count);
    free(codes);
}

/* K = 4: the codes u(k) - 2 .. u(k) + 1 around 4000 layer starts (the first layers, spread over
 * the middle, the last ones; valid codes only): a rest just outside its layer (negative, or S(B)
 * and above) must fail the layer check, as the 32-bit lanes' offset, modulo 2^32, cannot tell;
 * every output bit-identical. The layer estimate cannot resolve single codes next to a large
 * layer's start (its rounding there spans ~2^14 codes at 64 bits): ~15-40% of these lanes are
 * redone, so only a path that rejected nearly every lane fails. */
static void layer_starts(const sp_codec* c)
{
    uint64_t layers = (c->n + 1) / 2;
    size_t count = 0;
    uint64_t* codes = malloc(4 * 4000 * sizeof(uint64_t));
    for (uint64_t s = 0; s < 4000; ++s) {
        uint64_t k = s < 1000 ? s + 1 : s < 3000 ? layers / 4 + (s - 1000) * (layers / 2) / 2000 : layers - 1 - (s - 3000);
        uint64_t base = sp_oss_layer_base(c->n, k);
        for (uint64_t d = 0; d < 4 && base + d - 2 <= c->max_code; ++d) codes[count++] = base + d - 2;
    }
    size_t redo = decode_counted(c, codes, count, "layer starts");
    CHECK_MSG(redo <= count * 3 / 4, "layer starts K=4 N=%llu: %zu of %zu lanes redone", (unsigned long long)c->n, redo, count);
    free(codes);
}

/* K = 4 in the split lanes (float layer root, rows in 32-bit lanes): codes in the last 1/256 of
 * 2000 layers (the first ones, spread over the middle, the last ones), where the float root's
 * layer (a quarter of a float sum near 2N, good to about an ulp: 2^-8 of a layer at 44 bits) is
 * often one too high; the rest stage steps those lanes down, so no more than one in 10^3 may be
 * redone (without the step: 0.5 % at N = 1025, 41 % at 68158). */
static void split_layer_ends(const sp_codec* c)
{
    uint64_t layers = (c->n + 1) / 2;
    size_t count = 0;
    uint64_t* codes = malloc(2000 * 8 * sizeof(uint64_t));
    for (uint64_t s = 0; s < 2000; ++s) {
        uint64_t k = s < 500 ? s : s < 1500 ? layers / 4 + (s - 500) * (layers / 2) / 1000 : layers - 1 - (s - 1500);
        uint64_t end = sp_oss_layer_base(c->n, k + 1), size = end - sp_oss_layer_base(c->n, k);
        for (uint64_t d = 0; d < 8; ++d) codes[count++] = end - 1 - rng_next() % (size / 256 + 1);
    }
    size_t redo = decode_counted(c, codes, count, "split layer ends");
    CHECK_MSG(redo <= count / 1000, "split layer ends K=4 N=%llu: %zu of %zu lanes redone", (unsigned long long)c->n,
              redo, count);
    free(codes);
}

/* Sorted weights summing to about 1: `nonzero` of them from 1..1000 (the bench's), or random
 * floats in (0, 1] where nonzero is 0. */
static void sorted_weights(uint32_t k, uint32_t nonzero, float* w)
{
    float sum = 0;
    for (uint32_t i = 0; i < k; ++i) {
        w[i] = nonzero ? (i < nonzero ? (float)(rng_next() % 1000 + 1) : 0.0f) : (float)(1.0 - rng_unit());
        sum += w[i];
    }
    for (uint32_t i = 1; i < k; ++i) /* descending */
        for (uint32_t j = i; j > 0 && w[j - 1] < w[j]; --j) {
            float t = w[j];
            w[j] = w[j - 1];
            w[j - 1] = t;
        }
    for (uint32_t i = 0; i < k; ++i) w[i] /= sum;
}

/* Encodes 40000 sorted vertices through the counted lanes (the double ones up to `wide`): every
 * code of the full blocks bit-identical to sp_encode_weights, and none redone. */
static void encode_counted(const sp_codec* c, int wide)
{
    uint32_t k = c->influences;
    size_t count = 40000;
    float* w = malloc(count * k * sizeof(float));
    uint64_t* codes = malloc(count * sizeof(uint64_t));
    for (size_t v = 0; v < count; ++v) sorted_weights(k, (uint32_t)(v % (k + 1)), w + v * k);
    redone = 0;
    size_t done = wide ? counted_wide_encode(c, w, count, codes, NULL) : counted_encode(c, w, count, codes, NULL);
    CHECK_MSG(done == count / BLOCK * BLOCK, "encode K=%u N=%llu: %zu of %zu done", k, (unsigned long long)c->n, done, count);
    for (size_t v = 0, failures = 0; v < done && failures < 5; ++v) {
        int same = codes[v] == sp_encode_weights(c, w + v * k);
        CHECK_MSG(same, "encode K=%u N=%llu vertex %zu", k, (unsigned long long)c->n, v);
        failures += !same;
    }
    CHECK_MSG(redone == 0, "encode K=%u N=%llu: %zu of %zu lanes redone", k, (unsigned long long)c->n, redone, done);
    free(w);
    free(codes);
}

static void check_encode(void)
{
    static const uint32_t widths[] = {16, 22, 32, 44, 52, 64};
    for (uint32_t k = 2; k <= 4; ++k)
        for (size_t i = 0; i < sizeof(widths) / sizeof(widths[0]); ++i) {
            sp_codec c;
            if (sp_codec_from_bits(SP_METHOD_OSS, k, widths[i] - (k == 2 && widths[i] == 64), &c) != SP_OK) continue;
            encode_counted(&c, sp_oss_lanes_for(&c) == SP_LANES_WIDE);
        }
}

static void check_codec(const sp_codec* c)
{
    random_codes(c);
    if (c->influences == 3) row_starts(c, 0);
    else {
        uint64_t layers = (c->n + 1) / 2;
        row_starts(c, 0);
        row_starts(c, layers / 3);
        row_starts(c, layers - 3000);
        layer_starts(c);
    }
}

int main(void)
{
    if (sp_cpu_isa() < LANES_ISA) {
        printf("%s: the CPU lacks the ISA, nothing to check\n", LANES_TEST);
        return 0;
    }
    check_encode();
    static const uint64_t split[] = {NARROW_MAX_N4 + 1, 4258, 17038, 68158, SPLIT_MAX_N4};
    for (size_t i = 0; i < sizeof(split) / sizeof(split[0]); ++i) {
        sp_codec c = oss(4, split[i]);
        split_layer_ends(&c);
    }
    static const uint32_t widths[] = {52, 56, 60, 64};
    for (uint32_t k = 3; k <= 4; ++k)
        for (size_t i = 0; i < sizeof(widths) / sizeof(widths[0]); ++i) {
            sp_codec c;
            CHECK(sp_codec_from_bits(SP_METHOD_OSS, k, widths[i], &c) == SP_OK);
            check_codec(&c);
        }
    /* just past the double lanes */
    sp_codec k3 = oss(3, BATCH_MAX_N3 + 1), k4 = oss(4, BATCH_MAX_N4 + 1);
    check_codec(&k3);
    check_codec(&k4);
    return check_report(LANES_TEST);
}
#else
int main(void)
{
    printf("test_batch_wide_lanes: not x86, nothing to check\n");
    return 0;
}
#endif
