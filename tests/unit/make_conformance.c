/*
 * Writes the conformance vectors of docs/extension/conformance/weights.jsonl: for every method,
 * K = 1..4 and a spread of weight widths up to 64, valid codes with their integer grid point
 * and float32 weights (hex bit patterns), and invalid codes with the reason a reader rejects
 * them. Run by hand when the format changes (never by the tests, which check the committed
 * file): build/tests/unit/make_conformance > docs/extension/conformance/weights.jsonl
 */
#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include "conformance_common.h"

static uint64_t rng = 0x2545F4914F6CDD1Dull;
static uint64_t next_random(void)
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return rng;
}

static void print_codec(const sp_codec* c)
{
    printf("{\"method\": \"%s\", \"influences\": %u, \"n\": \"%" PRIu64 "\", \"axisSamples\": [", sp_method_name(c->method),
           c->influences, c->n);
    for (uint32_t a = 0; c->method == SP_METHOD_ANY && a + 1 < c->influences; ++a)
        printf("%s\"%" PRIu64 "\"", a ? ", " : "", c->axis_samples[a]);
    printf("], \"weightBits\": %u, \"maxCode\": \"%" PRIu64 "\", \"scale\": \"%" PRIu64 "\", ", c->bits, c->max_code,
           c->scale);
}

static void print_vector(const sp_codec* c, uint64_t code)
{
    float weights[SP_MAX_INFLUENCES];
    uint64_t grid[SP_MAX_INFLUENCES];
    size_t bad = 0;
    print_codec(c);
    if (code > c->max_code || sp_decode_weights_batch(c, &code, 1, weights, &bad) != SP_OK) {
        printf("\"code\": \"%" PRIu64 "\", \"valid\": false, \"reason\": \"%s\"}\n", code,
               code > c->max_code ? "above maxCode" : "outside the simplex");
        return;
    }
    uint32_t count = conformance_grid(c, code, grid);
    printf("\"code\": \"%" PRIu64 "\", \"valid\": true, \"grid\": [", code);
    for (uint32_t i = 0; i < count; ++i) printf("%s\"%" PRIu64 "\"", i ? ", " : "", grid[i]);
    printf("], \"weights\": [");
    for (uint32_t i = 0; i < c->influences; ++i) {
        uint32_t bits;
        memcpy(&bits, &weights[i], 4);
        printf("%s\"%08x\"", i ? ", " : "", bits);
    }
    printf("]}\n");
}

/* Codes worth pinning: the corners, encoded typical tuples, OSS layer and row boundaries,
 * random codes (valid or not), and the first code past the end when W bits can hold it. */
static void print_codec_vectors(const sp_codec* c)
{
    static const float tuples[][4] = {{1, 0, 0, 0}, {0.5f, 0.5f, 0, 0}, {0.25f, 0.25f, 0.25f, 0.25f},
                                      {0.4f, 0.3f, 0.2f, 0.1f}, {0.7f, 0.2f, 0.1f, 0}, {0.34f, 0.33f, 0.33f, 0}};
    uint32_t k = c->influences;
    uint64_t codes[32];
    size_t count = 0;
    codes[count++] = 0;
    codes[count++] = c->max_code;
    for (size_t t = 0; t < sizeof(tuples) / sizeof(tuples[0]) && k > 1; ++t) {
        float w[4] = {0};
        float sum = 0;
        for (uint32_t i = 0; i < k; ++i) sum += tuples[t][i];
        for (uint32_t i = 0; i < k; ++i) w[i] = tuples[t][i] / sum;
        codes[count++] = sp_encode_weights(c, w);
    }
    if (c->method == SP_METHOD_OSS && k == 4 && c->n > 4) {
        uint64_t layer = (c->n + 1) / 2 - 1, base = sp_oss_layer_base(c->n, layer);
        codes[count++] = base, codes[count++] = base - 1;
    }
    if (c->method == SP_METHOD_OSS && k == 3 && c->n > 4) {
        uint64_t base = sp_oss_row_base(c->n, 1);
        codes[count++] = base, codes[count++] = base - 1;
    }
    for (int r = 0; r < 3 && c->max_code > 0; ++r)
        codes[count++] = c->max_code == UINT64_MAX ? next_random() : next_random() % (c->max_code + 1);
    for (size_t i = 0; i < count; ++i) {
        int seen = 0;
        for (size_t j = 0; j < i; ++j) seen |= codes[j] == codes[i];
        if (!seen) print_vector(c, codes[i]);
    }
    if (c->max_code < UINT64_MAX && (c->bits == 64 || (c->max_code + 1) >> c->bits == 0)) print_vector(c, c->max_code + 1);
}

int main(void)
{
    static const uint32_t widths[] = {2, 3, 5, 8, 12, 16, 24, 32, 48, 53, 54, 64};
    sp_codec single;
    sp_codec_from_bits(SP_METHOD_OSS, 1, 0, &single);
    print_codec_vectors(&single);
    for (int m = 0; m < SP_METHOD_COUNT; ++m)
        for (uint32_t k = 2; k <= SP_MAX_INFLUENCES; ++k) {
            uint32_t last_bits = 0;
            for (size_t w = 0; w < sizeof(widths) / sizeof(widths[0]); ++w) {
                sp_codec c;
                if (sp_codec_from_bits((sp_method)m, k, widths[w], &c) != SP_OK || c.bits == last_bits) continue;
                last_bits = c.bits;
                print_codec_vectors(&c);
            }
        }
    return 0;
}
