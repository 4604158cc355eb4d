/*
 * conformance FILE: the GLSL decoders against the spec's conformance vectors
 * (docs/extension/conformance/weights.jsonl). Every valid code of a codec is decoded on the GPU,
 * by the default decoder and forced through the 64-bit one: the integers (q_i, or x_i for Any)
 * must be the vector's exactly and the float weights within 1e-6 of the vector's float32 (the
 * GPU computes in float32; the vector holds the reference double -> float32 result). The
 * vectors are fixed files, so a GPU and C decoder that drift together still fail here.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "conformance_vectors.h"
#include "harness.h"

#define CONFORMANCE_TOLERANCE 1e-6f

static void check_group(harness* h, const conformance_vector* group, size_t count, size_t first_line)
{
    sp_codec codec;
    if (count == 0) return;
    const conformance_vector* c = &group[0];
    if (sp_codec_from_params(c->method, c->k, c->n, c->axis_count ? c->axes : NULL, &codec) != SP_OK) {
        fail_check(h, "line %zu: codec parameters rejected", first_line);
        return;
    }
    uint32_t* words = malloc(count * 2 * sizeof(uint32_t));
    for (size_t i = 0; i < count; ++i) {
        words[2 * i] = (uint32_t)group[i].code;
        words[2 * i + 1] = (uint32_t)(group[i].code >> 32);
    }
    SpGpuCodec gpu = sp_gpu_codec_fill(&codec, 0, 2, 1, 1, 1);
    for (int force_wide = 0; force_wide < 2; ++force_wide) {
        SpDecodedRecord* records = gpu_decode(h, &gpu, SP_DECODE_MODE_CODES, words, count * 2, count, NULL, 0, force_wide);
        for (size_t i = 0; i < count; ++i) {
            const conformance_vector* v = &group[i];
            const float* got = record_weights(&records[i]);
            ++h->checked;
            /* records hold q1..qK, or x2..xK in slots 1..K-1 for Any */
            size_t first = v->method == SP_METHOD_ANY ? 1 : 0;
            for (size_t g = 0; g < v->grid_count; ++g)
                if (record_q(&records[i], (int)(first + g)) != v->grid[g])
                    fail_check(h, "%s K=%u bits=%u code %llu%s: integer %zu is %llu, the vector says %llu",
                               sp_method_name(v->method), v->k, v->weight_bits, (unsigned long long)v->code,
                               force_wide ? " (64-bit decoder)" : "", g, (unsigned long long)record_q(&records[i], (int)(first + g)),
                               (unsigned long long)v->grid[g]);
            for (uint32_t s = 0; s < v->k; ++s) {
                float want;
                uint32_t bits = (uint32_t)v->weights[s];
                memcpy(&want, &bits, 4);
                if (!(fabsf(got[s] - want) <= CONFORMANCE_TOLERANCE))
                    fail_check(h, "%s K=%u bits=%u code %llu%s: w%u = %.9g on the GPU, the vector says %.9g",
                               sp_method_name(v->method), v->k, v->weight_bits, (unsigned long long)v->code,
                               force_wide ? " (64-bit decoder)" : "", s + 1, (double)got[s], (double)want);
            }
        }
        free(records);
    }
    free(words);
}

void test_conformance(harness* h, const char* path)
{
    FILE* f = fopen(path, "r");
    if (!f) {
        fail_check(h, "cannot open %s", path);
        return;
    }
    static conformance_vector group[64];
    static char line[4096];
    char key[256] = "", previous[256] = "";
    size_t lines = 0, in_group = 0, group_line = 0;
    while (fgets(line, sizeof(line), f)) {
        conformance_vector v;
        memset(&v, 0, sizeof(v));
        ++lines;
        if (conformance_parse(line, &v) != 0) {
            fail_check(h, "line %zu does not parse", lines);
            continue;
        }
        const char* end = strstr(line, "\"code\"");
        snprintf(key, sizeof(key), "%.*s", (int)(end ? end - line : 0), line);
        if (strcmp(key, previous) != 0 || in_group == 64) {
            check_group(h, group, in_group, group_line);
            in_group = 0, group_line = lines;
            memcpy(previous, key, sizeof(key));
        }
        if (v.valid) group[in_group++] = v; /* GPU decoders assume validated input */
    }
    check_group(h, group, in_group, group_line);
    fclose(f);
    printf("conformance: %zu vector lines read from %s\n", lines, path);
}
