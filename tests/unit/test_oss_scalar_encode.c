/*
 * The scalar OSS batch encoder's own forms against the library's general ones (issue 14):
 *   - the K = 4 layer base past 2^21 (N from OSS_LAYER64_N up to the largest 64-bit K = 4 grid)
 *     taken modulo 2^64 with an exact division by 9 and a remainder table by k mod 3, against
 *     sp_oss_pack's 128-bit closed form, for N of each residue mod 3, every layer's neighbourhood
 *     sampled, the top layer, and unsorted weights (layers past the tetrahedron, where the code
 *     wraps as sp_oss_pack's does);
 *   - the rounding's skipped clamps: -0 in place of +0 must not change a code or a count (the
 *     remainders are ranked as bit patterns, where -0 would sort above every remainder).
 * The reference is sp_grid_quantize and sp_oss_pack vertex by vertex; the batch runs the
 * scalar path only (SP_ISA_SCALAR).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../../native/src/codec_internal.h" /* the *_isa batch forms, sp_grid_quantize, sp_oss_pack */
#include "check.h"
#include "skinpack.h"

#define VERTICES 60000

/* Sorted weights with the smallest one spread over [0, 1/4], so that q3 (the layer) takes every
 * value up to the top layer; a few all equal (the top layer itself) and a few unsorted. */
static void make_weights(size_t count, float* w)
{
    for (size_t v = 0; v < count; ++v) {
        double raw[4], sum = 0;
        for (int i = 0; i < 4; ++i) raw[i] = (double)(rng_next() >> 11) * 0x1p-53;
        for (int i = 1; i < 4; ++i) /* descending */
            for (int j = i; j > 0 && raw[j - 1] < raw[j]; --j) {
                double t = raw[j];
                raw[j] = raw[j - 1];
                raw[j - 1] = t;
            }
        if (v % 97 == 0) raw[0] = raw[1] = raw[2] = raw[3] = 1;
        for (int i = 0; i < 4; ++i) sum += raw[i];
        for (int i = 0; i < 4; ++i) w[v * 4 + i] = (float)(raw[i] / sum);
        if (v % 89 == 0) { /* unsorted: the largest weight last */
            float t = w[v * 4];
            w[v * 4] = w[v * 4 + 3];
            w[v * 4 + 3] = t;
        }
    }
}

/* Batch codes and counts (scalar path) against sp_grid_quantize + sp_oss_pack per vertex. */
static void compare_with_pack(const sp_codec* c, const float* w, size_t count, const char* what)
{
    uint64_t* codes = malloc(count * sizeof(uint64_t));
    uint8_t* significant = malloc(count);
    CHECK(sp_encode_weights_batch_isa(c, w, count, codes, significant, SP_ISA_SCALAR) == SP_OK);
    int before = check_failures;
    for (size_t v = 0; v < count && check_failures - before < 5; ++v) {
        uint64_t q[4];
        sp_grid_quantize(w + v * 4, 4, c->scale, q);
        uint64_t expected = sp_oss_pack(c->n, 4, q);
        CHECK_MSG(codes[v] == expected && significant[v] == sp_grid_significant(q, 4),
                  "%s N=%llu vertex %zu: %llu vs %llu (q %llu %llu %llu %llu)", what, (unsigned long long)c->n, v,
                  (unsigned long long)codes[v], (unsigned long long)expected, (unsigned long long)q[0],
                  (unsigned long long)q[1], (unsigned long long)q[2], (unsigned long long)q[3]);
    }
    free(codes), free(significant);
}

/* Every residue of N mod 3 just past 2^21 (the first grids of the modular form), just below it
 * (the last of the 64-bit form), and the largest K = 4 grids of 64-bit codes. */
static void layer_forms(void)
{
    sp_codec widest;
    CHECK(sp_codec_from_bits(SP_METHOD_OSS, 4, 64, &widest) == SP_OK);
    const uint64_t ns[] = {((uint64_t)1 << 21) - 1, (uint64_t)1 << 21, ((uint64_t)1 << 21) + 1, ((uint64_t)1 << 21) + 2,
                           3000001, 3000002, 3000003, widest.n - 2, widest.n - 1, widest.n};
    float* w = malloc(VERTICES * 4 * sizeof(float));
    make_weights(VERTICES, w);
    for (size_t i = 0; i < sizeof(ns) / sizeof(ns[0]); ++i) {
        sp_codec c;
        CHECK(sp_codec_from_params(SP_METHOD_OSS, 4, ns[i], NULL, &c) == SP_OK);
        compare_with_pack(&c, w, VERTICES, "layer form");
    }
    free(w);
}

/* The same weights with every +0 turned into -0: the codes and counts must not move, for each K
 * and the bench widths. */
static void negative_zeros(void)
{
    static const uint32_t budgets[] = {16, 32, 44, 52, 64};
    float* w = malloc(VERTICES * 4 * sizeof(float));
    float* negative = malloc(VERTICES * 4 * sizeof(float));
    uint64_t *codes = malloc(VERTICES * sizeof(uint64_t)), *negative_codes = malloc(VERTICES * sizeof(uint64_t));
    uint8_t *counts = malloc(VERTICES), *negative_counts = malloc(VERTICES);
    for (uint32_t k = 2; k <= 4; ++k) {
        for (size_t v = 0; v < VERTICES; ++v) { /* 1..k weights, the rest +0 */
            uint32_t used = 1 + (uint32_t)(rng_next() % k);
            float sum = 0;
            for (uint32_t i = 0; i < k; ++i) w[v * k + i] = i < used ? (float)(rng_next() % 1000 + 1) : 0.0f;
            for (uint32_t i = 0; i < k; ++i) sum += w[v * k + i];
            for (uint32_t i = 0; i < k; ++i) w[v * k + i] /= sum;
            for (uint32_t i = 0; i < k; ++i) negative[v * k + i] = w[v * k + i] == 0 ? -0.0f : w[v * k + i];
        }
        for (size_t b = 0; b < sizeof(budgets) / sizeof(budgets[0]); ++b) {
            sp_codec c;
            CHECK(sp_codec_from_bits(SP_METHOD_OSS, k, budgets[b], &c) == SP_OK);
            CHECK(sp_encode_weights_batch_isa(&c, w, VERTICES, codes, counts, SP_ISA_SCALAR) == SP_OK);
            CHECK(sp_encode_weights_batch_isa(&c, negative, VERTICES, negative_codes, negative_counts, SP_ISA_SCALAR) ==
                  SP_OK);
            CHECK_MSG(memcmp(codes, negative_codes, VERTICES * sizeof(uint64_t)) == 0 &&
                          memcmp(counts, negative_counts, VERTICES) == 0,
                      "-0 weights K=%u %u bits", k, budgets[b]);
        }
    }
    free(w), free(negative), free(codes), free(negative_codes), free(counts), free(negative_counts);
}

int main(void)
{
    layer_forms();
    negative_zeros();
    return check_report("test_oss_scalar_encode");
}
