/*
 * That the decode lanes really store by streaming stores where asked (codec_oss_simd.h's
 * prefetch_decode; AVX2, or AVX-512 where built with LANES_AVX512): test_batch_stream.c compares
 * the streamed outputs with the scalar code, but a primitive storing normally would pass it.
 * Here the ISA's driver is compiled into the test with the streaming stores counted: asked to
 * stream, every byte of the weights its blocks decode goes by them, for K = 2, 3, 4 and every
 * kind of lanes (narrow, split, double, wide), each output bit-identical; not asked, none does.
 */
#include <stdlib.h>
#include <string.h>

#include "../../native/src/codec_internal.h"

#include "check.h"
#include "skinpack.h"

#if SP_X86_SIMD
#include <immintrin.h>

/* The streaming stores, counted in bytes (the intrinsics the primitives call, replaced below). */
static size_t streamed_bytes = 0;
#define COUNTED_STREAM(name, vector, isa, store) \
    SP_TARGET(isa) static void name(float* p, vector v) \
    { \
        streamed_bytes += sizeof v; \
        store(p, v); \
    }
COUNTED_STREAM(counted_stream256, __m256, "avx2", _mm256_stream_ps)
#define _mm256_stream_ps(p, v) counted_stream256(p, v)

#include "../../native/src/codec_oss_wide.h"
#if LANES_AVX512
COUNTED_STREAM(counted_stream512, __m512, "avx512f", _mm512_stream_ps)
#define _mm512_stream_ps(p, v) counted_stream512(p, v)
#include "../../native/src/codec_oss_prim_avx512.h"
#define LANES_ISA SP_ISA_AVX512
#define LANES_TEST "test_batch_stream_lanes_avx512"
#else
COUNTED_STREAM(counted_stream128, __m128, "avx2", _mm_stream_ps)
#define _mm_stream_ps(p, v) counted_stream128(p, v)
#include "../../native/src/codec_oss_prim_avx2.h"
#define LANES_ISA SP_ISA_AVX2
#define LANES_TEST "test_batch_stream_lanes"
#endif
#undef SIMD_NAME
#define SIMD_NAME(name) counted_##name /* not the library's entry points */
#undef WIDE_NAME
#define WIDE_NAME(name) counted_wide_##name
#include "../../native/src/codec_oss_simd.h"
#include "../../native/src/codec_oss_wide_simd.h"

static sp_codec oss(uint32_t k, uint64_t n)
{
    sp_codec c;
    CHECK(sp_codec_from_params(SP_METHOD_OSS, k, n, NULL, &c) == SP_OK);
    return c;
}

/* Decodes random codes into a line-aligned output through the counted lanes (the wide ones past
 * the double lanes' N, as codec_oss_batch.c picks them), streaming or not, and checks the bytes
 * streamed and the outputs. */
static void decode_counted(const sp_codec* c, int wide, int stream)
{
    uint32_t k = c->influences;
    size_t count = 203;
    uint64_t* codes = malloc(count * sizeof(uint64_t));
    float* w = aligned_alloc(64, 64 * ((count * k * sizeof(float) + 63) / 64));
    float ref[SP_MAX_INFLUENCES];
    for (size_t v = 0; v < count; ++v) codes[v] = c->max_code == UINT64_MAX ? rng_next() : rng_next() % (c->max_code + 1);
    streamed_bytes = 0;
    size_t done = wide ? counted_wide_decode(c, codes, count, w, stream) : counted_decode(c, codes, count, w, stream);
    size_t lanes = wide && k == 4 ? NBLOCK : BLOCK; /* the wide K = 4 lanes take pairs of blocks */
    CHECK_MSG(done == count / lanes * lanes, "K=%u N=%llu: %zu of %zu done", k, (unsigned long long)c->n, done, count);
    CHECK_MSG(streamed_bytes == (stream ? done * k * sizeof(float) : 0), "K=%u N=%llu stream %d: %zu bytes streamed of %zu",
              k, (unsigned long long)c->n, stream, streamed_bytes, done * k * sizeof(float));
    for (size_t v = 0, failures = 0; v < done && failures < 5; ++v) {
        sp_decode_weights(c, codes[v], ref);
        int same = memcmp(w + v * k, ref, k * sizeof(float)) == 0;
        CHECK_MSG(same, "K=%u N=%llu code %llu", k, (unsigned long long)c->n, (unsigned long long)codes[v]);
        failures += !same;
    }
    free(codes), free(w);
}

int main(void)
{
    static const struct {
        uint32_t k;
        uint64_t n;
        int wide;
    } cases[] = {{2, 1000, 0},   {2, (uint64_t)1 << 50, 1}, {3, 5000, 0},   {3, 100000, 0},          {3, (uint64_t)1 << 26, 1},
                 {4, 500, 0},    {4, 20000, 0},             {4, 90000, 0},  {4, (uint64_t)1 << 21, 1}};
    if (sp_cpu_isa() < LANES_ISA) {
        printf("%s: the CPU lacks the ISA, nothing run\n", LANES_TEST);
        return 0;
    }
    for (size_t i = 0; i < sizeof cases / sizeof *cases; ++i) {
        sp_codec c = oss(cases[i].k, cases[i].n);
        decode_counted(&c, cases[i].wide, 1);
        decode_counted(&c, cases[i].wide, 0);
    }
    return check_report(LANES_TEST);
}
#else
int main(void)
{
    printf("test_batch_stream_lanes: no vector paths on this target\n");
    return 0;
}
#endif
