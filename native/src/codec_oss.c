/*
 * Optimal Simplex Sampling (Kuth & Meyer, Sec. 4.6 and Appendices A-C).
 *
 * With s = 2(N-1) the sorted weights are q/s; the sheared integers k = q4, j = q3 - q4,
 * i = q2 - q3 index valid tuples only: code = u(k) + s_{N-2k}(j) + i (K = 4),
 * s_N(j) + i (K = 3), i (K = 2). Encode and decode are O(1): decode estimates k and j with
 * the paper's mirrored cube and square roots, then fixes the estimate against the exact
 * integer base indices (the paper's off-by-one fix, done as a bounded search).
 */
#include <math.h>
#include <string.h>

#include "codec_internal.h"

/* Below this N every closed form fits in 64 bits (u(k) < 3N^3), so the fast path is exact. */
#define OSS_SMALL_N ((uint64_t)1 << 20)

/* 64-bit forms for N < OSS_SMALL_N, inlined into the encode and decode paths. */
static inline uint64_t row_base_small(uint64_t n, uint64_t j)
{
    return (4 * j * n + 2 * j + 1 - 3 * j * j) / 4;
}

static inline uint64_t layer_base_small(uint64_t n, uint64_t k)
{
    return (3 * n * k * (n - 2 * k + 3) + k * (4 * k * k - 9 * k + 6) + 2) / 9;
}

uint64_t sp_oss_row_base(uint64_t n, uint64_t j)
{
    /* floor((-3j^2 + 2j + 4jN + 1) / 4); the numerator is positive for rows inside the triangle. */
    if (n < OSS_SMALL_N && j < OSS_SMALL_N) return row_base_small(n, j);
    sp_u128 jj = j, nn = n;
    return (uint64_t)((4 * jj * nn + 2 * jj + 1 - 3 * jj * jj) / 4);
}

uint64_t sp_oss_triangle_count(uint64_t n)
{
    sp_u128 nn = n;
    return (uint64_t)((nn * nn + nn + 1) / 3);
}

uint64_t sp_oss_layer_base(uint64_t n, uint64_t k)
{
    /* floor((3Nk(N - 2k + 3) + k(4k^2 - 9k + 6) + 2) / 9), Appendix C. */
    if (n < OSS_SMALL_N) return layer_base_small(n, k);
    sp_u128 nn = n, kk = k;
    return (uint64_t)((3 * nn * kk * (nn - 2 * kk + 3) + kk * (4 * kk * kk - 9 * kk + 6) + 2) / 9);
}

uint64_t sp_oss_tetrahedron_count(uint64_t n)
{
    return sp_oss_layer_base(n, (n + 1) / 2);
}

sp_u128 sp_oss_code_count(uint64_t n, uint32_t k)
{
    sp_u128 nn = n;
    switch (k) {
    case 1: return 1;
    case 2: return nn;
    case 3: return (nn * nn + nn + 1) / 3;
    case 4: {
        /* u((N+1)/2) in 128 bits: N up to ~2^43 before this overflows, far past 64-bit codes. */
        sp_u128 kk = (nn + 1) / 2;
        return (3 * nn * kk * (nn - 2 * kk + 3) + kk * (4 * kk * kk - 9 * kk + 6) + 2) / 9;
    }
    default: return 0;
    }
}

uint64_t sp_oss_pack(uint64_t n, uint32_t k, const uint64_t* q)
{
    if (n < OSS_SMALL_N && k == 4) {
        uint64_t layer = q[3];
        return layer_base_small(n, layer) + row_base_small(n - 2 * layer, q[2] - q[3]) + (q[1] - q[2]);
    }
    switch (k) {
    case 2: return q[1];
    case 3: return sp_oss_row_base(n, q[2]) + (q[1] - q[2]);
    case 4: {
        uint64_t layer = q[3];
        return sp_oss_layer_base(n, layer) + sp_oss_row_base(n - 2 * layer, q[2] - q[3]) + (q[1] - q[2]);
    }
    default: return 0;
    }
}

/* Largest row j with s_N(j) <= w. Estimate from the mirrored square root:
 * s~(j*) - s~(j) = 3/4 (j* - j)^2 with j* = (2N+1)/3, and 12(s~(j*) - w) = (2N+1)^2 + 3 - 12w
 * exactly, so j~ = (2N + 1 - sqrt((2N+1)^2 + 3 - 12w)) / 3. (The paper prints "+ sqrt"; the
 * relevant root is the one left of the apex.) */
static uint64_t oss_find_row(uint64_t n, uint64_t w)
{
    uint64_t rows = (2 * n + 1) / 3;
    double mirrored, apex;
    if (n < OSS_SMALL_N) {
        uint64_t two_n1 = 2 * n + 1;
        mirrored = (double)(int64_t)(two_n1 * two_n1 + 3 - 12 * w);
        apex = (double)two_n1;
    } else {
        sp_u128 two_n1 = 2 * (sp_u128)n + 1;
        mirrored = (double)(two_n1 * two_n1 + 3 - 12 * (sp_u128)w);
        apex = (double)two_n1;
    }
    double estimate = (apex - sqrt(mirrored)) / 3.0;
    uint64_t j = estimate <= 0 ? 0 : (uint64_t)estimate;
    if (j >= rows) j = rows - 1;
    if (n < OSS_SMALL_N) {
        while (j + 1 < rows && row_base_small(n, j + 1) <= w) ++j;
        while (j > 0 && row_base_small(n, j) > w) --j;
        return j;
    }
    while (j + 1 < rows && sp_oss_row_base(n, j + 1) <= w) ++j;
    while (j > 0 && sp_oss_row_base(n, j) > w) --j;
    return j;
}

/* Largest layer k with u(k) <= code. With M = N + 1, 72(u~((N+1)/2) - code) equals
 * V = 4M^3 + 6M^2 + 16 - 72 code exactly, and the paper's root is
 * k~ = (2N + 3 - (c + 1/c)) / 4 with c = cbrt(V - 1 + sqrt(V (V - 2))). */
/* Cube root of x >= 1 to ~1e-12: exponent/3 bit trick, then three Newton steps. The layer
 * search below only needs the estimate to within a layer, and libm's cbrt costs ~4x more. */
static inline double cube_root(double x)
{
    uint64_t bits;
    double y;
    memcpy(&bits, &x, sizeof(bits));
    bits = bits / 3 + 0x2A9F7893782DA1CEull;
    memcpy(&y, &bits, sizeof(y));
    for (int i = 0; i < 3; ++i) y -= (y * y * y - x) / (3 * y * y);
    return y;
}

static uint64_t oss_find_layer(uint64_t n, uint64_t code)
{
    uint64_t layers = (n + 1) / 2;
    double v;
    if (n < OSS_SMALL_N) { /* everything below 2^63: no 128-bit conversions */
        uint64_t m = n + 1;
        v = (double)(int64_t)(4 * m * m * m + 6 * m * m + 16 - 72 * code);
    } else {
        sp_u128 m = (sp_u128)n + 1;
        v = (double)(4 * m * m * m + 6 * m * m + 16 - 72 * (sp_u128)code);
    }
    double root = v > 2 ? sqrt(v * (v - 2)) : 0;
    double c = n < OSS_SMALL_N ? cube_root(v - 1 + root) : cbrt(v - 1 + root);
    if (c < 1) c = 1;
    double estimate = (2.0 * (double)n + 3.0 - (c + 1.0 / c)) / 4.0;
    uint64_t k = estimate <= 0 ? 0 : (uint64_t)estimate;
    if (k >= layers) k = layers - 1;
    if (n < OSS_SMALL_N) {
        while (k + 1 < layers && layer_base_small(n, k + 1) <= code) ++k;
        while (k > 0 && layer_base_small(n, k) > code) --k;
        return k;
    }
    while (k + 1 < layers && sp_oss_layer_base(n, k + 1) <= code) ++k;
    while (k > 0 && sp_oss_layer_base(n, k) > code) --k;
    return k;
}

void sp_oss_unpack(uint64_t n, uint32_t k, uint64_t code, uint64_t* q)
{
    uint64_t layer = 0, row, rest = code, bottom = n;
    if (k == 2) {
        q[1] = code;
        q[0] = 2 * (n - 1) - code;
        return;
    }
    if (k == 4) {
        layer = oss_find_layer(n, code);
        rest -= sp_oss_layer_base(n, layer); /* inlined small form for small N */
        bottom = n - 2 * layer;
    }
    row = oss_find_row(bottom, rest);
    uint64_t i = rest - sp_oss_row_base(bottom, row);
    if (k == 4) q[3] = layer;
    q[2] = row + layer;
    q[1] = i + row + layer;
    q[0] = 2 * (n - 1) - q[1] - q[2] - (k == 4 ? q[3] : 0);
}
