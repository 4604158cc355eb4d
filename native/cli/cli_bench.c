/*
 * skinpack bench [--json] [--vertices N] [--repeats R] [--isa scalar|avx2|avx512]: single-thread
 * throughput of every codec's batch encode and decode and of the tuple-table build, as ratios to
 * a memcpy of the 4 float weights (16 bytes a vertex) timed right before each repetition. The R
 * repetitions are rounds over every codec (see time_rows). Rates are medians of R repetitions,
 * ratios the medians of the per-repetition ratios and the best-of ratios (fastest copy / fastest
 * run; the machine may be shared); --isa caps the vector paths (the widest the CPU has by
 * default), so one binary measures every path.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../src/codec_internal.h" /* sp_isa and the capped batch forms */
#include "bench_influences.h"
#include "commands.h"
#include "skinpack.h"

#define DEFAULT_REPEATS 7
#define MAX_REPEATS 101
#define INPUT_BYTES_PER_VERTEX 16
static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static uint64_t rng = 0x2545F4914F6CDD1Dull;
static uint64_t next_random(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return rng;
}

/* The influences, sorted, with neighbouring joints as in a real rig. */
static void make_influences(size_t count, int one_weight_percent, uint16_t* joints, float* weights)
{
    for (size_t v = 0; v < count; ++v) {
        size_t n = bench_influence_count(next_random, one_weight_percent);
        uint16_t bone = (uint16_t)(v * 64 / count);
        float raw[4], sum = 0;
        bench_raw_weights(next_random, n, raw);
        for (size_t i = 0; i < n; ++i) sum += raw[i];
        for (size_t i = 0; i < 4; ++i) {
            joints[v * 4 + i] = i < n ? (uint16_t)((bone + i) % 64) : 0;
            weights[v * 4 + i] = raw[i] / sum;
        }
    }
}


typedef struct bench_options {
    int json;
    size_t count;
    int repeats;
    int one_weight_percent; /* -1: the paper's mix */
    sp_isa isa;
} bench_options;

static const char* const isa_names[] = {"scalar", "avx2", "avx512"};

static int parse_options(int argc, char** argv, bench_options* o)
{
    o->json = 0, o->count = 1000000, o->repeats = DEFAULT_REPEATS, o->one_weight_percent = -1, o->isa = SP_ISA_AVX512;
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--json") == 0) o->json = 1;
        else if (strcmp(argv[i], "--vertices") == 0 && i + 1 < argc) o->count = strtoull(argv[++i], NULL, 10);
        else if (strcmp(argv[i], "--repeats") == 0 && i + 1 < argc) o->repeats = atoi(argv[++i]);
        else if (strcmp(argv[i], "--one-weight") == 0 && i + 1 < argc) {
            char* end;
            long percent = strtol(argv[++i], &end, 10);
            if (*end || end == argv[i] || percent < 0 || percent > 100) {
                fprintf(stderr, "Error: --one-weight %s: expected a percentage from 0 to 100\n", argv[i]);
                return 0;
            }
            o->one_weight_percent = (int)percent;
        }
        else if (strcmp(argv[i], "--isa") == 0 && i + 1 < argc) {
            const char* name = argv[++i];
            int found = -1;
            for (int n = 0; n < 3; ++n)
                if (strcmp(name, isa_names[n]) == 0) found = n;
            if (found < 0) {
                fprintf(stderr, "Error: --isa %s: expected scalar, avx2 or avx512\n", name);
                return 0;
            }
            o->isa = (sp_isa)found;
        } else {
            fprintf(stderr, "usage: skinpack bench [--json] [--vertices N] [--repeats R] [--isa scalar|avx2|avx512] "
                            "[--one-weight P]\n");
            return 0;
        }
    }
    if (o->count < 1000) o->count = 1000;
    if (o->repeats < 1) o->repeats = 1;
    if (o->repeats > MAX_REPEATS) o->repeats = MAX_REPEATS;
    return 1;
}

static int compare_doubles(const void* a, const void* b)
{
    double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

static double median(double* samples, int count)
{
    qsort(samples, (size_t)count, sizeof(double), compare_doubles);
    return count % 2 ? samples[count / 2] : 0.5 * (samples[count / 2 - 1] + samples[count / 2]);
}

static double rate(size_t count, double seconds)
{
    return seconds > 0 ? (double)count / seconds : 0;
}

/* Buffers of one run, sized for K = 4. */
typedef struct bench_buffers {
    uint16_t* joints;
    float *weights, *decoded, *narrowed;
    uint64_t* codes;
    uint8_t* significant;
    uint32_t* tuple_index;
    uint16_t* lut;
    void* scratch;
    size_t scratch_size;
    unsigned char *copy_src, *copy_dst;
} bench_buffers;

static int allocate(size_t count, bench_buffers* b)
{
    b->joints = malloc(count * 4 * sizeof(uint16_t));
    b->weights = malloc(count * 4 * sizeof(float));
    b->decoded = malloc(count * 4 * sizeof(float));
    b->narrowed = malloc(count * (2 + 3 + 4) * sizeof(float));
    b->codes = malloc(count * sizeof(uint64_t));
    b->significant = malloc(count);
    b->tuple_index = malloc(count * sizeof(uint32_t));
    b->lut = malloc(count * 4 * sizeof(uint16_t));
    b->scratch_size = sp_tuple_lut_scratch_bound(count, 4);
    b->scratch = malloc(b->scratch_size);
    b->copy_src = malloc(count * INPUT_BYTES_PER_VERTEX);
    b->copy_dst = malloc(count * INPUT_BYTES_PER_VERTEX);
    return b->joints && b->weights && b->decoded && b->narrowed && b->codes && b->significant && b->tuple_index &&
           b->lut && b->scratch && b->copy_src && b->copy_dst;
}

static void release(bench_buffers* b)
{
    free(b->joints), free(b->weights), free(b->decoded), free(b->narrowed), free(b->codes), free(b->significant);
    free(b->tuple_index), free(b->lut), free(b->scratch), free(b->copy_src), free(b->copy_dst);
}

/* The K-wide weights in `narrowed` (K = 2, 3, 4 one after the other: offsets 0, 2 and 5 counts). */
static float* narrowed_for(const bench_options* o, bench_buffers* b, uint32_t k)
{
    return b->narrowed + o->count * (k - 2) * (k + 1) / 2;
}

/* One timed memcpy of the weights' bytes (the baseline of every ratio, taken next to what it
 * is compared with, so that a busy spell of the shared machine slows both). */
static double time_memcpy(const bench_options* o, bench_buffers* b, int r)
{
    size_t bytes = o->count * INPUT_BYTES_PER_VERTEX;
    double t0 = now_seconds();
    memcpy(b->copy_dst, b->copy_src, bytes);
    double t = now_seconds() - t0;
    b->copy_src[r % 64] ^= b->copy_dst[bytes - 1 - r % 64]; /* keep the copy observable */
    return t;
}

/* A measured rate and its ratio to memcpy: medians over the repetitions of each alone, the
 * median of the per-repetition ratios, and the best-of ratio (fastest memcpy / fastest run):
 * on a shared machine a neighbour's burst slows the long codec runs more often than the short,
 * memory-bound copy, so the fastest of each is the figure least disturbed by other jobs. */
typedef struct bench_rate {
    double per_s, ratio, best_ratio;
} bench_rate;

static double fastest(const double* seconds, int count)
{
    double best = seconds[0];
    for (int r = 1; r < count; ++r) best = seconds[r] < best ? seconds[r] : best;
    return best;
}

static bench_rate summarise(const bench_options* o, double* seconds, double* copy_seconds)
{
    double ratios[MAX_REPEATS], best = fastest(seconds, o->repeats);
    for (int r = 0; r < o->repeats; ++r) ratios[r] = seconds[r] > 0 ? copy_seconds[r] / seconds[r] : 0;
    bench_rate result = {rate(o->count, median(seconds, o->repeats)), median(ratios, o->repeats),
                         best > 0 ? fastest(copy_seconds, o->repeats) / best : 0};
    return result;
}

static double memcpy_rate(const bench_options* o, bench_buffers* b)
{
    double t[MAX_REPEATS];
    memcpy(b->copy_dst, b->copy_src, o->count * INPUT_BYTES_PER_VERTEX); /* untimed: faults the pages in */
    for (int r = 0; r < o->repeats; ++r) t[r] = time_memcpy(o, b, r);
    return rate(o->count, median(t, o->repeats));
}

static bench_rate lut_rate(const bench_options* o, bench_buffers* b, size_t* lut_size)
{
    double t[MAX_REPEATS], copy[MAX_REPEATS];
    sp_codec codec;
    sp_codec_from_bits(SP_METHOD_OSS, 4, 22, &codec);
    sp_encode_weights_batch(&codec, b->weights, o->count, b->codes, b->significant);
    for (int r = 0; r < o->repeats; ++r) {
        copy[r] = time_memcpy(o, b, r);
        double t0 = now_seconds();
        sp_build_tuple_lut(b->joints, b->significant, o->count, 4, b->lut, lut_size, b->tuple_index, b->scratch,
                           b->scratch_size);
        t[r] = now_seconds() - t0;
    }
    return summarise(o, t, copy);
}

/* The K heaviest weights of each vertex, renormalised (what a K-influence skin holds), for
 * K = 2, 3 and 4 one after the other in `narrowed`. */
static void narrow(const bench_options* o, bench_buffers* b)
{
    for (uint32_t k = 2; k <= 4; ++k) {
        float* out = narrowed_for(o, b, k);
        for (size_t v = 0; v < o->count; ++v) {
            float sum = 0;
            for (uint32_t i = 0; i < k; ++i) sum += b->weights[v * 4 + i];
            for (uint32_t i = 0; i < k; ++i) out[v * k + i] = b->weights[v * 4 + i] / sum;
        }
    }
}

/* One row of the table: a codec, the budget it was made for and its timings, each next to the
 * memcpy timed right before it. */
typedef struct bench_row {
    sp_codec codec;
    uint32_t budget;
    double encode[MAX_REPEATS], decode[MAX_REPEATS], copy_encode[MAX_REPEATS], copy_decode[MAX_REPEATS];
} bench_row;

static const uint32_t budgets[] = {16, 22, 32, 38, 44, 52, 64};
#define BUDGET_COUNT (sizeof(budgets) / sizeof(budgets[0]))
#define MAX_ROWS (3 * SP_METHOD_COUNT * BUDGET_COUNT) /* K = 2, 3, 4 */

/* Every codec the bench measures (at most MAX_ROWS), in the table's order; returns how many. */
static size_t make_rows(bench_row* rows)
{
    size_t count = 0;
    for (uint32_t k = 2; k <= 4; ++k)
        for (int m = 0; m < SP_METHOD_COUNT; ++m)
            for (size_t i = 0; i < BUDGET_COUNT; ++i)
                if (sp_codec_from_bits((sp_method)m, k, budgets[i], &rows[count].codec) == SP_OK)
                    rows[count++].budget = budgets[i];
    return count;
}

/* Repetition r of one row: its encode and decode, each after a timed memcpy. */
static void time_row(const bench_options* o, bench_buffers* b, bench_row* row, int r)
{
    const float* weights = narrowed_for(o, b, row->codec.influences);
    row->copy_encode[r] = time_memcpy(o, b, r);
    double t0 = now_seconds();
    sp_encode_weights_batch_isa(&row->codec, weights, o->count, b->codes, NULL, o->isa);
    row->encode[r] = now_seconds() - t0;
    row->copy_decode[r] = time_memcpy(o, b, r);
    t0 = now_seconds();
    sp_decode_weights_batch_isa(&row->codec, b->codes, o->count, b->decoded, NULL, o->isa);
    row->decode[r] = now_seconds() - t0;
}

/* Every row's repetitions, as rounds: each round times every row once. A neighbour's burst on
 * the shared machine (seconds long) then slows one repetition of many rows instead of every
 * repetition of a few, so each row's best-of figures come from moments spread over the run.
 * The rows are known only after the last round, so the text output says on stderr how far the
 * rounds are. */
static void time_rows(const bench_options* o, bench_buffers* b, bench_row* rows, size_t count)
{
    for (int r = 0; r < o->repeats; ++r) {
        for (size_t i = 0; i < count; ++i) time_row(o, b, &rows[i], r);
        if (!o->json) fprintf(stderr, "skinpack bench: round %d of %d done\n", r + 1, o->repeats);
    }
}

/* The run's header: the machine's rates as a JSON object's head, or as text lines. */
static void print_header(const bench_options* o, sp_isa isa, sp_isa cpu, double copy, bench_rate lut, size_t lut_size)
{
    if (o->json) {
        printf("{\"vertices\": %zu, \"repeats\": %d, \"one_weight_percent\": %d, \"isa\": \"%s\", \"cpu_isa\": \"%s\", "
               "\"memcpy_bytes_per_vertex\": %d, \"memcpy_vertices_per_s\": %.0f, \"lut_build_vertices_per_s\": %.0f, "
               "\"lut_build_ratio\": %.3f, \"lut_size\": %zu, \"codecs\": [",
               o->count, o->repeats, o->one_weight_percent, isa_names[isa], isa_names[cpu], INPUT_BYTES_PER_VERTEX, copy,
               lut.per_s, lut.ratio, lut_size);
        return;
    }
    printf("skinpack bench: %zu vertices, single thread, median of %d, vector path %s (CPU: %s)\n", o->count,
           o->repeats, isa_names[isa], isa_names[cpu]);
    if (o->one_weight_percent >= 0) printf("influences: %d %% one weight, the rest in the paper's proportions\n", o->one_weight_percent);
    printf("memcpy (16 B/vertex)  %8.1f M vertices/s\n", copy / 1e6);
    printf("tuple table build     %8.1f M vertices/s  (%.3fx memcpy, %zu tuples)\n\n", lut.per_s / 1e6, lut.ratio,
           lut_size);
    printf("%-6s %2s %4s  %10s %7s %7s  %10s %7s %7s\n", "method", "K", "bits", "encode M/s", "ratio", "best",
           "decode M/s", "ratio", "best");
}

/* One codec's row (JSON: `first` says whether a comma goes before it). */
static void print_row(const bench_options* o, const sp_codec* codec, uint32_t budget, int vector, bench_rate enc,
                      bench_rate dec, int first)
{
    const char* name = sp_method_name(codec->method);
    if (o->json)
        printf("%s{\"method\": \"%s\", \"influences\": %u, \"budget\": %u, \"bits\": %u, "
               "\"encode_vector\": %s, \"decode_vector\": %s, "
               "\"encode_vertices_per_s\": %.0f, \"decode_vertices_per_s\": %.0f, "
               "\"encode_ratio\": %.3f, \"decode_ratio\": %.3f, \"encode_best_ratio\": %.3f, "
               "\"decode_best_ratio\": %.3f}",
               first ? "" : ", ", name, codec->influences, budget, codec->bits, vector ? "true" : "false",
               vector ? "true" : "false", enc.per_s, dec.per_s, enc.ratio, dec.ratio, enc.best_ratio, dec.best_ratio);
    else
        printf("%-6s %2u %4u  %10.1f %6.3fx %6.3fx  %10.1f %6.3fx %6.3fx%s\n", name, codec->influences, codec->bits,
               enc.per_s / 1e6, enc.ratio, enc.best_ratio, dec.per_s / 1e6, dec.ratio, dec.best_ratio,
               vector ? "" : "  (scalar)");
}

int skinpack_cmd_bench(int argc, char** argv)
{
    bench_options o;
    bench_buffers b;
    if (!parse_options(argc, argv, &o)) return 2;
    bench_row* rows = malloc(MAX_ROWS * sizeof(bench_row));
    if (!allocate(o.count, &b) || !rows) {
        fprintf(stderr, "Error: skinpack bench: out of memory for %zu vertices\n", o.count);
        release(&b), free(rows);
        return 1;
    }
    make_influences(o.count, o.one_weight_percent, b.joints, b.weights);
    for (size_t i = 0; i < o.count * INPUT_BYTES_PER_VERTEX; ++i) b.copy_src[i] = (unsigned char)next_random();
    sp_isa cpu = sp_cpu_isa(), isa = cpu < o.isa ? cpu : o.isa;
    double copy = memcpy_rate(&o, &b);
    size_t lut_size = 0;
    bench_rate lut = lut_rate(&o, &b, &lut_size);
    narrow(&o, &b);
    size_t row_count = make_rows(rows);
    print_header(&o, isa, cpu, copy, lut, lut_size);
    fflush(stdout); /* the header before the rounds, also through a pipe */
    time_rows(&o, &b, rows, row_count);
    for (size_t i = 0; i < row_count; ++i) {
        const sp_codec* codec = &rows[i].codec;
        int vector = codec->method == SP_METHOD_OSS && sp_oss_batch_supported(codec, isa);
        print_row(&o, codec, rows[i].budget, vector, summarise(&o, rows[i].encode, rows[i].copy_encode),
                  summarise(&o, rows[i].decode, rows[i].copy_decode), i == 0);
    }
    if (o.json) printf("]}\n");
    release(&b), free(rows);
    return 0;
}
