/*
 * Grid codecs: Fixed, Unit Cube and POT AABB, plus the largest-remainder rounding they share
 * with OSS. All four place the weights on the integer grid q/s with q summing to s, so the
 * decoded tuple is sorted, non-negative and sums to exactly one.
 */
#include <float.h>
#include <string.h>

#include "codec_internal.h"

#if (defined(__x86_64__) || defined(__i386__)) && LDBL_MANT_DIG == 64
/* The double of a 64-bit fraction f 2^-64, rounded to nearest: a 63-bit integer converts exactly
 * rounded; a 64-bit one as its top 63 bits with the last one sticky (the dropped bit lies below
 * the rounding point). Selects, no branch on the top bit. */
SP_INLINE double fraction_to_double(uint64_t fraction)
{
    static const double unit[2] = {0x1p-64, 0x1p-63};
    uint64_t top = fraction >> 63, pick = (uint64_t)0 - top;
    uint64_t integer = (fraction & ~pick) | (((fraction >> 1) | (fraction & 1)) & pick);
    return (double)(int64_t)integer * unit[top];
}
#endif

/* Slot order by descending remainder, ties to the lower slot (stable insertion sort). */
SP_INLINE void order_by_remainder(const double* remainder, uint32_t k, uint32_t* order)
{
    for (uint32_t i = 0; i < k; ++i) {
        uint32_t j = i;
        while (j > 0 && remainder[order[j - 1]] < remainder[i]) {
            order[j] = order[j - 1];
            --j;
        }
        order[j] = i;
    }
}

/*
 * floor(min(x, limit)) of a long double x >= 0 or NaN (NaN to 0), and the remainder min(x, limit)
 * - floor rounded to double; long double keeps all 64 bits of large grids. Where long double is
 * the x87 80-bit format: x = significand 2^(e - 63) with an explicit 64-bit significand, so
 * floor(x) is the significand shifted right by 63 - e (0 for x < 1, e < 0) and the remainder its
 * bits below that, the fraction significand << (e + 1). The x87 is left as soon as x is made, as
 * each of its usual steps stalls it: C's conversion switches its rounding mode twice
 * (fnstcw/fldcw), reading the exponent from the 80-bit value's last two bytes waits for the
 * store (the load is not forwarded), and its compares and conditional moves for the clamp are
 * slow. So e comes from the double of x (an 8-byte store, which is forwarded), whose exponent is
 * e, or e + 1 where x rounds up to a power of two (then the double's fraction bits are 0 and the
 * significand is all ones at the top, bit 62 set); the double is also the remainder of x < 1;
 * and the clamp compares the integers. Masks and selects, not branches: zero weights (x = 0)
 * come in no predictable order.
 */
SP_INLINE uint64_t floor_clamped(long double x, uint64_t limit, double* remainder)
{
#if (defined(__x86_64__) || defined(__i386__)) && LDBL_MANT_DIG == 64
    uint64_t significand, bits;
    double rounded = (double)x;
    memcpy(&significand, &x, sizeof(significand)); /* little endian: the significand first */
    memcpy(&bits, &rounded, sizeof(bits));
    uint64_t fraction_bits = bits & (((uint64_t)1 << 52) - 1), exponent_bits = (bits >> 52) & 0x7FF; /* NaN may be signed */
    uint64_t not_a_number = (uint64_t)(exponent_bits == 0x7FF) & (uint64_t)(fraction_bits != 0);
    uint64_t rounded_up = (uint64_t)(fraction_bits == 0) & (uint64_t)(significand >> 62 == 3);
    int e = (int)exponent_bits - 1023 - (int)rounded_up; /* x >= 2^64 (or infinite) for e > 63 */
    uint32_t in_range = (uint32_t)(e >= 0) & (uint32_t)(e <= 63);
    uint64_t whole_mask = (uint64_t)0 - in_range;
    uint64_t whole = (significand >> ((uint32_t)(63 - e) & 63)) & whole_mask;
    uint64_t fraction = (significand << ((uint32_t)(e + 1) & 63)) & whole_mask & ((uint64_t)0 - (uint64_t)(e < 63));
    uint64_t over = (uint64_t)(e > 63) | (uint64_t)(whole > limit) | ((uint64_t)(whole == limit) & (uint64_t)(fraction != 0));
    double below_one = e < 0 ? rounded : 0.0, fraction_value = fraction_to_double(fraction);
    uint64_t value_bits, small_bits;
    memcpy(&value_bits, &fraction_value, sizeof(value_bits));
    memcpy(&small_bits, &below_one, sizeof(small_bits));
    value_bits = (value_bits | small_bits) & ((uint64_t)0 - ((over | not_a_number) ^ 1)); /* x > limit: limit, remainder 0 */
    memcpy(remainder, &value_bits, sizeof(value_bits));
    return (whole ^ ((whole ^ limit) & ((uint64_t)0 - over))) & ((uint64_t)0 - (not_a_number ^ 1));
#else
    long double top = (long double)limit;
    x = x > 0 ? x : 0;
    x = x < top ? x : top;
    uint64_t f = (uint64_t)x;
    *remainder = (double)(x - (long double)f);
    return f;
#endif
}

/* floor_clamped(weight scale): the weight clamped at 0 first (negative and NaN weights to 0, in
 * SSE), so that the product is >= 0 or NaN (an infinite weight over an infinite sum) for a
 * scale >= 0, as floor_clamped needs. */
SP_INLINE uint64_t floor_product(float weight, long double scale, uint64_t limit, double* remainder)
{
    return floor_clamped((long double)sp_positive_or_zero(weight) * scale, limit, remainder);
}

/* General rounding: any grid size, any deficit (also the rare wrap-around of huge grids). */
SP_INLINE void quantize_general(const float* weights, uint32_t k, uint64_t s, uint64_t* q)
{
    double remainder[SP_MAX_INFLUENCES];
    uint32_t order[SP_MAX_INFLUENCES];
    double sum = 0;
    for (uint32_t i = 0; i < k; ++i) sum += weights[i];
    if (!(sum > 0)) sum = 1;

    sp_u128 total = sp_u128_from(0), grid = sp_u128_from(s);
    long double scale = (long double)s / (long double)sum;
    for (uint32_t i = 0; i < k; ++i) {
        q[i] = floor_product(weights[i], scale, s, &remainder[i]);
        total = sp_u128_add_u64(total, q[i]);
    }
    order_by_remainder(remainder, k, order);
    /* The deficit is 0..k-1 for proper input; degenerate input (a sum of zero or rounding of
     * huge grids) is settled in bulk, never one grid step at a time. */
    if (sp_u128_less(total, grid)) {
        uint64_t deficit = sp_u128_low(sp_u128_sub(grid, total));
        for (uint32_t i = 0; i < k; ++i) q[i] += deficit / k;
        for (uint32_t t = 0; t < deficit % k; ++t) q[order[t]]++;
    }
    for (uint32_t t = 0; sp_u128_less(grid, total) && t < k; ++t) { /* smallest remainders give back first */
        uint32_t slot = order[k - 1 - t];
        sp_u128 excess = sp_u128_sub(total, grid); /* < 4s: the low half unless s is near 2^64 */
        uint64_t take = sp_u128_high(excess) || sp_u128_low(excess) >= q[slot] ? q[slot] : sp_u128_low(excess);
        q[slot] -= take;
        total = sp_u128_sub(total, sp_u128_from(take));
    }
    /* Keep descending order even where the rounding loops above had to wrap around. */
    for (uint32_t i = 1; i < k; ++i)
        for (uint32_t j = i; j > 0 && q[j - 1] < q[j]; --j) {
            uint64_t t = q[j];
            q[j] = q[j - 1];
            q[j - 1] = t;
        }
}

/* quantize_general for k = 2, what odd input (not plain, see sp_grid_pair; its results are kept
 * as they were) takes on every grid, and any input on grids below SP_GRID_DOUBLE_LIMIT: the same
 * floors, and for a deficit d (s - q0 - q1 >= 0) the same d/2 each and the odd one to the larger
 * remainder (ties to slot 0), as selects. A sum past s (degenerate input) takes the general code. */
SP_INLINE void quantize_pair(const float* weights, uint64_t s, uint64_t* q)
{
    double remainder[2], sum = 0;
    sum += weights[0]; /* the general code's order of additions */
    sum += weights[1];
    if (!(sum > 0)) sum = 1;
    long double scale = (long double)s / (long double)sum;
    uint64_t q0 = floor_product(weights[0], scale, s, &remainder[0]);
    uint64_t q1 = floor_product(weights[1], scale, s, &remainder[1]);
    if (q0 > s - q1) { /* q0 + q1 > s (q1 <= s) */
        quantize_general(weights, 2, s, q);
        return;
    }
    uint64_t deficit = s - q0 - q1, odd = deficit & 1, to_second = remainder[0] < remainder[1];
    q0 += deficit / 2 + (odd & (to_second ^ 1));
    q1 += deficit / 2 + (odd & to_second);
    q[0] = q0 > q1 ? q0 : q1; /* descending, as the general code's final sort */
    q[1] = q0 > q1 ? q1 : q0;
}

/* sp_grid_round_pair's exact rounding for plain pairs of any gap, in 128 bits: a gap past 66
 * puts x below 1/4 (x < s small / (large 2^gap) < 2^64 2^24 / 2^(23 + gap), the larger weight
 * being normal), else D < 2^91 and s small < 2^88, floor and remainder by division. Past a gap of
 * 23 no x is a tie (that needs the two weights' lowest set bits at the same place, large's is at
 * least gap places up), so the tie rule only matters in sp_grid_round_pair. Returns 0 for input
 * that is not plain. */
static int quantize_pair_exact(const float* weights, uint64_t s, uint64_t* q)
{
    sp_grid_pair pair = sp_grid_pair_parts(weights);
    if (!pair.plain) return 0;
    uint64_t nearest = 0;
    if (pair.gap <= 66) {
        sp_u128 sum = sp_u128_add_u64(sp_u128_mul_u64(sp_u128_pow2(pair.gap), pair.large), pair.small);
        sp_u128 product = sp_u128_mul_u64(sp_u128_from(s), pair.small);
        sp_u128 whole = sp_u128_div(product, sum), rest = sp_u128_sub(product, sp_u128_mul(whole, sum));
        sp_u128 twice = sp_u128_add_u64(sp_u128_add(rest, rest), pair.ties_up);
        nearest = sp_u128_low(whole) + (uint64_t)sp_u128_less(sum, twice);
    }
    q[0] = s - nearest;
    q[1] = nearest;
    return 1;
}

void sp_grid_quantize_general(const float* weights, uint32_t k, uint64_t s, uint64_t* q)
{
    if (k != 2) quantize_general(weights, k, s, q);
    else if (s < SP_GRID_DOUBLE_LIMIT || !quantize_pair_exact(weights, s, q)) quantize_pair(weights, s, q);
}

/* Stored components: Fixed stores q[0..k-1], Cube and POT q[1..k-1]. */
static uint32_t first_stored(const sp_codec* codec)
{
    return codec->method == SP_METHOD_FIXED ? 0 : 1;
}

uint64_t sp_grid_pack(const sp_codec* codec, const uint64_t* q)
{
    uint64_t code = 0;
    uint32_t shift = 0;
    for (uint32_t i = first_stored(codec), c = 0; i < codec->influences; ++i, ++c) {
        if (shift < 64) code |= q[i] << shift;
        shift += codec->component_bits[c];
    }
    return code;
}

void sp_grid_unpack(const sp_codec* codec, uint64_t code, uint64_t* q)
{
    uint32_t shift = 0;
    uint64_t rest = codec->scale;
    for (uint32_t i = first_stored(codec), c = 0; i < codec->influences; ++i, ++c) {
        uint32_t bits = codec->component_bits[c];
        uint64_t mask = bits >= 64 ? ~(uint64_t)0 : (((uint64_t)1 << bits) - 1);
        q[i] = shift < 64 ? (code >> shift) & mask : 0;
        shift += bits;
        if (i > 0) rest = rest >= q[i] ? rest - q[i] : 0;
    }
    /* Cube/POT drop the largest weight: it is whatever the grid has left (0 for the invalid
     * tuples of the AABB corners, which no encoder writes and the validating decode rejects). */
    if (codec->method != SP_METHOD_FIXED) q[0] = rest;
}
