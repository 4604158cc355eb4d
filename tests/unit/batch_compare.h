/*
 * The batch-against-scalar comparisons test_batch.c and test_batch_wide.c share (included once
 * per test program, after check.h and the internal header): a batch of one vertex never reaches a
 * vector path, so it is the encode reference; sp_decode_weights is the decode reference.
 */
#ifndef SKINPACK_TEST_BATCH_COMPARE_H
#define SKINPACK_TEST_BATCH_COMPARE_H

#include <stdlib.h>
#include <string.h>

/* The widest vector path the batch calls under test may take (main walks AVX-512, then AVX2). */
static sp_isa widest = SP_ISA_AVX512;
#define encode_batch(c, w, n, codes, sig) sp_encode_weights_batch_isa(c, w, n, codes, sig, widest)
#define decode_batch(c, codes, n, w, bad) sp_decode_weights_batch_isa(c, codes, n, w, bad, widest)

/* Reference: each vertex on its own (a one-vertex batch never reaches the vector path). */
static void encode_reference(const sp_codec* c, const float* w, size_t count, uint64_t* codes, uint8_t* sig)
{
    for (size_t v = 0; v < count; ++v)
        encode_batch(c, w + v * c->influences, 1, codes + v, sig + v);
}

/* Batch-encodes count vertices and compares codes and significant counts with the reference;
 * also the run without significant. Returns the failures seen. */
static int compare_encode(const sp_codec* c, const float* w, size_t count, const char* what)
{
    uint64_t* codes = malloc((count + 1) * sizeof(uint64_t));
    uint64_t* bare = malloc((count + 1) * sizeof(uint64_t));
    uint64_t* ref = malloc((count + 1) * sizeof(uint64_t));
    uint8_t* sig = malloc(count + 1);
    uint8_t* ref_sig = malloc(count + 1);
    int before = check_failures;
    encode_reference(c, w, count, ref, ref_sig);
    CHECK(encode_batch(c, w, count, codes, sig) == SP_OK);
    CHECK(encode_batch(c, w, count, bare, NULL) == SP_OK);
    for (size_t v = 0; v < count; ++v) {
        CHECK_MSG(codes[v] == ref[v] && bare[v] == ref[v], "%s K=%u N=%llu vertex %zu: %llu vs %llu (w %.9g %.9g %.9g %.9g)",
                  what, c->influences, (unsigned long long)c->n, v, (unsigned long long)codes[v],
                  (unsigned long long)ref[v], w[v * c->influences], w[v * c->influences + 1],
                  c->influences > 2 ? w[v * c->influences + 2] : 0.0f, c->influences > 3 ? w[v * c->influences + 3] : 0.0f);
        CHECK_MSG(sig[v] == ref_sig[v], "%s significant K=%u vertex %zu", what, c->influences, v);
        if (check_failures - before > 5) break;
    }
    free(codes), free(bare), free(ref), free(sig), free(ref_sig);
    return check_failures - before;
}

/* Batch-decodes and compares the floats bit for bit with sp_decode_weights. */
static int compare_decode(const sp_codec* c, const uint64_t* codes, size_t count, const char* what)
{
    uint32_t k = c->influences;
    float* w = malloc((count * k + 1) * sizeof(float));
    float* ref = malloc((count * k + 1) * sizeof(float));
    int before = check_failures;
    size_t bad = (size_t)-1;
    CHECK(decode_batch(c, codes, count, w, &bad) == SP_OK);
    CHECK(bad == (size_t)-1);
    for (size_t v = 0; v < count; ++v) {
        sp_decode_weights(c, codes[v], ref + v * k);
        CHECK_MSG(memcmp(w + v * k, ref + v * k, k * sizeof(float)) == 0, "%s K=%u N=%llu code %llu", what, k,
                  (unsigned long long)c->n, (unsigned long long)codes[v]);
        if (check_failures - before > 5) break;
    }
    free(w), free(ref);
    return check_failures - before;
}

static sp_codec oss(uint32_t k, uint64_t n)
{
    sp_codec c;
    CHECK(sp_codec_from_params(SP_METHOD_OSS, k, n, NULL, &c) == SP_OK);
    return c;
}

#endif
