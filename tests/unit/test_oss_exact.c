/*
 * K = 2 rounding on grids past 2^50 (OSS codes of 50..63 bits, Cube and POT of 52..64) against
 * a reference in exact integer arithmetic: each weight as an integer times a power of two, the
 * sum D exact, x_i = s W_i / D by long division in 384-bit integers, floors, and the deficit to
 * the larger remainder (ties to slot 0), then sorted: the spec's largest-remainder rule as
 * written, nothing shared with the library's rounding. Random pairs of every exponent gap
 * 0..70, normalised ones, zeros, denormals and both slot orders, exact ties and ties +-1/D, near
 * ties at large gaps, and two cases the long double rounding got wrong; every path (batch on
 * each ISA, one vertex) must give the reference's codes and significant counts.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../../native/src/codec_internal.h" /* the *_isa batch forms */
#include "check.h"
#include "skinpack.h"

#define RANDOM_PAIRS 200000
#define LIMBS 12 /* 384 bits: s (64) times a weight shifted by the largest exponent gap (277 + 24) */

typedef struct big {
    uint32_t limb[LIMBS]; /* little endian */
} big;

static big big_from(uint64_t x)
{
    big r;
    memset(&r, 0, sizeof(r));
    r.limb[0] = (uint32_t)x;
    r.limb[1] = (uint32_t)(x >> 32);
    return r;
}

static big big_shift_left(big a, uint32_t bits) /* bits dropped past LIMBS 32 */
{
    big r = big_from(0);
    uint32_t limbs = bits / 32, rest = bits % 32;
    for (uint32_t i = 0; i + limbs < LIMBS; ++i) {
        uint64_t wide = (uint64_t)a.limb[i] << rest;
        r.limb[i + limbs] |= (uint32_t)wide;
        if (i + limbs + 1 < LIMBS) r.limb[i + limbs + 1] |= (uint32_t)(wide >> 32);
    }
    return r;
}

static big big_shift_right_one(big a)
{
    for (int i = 0; i < LIMBS; ++i) a.limb[i] = (a.limb[i] >> 1) | (i + 1 < LIMBS ? a.limb[i + 1] << 31 : 0);
    return a;
}

static big big_add(big a, big b)
{
    uint64_t carry = 0;
    for (int i = 0; i < LIMBS; ++i) {
        carry += (uint64_t)a.limb[i] + b.limb[i];
        a.limb[i] = (uint32_t)carry;
        carry >>= 32;
    }
    return a;
}

static big big_sub(big a, big b) /* a >= b */
{
    uint64_t borrow = 0;
    for (int i = 0; i < LIMBS; ++i) {
        uint64_t d = (uint64_t)a.limb[i] - b.limb[i] - borrow;
        a.limb[i] = (uint32_t)d;
        borrow = d >> 63;
    }
    return a;
}

static int big_compare(big a, big b)
{
    for (int i = LIMBS - 1; i >= 0; --i)
        if (a.limb[i] != b.limb[i]) return a.limb[i] < b.limb[i] ? -1 : 1;
    return 0;
}

static big big_mul_u64(big a, uint64_t m) /* schoolbook, by m's two 32-bit halves; the product fits */
{
    big r = big_from(0);
    for (int half = 0; half < 2; ++half) {
        uint64_t digit = half ? m >> 32 : (uint32_t)m, carry = 0;
        big part = big_from(0);
        for (int i = 0; i + half < LIMBS; ++i) {
            carry += (uint64_t)a.limb[i] * digit;
            part.limb[i + half] = (uint32_t)carry;
            carry >>= 32;
        }
        r = big_add(r, part);
    }
    return r;
}

/* floor(n / d) (below 2^64 here: n < 2^64 d) and the remainder, by restoring long division. */
static uint64_t big_divide(big n, big d, big* rest)
{
    uint64_t quotient = 0;
    big step = big_shift_left(d, 63);
    for (int bit = 63; bit >= 0; --bit, step = big_shift_right_one(step)) { /* step = d 2^bit */
        if (big_compare(n, step) >= 0) {
            n = big_sub(n, step);
            quotient |= (uint64_t)1 << bit;
        }
    }
    CHECK(big_compare(n, d) < 0);
    *rest = n;
    return quotient;
}

/* A finite float >= 0 as significand 2^exponent. */
static uint64_t float_parts(float w, int* exponent)
{
    uint32_t bits;
    memcpy(&bits, &w, sizeof(bits));
    uint32_t field = (bits >> 23) & 0xFF;
    *exponent = (field ? (int)field : 1) - 150;
    return (bits & 0x7FFFFF) | (field ? 0x800000u : 0);
}

/* The spec's rounding of (w0, w1) to the grid s, sorted: returns q[1] (the code of every K = 2
 * grid method). */
static uint64_t reference_small(float w0, float w1, uint64_t s)
{
    int e0, e1;
    uint64_t m0 = float_parts(w0, &e0), m1 = float_parts(w1, &e1);
    int low = e0 < e1 ? e0 : e1;
    big W0 = big_shift_left(big_from(m0), (uint32_t)(e0 - low)), W1 = big_shift_left(big_from(m1), (uint32_t)(e1 - low));
    big D = big_add(W0, W1), r0, r1;
    uint64_t q0 = big_divide(big_mul_u64(W0, s), D, &r0), q1 = big_divide(big_mul_u64(W1, s), D, &r1);
    uint64_t deficit = s - q0 - q1;
    CHECK(deficit <= 1);
    if (deficit == 1) {
        if (big_compare(r0, r1) >= 0) ++q0;
        else ++q1;
    }
    return q0 < q1 ? q0 : q1;
}

/* w = significand 2^exponent, significand 24 bits with the top one set. */
static float make_float(uint64_t significand, int exponent)
{
    return ldexpf((float)(significand | 0x800000u), exponent);
}

/* Random pairs: every exponent gap 0..70 (past 66 the smaller rounds to 0) with random significands, normalised pairs w0 = 1 - w1,
 * zeros, equal weights and denormals; slots in either order. */
static void random_pairs(float* weights, size_t count)
{
    for (size_t v = 0; v < count; ++v) {
        uint32_t kind = (uint32_t)(rng_next() % 8), gap = (uint32_t)(rng_next() % 71);
        int exponent = -(int)(rng_next() % 40);
        float a = make_float(rng_next() & 0x7FFFFF, exponent - 23), b = make_float(rng_next() & 0x7FFFFF, exponent - 23 - (int)gap);
        if (kind == 0) a = 1.0f - b / 2, b = 1.0f - a;
        if (kind == 1 && v % 4 == 0) b = 0.0f;
        if (kind == 1 && v % 4 == 1) b = a;
        if (kind == 2) { /* denormals, alone or with a normal weight */
            b = ldexpf((float)(rng_next() % 0x800000 + 1), -149);
            if (v % 2) a = ldexpf((float)(rng_next() % 0x800000 + 1), -149);
        }
        int swap = rng_next() % 2;
        weights[v * 2] = swap ? b : a;
        weights[v * 2 + 1] = swap ? a : b;
    }
}

/* u^-1 modulo 2^64 for odd u (Newton). */
static uint64_t odd_inverse(uint64_t u)
{
    uint64_t x = u;
    for (int i = 0; i < 6; ++i) x *= 2 - u * x;
    return x;
}

/* Pairs summing to 2^-j with x1 = m + 1/2 + delta / 2^k exactly (delta = -2..2 where s allows):
 * w1 = B 2^-k-j, w0 = (2^k - B) 2^-k-j, s B = 2^(k-1) + delta modulo 2^k. */
static size_t tie_pairs(uint64_t s, float* weights)
{
    size_t count = 0;
    uint32_t twos = 0;
    while (!((s >> twos) & 1)) ++twos;
    uint64_t inverse = odd_inverse(s >> twos);
    for (uint32_t k = twos + 2; k <= 24; ++k)
        for (int delta = -2; delta <= 2; ++delta) {
            uint64_t target = ((uint64_t)1 << (k - 1)) + (uint64_t)(int64_t)delta;
            if (target & (((uint64_t)1 << twos) - 1)) continue; /* s B is a multiple of 2^twos */
            uint64_t modulus = (uint64_t)1 << (k - twos), b = ((target >> twos) * inverse) & (modulus - 1);
            for (uint64_t B = b; B < ((uint64_t)1 << k) && B < b + 2 * modulus; B += modulus) { /* two of them */
                int j = (int)(k % 5) * 20 - 40;
                weights[count * 2] = ldexpf((float)(((uint64_t)1 << k) - B), -(int)k - j);
                weights[count * 2 + 1] = ldexpf((float)B, -(int)k - j);
                ++count;
            }
        }
    return count;
}

/* Exact ties whose sum is not a power of two (tie_pairs' are; there the tie is x = s/4 or s/2
 * for most grids, the same side of every quotient): a = A 2^e, d = q 2^(e + t + 1) for odd q
 * and s = s' 2^t with s' odd, so that x = s a / d = s' (A / q) 2^-1 is an odd multiple of 1/2
 * where q divides s' (any odd A < q 2^t) or A (A = q A', A' odd < 2^t); the two weights in
 * either slot order, so that some ties go up and some down, on either side of the lanes'
 * estimate. */
static size_t odd_tie_pairs(uint64_t s, float* weights)
{
    uint32_t twos = 0;
    while (!((s >> twos) & 1)) ++twos;
    size_t count = 0;
    for (uint64_t q = 3; q < 0x400000 && count < 1000; q += 2)
        for (int t = 0, divides = (s >> twos) % q == 0; t < (divides ? 64 : q < 4096 ? 4 : 0); ++t) {
            uint64_t sum = q << (twos + 1), half = sum / 2, a = q * (2 * (rng_next() % ((half / q + 1) / 2)) + 1);
            if (divides) a = 2 * (rng_next() % (half / 2)) + 1;
            if (sum >= 0x1000000 || a >= half) continue;
            int exponent = -10 - (int)(rng_next() % 50), swap = (int)(rng_next() % 2);
            weights[count * 2 + swap] = ldexpf((float)a, exponent);
            weights[count * 2 + 1 - swap] = ldexpf((float)(sum - a), exponent);
            ++count;
        }
    return count;
}

/* Near ties at gaps 25..60: for w0 = a 2^g (units of w1's last bit), b random, a picked so that
 * x1 = s b / (a 2^g + b) is near m + 1/2 (within x 2^-25, where that is below 1). */
static size_t near_tie_pairs(uint64_t s, float* weights)
{
    size_t count = 0;
    for (uint32_t g = 25; g <= 60; ++g)
        for (int t = 0; t < 4; ++t) {
            long double b = (long double)((rng_next() & 0x7FFFFF) | 0x800000), a = (long double)((rng_next() & 0x7FFFFF) | 0x800000);
            long double unit = ldexpl(1.0L, (int)g), x = (long double)s * b / (a * unit + b);
            long double m = floorl(x), better = roundl(((long double)s * b * 2 / (2 * m + 1) - b) / unit);
            if (better < 0x800000 || better > 0xFFFFFF) continue;
            weights[count * 2] = (float)ldexpl(better, (int)g - 30);
            weights[count * 2 + 1] = (float)ldexpl(b, -30);
            ++count;
        }
    return count;
}

/* Pairs the vector lanes' FMA rounding (codec_oss_wide_simd.h's wide_pair_start) takes at any
 * gap where d = w0 + w1 is exact in double: the smaller weight with 1..24 significant bits, so
 * that x1 = s w1 / d lies on or next to targets at the lanes' cut-offs (no f below y = 2^13,
 * f = round(y / 2^12) 2^12 above it, whose first steps 2^12, 3 2^11 lie around there) and at
 * larger quotients, and the gaps 26..32 around d's exactness with full significands. */
static size_t sparse_pairs(uint64_t s, float* weights)
{
    static const double targets[] = {0x1p11, 0x1p11 + 1, 0x1.8p11, 0x1p12, 0x1.4p12, 0x1.8p12, 0x1p13 - 2, 0x1p13 - 1,
                                     0x1p13 - 0.5, 0x1p13, 0x1p13 + 0.5, 0x1p13 + 1, 0x1p13 + 2, 0x1.4p13, 0x1p14,
                                     0x1p14 + 1, 0x1p15, 0x1p20 + 0.5, 0x1p30, 0x1p40 + 0.5, 0x1p50};
    static const int precisions[] = {1, 2, 3, 4, 6, 8, 16, 24};
    size_t count = 0;
    for (size_t t = 0; t < sizeof(targets) / sizeof(targets[0]) && targets[t] < (double)s / 4; ++t)
        for (size_t p = 0; p < sizeof(precisions) / sizeof(precisions[0]); ++p)
            for (int step = -1; step <= 1; ++step) {
                long double large = ldexpl((long double)((rng_next() & 0x7FFFFF) | 0x800000), -24 - (int)(rng_next() % 20));
                long double small = (long double)targets[t] * large / ((long double)s - targets[t]);
                int exponent = ilogbl(small) - precisions[p] + 1; /* small's last bit */
                long double significand = roundl(ldexpl(small, -exponent)) + step;
                weights[count * 2] = (float)large;
                weights[count * 2 + 1] = (float)ldexpl(significand, exponent);
                ++count;
            }
    for (int gap = 26; gap <= 32; ++gap)
        for (int t = 0; t < 8; ++t) {
            uint64_t significand = t < 2 ? 0xFFFFFF : (rng_next() & 0x7FFFFF) | 0x800000;
            weights[count * 2] = make_float(rng_next() & 0x7FFFFF, -24);
            weights[count * 2 + 1] = make_float(significand, -24 - gap);
            ++count;
        }
    return count;
}

/* Cases the long double rounding got wrong: x1 = 12516699805865424.164 at 63 bits (it gave
 * ...425), x1 = 3753035995369754.50002 at 52 bits (it gave ...754). */
static void known_cases(void)
{
    sp_codec codec;
    CHECK(sp_codec_from_bits(SP_METHOD_OSS, 2, 63, &codec) == SP_OK && codec.scale == 18446744073709551614ull);
    float pair63[2] = {0x1.ffa71p-1f, 0x1.63befap-11f};
    CHECK(sp_encode_weights(&codec, pair63) == 12516699805865424ull);
    CHECK(sp_codec_from_bits(SP_METHOD_OSS, 2, 52, &codec) == SP_OK && codec.scale == 9007199254740990ull);
    float pair52[2] = {0x1.2aaa24p-1f, 0x1.aaabbap-2f};
    CHECK(sp_encode_weights(&codec, pair52) == 3753035995369755ull);
}

/* Every path's codes and significant counts for the pairs against the reference. */
static void check_codec(const sp_codec* codec, const float* weights, size_t count, const char* what)
{
    static const sp_isa paths[] = {SP_ISA_SCALAR, SP_ISA_AVX2, SP_ISA_AVX512};
    uint64_t* codes = malloc(count * sizeof(uint64_t));
    uint64_t* expected = malloc(count * sizeof(uint64_t));
    uint8_t* significant = malloc(count);
    for (size_t v = 0; v < count; ++v) expected[v] = reference_small(weights[v * 2], weights[v * 2 + 1], codec->scale);
    for (size_t p = 0; p < sizeof(paths) / sizeof(paths[0]); ++p) {
        CHECK(sp_encode_weights_batch_isa(codec, weights, count, codes, significant, paths[p]) == SP_OK);
        size_t wrong = 0, first = count;
        for (size_t v = 0; v < count; ++v)
            if (codes[v] != expected[v] || significant[v] != (expected[v] ? 2 : 1)) wrong++, first = first < v ? first : v;
        CHECK_MSG(wrong == 0, "%s %s s=%llu isa %d: %zu of %zu off, first (%a, %a): %llu, exact %llu", what,
                  sp_method_name(codec->method), (unsigned long long)codec->scale, (int)paths[p], wrong, count,
                  first < count ? weights[first * 2] : 0.0, first < count ? weights[first * 2 + 1] : 0.0,
                  first < count ? (unsigned long long)codes[first] : 0ull,
                  first < count ? (unsigned long long)expected[first] : 0ull);
    }
    size_t wrong = 0;
    for (size_t v = 0; v < count; ++v) wrong += sp_encode_weights(codec, weights + v * 2) != expected[v];
    CHECK_MSG(wrong == 0, "%s %s s=%llu sp_encode_weights: %zu off", what, sp_method_name(codec->method),
              (unsigned long long)codec->scale, wrong);
    free(codes), free(expected), free(significant);
}

int main(void)
{
    /* OSS at 50..63 bits, the smallest grid past 2^50 (s = 2^50, by spacing), Cube and POT up to
     * the largest grid 2^64 - 1 */
    static const struct {
        sp_method method;
        uint32_t bits, pairs;
    } codecs[] = {{SP_METHOD_OSS, 51, RANDOM_PAIRS}, {SP_METHOD_OSS, 52, RANDOM_PAIRS}, {SP_METHOD_OSS, 56, RANDOM_PAIRS},
                  {SP_METHOD_OSS, 60, RANDOM_PAIRS}, {SP_METHOD_OSS, 63, RANDOM_PAIRS}, {SP_METHOD_OSS, 50, 20000},
                  {SP_METHOD_OSS, 0, 20000},         {SP_METHOD_CUBE, 52, 20000},       {SP_METHOD_CUBE, 64, 50000},
                  {SP_METHOD_POT, 52, 20000},         {SP_METHOD_POT, 63, 50000}};
    float* weights = malloc(RANDOM_PAIRS * 2 * sizeof(float));
    known_cases();
    for (size_t c = 0; c < sizeof(codecs) / sizeof(codecs[0]); ++c) {
        sp_codec codec;
        sp_result r = codecs[c].bits ? sp_codec_from_bits(codecs[c].method, 2, codecs[c].bits, &codec)
                                     : sp_codec_from_spacing(SP_METHOD_OSS, 2, 0x1p-50, &codec);
        CHECK(r == SP_OK && codec.scale >= SP_GRID_DOUBLE_LIMIT);
        if (r != SP_OK) continue;
        CHECK(codecs[c].bits || codec.scale == SP_GRID_DOUBLE_LIMIT);
        rng_state = 0x5EED000000000000ull + c;
        random_pairs(weights, codecs[c].pairs);
        check_codec(&codec, weights, codecs[c].pairs, "random");
        size_t ties = tie_pairs(codec.scale, weights);
        CHECK(ties > 20 || codec.scale % ((uint64_t)1 << 22) == 0); /* s = 2^50: no ties at sums 2^-j */
        check_codec(&codec, weights, ties, "ties");
        size_t near = near_tie_pairs(codec.scale, weights);
        CHECK(near > 20);
        check_codec(&codec, weights, near, "near ties");
        check_codec(&codec, weights, sparse_pairs(codec.scale, weights), "sparse");
        size_t odd_ties = odd_tie_pairs(codec.scale, weights);
        CHECK(odd_ties > 100 || codec.scale % ((uint64_t)1 << 22) == 0); /* s = 2^50: no ties of floats */
        check_codec(&codec, weights, odd_ties, "odd ties");
    }
    free(weights);
    return check_report("test_oss_exact");
}
