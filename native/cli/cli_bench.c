/*
 * skinpack bench [--json] [--vertices N]: single-thread throughput of every codec's batch
 * encode and decode and of the tuple-table build, as ratios to memcpy of the same input bytes
 * (4 u8 joints + 4 float weights = 20 bytes a vertex) measured in the same run.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "commands.h"
#include "skinpack.h"

#define REPEATS 5
#define INPUT_BYTES_PER_VERTEX 20

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

/* The paper's influence mix (51 % one, 22 % two, 13 % three, 14 % four weights), sorted,
 * with neighbouring joints as in a real rig. */
static void make_influences(size_t count, uint16_t* joints, float* weights)
{
    for (size_t v = 0; v < count; ++v) {
        uint64_t r = next_random() % 100;
        size_t n = r < 51 ? 1 : r < 73 ? 2 : r < 86 ? 3 : 4;
        uint16_t bone = (uint16_t)(v * 64 / count);
        float raw[4] = {0, 0, 0, 0}, sum = 0;
        for (size_t i = 0; i < n; ++i) {
            raw[i] = (float)(next_random() % 1000 + 1);
            sum += raw[i];
        }
        for (size_t i = 1; i < 4; ++i) /* descending */
            for (size_t j = i; j > 0 && raw[j - 1] < raw[j]; --j) {
                float t = raw[j];
                raw[j] = raw[j - 1];
                raw[j - 1] = t;
            }
        for (size_t i = 0; i < 4; ++i) {
            joints[v * 4 + i] = i < n ? (uint16_t)((bone + i) % 64) : 0;
            weights[v * 4 + i] = raw[i] / sum;
        }
    }
}


static double vertices_per_second(size_t count, double seconds)
{
    return seconds > 0 ? (double)count / seconds : 0;
}

int skinpack_cmd_bench(int argc, char** argv)
{
    int json = 0;
    size_t count = 1000000;
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--json") == 0) json = 1;
        else if (strcmp(argv[i], "--vertices") == 0 && i + 1 < argc) count = strtoull(argv[++i], NULL, 10);
        else {
            fprintf(stderr, "usage: skinpack bench [--json] [--vertices N]\n");
            return 2;
        }
    }
    if (count < 1000) count = 1000;
    uint16_t* joints = malloc(count * 4 * sizeof(uint16_t));
    float* weights = malloc(count * 4 * sizeof(float));
    float* decoded = malloc(count * 4 * sizeof(float));
    float* narrowed = malloc(count * 4 * sizeof(float));
    uint64_t* codes = malloc(count * sizeof(uint64_t));
    uint8_t* significant = malloc(count);
    uint32_t* tuple_index = malloc(count * sizeof(uint32_t));
    uint16_t* lut = malloc(count * 4 * sizeof(uint16_t));
    size_t scratch_size = sp_tuple_lut_scratch_bound(count, 4);
    void* scratch = malloc(scratch_size);
    unsigned char* copy_src = malloc(count * INPUT_BYTES_PER_VERTEX);
    unsigned char* copy_dst = malloc(count * INPUT_BYTES_PER_VERTEX);
    if (!joints || !weights || !decoded || !narrowed || !codes || !significant || !tuple_index || !lut || !scratch ||
        !copy_src || !copy_dst) {
        fprintf(stderr, "skinpack bench: out of memory for %zu vertices\n", count);
        return 1;
    }
    make_influences(count, joints, weights);
    for (size_t i = 0; i < count * INPUT_BYTES_PER_VERTEX; ++i) copy_src[i] = (unsigned char)next_random();

    double best = 1e30;
    for (int r = 0; r < REPEATS; ++r) {
        double t0 = now_seconds();
        memcpy(copy_dst, copy_src, count * INPUT_BYTES_PER_VERTEX);
        best = fmin(best, now_seconds() - t0);
        copy_src[r] ^= copy_dst[count * INPUT_BYTES_PER_VERTEX - 1 - r]; /* keep the copy observable */
    }
    double memcpy_rate = vertices_per_second(count, best);

    sp_codec lut_codec;
    sp_codec_from_bits(SP_METHOD_OSS, 4, 22, &lut_codec);
    sp_encode_weights_batch(&lut_codec, weights, count, codes, significant);
    best = 1e30;
    size_t lut_size = 0;
    for (int r = 0; r < REPEATS; ++r) {
        double t0 = now_seconds();
        sp_build_tuple_lut(joints, significant, count, 4, lut, &lut_size, tuple_index, scratch, scratch_size);
        best = fmin(best, now_seconds() - t0);
    }
    double lut_rate = vertices_per_second(count, best);

    if (json) printf("{\"vertices\": %zu, \"memcpy_vertices_per_s\": %.0f, \"lut_build_vertices_per_s\": %.0f, "
                     "\"lut_build_ratio\": %.3f, \"codecs\": [", count, memcpy_rate, lut_rate, lut_rate / memcpy_rate);
    else {
        printf("skinpack bench: %zu vertices, single thread, best of %d\n", count, REPEATS);
        printf("memcpy (20 B/vertex)  %8.1f M vertices/s\n", memcpy_rate / 1e6);
        printf("tuple table build     %8.1f M vertices/s  (%.2fx memcpy, %zu tuples)\n\n", lut_rate / 1e6,
               lut_rate / memcpy_rate, lut_size);
        printf("%-6s %2s %4s  %10s %7s  %10s %7s\n", "method", "K", "bits", "encode M/s", "ratio", "decode M/s",
               "ratio");
    }
    int first = 1;
    static const uint32_t budgets[] = {22, 38};
    for (uint32_t k = 2; k <= 4; ++k) {
        /* the K heaviest weights of each vertex, renormalised: what a K-influence skin holds */
        for (size_t v = 0; v < count; ++v) {
            float sum = 0;
            for (uint32_t i = 0; i < k; ++i) sum += weights[v * 4 + i];
            for (uint32_t i = 0; i < k; ++i) narrowed[v * k + i] = weights[v * 4 + i] / sum;
        }
        for (int m = 0; m < SP_METHOD_COUNT; ++m)
            for (size_t b = 0; b < sizeof(budgets) / sizeof(budgets[0]); ++b) {
                sp_codec codec;
                if (sp_codec_from_bits((sp_method)m, k, budgets[b], &codec) != SP_OK) continue;
                double encode_best = 1e30, decode_best = 1e30;
                for (int r = 0; r < REPEATS; ++r) {
                    double t0 = now_seconds();
                    sp_encode_weights_batch(&codec, narrowed, count, codes, NULL);
                    double t1 = now_seconds();
                    sp_decode_weights_batch(&codec, codes, count, decoded, NULL);
                    double t2 = now_seconds();
                    encode_best = fmin(encode_best, t1 - t0);
                    decode_best = fmin(decode_best, t2 - t1);
                }
                double enc = vertices_per_second(count, encode_best), dec = vertices_per_second(count, decode_best);
                if (json)
                    printf("%s{\"method\": \"%s\", \"influences\": %u, \"bits\": %u, \"encode_vertices_per_s\": %.0f, "
                           "\"decode_vertices_per_s\": %.0f, \"encode_ratio\": %.3f, \"decode_ratio\": %.3f}",
                           first ? "" : ", ", sp_method_name((sp_method)m), k, codec.bits, enc, dec,
                           enc / memcpy_rate, dec / memcpy_rate);
                else
                    printf("%-6s %2u %4u  %10.1f %6.2fx  %10.1f %6.2fx\n", sp_method_name((sp_method)m), k,
                           codec.bits, enc / 1e6, enc / memcpy_rate, dec / 1e6, dec / memcpy_rate);
                first = 0;
            }
    }
    if (json) printf("]}\n");
    free(joints); free(weights); free(decoded); free(narrowed); free(codes); free(significant);
    free(tuple_index); free(lut); free(scratch); free(copy_src); free(copy_dst);
    return 0;
}
