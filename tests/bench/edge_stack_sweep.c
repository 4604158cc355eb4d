/*
 * edge_stack_sweep K BITS scalar|avx2|avx512 [--rounds R] [--step BYTES] [--vertices N] [--codes]
 *
 * The OSS batch decode of the bench's influence mix (51 % one, 22 % two, 13 % three, 14 % four
 * weights) called from 4096 / BYTES stack depths, BYTES apart, in one process: the decode's stack
 * then lies at every page offset, where from one process to the next the address randomisation
 * puts it at one of them by chance. Rounds alternate the depths, so the machine's drift hits them
 * alike; each depth's best rate is printed (M vertices/s), then their mean, minimum and maximum.
 * With --codes, the stack stays and the codes move instead: copied (untimed) to each offset of a
 * page, which the caller's buffers set. A memcpy of the output's bytes before each call, as in
 * `skinpack bench`. Nothing is asserted
 * (docs/benchmarks.md, session 16: the edge decode's buffers and the streaming stores).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../../native/cli/bench_influences.h"
#include "../../native/src/codec_internal.h"
#include "../unit/check.h" /* rng_next */
#include "skinpack.h"

#define MAX_DEPTHS 4096

typedef struct sweep_options {
    uint32_t k, bits;
    sp_isa isa;
    int rounds, move_codes;
    size_t step, vertices;
} sweep_options;

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static int parse(int argc, char** argv, sweep_options* o)
{
    static const char* const isas[] = {"scalar", "avx2", "avx512"};
    if (argc < 4) return 0;
    o->k = (uint32_t)atoi(argv[1]), o->bits = (uint32_t)atoi(argv[2]), o->rounds = 6, o->step = 256;
    o->vertices = (size_t)1 << 20, o->isa = (sp_isa)3, o->move_codes = 0;
    for (int n = 0; n < 3; ++n)
        if (strcmp(argv[3], isas[n]) == 0) o->isa = (sp_isa)n;
    for (int i = 4; i < argc; ++i) {
        if (strcmp(argv[i], "--codes") == 0) o->move_codes = 1;
        else if (i + 1 == argc) return 0;
        else if (strcmp(argv[i], "--rounds") == 0) o->rounds = atoi(argv[++i]);
        else if (strcmp(argv[i], "--step") == 0) o->step = strtoull(argv[++i], NULL, 10);
        else if (strcmp(argv[i], "--vertices") == 0) o->vertices = strtoull(argv[++i], NULL, 10);
        else return 0;
    }
    return (int)o->isa < 3 && o->k >= 2 && o->k <= 4 && o->rounds > 0 && o->step >= 16 && o->step <= 4096 &&
           o->vertices > 0;
}

/* Normalised weights of the bench's mix, sorted descending, K a vertex. */
static void make_weights(const sweep_options* o, float* weights)
{
    for (size_t v = 0; v < o->vertices; ++v) {
        float raw[4], sum = 0;
        bench_raw_weights(rng_next, bench_influence_count(rng_next, -1), raw);
        for (uint32_t i = 0; i < o->k; ++i) sum += raw[i];
        for (uint32_t i = 0; i < o->k; ++i) weights[v * o->k + i] = raw[i] / sum;
    }
}

/* One decode `depth` bytes deeper in the stack than the caller's frame, timed. */
static __attribute__((noinline)) double decode_at_depth(size_t depth, const sp_codec* codec, const uint64_t* codes,
                                                         size_t count, float* weights, sp_isa isa)
{
    volatile char* below = __builtin_alloca(depth + 16);
    below[0] = 0;
    double t0 = now_seconds();
    sp_decode_weights_batch_isa(codec, codes, count, weights, NULL, isa);
    return now_seconds() - t0;
}

/* Each place's best decode time over the rounds: stack depths, or the codes' page offsets. */
static void sweep(const sweep_options* o, const sp_codec* codec, const float* weights, const uint64_t* codes,
                  uint64_t* moved_area, float* decoded, float* copy, double* best)
{
    size_t places = 4096 / o->step, bytes = o->vertices * o->k * sizeof(float);
    for (size_t p = 0; p < places; ++p) best[p] = 1e30;
    for (int r = 0; r < o->rounds; ++r)
        for (size_t p = 0; p < places; ++p) {
            const uint64_t* in = codes;
            if (o->move_codes) {
                in = (const uint64_t*)((unsigned char*)moved_area + p * o->step);
                memmove((void*)in, codes, o->vertices * sizeof(uint64_t));
            }
            memcpy(copy, weights, bytes);
            double t = decode_at_depth(o->move_codes ? 0 : p * o->step, codec, in, o->vertices, decoded, o->isa);
            best[p] = t < best[p] ? t : best[p];
        }
}

int main(int argc, char** argv)
{
    sweep_options o;
    sp_codec codec;
    if (!parse(argc, argv, &o)) {
        fprintf(stderr, "usage: edge_stack_sweep K BITS scalar|avx2|avx512 [--rounds R] [--step BYTES] [--vertices N] "
                        "[--codes]\n");
        return 2;
    }
    if (sp_codec_from_bits(SP_METHOD_OSS, o.k, o.bits, &codec) != SP_OK) {
        fprintf(stderr, "Error: no OSS codec for K = %u at %u bits\n", o.k, o.bits);
        return 2;
    }
    size_t bytes = o.vertices * o.k * sizeof(float), places = 4096 / o.step;
    float *weights = malloc(bytes), *decoded = malloc(bytes), *copy = malloc(bytes);
    uint64_t* codes = malloc(o.vertices * sizeof(uint64_t));
    uint64_t* moved_area = aligned_alloc(4096, (o.vertices * sizeof(uint64_t) / 4096 + 2) * 4096);
    static double best[MAX_DEPTHS];
    if (!weights || !decoded || !copy || !codes || !moved_area) return 1;
    make_weights(&o, weights);
    sp_encode_weights_batch_isa(&codec, weights, o.vertices, codes, NULL, o.isa);
    sweep(&o, &codec, weights, codes, moved_area, decoded, copy, best);
    double sum = 0, low = 1e30, high = 0;
    for (size_t p = 0; p < places; ++p) {
        double rate = (double)o.vertices / best[p] / 1e6;
        printf("%s %zu: %.0f M vertices/s\n", o.move_codes ? "codes offset" : "depth", p * o.step, rate);
        sum += rate, low = rate < low ? rate : low, high = rate > high ? rate : high;
    }
    printf("K = %u, %u bits, %s: mean %.0f, min %.0f, max %.0f M vertices/s over %zu %s\n", o.k, codec.bits, argv[3],
           sum / (double)places, low, high, places, o.move_codes ? "codes offsets" : "depths");
    free(weights), free(decoded), free(copy), free(codes), free(moved_area);
    return 0;
}
