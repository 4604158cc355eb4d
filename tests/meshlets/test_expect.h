/*
 * test_expect.h - the meshlet unit tests' check macro: EXPECT(cond, printf-style message) prints
 * the failed condition with its location and counts it in `failures` (one per test program).
 */
#ifndef SKINPACK_TEST_EXPECT_H
#define SKINPACK_TEST_EXPECT_H

#include <stdio.h>

static int failures;

#define EXPECT(cond, ...)                                              \
    do {                                                               \
        if (!(cond)) {                                                 \
            fprintf(stderr, "%s:%d: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                              \
            fprintf(stderr, "\n");                                     \
            failures++;                                                \
        }                                                              \
    } while (0)

#endif
