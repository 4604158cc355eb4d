/*
 * The scalar OSS batch encoder's own forms against the library's general ones (issue 14):
 *   - the K = 4 layer base past 2^21 (N from OSS_LAYER64_N up to the largest 64-bit K = 4 grid)
 *     taken modulo 2^64 with an exact division by 9 and a remainder table by k mod 3, against
 *     sp_oss_pack's 128-bit closed form, for N of each residue mod 3, layers up to the top one,
 *     and unsorted weights (layers past the tetrahedron, where the code wraps as sp_oss_pack's
 *     does); likewise the K = 3 row base past 2^30 (OSS_ROW64_N) modulo 2^64;
 *   - the rounding's skipped clamps: -0 in place of +0 must not change a code or a count (the
 *     remainders are ranked as bit patterns, where -0 would sort above every remainder);
 *   - the one-weight code written without a rounding (and its weights without a decode): every
 *     w0 > 0 of each exponent, denormals and the largest float, among vertices it must not
 *     take: -0 or a denormal in another slot, w0 of 0, -0, < 0, inf or NaN, the weight in slot 1.
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

/* Sorted k weights with the smallest one spread over [0, 1/k], so that the last q (the layer,
 * or the row for K = 3) takes every value up to the top one; a few all equal (the top itself)
 * and a few unsorted. */
static void make_weights(uint32_t k, size_t count, float* w)
{
    for (size_t v = 0; v < count; ++v) {
        double raw[4], sum = 0;
        for (uint32_t i = 0; i < k; ++i) raw[i] = rng_unit();
        for (uint32_t i = 1; i < k; ++i) /* descending */
            for (uint32_t j = i; j > 0 && raw[j - 1] < raw[j]; --j) {
                double t = raw[j];
                raw[j] = raw[j - 1];
                raw[j - 1] = t;
            }
        if (v % 97 == 0)
            for (uint32_t i = 0; i < k; ++i) raw[i] = 1;
        for (uint32_t i = 0; i < k; ++i) sum += raw[i];
        for (uint32_t i = 0; i < k; ++i) w[v * k + i] = (float)(raw[i] / sum);
        if (v % 89 == 0) { /* unsorted: the largest weight last */
            float t = w[v * k];
            w[v * k] = w[v * k + k - 1];
            w[v * k + k - 1] = t;
        }
    }
}

/* Batch codes and counts (scalar path) against sp_grid_quantize + sp_oss_pack per vertex. */
static void compare_with_pack(const sp_codec* c, const float* w, size_t count, const char* what)
{
    uint32_t k = c->influences;
    uint64_t* codes = malloc(count * sizeof(uint64_t));
    uint8_t* significant = malloc(count);
    CHECK(sp_encode_weights_batch_isa(c, w, count, codes, significant, SP_ISA_SCALAR) == SP_OK);
    int before = check_failures;
    for (size_t v = 0; v < count && check_failures - before < 5; ++v) {
        uint64_t q[4] = {0, 0, 0, 0};
        sp_grid_quantize(w + v * k, k, c->scale, q);
        uint64_t expected = sp_oss_pack(c->n, k, q);
        CHECK_MSG(codes[v] == expected && significant[v] == sp_grid_significant(q, k),
                  "%s K=%u N=%llu vertex %zu: %llu vs %llu (q %llu %llu %llu %llu)", what, k, (unsigned long long)c->n,
                  v, (unsigned long long)codes[v], (unsigned long long)expected, (unsigned long long)q[0],
                  (unsigned long long)q[1], (unsigned long long)q[2], (unsigned long long)q[3]);
    }
    free(codes), free(significant);
}

/* Every residue of N mod 3 just past the limit of the 64-bit form (K = 4: 2^21, K = 3: 2^30),
 * just below it, in between, and the largest grids of 64-bit codes. */
static void modular_forms(void)
{
    float* w = malloc(VERTICES * 4 * sizeof(float));
    for (uint32_t k = 3; k <= 4; ++k) {
        sp_codec widest;
        CHECK(sp_codec_from_bits(SP_METHOD_OSS, k, 64, &widest) == SP_OK);
        uint64_t limit = (uint64_t)1 << (k == 4 ? 21 : 30), middle = (limit + widest.n) / 2;
        const uint64_t ns[] = {limit - 1, limit, limit + 1, limit + 2, middle, middle + 1, middle + 2,
                               widest.n - 2, widest.n - 1, widest.n};
        make_weights(k, VERTICES, w);
        for (size_t i = 0; i < sizeof(ns) / sizeof(ns[0]); ++i) {
            sp_codec c;
            CHECK(sp_codec_from_params(SP_METHOD_OSS, k, ns[i], NULL, &c) == SP_OK);
            compare_with_pack(&c, w, VERTICES, "modular form");
        }
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

/* w0 of vertex v: every exponent from denormal to the largest with a random significand, and
 * every 11th one from a list of ones the shortcut must take (1, the extremes) or leave to the
 * rounding (zeros, negative, inf, NaN). */
static float one_weight_w0(size_t v)
{
    static const uint32_t listed[] = {0x00000000u, 0x80000000u, 0xBF800000u, 0x7F800000u, 0x7FC00000u,
                                      0xFF800000u, 0x7F7FFFFFu, 0x00000001u, 0x3F800000u};
    uint32_t bits = v % 11 == 0 ? listed[v / 11 % (sizeof(listed) / sizeof(listed[0]))]
                                : (uint32_t)(v % 255) << 23 | (uint32_t)(rng_next() & 0x7FFFFFu);
    float w0;
    memcpy(&w0, &bits, sizeof(w0));
    return w0;
}

/* Vertices (w0, +0, ...) among ones the shortcut must not take, encoded and decoded by the
 * scalar path against the per-vertex reference, for each K and the bench widths; in the middle
 * a run where one vertex in 9 has one weight, too few for the shortcut to list its chunks. */
static void one_weight_vertices(void)
{
    static const uint32_t budgets[] = {16, 22, 32, 44, 52, 64};
    float* w = malloc(VERTICES * 4 * sizeof(float));
    float* decoded = malloc(VERTICES * 4 * sizeof(float));
    uint64_t* codes = malloc(VERTICES * sizeof(uint64_t));
    for (uint32_t k = 2; k <= 4; ++k) {
        for (size_t v = 0; v < VERTICES; ++v) {
            float* vertex = w + v * k;
            for (uint32_t i = 0; i < k; ++i) vertex[i] = 0.0f;
            vertex[0] = one_weight_w0(v);
            if (v % 7 == 0) vertex[k - 1] = v % 14 ? -0.0f : 1e-45f; /* not one weight */
            if (v % 17 == 0) vertex[1] = vertex[0], vertex[0] = 0.0f;
            int sparse = v >= VERTICES / 2 && v < VERTICES / 2 + 8192; /* chunks the shortcut skips */
            if (v % 5 == 0 || (sparse && v % 9)) /* a plain many-weight vertex */
                for (uint32_t i = 0; i < k; ++i) vertex[i] = (float)(k - i) / (float)(k * (k + 1) / 2);
        }
        for (size_t b = 0; b < sizeof(budgets) / sizeof(budgets[0]); ++b) {
            sp_codec c;
            CHECK(sp_codec_from_bits(SP_METHOD_OSS, k, budgets[b], &c) == SP_OK);
            compare_with_pack(&c, w, VERTICES, "one weight");
            CHECK(sp_encode_weights_batch_isa(&c, w, VERTICES, codes, NULL, SP_ISA_SCALAR) == SP_OK);
            size_t valid = 0; /* unsorted weights wrap past max_code, which a decode refuses */
            for (size_t v = 0; v < VERTICES; ++v)
                if (codes[v] <= c.max_code) codes[valid++] = codes[v];
            CHECK(sp_decode_weights_batch_isa(&c, codes, valid, decoded, NULL, SP_ISA_SCALAR) == SP_OK);
            int before = check_failures;
            for (size_t v = 0; v < valid && check_failures - before < 5; ++v) {
                float expected[4];
                sp_oss_decode_one(&c, codes[v], expected);
                CHECK_MSG(memcmp(decoded + v * k, expected, k * sizeof(float)) == 0,
                          "one weight decode K=%u %u bits vertex %zu (code %llu)", k, budgets[b], v,
                          (unsigned long long)codes[v]);
            }
        }
    }
    free(w), free(decoded), free(codes);
}

int main(void)
{
    modular_forms();
    negative_zeros();
    one_weight_vertices();
    return check_report("test_oss_scalar_encode");
}
