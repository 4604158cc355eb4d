/*
 * The edge codes' two-pass decode (codec_oss_simd.h, "the edge codes"): K = 4 codes below N,
 * the vertices of one or two weights, decoded directly while the other codes of their chunk go
 * through the driver's walk as a list. The ISA's driver is compiled into the test with the
 * chunks that take the two passes counted (EDGE_TWO_PASSES), so a path that silently stopped
 * taking them fails here, not only one that decodes wrongly. For every kind of K = 4 lanes past
 * the narrow ones (split, double, wide with whole codes, wide up to 64-bit codes) and of K = 3
 * (double, wide, wide up to 64-bit codes): the bench's share of edge codes (3 in 4, the edges
 * N - 1 and N among them) in full chunks and a tail, with normal and with streaming stores, bit-identical to
 * sp_decode_weights and nothing written past the batch, also through the library's dispatch at
 * every 4-byte offset from a line; an invalid code in a chunk's list or at its first vertex,
 * where the walk must stop before it with every vertex up to there decoded; few edge codes and
 * narrow lanes, which must keep the one-pass walk (edge_decode, edge_chunk_pays); and where the
 * chunk buffers and the list are placed (edge_place).
 */
#include <stdlib.h>
#include <string.h>

#include "../../native/src/codec_internal.h"

#include "check.h"
#include "skinpack.h"

#if SP_X86_SIMD
static size_t two_pass_chunks = 0;
#define EDGE_TWO_PASSES() (++two_pass_chunks)

#include "../../native/src/codec_oss_wide.h"
#if LANES_AVX512
#include "../../native/src/codec_oss_prim_avx512.h"
#define LANES_ISA SP_ISA_AVX512
#define LANES_TEST "test_batch_edges_avx512"
#else
#include "../../native/src/codec_oss_prim_avx2.h"
#define LANES_ISA SP_ISA_AVX2
#define LANES_TEST "test_batch_edges"
#endif
#undef SIMD_NAME
#define SIMD_NAME(name) counted_##name /* not the library's entry points */
#undef WIDE_NAME
#define WIDE_NAME(name) counted_wide_##name
#include "../../native/src/codec_oss_simd.h"
#include "../../native/src/codec_oss_wide_simd.h"

#define COUNT (6 * EDGE_CHUNK + 13) /* six full chunks and a tail */
#define GUARD 64                    /* bytes after the output that must stay untouched */

static sp_codec oss(uint32_t k, uint64_t n)
{
    sp_codec c;
    CHECK(sp_codec_from_params(SP_METHOD_OSS, k, n, NULL, &c) == SP_OK);
    return c;
}

/* Codes with `edges` in 4 of them edge codes (the first row's ends among them), the others
 * valid codes past the first row. */
static void make_codes(const sp_codec* c, unsigned edges, uint64_t* codes, size_t count)
{
    for (size_t v = 0; v < count; ++v) {
        uint64_t r = rng_next();
        if (r % 4 < edges) codes[v] = v % 97 == 0 ? c->n - 1 : rng_next() % c->n;
        else codes[v] = v % 89 == 0 ? c->n : c->n + rng_next() % (c->max_code - c->n + 1);
    }
}

/* Decodes through the counted driver into a 64-byte-aligned buffer; returns where it stopped
 * and the chunks taken in two passes, after checking every vertex before that against
 * sp_decode_weights and the guard after the batch. */
static size_t decode_counted(const sp_codec* c, const uint64_t* codes, size_t count, int stream, size_t* done)
{
    uint32_t k = c->influences;
    size_t bytes = count * k * sizeof(float);
    unsigned char* buffer = aligned_alloc(64, (bytes + GUARD + 63) / 64 * 64);
    memset(buffer, 0xA5, bytes + GUARD);
    float* w = (float*)buffer;
    float ref[SP_MAX_INFLUENCES];
    two_pass_chunks = 0;
    int wide = sp_oss_lanes_for(c) == SP_LANES_WIDE;
    *done = wide ? counted_wide_decode(c, codes, count, w, stream) : counted_decode(c, codes, count, w, stream);
    for (size_t v = 0, failures = 0; v < *done && failures < 5; ++v) {
        sp_decode_weights(c, codes[v], ref);
        int same = memcmp(w + v * k, ref, k * sizeof(float)) == 0;
        CHECK_MSG(same, "K=%u N=%llu stream %d vertex %zu code %llu", k, (unsigned long long)c->n, stream, v,
                  (unsigned long long)codes[v]);
        failures += !same;
    }
    for (size_t i = bytes; i < bytes + GUARD; ++i)
        CHECK_MSG(buffer[i] == 0xA5, "K=%u N=%llu: byte %zu past the batch written", k, (unsigned long long)c->n, i - bytes);
    free(buffer);
    return two_pass_chunks;
}

/* The bench's share of edge codes: every full chunk in two passes, every vertex but the tail's
 * last partial block decoded. */
static void mixed(const sp_codec* c, int stream)
{
    uint64_t* codes = malloc(COUNT * sizeof(uint64_t));
    make_codes(c, 3, codes, COUNT);
    size_t done, chunks = decode_counted(c, codes, COUNT, stream, &done);
    CHECK_MSG(chunks == COUNT / EDGE_CHUNK, "N=%llu stream %d: %zu of %d chunks in two passes", (unsigned long long)c->n,
              stream, chunks, COUNT / EDGE_CHUNK);
    CHECK_MSG(done >= COUNT / EDGE_CHUNK * EDGE_CHUNK && done <= COUNT, "N=%llu: %zu of %d done", (unsigned long long)c->n,
              done, COUNT);
    free(codes);
}

/* An invalid code at `at`: the walk stops at or before it, every vertex before decoded, and the
 * chunks before its own taken in two passes. */
static void invalid_at(const sp_codec* c, size_t at)
{
    if (c->max_code == UINT64_MAX) return; /* no invalid code */
    uint64_t* codes = malloc(COUNT * sizeof(uint64_t));
    make_codes(c, 3, codes, COUNT);
    codes[at] = c->max_code + 1 + rng_next() % 16; /* past the first row: in the chunk's list */
    size_t done, chunks = decode_counted(c, codes, COUNT, 1, &done);
    CHECK_MSG(done <= at, "N=%llu: decoded past the invalid code at %zu (%zu)", (unsigned long long)c->n, at, done);
    CHECK_MSG(chunks >= at / EDGE_CHUNK, "N=%llu: %zu chunks before %zu in two passes", (unsigned long long)c->n, chunks, at);
    /* the public call finishes the walk by the scalar code and names the vertex */
    float* w = malloc(COUNT * 4 * sizeof(float));
    size_t bad = 0;
    CHECK(sp_decode_weights_batch_isa(c, codes, COUNT, w, &bad, LANES_ISA) == SP_ERR_CODE_OUT_OF_RANGE);
    CHECK_MSG(bad == at, "N=%llu: error at %zu, not %zu", (unsigned long long)c->n, bad, at);
    free(w), free(codes);
}

/* The library's own dispatch (codec_oss_batch.c) at every 4-byte offset from a cache line,
 * streaming from the first line start (its threshold lowered to 0) or not: every vertex
 * bit-identical, nothing written outside the batch. */
static void offsets(const sp_codec* c)
{
    uint32_t k = c->influences;
    uint64_t* codes = malloc(COUNT * sizeof(uint64_t));
    float* ref = malloc(COUNT * k * sizeof(float));
    make_codes(c, 3, codes, COUNT);
    for (size_t v = 0; v < COUNT; ++v) sp_decode_weights(c, codes[v], ref + v * k);
    size_t bytes = COUNT * k * sizeof(float), room = GUARD + 64 + bytes + GUARD;
    unsigned char* buffer = aligned_alloc(64, (room + 63) / 64 * 64);
    for (size_t offset = 0; offset < 64; offset += 4)
        for (size_t min_bytes = 0; min_bytes <= bytes + 1; min_bytes += bytes + 1) { /* streamed, then not */
            memset(buffer, 0xA5, room);
            float* w = (float*)(buffer + GUARD + offset);
            size_t streamed = 0;
            size_t done = sp_oss_decode_batch_streaming(c, codes, COUNT, w, LANES_ISA, min_bytes, &streamed);
            CHECK(sp_oss_decode_scalar(c, codes, done, COUNT, w) == COUNT);
            CHECK_MSG(memcmp(w, ref, bytes) == 0, "K=%u N=%llu offset %zu min_bytes %zu", k, (unsigned long long)c->n,
                      offset, min_bytes);
            int line = 0; /* a vertex within a line's worth starts a line: the dispatch streams from there */
            for (size_t v = 0; v < 16; ++v) line |= !((uintptr_t)(w + v * k) % 64);
            CHECK_MSG(min_bytes || !line ? !streamed : streamed > 0, "K=%u offset %zu min_bytes %zu: %zu streamed", k,
                      offset, min_bytes, streamed);
            for (size_t i = 0; i < GUARD; ++i)
                CHECK_MSG(buffer[i] == 0xA5 && buffer[GUARD + offset + bytes + i] == 0xA5,
                          "K=%u N=%llu offset %zu: a byte outside the batch written", k, (unsigned long long)c->n, offset);
        }
    free(buffer), free(ref), free(codes);
}

/* Where the chunks must keep the one-pass walk: codes mostly past the first row, narrow lanes;
 * each still decoded right. */
static void one_pass(const sp_codec* c, unsigned edges)
{
    uint64_t* codes = malloc(COUNT * sizeof(uint64_t));
    make_codes(c, edges, codes, COUNT);
    for (size_t v = 0; edges == 0 && v < COUNT; v += 8) codes[v] = rng_next() % c->n; /* 1 in 8: below the sample's 1 in 4 */
    size_t done, chunks = decode_counted(c, codes, COUNT, 0, &done);
    CHECK_MSG(chunks == 0, "K=%u N=%llu edges %u/4: %zu chunks in two passes", c->influences, (unsigned long long)c->n,
              edges, chunks);
    free(codes);
}

/* The page offset of `p` past that of `from` (0 to EDGE_PAGE - 1). */
static size_t page_ahead(const void* p, const void* from)
{
    return (size_t)(((uintptr_t)p - (uintptr_t)from) & (EDGE_PAGE - 1));
}

/* The buffers' places (edge_place), for weights at every 4-byte offset of a page: inside their
 * areas, on 64-byte lines, EDGE_AHEAD bytes (up to the next line) past the page offset of the
 * weights they serve, the second chunk buffer half a page further, the vertex numbers right after
 * the rows and the list's weights after its codes. */
static void placement(void)
{
    static edge_list list; /* static: only the addresses are checked */
    float* page = malloc(2 * EDGE_PAGE);
    for (size_t offset = 0; offset < EDGE_PAGE; offset += 4)
        for (unsigned filling = 0; filling < 2; ++filling) {
            const float* out = (const float*)((const unsigned char*)page + offset);
            list.filling = filling;
            edge_place(&list, out);
            const edge_buffer* b = &list.buffer[filling];
            size_t rows_ahead = page_ahead(b->rows, out), codes_ahead = page_ahead(list.codes, out);
            size_t want = EDGE_AHEAD + filling * EDGE_PAGE / 2;
            CHECK_MSG(rows_ahead >= want && rows_ahead < want + 64 && (uintptr_t)b->rows % 64 == 0,
                      "offset %zu buffer %u: rows %zu bytes ahead", offset, filling, rows_ahead);
            CHECK(b->at == (uint32_t*)(b->rows + EDGE_CHUNK * SP_MAX_INFLUENCES));
            CHECK((const unsigned char*)b->rows >= b->area &&
                  (const unsigned char*)(b->at + EDGE_LIST) <= b->area + sizeof b->area);
            CHECK_MSG(codes_ahead >= EDGE_AHEAD && codes_ahead < EDGE_AHEAD + 64 && (uintptr_t)list.codes % 64 == 0,
                      "offset %zu: list codes %zu bytes ahead", offset, codes_ahead);
            CHECK(list.weights == (float*)(list.codes + EDGE_LIST));
            CHECK((const unsigned char*)list.codes >= list.area &&
                  (const unsigned char*)(list.weights + EDGE_LIST * SP_MAX_INFLUENCES) <= list.area + sizeof list.area);
        }
    free(page);
}

int main(void)
{
    if (sp_cpu_isa() < LANES_ISA) {
        printf("%s: the CPU lacks the ISA, nothing to check\n", LANES_TEST);
        return 0;
    }
    sp_codec widest, widest3;
    CHECK(sp_codec_from_bits(SP_METHOD_OSS, 4, 64, &widest) == SP_OK);
    CHECK(sp_codec_from_bits(SP_METHOD_OSS, 3, 64, &widest3) == SP_OK);
    /* K = 4: split lanes (two), double lanes, wide with whole codes, wide up to 64-bit codes; K = 3: double lanes
     * (two), wide lanes, wide up to 64-bit codes */
    sp_codec codecs[] = {oss(4, NARROW_MAX_N4 + 1), oss(4, 60000), oss(4, 90000), oss(4, (uint64_t)1 << 17), widest,
                         oss(3, 9000), oss(3, BATCH_MAX_N3), oss(3, (uint64_t)1 << 26), widest3};
    for (size_t i = 0; i < sizeof codecs / sizeof codecs[0]; ++i) {
        mixed(&codecs[i], 0);
        mixed(&codecs[i], 1);
        invalid_at(&codecs[i], 3 * EDGE_CHUNK + 77);
        invalid_at(&codecs[i], 2 * EDGE_CHUNK);
        one_pass(&codecs[i], 0);
        offsets(&codecs[i]);
    }
    sp_codec narrow = oss(4, 1000), narrow_rows = oss(3, 5000);
    one_pass(&narrow, 3);
    one_pass(&narrow_rows, 3);
    placement();
    return check_report(LANES_TEST);
}
#else
int main(void)
{
    printf("test_batch_edges: not x86, nothing to check\n");
    return 0;
}
#endif
