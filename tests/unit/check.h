/* Minimal test harness: CHECK keeps going and counts, main returns the failure count. */
#ifndef SKINPACK_CHECK_H
#define SKINPACK_CHECK_H

#include <stdio.h>
#include <stdint.h>

static int check_failures = 0;
static int check_count = 0;

#define CHECK(cond)                                                                    \
    do {                                                                               \
        ++check_count;                                                                 \
        if (!(cond)) {                                                                 \
            if (++check_failures < 20) fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
        }                                                                              \
    } while (0)

#define CHECK_MSG(cond, ...)                                                           \
    do {                                                                               \
        ++check_count;                                                                 \
        if (!(cond)) {                                                                 \
            if (++check_failures < 20) {                                               \
                fprintf(stderr, "%s:%d: CHECK failed: %s: ", __FILE__, __LINE__, #cond); \
                fprintf(stderr, __VA_ARGS__);                                          \
                fprintf(stderr, "\n");                                                 \
            }                                                                          \
        }                                                                              \
    } while (0)

static inline int check_report(const char* name)
{
    printf("%s: %d checks, %d failed\n", name, check_count, check_failures);
    return check_failures ? 1 : 0;
}

/* Deterministic xorshift generator: tests must be reproducible. */
static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static inline uint64_t rng_next(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}
static inline double rng_unit(void) { return (double)(rng_next() >> 11) * (1.0 / 9007199254740992.0); }

#endif
