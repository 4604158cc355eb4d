/* Private helpers shared by the codec sources. Not part of the public API. */
#ifndef SKINPACK_CODEC_INTERNAL_H
#define SKINPACK_CODEC_INTERNAL_H

#include <string.h> /* memcpy */

#include "skinpack.h"

#include "cpu_features.h"
#if defined(__SSE2__) || defined(_M_X64) || (defined(_M_IX86_FP) && _M_IX86_FP >= 2)
#include <emmintrin.h> /* sp_positive_or_zero */
#endif
#include "platform.h" /* SP_INLINE, sp_u128 (the OSS closed forms overflow 64 bits near 64-bit codes) */

/* Float rounding of the input weights and of the decoded floats, added to every bound. */
#define SP_FLOAT_SLACK 3.6e-7

/* Largest-remainder rounding for any grid and any deficit (the slow, general path). */
void sp_grid_quantize_general(const float* weights, uint32_t k, uint64_t s, uint64_t* q);

/* x > 0 ? x : 0 (NaN and -0 to +0) without a branch: zero weights are common and in no
 * predictable order, and compilers keep the branch for the NaN semantics. MAXSD returns its
 * second operand unless the first is greater, which is exactly this. */
SP_INLINE double sp_positive_or_zero(double x)
{
#if defined(__SSE2__) || defined(_M_X64) || (defined(_M_IX86_FP) && _M_IX86_FP >= 2)
    return _mm_cvtsd_f64(_mm_max_sd(_mm_set_sd(x), _mm_setzero_pd()));
#else
    return x > 0 ? x : 0;
#endif
}

/* Grids below this size take the double-precision rounding (sp_grid_round); larger ones the
 * exact K = 2 rounding (sp_grid_round_pair; no grid of K = 3, 4 codes is this large) or, for odd
 * input, the long double one of sp_grid_quantize_general. */
#define SP_GRID_DOUBLE_LIMIT ((uint64_t)1 << 50)

/* The k weights as doubles in w and the grid scale of the vertex, s / (their sum): a step of its
 * own, so that a batch can run the division of one vertex (the end of a long chain) while it
 * rounds another. The sum starts at weights[0], not 0 + weights[0]: they differ only when every
 * weight is -0, where the scale is -inf instead of +inf and every product 0 * inf is NaN either
 * way. */
SP_INLINE double sp_grid_load(const float* weights, uint32_t k, double s, double* w)
{
    SP_UNROLL for (uint32_t i = 0; i < k; ++i) w[i] = weights[i];
    double sum = w[0];
    SP_UNROLL for (uint32_t i = 1; i < k; ++i) sum += w[i];
    return s / sum;
}

/* Whether the k weights are all finite and >= 0 (-0 not) and not all zero, from the OR of their
 * bits (which is then in [1, 0x7F7FFFFF]; an OR with the exponent field all ones takes weights
 * past 2, so no weight in [0, 1] is turned away): sp_grid_round needs no clamps for them. */
SP_INLINE int sp_grid_plain(const float* weights, uint32_t k)
{
    uint32_t bits = 0;
    SP_UNROLL for (uint32_t i = 0; i < k; ++i) {
        uint32_t weight_bits;
        memcpy(&weight_bits, &weights[i], sizeof(weight_bits));
        bits |= weight_bits;
    }
    return bits - 1 < 0x7F7FFFFFu;
}

/* Floors q and remainders x - q of x = w scale, each x first clamped to [0, s] (NaN to +0)
 * where `clamp`; returns the deficit s - sum q, modulo 2^64. Every remainder is in [+0, 1), never
 * -0 (x is +0 or more: max(x, 0) returns +0 for -0, and plain input has no -0, see
 * sp_grid_round), which sp_grid_bump relies on. */
SP_INLINE uint64_t sp_grid_floor(const double* w, uint32_t k, uint64_t s, double scale, int clamp, uint64_t* q,
                                 double* remainder)
{
    uint64_t deficit = s;
    SP_UNROLL for (uint32_t i = 0; i < k; ++i) {
        double x = w[i] * scale;
        if (clamp) {
            x = sp_positive_or_zero(x);        /* also maps NaN to 0 */
            x = x < (double)s ? x : (double)s; /* degenerate sums: keep the conversion defined */
        }
        int64_t f = (int64_t)x;
        q[i] = (uint64_t)f;
        remainder[i] = x - (double)f;
        deficit -= (uint64_t)f; /* s < 2^50 and each f <= s: wraps only below zero */
    }
    return deficit;
}

/* The deficit d in [0, k) goes, one each, to the d largest remainders (ties to the lower slot),
 * chosen by rank instead of by sorting: rank[i] counts the slots that win before i, where an
 * earlier slot a wins against a later b when its remainder is not smaller. The remainders are
 * compared as integers: doubles in [+0, 1) (sp_grid_floor) order as their bit patterns do, and
 * integer compares feed add-with-carry directly, where double compares (on x86 a transfer to the
 * integer flags each) came out 5% slower for K = 4. */
SP_INLINE void sp_grid_bump(const double* remainder, uint32_t k, uint64_t deficit, uint64_t* q)
{
    uint64_t rank[SP_MAX_INFLUENCES] = {0, 0, 0, 0}, bits[SP_MAX_INFLUENCES] = {0, 0, 0, 0};
    SP_UNROLL for (uint32_t i = 0; i < k; ++i) memcpy(&bits[i], &remainder[i], sizeof(bits[i]));
    SP_UNROLL for (uint32_t a = 0; a < k; ++a)
        SP_UNROLL for (uint32_t b = a + 1; b < k; ++b) {
            rank[a] += bits[a] < bits[b];
            rank[b] += bits[a] >= bits[b];
        }
    SP_UNROLL for (uint32_t i = 0; i < k; ++i) q[i] += rank[i] < deficit;
}

/*
 * Largest-remainder rounding of k weights (sorted, summing to ~1) to integers q summing to s,
 * for grids s < SP_GRID_DOUBLE_LIMIT (double is exact enough), with w and scale from
 * sp_grid_load: floor by conversion, then add one to the d largest remainders (sp_grid_bump).
 * Returns 0, q undefined, where the deficit d is not in [0, k) (degenerate input): the general
 * rounding decides those. Inlined so that callers with a constant k get unrolled code with q in
 * registers.
 * Each x is clamped to [0, s] (NaN to 0) before its conversion, which only changes anything for
 * input that is not sp_grid_plain: for plain input x is in [+0, s (1 + 2^-52)] (each weight is
 * at most the rounded sum), and an x past s floors to s, so that the deficit is 0 (no bump: the
 * remainders are not read) or below 0 (returns 0) with or without the clamp. So plain input,
 * all real input, skips the clamps (12 instructions for K = 4, against 7 for the test).
 */
SP_INLINE int sp_grid_round(const float* weights, const double* w, uint32_t k, uint64_t s, double scale, uint64_t* q)
{
    k = k < SP_MAX_INFLUENCES ? k : SP_MAX_INFLUENCES;
    double remainder[SP_MAX_INFLUENCES] = {0, 0, 0, 0};
    uint64_t deficit;
    if (sp_grid_plain(weights, k)) deficit = sp_grid_floor(w, k, s, scale, 0, q, remainder);
    else deficit = sp_grid_floor(w, k, s, scale, 1, q, remainder);
    if (deficit >= k) return 0;
    sp_grid_bump(remainder, k, deficit, q);
    return 1;
}

/*
 * The two weights of a K = 2 rounding as exact integers: the smaller one is small 2^e, the
 * larger large 2^(e + gap), with 24-bit significands (a denormal's exponent is the smallest
 * normal one's). The smaller is slot 1 where the two are equal; ties_up is 1 where it is slot 0
 * (the tie rule gives a tie to slot 0, so that slot's x rounds half up, slot 1's half down).
 * plain: both finite and >= 0 (-0 counts as 0) and not both zero; the rest is the general
 * rounding's (odd input keeps its results).
 */
typedef struct sp_grid_pair {
    uint64_t small, large;
    uint32_t gap, ties_up, plain;
} sp_grid_pair;

SP_INLINE sp_grid_pair sp_grid_pair_parts(const float* weights)
{
    uint32_t bits0, bits1;
    memcpy(&bits0, &weights[0], sizeof(bits0));
    memcpy(&bits1, &weights[1], sizeof(bits1));
    uint32_t magnitude0 = bits0 & 0x7FFFFFFFu, magnitude1 = bits1 & 0x7FFFFFFFu; /* the order of >= 0 floats */
    sp_grid_pair pair;
    pair.ties_up = magnitude0 < magnitude1;
    uint32_t small = pair.ties_up ? magnitude0 : magnitude1, large = pair.ties_up ? magnitude1 : magnitude0;
    uint32_t small_exponent = small >> 23, large_exponent = large >> 23;
    pair.small = (small & 0x7FFFFFu) | (small_exponent ? 0x800000u : 0);
    pair.large = (large & 0x7FFFFFu) | (large_exponent ? 0x800000u : 0);
    small_exponent += small_exponent == 0, large_exponent += large_exponent == 0; /* denormals: 2^-149 units */
    pair.gap = (large_exponent - small_exponent) * (uint32_t)(small != 0); /* no branch: zero weights are common */
    pair.plain = (uint32_t)(bits0 <= 0x80000000u) & (uint32_t)(bits1 <= 0x80000000u) & /* >= 0 or -0 */
                 (uint32_t)(large < 0x7F800000u) & (uint32_t)(large != 0);
    return pair;
}

/* The largest gap sp_grid_round_pair takes: D < 2^(25 + gap) = 2^60, and its remainders fit 63
 * bits (below). */
#define SP_GRID_PAIR_GAP 35

/*
 * The K = 2 rounding of grids s >= SP_GRID_DOUBLE_LIMIT, exact: x = s small / D for the smaller
 * weight and D = large 2^gap + small (so x <= s/2 < 2^63, and x < 2^(65 - gap) for gap > 0, as
 * the larger weight is then normal) rounded to the nearest integer, ties as sp_grid_pair says;
 * q = (s - that, that). Floor and remainder of s small / D come from x86-64's DIV where it is
 * there (SP_NARROW_DIVIDE: 3.7 against 5.9 ns a vertex); elsewhere from a double estimate f of x
 * (5 roundings: within 2^-50 x + 1 of it), the remainder s small - f D exactly (|r| < (2^(15 -
 * gap) + 2) D < 2^62, so modulo 2^64 is exact), f corrected by r / D in double (within 2^-35 of
 * the truth, so the remainder is then below 1.01 D) and a last +-1 from the exact remainder's
 * comparison with D/2.
 * Returns 0, q untouched, for input that is not plain or has a gap past SP_GRID_PAIR_GAP: the
 * general rounding decides those.
 */
SP_INLINE int sp_grid_round_pair(const float* weights, uint64_t s, uint64_t* q)
{
    sp_grid_pair pair = sp_grid_pair_parts(weights);
    if (!pair.plain || pair.gap > SP_GRID_PAIR_GAP) return 0;
    uint64_t sum = (pair.large << pair.gap) + pair.small, nearest;
#if SP_NARROW_DIVIDE
    uint64_t rest, whole = sp_u128_divide_narrow(sp_u128_mul_u64(sp_u128_from(s), pair.small), sum, &rest);
    nearest = whole + (2 * rest + pair.ties_up > sum);
#else
    double inverse = 1.0 / (double)(int64_t)sum, estimate = (double)(int64_t)pair.small * (double)s * inverse;
    estimate = estimate < 0x1.fffffffffffffp62 ? estimate : 0x1.fffffffffffffp62; /* (int64_t) stays defined */
    int64_t whole = (int64_t)estimate;
    int64_t rest = (int64_t)(s * pair.small - (uint64_t)whole * sum);
    int64_t steps = (int64_t)((double)rest * inverse);
    whole += steps;
    rest -= steps * (int64_t)sum; /* |rest| < 1.01 D */
    int64_t twice = 2 * rest + (int64_t)pair.ties_up, d = (int64_t)sum;
    nearest = (uint64_t)(whole + (twice > d) - (twice <= -d));
#endif
    q[0] = s - nearest;
    q[1] = nearest;
    return 1;
}

/* Largest-remainder rounding of k weights (sorted, summing to ~1) to integers q summing to s:
 * sp_grid_round where it applies, sp_grid_round_pair for K = 2 on larger grids, else the general
 * rounding. */
SP_INLINE void sp_grid_quantize(const float* weights, uint32_t k, uint64_t s, uint64_t* q)
{
    k = k < SP_MAX_INFLUENCES ? k : SP_MAX_INFLUENCES; /* the bound the unrolled loops may rely on */
    if (s < SP_GRID_DOUBLE_LIMIT) {
        double w[SP_MAX_INFLUENCES] = {0, 0, 0, 0};
        double scale = sp_grid_load(weights, k, (double)s, w);
        if (sp_grid_round(weights, w, k, s, scale, q)) return;
    } else if (k == 2 && sp_grid_round_pair(weights, s, q))
        return;
    sp_grid_quantize_general(weights, k, s, q);
}

/* How many leading slots of grid point q carry weight: one past the last non-zero one, so that
 * every slot from there on is zero (don't-care for the tuple table). For the sorted grids that
 * is also the first zero slot. */
static inline uint8_t sp_grid_significant(const uint64_t* q, uint32_t k)
{
    uint8_t count = 1;
    SP_UNROLL for (uint32_t i = 1; i < k; ++i)
        if (q[i] > 0) count = (uint8_t)(i + 1);
    return count;
}

/* Fixed/Cube/POT: pack and unpack the integer grid coordinates q[0..k-1] (q[0] = largest). */
uint64_t sp_grid_pack(const sp_codec* codec, const uint64_t* q);
void sp_grid_unpack(const sp_codec* codec, uint64_t code, uint64_t* q);

/* OSS: simplex index of grid coordinates and back (q[0] is implied by the others). */
uint64_t sp_oss_pack(uint64_t n, uint32_t k, const uint64_t* q);
void sp_oss_unpack(uint64_t n, uint32_t k, uint64_t code, uint64_t* q);

/* The batch forms with a cap on the vector path (SP_ISA_SCALAR: none), so one test binary
 * checks every path the CPU has against the scalar code; the public forms pass SP_ISA_AVX512. */
sp_result sp_encode_weights_batch_isa(const sp_codec* codec, const float* weights, size_t vertex_count,
                                      uint64_t* codes, uint8_t* significant, sp_isa widest);
sp_result sp_decode_weights_batch_isa(const sp_codec* codec, const uint64_t* codes, size_t vertex_count,
                                      float* weights, size_t* error_vertex, sp_isa widest);

/* OSS batch dispatch (codec_oss_batch.c): encode or decode a prefix of the vertices with vector
 * code where the CPU, the cap and the codec allow it, bit-identical to the scalar path; return
 * how many leading vertices were done (0 when not applicable). Decode stops before a block
 * holding a code above max_code, so the scalar loop reports it. */
size_t sp_oss_encode_batch(const sp_codec* codec, const float* weights, size_t count, uint64_t* codes,
                           uint8_t* significant, sp_isa widest);
size_t sp_oss_decode_batch(const sp_codec* codec, const uint64_t* codes, size_t count, float* weights,
                           sp_isa widest);
/* sp_oss_decode_batch with the streaming stores' threshold as an argument (count * K * 4 bytes
 * of weights at least stream_min_bytes, lanes where it pays: streaming stores, after a scalar
 * head of vertices up to a 64-byte aligned output), so the tests take the streaming path on small batches; streamed
 * (may be NULL) gets how many of the vertices done were decoded with streaming stores. */
size_t sp_oss_decode_batch_streaming(const sp_codec* codec, const uint64_t* codes, size_t count, float* weights,
                                     sp_isa widest, size_t stream_min_bytes, size_t* streamed);
/* Whether a vector path takes this codec (its encode and its decode alike) on this CPU with the
 * vector paths capped at `widest`. */
int sp_oss_batch_supported(const sp_codec* codec, sp_isa widest);

/* The per-ISA paths (codec_oss_batch_avx2.c: blocks of 4; codec_oss_batch_avx512.c: blocks of
 * 8), same contract; call only where sp_cpu_isa() has the ISA and the codec is supported. */
size_t sp_oss_encode_avx2(const sp_codec* codec, const float* weights, size_t count, uint64_t* codes,
                          uint8_t* significant);
size_t sp_oss_decode_avx2(const sp_codec* codec, const uint64_t* codes, size_t count, float* weights, int stream);
size_t sp_oss_encode_avx512(const sp_codec* codec, const float* weights, size_t count, uint64_t* codes,
                            uint8_t* significant);
size_t sp_oss_decode_avx512(const sp_codec* codec, const uint64_t* codes, size_t count, float* weights, int stream);

/* The scalar OSS encode (grid rounding, significant count, index; significant may be NULL) and
 * decode (codec_oss.c) of one vertex: what the batch loops and the vector lanes that cannot
 * prove themselves exact use. */
uint64_t sp_oss_encode_one(const sp_codec* codec, const float* weights, uint8_t* significant);
/* The scalar OSS encode of vertices first..count-1 (K = 2..4; significant may be NULL), the
 * rounding and index unrolled per K: what the batch encode runs after the vector prefix. */
void sp_oss_encode_scalar(const sp_codec* codec, const float* weights, size_t first, size_t count, uint64_t* codes,
                          uint8_t* significant);
/* The scalar OSS decode of codes first..count-1 (K = 2..4), inlined per K: returns the index of
 * the first code past the codec's range (weights untouched from there), count if none. */
size_t sp_oss_decode_scalar(const sp_codec* codec, const uint64_t* codes, size_t first, size_t count, float* weights);
void sp_oss_decode_one(const sp_codec* codec, uint64_t code, float* weights);

/* Grid coordinates to weights, q[i] / s rounded once to float: every decoder's last step. */
static inline void sp_grid_to_weights(const uint64_t* q, uint32_t k, uint64_t scale, float* weights)
{
    double inverse = 1.0 / (double)scale;
    for (uint32_t i = 0; i < k; ++i) weights[i] = (float)((double)q[i] * inverse);
}

/* Any AABB works on floats directly (its axes do not share a grid). */
uint64_t sp_any_encode(const sp_codec* codec, const float* weights);
/* Returns w1 in double before rounding: the code is valid iff it is >= 0. */
double sp_any_decode(const sp_codec* codec, uint64_t code, float* weights);

/* Finish a codec description (code_bits, bits, bounds) once method-specific fields are set. */
sp_result sp_any_configure(uint32_t influences, const uint64_t* axis_samples, sp_codec* codec);

/* Format rule shared by sp_validate_packed and sp_decompress_skin: 1 (and the two slots) if a
 * vertex has the same joint in two slots that both carry weight, else 0. */
int sp_find_duplicate_joint(const uint16_t* joints, const float* weights, uint32_t k, uint32_t* slot,
                            uint32_t* other_slot);

/* Number of codes per method and parameter, or 0 when it does not fit in 64 bits. */
sp_u128 sp_oss_code_count(uint64_t n, uint32_t k);

#endif
