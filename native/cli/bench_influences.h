/*
 * The bench's vertices: the paper's influence mix and their raw weights, one rule for
 * `skinpack bench` (cli_bench.c) and the benchmark tools (tests/bench/edge_stack_sweep.c), each
 * drawing from its own random source.
 */
#ifndef SKINPACK_BENCH_INFLUENCES_H
#define SKINPACK_BENCH_INFLUENCES_H

#include <stddef.h>
#include <stdint.h>

typedef uint64_t (*bench_random)(void);

/* How many weights a vertex has: the paper's influence mix (51 % one, 22 % two, 13 % three,
 * 14 % four weights), or for one_weight_percent P >= 0, P % one and the rest in the paper's
 * proportions of two, three and four (22 : 13 : 14), for the shortcuts one-weight vertices take. */
static inline size_t bench_influence_count(bench_random random, int one_weight_percent)
{
    uint64_t r = random() % 100;
    if (one_weight_percent < 0) return r < 51 ? 1 : r < 73 ? 2 : r < 86 ? 3 : 4;
    if (r < (uint64_t)one_weight_percent) return 1;
    uint64_t rest = random() % 49;
    return rest < 22 ? 2 : rest < 35 ? 3 : 4;
}

/* `count` (<= 4) raw weights from 1 to 1000 in raw[0, count), sorted descending, zeros after. */
static inline void bench_raw_weights(bench_random random, size_t count, float raw[4])
{
    for (size_t i = 0; i < 4; ++i) raw[i] = i < count ? (float)(random() % 1000 + 1) : 0.0f;
    for (size_t i = 1; i < 4; ++i)
        for (size_t j = i; j > 0 && raw[j - 1] < raw[j]; --j) {
            float t = raw[j];
            raw[j] = raw[j - 1], raw[j - 1] = t;
        }
}

#endif
