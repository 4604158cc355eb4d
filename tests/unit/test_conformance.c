/*
 * Checks the library against the committed conformance vectors (docs/extension/conformance/
 * weights.jsonl, argv[1]), like meshoptimizer's golden byte tests: every codec rebuilt from its
 * stored parameters has the stated width, largest code and grid; every valid code decodes to
 * the stated grid point and float32 bit patterns, one at a time and in batches (the SIMD paths);
 * every invalid code is rejected by the decoder and by sp_validate_packed with the stated reason.
 */
#include <inttypes.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "conformance_common.h"
#include "conformance_vectors.h"

/* A one-vertex primitive holding the code, validated by the library's reader entry point. */
static sp_result validate_one(const conformance_vector* v, const sp_codec* codec, float* weights)
{
    static const uint16_t lut[4] = {0, 1, 2, 3};
    uint32_t words[2] = {(uint32_t)v->code, (uint32_t)(v->code >> 32)};
    uint16_t joints[4];
    sp_packed_params params = {(uint32_t)v->method, v->k, 4, codec->bits, 0, v->n, {0}, 0, 0, 0};
    memcpy(params.axis_samples, v->axes, sizeof(v->axes));
    params.axis_sample_count = (uint32_t)v->axis_count;
    sp_packed_primitive prim = {params, words, 1, codec->bits > 32 ? 2 : 1, 1, lut, 1, v->k, 1, 0, NULL};
    return sp_validate_packed(&prim, joints, weights, NULL);
}

static void check_vector(const conformance_vector* v, size_t line)
{
    sp_codec codec;
    CHECK_MSG(sp_codec_from_params(v->method, v->k, v->n, v->axis_count ? v->axes : NULL, &codec) == SP_OK, "line %zu",
              line);
    CHECK_MSG(codec.bits == v->weight_bits && codec.max_code == v->max_code && codec.scale == v->scale, "line %zu",
              line);
    float weights[4] = {0}, validated[4] = {0};
    size_t bad = 0;
    sp_result decoded = sp_decode_weights_batch(&codec, &v->code, 1, weights, &bad);
    sp_result read = validate_one(v, &codec, validated);
    if (!v->valid) {
        sp_result want = strcmp(v->reason, "above maxCode") == 0 ? SP_ERR_CODE_OUT_OF_RANGE : SP_ERR_CODE_OUTSIDE_SIMPLEX;
        CHECK_MSG(decoded == SP_ERR_CODE_OUT_OF_RANGE, "line %zu: invalid code %" PRIu64 " decoded", line, v->code);
        CHECK_MSG(read == want, "line %zu: validator gives %d for %s", line, read, v->reason);
        return;
    }
    CHECK_MSG(decoded == SP_OK && read == SP_OK, "line %zu: valid code %" PRIu64 " rejected", line, v->code);
    uint64_t grid[4];
    uint32_t count = conformance_grid(&codec, v->code, grid);
    CHECK_MSG(count == v->grid_count && memcmp(grid, v->grid, count * sizeof(uint64_t)) == 0, "line %zu: grid", line);
    CHECK(v->weight_count == v->k);
    for (uint32_t i = 0; i < v->k; ++i) {
        uint32_t bits, validated_bits;
        memcpy(&bits, &weights[i], 4);
        memcpy(&validated_bits, &validated[i], 4);
        CHECK_MSG(bits == v->weights[i] && validated_bits == v->weights[i], "line %zu slot %u: %08x, want %08" PRIx64,
                  line, i, bits, v->weights[i]);
    }
}

/* All valid codes of one codec decoded in one batch (repeated to fill vector blocks). */
static void check_batch(const conformance_vector* group, size_t count, size_t first_line)
{
    enum { COPIES = 8 };
    uint64_t codes[64 * COPIES];
    float weights[64 * COPIES * 4];
    size_t n = 0;
    for (size_t c = 0; c < COPIES; ++c)
        for (size_t i = 0; i < count && n < 64 * COPIES; ++i)
            if (group[i].valid) codes[n++] = group[i].code;
    sp_codec codec;
    if (n == 0 || sp_codec_from_params(group[0].method, group[0].k, group[0].n,
                                       group[0].axis_count ? group[0].axes : NULL, &codec) != SP_OK)
        return;
    size_t bad = 0;
    CHECK_MSG(sp_decode_weights_batch(&codec, codes, n, weights, &bad) == SP_OK, "batch at line %zu", first_line);
    for (size_t i = 0, at = 0; i < n; ++at) {
        const conformance_vector* v = &group[at % count];
        if (!v->valid) continue;
        for (uint32_t s = 0; s < v->k; ++s) {
            uint32_t bits;
            memcpy(&bits, &weights[i * v->k + s], 4);
            CHECK_MSG(bits == v->weights[s], "batch at line %zu, code %" PRIu64, first_line, v->code);
        }
        ++i;
    }
}

int main(int argc, char** argv)
{
    FILE* f = argc > 1 ? fopen(argv[1], "r") : NULL;
    if (!f) {
        fprintf(stderr, "usage: test_conformance weights.jsonl\n");
        return 2;
    }
    static conformance_vector group[64];
    static char line[4096];
    size_t lines = 0, in_group = 0, group_line = 0, valid = 0, invalid = 0;
    uint32_t methods_seen = 0, widths64 = 0;
    char key[256] = "", previous[256] = "";
    while (fgets(line, sizeof(line), f)) {
        conformance_vector v;
        memset(&v, 0, sizeof(v));
        ++lines;
        CHECK_MSG(conformance_parse(line, &v) == 0, "line %zu does not parse", lines);
        check_vector(&v, lines);
        v.valid ? ++valid : ++invalid;
        methods_seen |= 1u << v.method;
        widths64 += v.weight_bits == 64;
        const char* end = strstr(line, "\"code\"");
        snprintf(key, sizeof(key), "%.*s", (int)(end ? end - line : 0), line);
        if (strcmp(key, previous) != 0 || in_group == 64) {
            check_batch(group, in_group, group_line);
            in_group = 0, group_line = lines;
            memcpy(previous, key, sizeof(key));
        }
        group[in_group++] = v;
    }
    check_batch(group, in_group, group_line);
    fclose(f);
    CHECK(lines > 1000 && valid > 800 && invalid > 100);
    CHECK(methods_seen == (1u << SP_METHOD_COUNT) - 1 && widths64 > 0);
    printf("%zu vectors (%zu valid, %zu invalid)\n", lines, valid, invalid);
    return check_report("test_conformance");
}
