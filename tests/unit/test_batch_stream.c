/*
 * The decode's streaming stores (codec_oss_batch.c's sp_oss_decode_batch_streaming, the
 * primitives' put8 and the like) against the scalar code, bit for bit, once per vector path the
 * CPU has: the threshold lowered so small batches stream, for K = 2, 3, 4 and every kind of lanes
 * (narrow, split, double, wide), outputs at every 4-byte offset from a cache line, random codes
 * (the wide and split lanes send some to the scalar redo, which rewrites streamed lines), tails
 * and invalid codes. A path that silently stops streaming fails the count of streamed vertices;
 * one that streams to the wrong place, past the batch or before it fails the comparison and the
 * guard bytes around the output.
 */
#include <stdlib.h>
#include <string.h>

#include "../../native/src/codec_internal.h"
#include "check.h"
#include "skinpack.h"

#define GUARD 64 /* bytes checked on either side of the output */
#define MAX_COUNT 1200

static sp_isa widest;

static sp_codec oss(uint32_t k, uint64_t n)
{
    sp_codec c;
    CHECK(sp_codec_from_params(SP_METHOD_OSS, k, n, NULL, &c) == SP_OK);
    return c;
}

/* The vertices before the first whose weights start a 64-byte line (what the dispatch decodes
 * by the scalar code first), count where none within 16 does. */
static size_t expected_head(const float* weights, uint32_t k, size_t count)
{
    for (size_t v = 0; v < count && v < 16; ++v)
        if (!((uintptr_t)(weights + v * k) % 64)) return v;
    return count;
}

/* Decodes codes into a buffer `offset` bytes past a line with the given threshold, finishes the
 * tail by the scalar code, and compares with the scalar decode and the guards; returns how many
 * vertices were streamed. */
static size_t decode_at(const sp_codec* c, const uint64_t* codes, size_t count, size_t offset, size_t min_bytes,
                        const float* ref)
{
    uint32_t k = c->influences;
    size_t bytes = count * k * sizeof(float), streamed = 0;
    unsigned char* buffer = aligned_alloc(64, GUARD + MAX_COUNT * 16 + 64 + GUARD);
    memset(buffer, 0xA5, GUARD + MAX_COUNT * 16 + 64 + GUARD);
    float* weights = (float*)(buffer + GUARD + offset);
    size_t done = sp_oss_decode_batch_streaming(c, codes, count, weights, widest, min_bytes, &streamed);
    CHECK(sp_oss_decode_scalar(c, codes, done, count, weights) == count);
    CHECK_MSG(memcmp(weights, ref, bytes) == 0, "isa %d K=%u N=%llu offset %zu count %zu", (int)widest, k,
              (unsigned long long)c->n, offset, count);
    for (size_t i = 0; i < GUARD + offset; ++i) CHECK(buffer[i] == 0xA5);
    for (size_t i = GUARD + offset + bytes; i < GUARD + offset + bytes + GUARD; ++i) CHECK(buffer[i] == 0xA5);
    size_t head = expected_head(weights, k, count);
    CHECK_MSG(streamed == (bytes >= min_bytes && head < count ? done - head : 0),
              "isa %d K=%u N=%llu offset %zu: %zu streamed of %zu done, head %zu", (int)widest, k,
              (unsigned long long)c->n, offset, streamed, done, head);
    free(buffer);
    return streamed;
}

/* Every offset of one codec's random codes (and its first and last), count vertices. */
static void check_offsets(const sp_codec* c, size_t count)
{
    uint32_t k = c->influences;
    uint64_t* codes = malloc(count * sizeof(uint64_t));
    float* ref = malloc(count * k * sizeof(float));
    for (size_t v = 0; v < count; ++v) codes[v] = c->max_code == UINT64_MAX ? rng_next() : rng_next() % (c->max_code + 1);
    codes[0] = 0, codes[count - 1] = c->max_code;
    CHECK(sp_decode_weights_batch_isa(c, codes, count, ref, NULL, SP_ISA_SCALAR) == SP_OK);
    size_t streamed = 0;
    for (size_t offset = 0; offset < 64; offset += 4) streamed += decode_at(c, codes, count, offset, 0, ref);
    CHECK_MSG(streamed >= count / 2, "isa %d K=%u N=%llu: %zu streamed", (int)widest, k, (unsigned long long)c->n, streamed);
    free(codes), free(ref);
}

/* The threshold's boundary: a batch of exactly stream_min_bytes streams, one byte less does not. */
static void check_threshold(const sp_codec* c)
{
    size_t count = 301, bytes = count * c->influences * sizeof(float);
    uint64_t* codes = malloc(count * sizeof(uint64_t));
    float* ref = malloc(bytes);
    for (size_t v = 0; v < count; ++v) codes[v] = rng_next() % (c->max_code + 1);
    CHECK(sp_decode_weights_batch_isa(c, codes, count, ref, NULL, SP_ISA_SCALAR) == SP_OK);
    CHECK(decode_at(c, codes, count, 16, bytes, ref) > 0);
    CHECK(decode_at(c, codes, count, 16, bytes + 1, ref) == 0);
    free(codes), free(ref);
}

/* An invalid code: the streamed decode stops before it, as the normal one does, with what it
 * wrote equal to the scalar decode; also in the scalar head. */
static void check_invalid(const sp_codec* c, size_t bad)
{
    uint32_t k = c->influences;
    size_t count = 400, streamed = 0;
    uint64_t* codes = malloc(count * sizeof(uint64_t));
    float* ref = malloc(count * k * sizeof(float));
    float* weights = aligned_alloc(64, count * k * sizeof(float) + 64);
    float* out = weights + 4; /* a head of 3 (K = 4) or 4 (K = 3) vertices first */
    for (size_t v = 0; v < count; ++v) codes[v] = rng_next() % (c->max_code + 1);
    codes[bad] = c->max_code + 1;
    CHECK(sp_oss_decode_scalar(c, codes, 0, count, ref) == bad);
    size_t done = sp_oss_decode_batch_streaming(c, codes, count, out, widest, 0, &streamed);
    CHECK_MSG(done <= bad, "K=%u: %zu done past the invalid code %zu", k, done, bad);
    CHECK(memcmp(out, ref, done * k * sizeof(float)) == 0);
    free(codes), free(ref), free(weights);
}

int main(void)
{
    static const uint64_t n2[] = {1000, (uint64_t)1 << 50};                /* double, wide */
    static const uint64_t n3[] = {5000, 100000, (uint64_t)1 << 26};         /* narrow, double, wide */
    static const uint64_t n4[] = {500, 20000, 90000, 200000, (uint64_t)1 << 21}; /* narrow, split, double, wide */
    sp_isa cpu = sp_cpu_isa();
    for (widest = SP_ISA_AVX2; widest <= SP_ISA_AVX512 && widest <= cpu; widest = (sp_isa)(widest + 1)) {
        for (size_t i = 0; i < sizeof n2 / sizeof *n2; ++i) {
            sp_codec c = oss(2, n2[i]);
            check_offsets(&c, 517);
            check_offsets(&c, 40);
        }
        for (size_t i = 0; i < sizeof n3 / sizeof *n3; ++i) {
            sp_codec c = oss(3, n3[i]);
            check_offsets(&c, 517);
            check_offsets(&c, 40);
        }
        for (size_t i = 0; i < sizeof n4 / sizeof *n4; ++i) {
            sp_codec c = oss(4, n4[i]);
            check_offsets(&c, 517);
            check_offsets(&c, 40);
        }
        sp_codec c3 = oss(3, 100000), c4 = oss(4, 20000);
        check_threshold(&c3);
        check_threshold(&c4);
        check_invalid(&c4, 300);
        check_invalid(&c4, 2);
        check_invalid(&c3, 301);
    }
    if (cpu < SP_ISA_AVX2) printf("test_batch_stream: no vector path on this CPU\n");
    return check_report("test_batch_stream");
}
