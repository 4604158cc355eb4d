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

/* Below OSS_SMALL_N the decoder's layer root argument 8(N + 1)^3 + ... is exact in 64 bits;
 * below OSS_ROW64_N so is its row root argument (2N + 1)^2 + 3 - 12w < 2^62. Below OSS_ROW64_N
 * and OSS_LAYER64_N the closed forms' numerators fit in 64 bits, so the 64-bit forms are exact:
 * 4jN + 2j + 1 < 2^62 + 2^31 for rows j, N < 2^30; 3Nk(N - 2k + 3) <= 3N^3/8 and
 * k(4k^2 - 9k + 6) < 4k^3 for layers k <= (N + 1)/2, below 2^63 for N < 2^21. */
#define OSS_SMALL_N ((uint64_t)1 << 20)
#define OSS_ROW64_N ((uint64_t)1 << 30)
#define OSS_LAYER64_N ((uint64_t)1 << 21)

/* 64-bit forms for N below OSS_ROW64_N and OSS_LAYER64_N, inlined into the encode and decode
 * paths. */
static inline uint64_t row_base_small(uint64_t n, uint64_t j)
{
    return (4 * j * n + 2 * j + 1 - 3 * j * j) / 4;
}

static inline uint64_t layer_base_small(uint64_t n, uint64_t k)
{
    return (3 * n * k * (n - 2 * k + 3) + k * (4 * k * k - 9 * k + 6) + 2) / 9;
}

/* floor(a / d) for a small constant d and a quotient below 2^64, without a 128-bit division:
 * with a = h 2^64 + l and 2^64 = d Q + r, a / d = h Q + floor(l / d) + floor((h r + l mod d) / d). */
SP_INLINE uint64_t u128_div_small(sp_u128 a, uint64_t d)
{
    uint64_t q = UINT64_MAX / d, r = UINT64_MAX % d + 1;
    if (r == d) q += 1, r = 0;
    uint64_t h = sp_u128_high(a), l = sp_u128_low(a);
    return h * q + l / d + (h * r + l % d) / d;
}

/* 9 u(k) + (9 u(k)'s remainder): 3Nk(N - 2k + 3) + k(4k^2 - 9k + 6) + 2 in 128 bits,
 * k <= (N + 1)/2 (so N - 2k + 3 > 0; 4k^2 - 9k + 6 > 0 for every k). */
static sp_u128 layer_numerator(uint64_t n, uint64_t k)
{
    sp_u128 nn = sp_u128_from(n), kk = sp_u128_from(k);
    sp_u128 width = sp_u128_sub(sp_u128_add_u64(nn, 3), sp_u128_mul_u64(kk, 2)); /* N - 2k + 3 */
    sp_u128 outer = sp_u128_mul(sp_u128_mul_u64(sp_u128_mul(nn, kk), 3), width);
    sp_u128 inner = sp_u128_add_u64(sp_u128_mul(sp_u128_sub(sp_u128_mul_u64(kk, 4), sp_u128_from(9)), kk), 6);
    return sp_u128_add_u64(sp_u128_add(outer, sp_u128_mul(kk, inner)), 2);
}

uint64_t sp_oss_row_base(uint64_t n, uint64_t j)
{
    /* floor((-3j^2 + 2j + 4jN + 1) / 4); the numerator is positive for rows inside the triangle. */
    if (n < OSS_ROW64_N && j < OSS_ROW64_N) return row_base_small(n, j);
    /* (4N + 2 - 3j) j + 1, positive inside the triangle */
    sp_u128 slope = sp_u128_sub(sp_u128_add_u64(sp_u128_mul_u64(sp_u128_from(n), 4), 2), sp_u128_mul_u64(sp_u128_from(j), 3));
    sp_u128 numerator = sp_u128_add_u64(sp_u128_mul_u64(slope, j), 1);
    return u128_div_small(numerator, 4);
}

uint64_t sp_oss_triangle_count(uint64_t n)
{
    return sp_u128_low(sp_oss_code_count(n, 3));
}

uint64_t sp_oss_layer_base(uint64_t n, uint64_t k)
{
    /* floor((3Nk(N - 2k + 3) + k(4k^2 - 9k + 6) + 2) / 9), Appendix C. */
    if (n < OSS_LAYER64_N) return layer_base_small(n, k);
    if (n < OSS_ROW64_N) { /* 3Nk < 2^61 and 4k^2 - 9k + 6 < 2^60 in 64 bits: two 64 x 64-bit products */
        sp_u128 outer = sp_u128_mul(sp_u128_from(3 * n * k), sp_u128_from(n - 2 * k + 3));
        sp_u128 inner = sp_u128_mul(sp_u128_from(k), sp_u128_from(4 * k * k - 9 * k + 6));
        return u128_div_small(sp_u128_add_u64(sp_u128_add(outer, inner), 2), 9);
    }
    return u128_div_small(layer_numerator(n, k), 9);
}

uint64_t sp_oss_tetrahedron_count(uint64_t n)
{
    return sp_oss_layer_base(n, (n + 1) / 2);
}

sp_u128 sp_oss_code_count(uint64_t n, uint32_t k)
{
    switch (k) {
    case 1: return sp_u128_from(1);
    case 2: return sp_u128_from(n);
    case 3: { /* (N^2 + N + 1) / 3 */
        sp_u128 nn = sp_u128_from(n);
        return sp_u128_div_u64(sp_u128_add_u64(sp_u128_mul(nn, sp_u128_add_u64(nn, 1)), 1), 3);
    }
    case 4: /* u((N+1)/2), whose numerator fits 128 bits for N < 2^42, far past 64-bit codes */
        return n < ((uint64_t)1 << 42) ? sp_u128_div_u64(layer_numerator(n, n / 2 + (n & 1)), 9) : sp_u128_from(0);
    default: return sp_u128_from(0);
    }
}

/* The index of grid point q, inlined into the batch encoder below with a constant k: the 64-bit
 * closed forms wherever they are exact, the 128-bit ones (no 128-bit division) past them. */
SP_INLINE uint64_t oss_pack(uint64_t n, uint32_t k, const uint64_t* q)
{
    switch (k) {
    case 2: return q[1];
    case 3: return (n < OSS_ROW64_N ? row_base_small(n, q[2]) : sp_oss_row_base(n, q[2])) + (q[1] - q[2]);
    case 4: {
        uint64_t layer = q[3], bottom = n - 2 * layer, row = q[2] - q[3];
        uint64_t layer_base = n < OSS_LAYER64_N ? layer_base_small(n, layer) : sp_oss_layer_base(n, layer);
        uint64_t row_base = n < OSS_ROW64_N ? row_base_small(bottom, row) : sp_oss_row_base(bottom, row);
        return layer_base + row_base + (q[1] - q[2]);
    }
    default: return 0;
    }
}

uint64_t sp_oss_pack(uint64_t n, uint32_t k, const uint64_t* q)
{
    return oss_pack(n, k, q);
}

/* The index of sorted grid coordinates for N below OSS_ROW64_N, with the codec's constants taken
 * out of the closed forms: u(k) in Horner form ((4k - 6N - 9) k + 3N^2 + 9N + 6) k + 2 over 9
 * and s_b(j) for the row's bottom b = N - 2k as ((4N + 2 - 8k - 3j) j + 1) / 4, both modulo
 * 2^64 (negative intermediates wrap and come back). The row's numerator fits 64 bits (see the
 * 64-bit forms above), so its floor is exact. So is the layer's below OSS_LAYER64_N (form
 * OSS_FORM_64); past it (OSS_FORM_MODULAR) the numerator a wraps, but u(k) < 2^64 (the code
 * count of a codec is at most 2^64), so u(k) = (a - a mod 9) / 9 is an exact division, which
 * modulo 2^64 is the product with 9's inverse, and a mod 9 depends on k only through k mod 3
 * (layer_remainder; as the wide vector lanes do it, codec_oss_wide_simd.h). That holds for the
 * layers of the tetrahedron, k <= (N + 1)/2; past them (q not sorted, the rounding of unsorted
 * weights) the index is sp_oss_layer_base's, as oss_pack's, whatever it wraps to. For K = 3 past
 * OSS_ROW64_N (also OSS_FORM_MODULAR) the row base is s_N(j) = j (N - j) + floor((j + 1)^2 / 4)
 * (the numerator is 4j (N - j) + (j + 1)^2) modulo 2^64: for every j, past the triangle too,
 * what sp_oss_row_base gives, the floor by 4 of the same numerator modulo 2^128, taken modulo
 * 2^64 (2^128 / 4 is a multiple of 2^64). K = 4 grids (N < 2^23) never need it. */
typedef struct oss_pack_form {
    uint64_t n, layer_linear, layer_constant, row_constant; /* N, -(6N + 9), 3N^2 + 9N + 6, 4N + 2 */
    uint64_t layer_remainder[3]; /* u(k)'s numerator mod 9 for k mod 3 = 0, 1, 2 */
} oss_pack_form;

/* How the encoder's index is computed: oss_pack (128-bit forms past the 64-bit ones), or
 * oss_pack_small with the 64-bit numerators' floors or with the modulo 2^64 forms. */
enum { OSS_FORM_GENERAL, OSS_FORM_64, OSS_FORM_MODULAR };

/* 9 u mod 2^64 -> u: 9 * OSS_INVERSE_OF_9 = 1 mod 2^64. */
#define OSS_INVERSE_OF_9 0x8E38E38E38E38E39ull

static oss_pack_form pack_form(uint64_t n)
{
    oss_pack_form form = {n, (uint64_t)0 - (6 * n + 9), 3 * n * n + 9 * n + 6, 4 * n + 2, {0, 0, 0}};
    /* 3Nk(N - 2k + 3) + k(4k^2 - 9k + 6) + 2 mod 9: the first term is 3 times something taken
     * mod 3 (N mod 3 and k mod 3 decide it), the second 4k^3 + 6k mod 9, and (k + 3)^3 = k^3
     * mod 9. */
    uint64_t n3 = n % 3;
    for (uint64_t k = 0; k < 3; ++k)
        form.layer_remainder[k] = (3 * (n3 * k * (n3 + 6 - 2 * k) % 3) + k * (4 * k * k + 6) + 2) % 9;
    return form;
}

SP_INLINE uint64_t oss_pack_small(const oss_pack_form* form, uint32_t k, const uint64_t* q, int modular)
{
    if (k == 2) return q[1];
    uint64_t layer = k == 4 ? q[3] : 0, row = q[2] - layer, row_base;
    if (k == 4 || !modular) row_base = ((form->row_constant - 8 * layer - 3 * row) * row + 1) / 4;
    else row_base = row * (form->n - row) + ((row + 1) >> 1) * ((row + 2) >> 1);
    uint64_t layer_base = 0;
    if (k == 4) {
        uint64_t numerator = ((4 * layer + form->layer_linear) * layer + form->layer_constant) * layer + 2;
        if (!modular) layer_base = numerator / 9;
        else if (layer <= (form->n + 1) / 2) layer_base = (numerator - form->layer_remainder[layer % 3]) * OSS_INVERSE_OF_9;
        else layer_base = sp_oss_layer_base(form->n, layer); /* unsorted q: as oss_pack wraps */
    }
    return layer_base + row_base + (q[1] - q[2]);
}

/* One vertex of oss_encode_listed: w and scale are its weights as doubles and its grid scale
 * (sp_grid_load), loaded a vertex before; loads those of `next_vertex` (the next vertex to
 * encode, or its own weights again for the last) into next and returns their scale. The grid s
 * comes as a value (also as a double), not read through codec, which the stores to codes might
 * alias. */
SP_INLINE double oss_encode_vertex(const sp_codec* codec, const oss_pack_form* form, uint64_t s, double grid,
                                   const float* weights, size_t v, const float* next_vertex, const double* w,
                                   double scale, double* next, uint64_t* codes, uint8_t* significant, uint32_t k,
                                   int form_kind)
{
    const float* vertex = weights + v * k;
    double next_scale = sp_grid_load(next_vertex, k, grid, next);
    uint64_t q[SP_MAX_INFLUENCES];
    if (!sp_grid_round(vertex, w, k, s, scale, q)) {
        codes[v] = sp_oss_encode_one(codec, vertex, significant ? significant + v : NULL);
        return next_scale;
    }
    if (significant) significant[v] = sp_grid_significant(q, k);
    codes[v] = form_kind == OSS_FORM_GENERAL ? oss_pack(form->n, k, q)
                                             : oss_pack_small(form, k, q, form_kind == OSS_FORM_MODULAR);
    return next_scale;
}

/*
 * One-weight vertices, (w0, +0, ..., +0) with w0 finite and > 0: half of a rig's vertices (the
 * paper's mix has 51 %), all with one code. The general rounding gives each q = (s, 0, ..., 0):
 * the sum is w0, the scale s / w0 and x0 = w0 (s / w0) is s within two roundings, so it floors
 * to s (deficit 0) or to s - 1 with the only remainder above +0 (deficit 1, given to slot 0);
 * every other x is +0 * scale = +0. So a chunk of the scalar encoder first writes that code to
 * every vertex and lists the others, which it then encodes, and a chunk of the decoder writes
 * that code's weights and decodes the other codes: no per-vertex branch, which would mispredict
 * where one- and many-weight vertices mix.
 */
#define ONE_WEIGHT_CHUNK 256

/* The listing costs about a sixth of a many-weight vertex's encode, so it pays where more than
 * ~1/5 of a chunk's vertices have one weight. After a chunk with fewer than 1/4 the next
 * ONE_WEIGHT_SKIP chunks go unlisted (their one-weight vertices take the general path, with the
 * same result): a mesh without one-weight vertices lists one chunk in ONE_WEIGHT_SKIP + 1 and
 * encodes up to ~6 % slower than without the shortcut, one of the paper's mix (51 %) 1.3-1.5x
 * faster to encode and 1.5-2.2x to decode (K = 3, 4; docs/benchmarks.md, session 14). */
#define ONE_WEIGHT_SKIP 7

SP_INLINE size_t oss_chunks_to_skip(size_t ones, size_t size)
{
    return ones * 4 < size ? ONE_WEIGHT_SKIP : 0;
}

/* Entry i of the list of a chunk's other vertices, or i where nothing was listed (others NULL,
 * a constant once inlined: the loops then run over the chunk as they did before the shortcut). */
SP_INLINE size_t oss_listed_at(const uint32_t* others, size_t i)
{
    return others ? others[i] : i;
}

/* 1 unless the vertex is a one-weight vertex (above): w0 passes sp_grid_plain and the other
 * weights' bits are all 0. */
SP_INLINE size_t oss_not_one_weight(const float* vertex, uint32_t k)
{
    uint32_t rest = 0;
    SP_UNROLL for (uint32_t i = 1; i < k; ++i) {
        uint32_t bits;
        memcpy(&bits, &vertex[i], sizeof(bits));
        rest |= bits;
    }
    return (size_t)((rest != 0) | !sp_grid_plain(vertex, 1));
}

/* The code of a one-weight vertex and its count of significant weights. */
static uint64_t oss_one_weight_code(const sp_codec* codec, uint8_t* significant)
{
    const float one[SP_MAX_INFLUENCES] = {1, 0, 0, 0};
    return sp_oss_encode_one(codec, one, significant);
}

/* Vertices first..end-1: the one-weight code into every one, the others' indices (from first)
 * into `others`; returns how many those are. */
SP_INLINE size_t oss_list_others(const float* weights, size_t first, size_t end, uint32_t k, uint64_t one_code,
                                 uint8_t one_significant, uint64_t* codes, uint8_t* significant, uint32_t* others)
{
    size_t listed = 0;
    if (significant) memset(significant + first, one_significant, end - first);
    for (size_t v = first; v < end; ++v) {
        others[listed] = (uint32_t)(v - first);
        listed += oss_not_one_weight(weights + v * k, k);
        codes[v] = one_code;
    }
    return listed;
}

/* The vertices oss_listed_at(others, 0..listed-1) of a chunk (its weights, codes and counts at
 * `weights`, `codes`, `significant`), software-pipelined: each vertex's weights are loaded and
 * its grid scale divided one vertex ahead, so that the division (the end of a long chain)
 * overlaps the previous vertex's rounding and index, and the weights are converted to double
 * once; two vertices a turn, so that the two sets of loaded weights take turns in registers
 * instead of being copied. */
SP_INLINE void oss_encode_listed(const sp_codec* codec, const oss_pack_form* form, const float* weights,
                                 const uint32_t* others, size_t listed, uint64_t* codes, uint8_t* significant,
                                 uint32_t k, int form_kind)
{
    uint64_t s = codec->scale;
    double grid = (double)s;
    double even[SP_MAX_INFLUENCES], odd[SP_MAX_INFLUENCES];
    double even_scale = sp_grid_load(weights + oss_listed_at(others, 0) * k, k, grid, even), odd_scale;
    for (size_t i = 0; i < listed; i += 2) {
        const float* next = weights + oss_listed_at(others, i + 1 < listed ? i + 1 : i) * k;
        odd_scale = oss_encode_vertex(codec, form, s, grid, weights, oss_listed_at(others, i), next, even,
                                      even_scale, odd, codes, significant, k, form_kind);
        if (i + 1 == listed) break;
        next = weights + oss_listed_at(others, i + 2 < listed ? i + 2 : i + 1) * k;
        even_scale = oss_encode_vertex(codec, form, s, grid, weights, oss_listed_at(others, i + 1), next, odd,
                                       odd_scale, even, codes, significant, k, form_kind);
    }
}

/* The vertices first..count-1 with k constant, so the rounding and the index unroll into
 * straight-line code with q in registers: the index in the given OSS_FORM_*. Vertices the
 * double rounding does not settle take sp_oss_encode_one. Per chunk, the one-weight vertices
 * take their code at once (above) and the others are encoded by oss_encode_listed. */
SP_INLINE void oss_encode_chunks(const sp_codec* codec, const float* weights, size_t first, size_t count,
                                 uint64_t* codes, uint8_t* significant, uint32_t k, int form_kind)
{
    oss_pack_form form = pack_form(codec->n);
    uint8_t one_significant;
    uint64_t one_code = oss_one_weight_code(codec, &one_significant);
    uint32_t others[ONE_WEIGHT_CHUNK];
    size_t skipped = 0; /* chunks left to encode unlisted (oss_chunks_to_skip) */
    for (size_t start = first; start < count; start += ONE_WEIGHT_CHUNK) {
        size_t end = count - start < ONE_WEIGHT_CHUNK ? count : start + ONE_WEIGHT_CHUNK, listed = end - start;
        if (skipped) {
            --skipped;
        } else {
            listed = oss_list_others(weights, start, end, k, one_code, one_significant, codes, significant, others);
            skipped = oss_chunks_to_skip(end - start - listed, end - start);
        }
        const float* chunk = weights + start * k;
        uint8_t* chunk_significant = significant ? significant + start : NULL;
        if (listed == end - start)
            oss_encode_listed(codec, &form, chunk, NULL, listed, codes + start, chunk_significant, k, form_kind);
        else if (listed)
            oss_encode_listed(codec, &form, chunk, others, listed, codes + start, chunk_significant, k, form_kind);
    }
}

/* K = 2 codes past 50 bits (grids from SP_GRID_DOUBLE_LIMIT): sp_grid_quantize's path there,
 * called directly (sp_grid_round_pair, or the general rounding for the pairs it leaves; 70
 * instructions a vertex against 76 through sp_grid_quantize), the code q[1]. */
static void oss_encode_wide_pairs(const sp_codec* codec, const float* weights, size_t first, size_t count,
                                  uint64_t* codes, uint8_t* significant)
{
    for (size_t v = first; v < count; ++v) {
        uint64_t q[2];
        if (!sp_grid_round_pair(weights + v * 2, codec->scale, q))
            sp_grid_quantize_general(weights + v * 2, 2, codec->scale, q);
        if (significant) significant[v] = sp_grid_significant(q, 2);
        codes[v] = q[1];
    }
}

/* The scalar encode with k constant: K = 2 codes past 50 bits by oss_encode_wide_pairs, the
 * others in chunks (no grid of K = 3, 4 reaches SP_GRID_DOUBLE_LIMIT). */
SP_INLINE void oss_encode_run(const sp_codec* codec, const float* weights, size_t first, size_t count,
                              uint64_t* codes, uint8_t* significant, uint32_t k)
{
    if (codec->scale >= SP_GRID_DOUBLE_LIMIT) {
        if (k == 2) oss_encode_wide_pairs(codec, weights, first, count, codes, significant);
        else
            for (size_t v = first; v < count; ++v) codes[v] = sp_oss_encode_one(codec, weights + v * k, significant ? significant + v : NULL);
    } else if (codec->n < (k == 4 ? OSS_LAYER64_N : OSS_ROW64_N))
        oss_encode_chunks(codec, weights, first, count, codes, significant, k, OSS_FORM_64);
    else if (k == 3 || (k == 4 && codec->n < OSS_ROW64_N))
        oss_encode_chunks(codec, weights, first, count, codes, significant, k, OSS_FORM_MODULAR);
    else
        oss_encode_chunks(codec, weights, first, count, codes, significant, k, OSS_FORM_GENERAL);
}

void sp_oss_encode_scalar(const sp_codec* codec, const float* weights, size_t first, size_t count, uint64_t* codes,
                          uint8_t* significant)
{
    switch (codec->influences) {
    case 2: oss_encode_run(codec, weights, first, count, codes, significant, 2); break;
    case 3: oss_encode_run(codec, weights, first, count, codes, significant, 3); break;
    case 4: oss_encode_run(codec, weights, first, count, codes, significant, 4); break;
    default: break;
    }
}

/* Codes in row j of the triangle with bottom n, s_n(j + 1) - s_n(j): floor((2n - 3j) / 2). */
static inline uint64_t row_length(uint64_t n, uint64_t j)
{
    return n - j - (j + 1) / 2;
}

/* Codes in layer k, u(k + 1) - u(k): the triangle of bottom b = n - 2k, (b^2 + b + 1) / 3
 * (64-bit for b < 2^32, past any N of a 64-bit K = 4 code). */
static inline uint64_t layer_length(uint64_t n, uint64_t k)
{
    uint64_t b = n - 2 * k;
    return (b * b + b + 1) / 3;
}

/* The largest index i < count with base_of(n, i) <= w, from an estimate that is it but for
 * rounding: clamped, one closed form for its base, then steps each way by length_of(n, i) =
 * base_of(n, i + 1) - base_of(n, i) (one each for the estimates here; inlined with the
 * functions, so no indirect call, and the 128-bit closed forms of wide codes run once). */
SP_INLINE uint64_t settle_estimate(double estimate, uint64_t count, uint64_t n, uint64_t w,
                                   uint64_t (*base_of)(uint64_t, uint64_t),
                                   uint64_t (*length_of)(uint64_t, uint64_t), uint64_t* base)
{
    double clamped = estimate > 0 ? estimate : 0; /* a max, not a branch: row 0's estimates are <= 0 */
    uint64_t i = (uint64_t)clamped;
    if (i >= count) i = count - 1;
    uint64_t at = base_of(n, i);
    /* No test of i > 0: base_of(n, 0) = 0 <= w, so the loop stops at i = 0 by itself, and that
     * test, where the compiler put it first, is data (row 0 holds every K = 3 code of two
     * weights, in random order in the bench): its mispredictions halved the K = 3 decode. */
    while (at > w) at -= length_of(n, --i);
    for (uint64_t next; i + 1 < count && (next = at + length_of(n, i)) <= w; ++i) at = next; /* next <= max code */
    *base = at;
    return i;
}

/* Largest row j with s_N(j) <= w. Estimate from the mirrored square root:
 * s~(j*) - s~(j) = 3/4 (j* - j)^2 with j* = (2N+1)/3, and 12(s~(j*) - w) = (2N+1)^2 + 3 - 12w
 * exactly, so j~ = (2N + 1 - sqrt((2N+1)^2 + 3 - 12w)) / 3. (The paper prints "+ sqrt"; the
 * relevant root is the one left of the apex.) Taken for w + 7/8, as row_estimate in
 * codec_oss_simd.h: the estimate is then the row in exact arithmetic, so the checks take one
 * step, not two. For N < OSS_ROW64_N the root's argument is a 64-bit integer ((2N + 1)^2 <
 * 2^62; its double rounds past 2^53, which moves the estimate by far less than a row) and the
 * bases are the 64-bit forms (inlined into the batch decoder); past it both are 128-bit. */
SP_INLINE uint64_t find_row_small(uint64_t n, uint64_t w, uint64_t* base)
{
    uint64_t rows = (2 * n + 1) / 3, two_n1 = 2 * n + 1; /* (2N + 1)^2 + 3 - 12w >= 0 in the triangle */
    double mirrored = (double)(int64_t)(two_n1 * two_n1 + 3 - 12 * w) - 10.5;
    double estimate = ((double)two_n1 - sqrt(mirrored > 0 ? mirrored : 0)) * (1.0 / 3.0);
    return settle_estimate(estimate, rows, n, w, row_base_small, row_length, base);
}

/* A 128-bit integer as a double for an estimate: within 2^-52 of it, not always the nearest
 * (no call to the compiler's exact conversion). */
static inline double u128_estimate(sp_u128 a)
{
    return (double)sp_u128_high(a) * 18446744073709551616.0 + (double)sp_u128_low(a);
}

static uint64_t find_row_wide(uint64_t n, uint64_t w, uint64_t* base)
{
    uint64_t rows = (2 * n + 1) / 3, two_n1 = 2 * n + 1; /* n < 2^63 */
    sp_u128 square = sp_u128_add_u64(sp_u128_mul(sp_u128_from(two_n1), sp_u128_from(two_n1)), 3);
    double mirrored = u128_estimate(sp_u128_sub(square, sp_u128_mul_u64(sp_u128_from(w), 12))) - 10.5;
    double estimate = ((double)two_n1 - sqrt(mirrored > 0 ? mirrored : 0)) * (1.0 / 3.0);
    return settle_estimate(estimate, rows, n, w, sp_oss_row_base, row_length, base);
}

/*
 * cbrt(x) + 1/cbrt(x) for x >= 1 to ~1e-8 without a division or square root, as the AVX2 path
 * computes it (codec_oss_prim_avx2.h, root_start/root_finish): z ~ x^(-1/3) from the float
 * exponent/3 bit trick and a third-order step, then c + z with c = x z^2 corrected by one
 * Newton step's first-order term.
 */
static inline double cube_root_sum(double x)
{
    float xf = (float)x, zf;
    int32_t bits;
    memcpy(&bits, &xf, sizeof(bits));
    bits = 1419916032 - (int32_t)((float)bits * (1.0f / 3.0f));
    memcpy(&zf, &bits, sizeof(zf));
    float r = 1.0f - (xf * zf) * (zf * zf);
    zf += (zf * r) * (r * (2.0f / 9.0f) + 1.0f / 3.0f);
    double z = zf, xz = x * z, c = xz * z, rd = 1.0 - xz * (z * z);
    return (c + z) + rd * (c * (2.0 / 3.0) + z * (1.0 / 3.0));
}

/* Largest layer k with u(k) <= code. The estimate of the vector paths: (2N + 3 - t) / 4 with
 * t = cbrt(x) + 1/cbrt(x), x = 2(V - 1) = 8M^3 + 12M^2 - 106 - 144 code (M = N + 1) for
 * code + 17/18, which puts every code strictly inside its layer (see codec_oss_simd.h): one check
 * each way, no square root. With M = N + 1, 72(u~((N+1)/2) - code) is V = 4M^3 + 6M^2 + 16 -
 * 72 code exactly, and the paper's root is k~ = (2N + 3 - (c + 1/c)) / 4 with
 * c = cbrt(V - 1 + sqrt(V (V - 2))), c^3 + 1/c^3 = x. x is a 64-bit integer below OSS_SMALL_N
 * (8M^3 + 12M^2 < 2^64; inlined into the batch decoder), a 128-bit one past it (whose double is
 * exact enough for an estimate: the root's relative error stays near 1e-8, a fraction of a
 * layer); the bases are the 64-bit forms below OSS_LAYER64_N, the 128-bit ones past it. */
SP_INLINE uint64_t find_layer_small(uint64_t n, uint64_t code, uint64_t* base)
{
    uint64_t layers = (n + 1) / 2, m = n + 1;
    uint64_t x = 8 * m * m * m + 12 * m * m - 106 - 144 * code; /* >= 6 for valid codes */
    double estimate = (double)(2 * n + 3) * 0.25 - cube_root_sum(x >= 1 ? (double)x : 1.0) * 0.25;
    return settle_estimate(estimate, layers, n, code, layer_base_small, layer_length, base);
}

static uint64_t find_layer_wide(uint64_t n, uint64_t code, uint64_t* base)
{
    uint64_t layers = (n + 1) / 2;
    sp_u128 m = sp_u128_from(n + 1), m2 = sp_u128_mul(m, m);
    sp_u128 cubic = sp_u128_add(sp_u128_mul_u64(sp_u128_mul(m2, m), 8), sp_u128_mul_u64(m2, 12));
    double x = u128_estimate(sp_u128_sub(cubic, sp_u128_add_u64(sp_u128_mul_u64(sp_u128_from(code), 144), 106)));
    double estimate = (double)(2 * n + 3) * 0.25 - cube_root_sum(x >= 1 ? x : 1.0) * 0.25;
    return n < OSS_LAYER64_N ? settle_estimate(estimate, layers, n, code, layer_base_small, layer_length, base)
                             : settle_estimate(estimate, layers, n, code, sp_oss_layer_base, layer_length, base);
}

/* The layer of a K = 4 code and its index inside the layer (sp_oss_unpack's first half). */
SP_INLINE uint64_t unpack_layer(uint64_t n, uint64_t code, uint64_t* rest)
{
    uint64_t base, layer = n < OSS_SMALL_N ? find_layer_small(n, code, &base) : find_layer_wide(n, code, &base);
    *rest = code - base;
    return layer;
}

/* Sorted grid coordinates (K = 3, 4) from the layer (0 for K = 3) and the index inside it. */
SP_INLINE void unpack_rows(uint64_t n, uint32_t k, uint64_t layer, uint64_t rest, uint64_t* q)
{
    uint64_t base, bottom = n - 2 * layer;
    uint64_t row = bottom < OSS_ROW64_N ? find_row_small(bottom, rest, &base) : find_row_wide(bottom, rest, &base);
    uint64_t i = rest - base;
    if (k == 4) q[3] = layer;
    q[2] = row + layer;
    q[1] = i + row + layer;
    q[0] = 2 * (n - 1) - q[1] - q[2] - (k == 4 ? q[3] : 0);
}

/* Grid coordinates of a code, inlined with a constant k. */
SP_INLINE void oss_unpack(uint64_t n, uint32_t k, uint64_t code, uint64_t* q)
{
    uint64_t layer = 0, rest = code;
    if (k == 2) {
        q[1] = code;
        q[0] = 2 * (n - 1) - code;
        return;
    }
    if (k == 4) layer = unpack_layer(n, code, &rest);
    unpack_rows(n, k, layer, rest, q);
}

void sp_oss_unpack(uint64_t n, uint32_t k, uint64_t code, uint64_t* q)
{
    oss_unpack(n, k, code, q);
}

/* Codes per stage of the scalar decoder. A K = 3, 4 decode is one long dependency chain (a
 * cube root and a layer base, then a square root and a row base), longer than the core's
 * reorder window holds a few of, so the decoder runs in stages (layers, then rows) over a chunk:
 * the codes of a stage are independent, and the core overlaps more of them. The one-weight code
 * (oss_one_weight_code) skips both: a listed chunk first writes its weights to every vertex and
 * lists the other codes, which the stages then decode (a chunk twice as long as the stages take,
 * since about half of a rig's codes are that one). */
#define SCALAR_CHUNK 32

/* The codes oss_listed_at(others, 0..listed-1) of a chunk (at `codes`, weights at `weights`),
 * K = 3 or 4, all valid: the layer stage, then the row stage. */
SP_INLINE void oss_decode_listed(uint64_t n, double inverse, const uint64_t* codes, const uint32_t* others,
                                 size_t listed, float* weights, uint32_t k)
{
    uint64_t layer[SCALAR_CHUNK], rest[SCALAR_CHUNK];
    for (size_t i = 0; i < listed; ++i) {
        layer[i] = 0, rest[i] = codes[oss_listed_at(others, i)];
        if (k == 4) layer[i] = unpack_layer(n, rest[i], &rest[i]);
    }
    for (size_t i = 0; i < listed; ++i) {
        uint64_t q[SP_MAX_INFLUENCES] = {0, 0, 0, 0};
        unpack_rows(n, k, layer[i], rest[i], q);
        float* vertex = weights + oss_listed_at(others, i) * k;
        SP_UNROLL
        for (uint32_t j = 0; j < k; ++j) vertex[j] = (float)((double)q[j] * inverse);
    }
}

/* Codes first..end-1 (all valid): the one-weight code's weights into every vertex, the other
 * codes' indices (from first) into `others`; returns how many those are. */
SP_INLINE size_t oss_list_other_codes(const uint64_t* codes, size_t first, size_t end, uint64_t one_code,
                                      const float* one, float* weights, uint32_t k, uint32_t* others)
{
    size_t listed = 0;
    for (size_t v = first; v < end; ++v) {
        others[listed] = (uint32_t)(v - first);
        listed += codes[v] != one_code;
        memcpy(weights + v * k, one, k * sizeof(float));
    }
    return listed;
}

/* Decodes codes first..count-1 with k constant; stops at a code past the codec's range. */
SP_INLINE size_t oss_decode_run(const sp_codec* codec, const uint64_t* codes, size_t first, size_t count,
                                float* weights, uint32_t k)
{
    uint64_t n = codec->n, max_code = codec->max_code;
    double inverse = 1.0 / (double)codec->scale; /* as sp_grid_to_weights */
    if (k == 2) { /* a subtraction: no chain to break up */
        for (size_t v = first; v < count; ++v) {
            if (codes[v] > max_code) return v;
            weights[v * 2] = (float)((double)(2 * (n - 1) - codes[v]) * inverse);
            weights[v * 2 + 1] = (float)((double)codes[v] * inverse);
        }
        return count;
    }
    uint64_t one_code = oss_one_weight_code(codec, NULL);
    float one[SP_MAX_INFLUENCES] = {0, 0, 0, 0};
    sp_oss_decode_one(codec, one_code, one); /* sp_grid_to_weights: the stages' own arithmetic */
    uint32_t others[SCALAR_CHUNK];
    size_t skipped = 0; /* chunks left to decode unlisted (oss_chunks_to_skip) */
    for (size_t v = first; v < count;) {
        size_t end = count - v < SCALAR_CHUNK ? count : v + SCALAR_CHUNK, valid = v;
        while (valid < end && codes[valid] <= max_code) ++valid;
        if (skipped) {
            --skipped;
            oss_decode_listed(n, inverse, codes + v, NULL, valid - v, weights + v * k, k);
        } else {
            size_t listed = oss_list_other_codes(codes, v, valid, one_code, one, weights, k, others);
            skipped = oss_chunks_to_skip(valid - v - listed, valid - v);
            oss_decode_listed(n, inverse, codes + v, others, listed, weights + v * k, k);
        }
        if (valid < end) return valid;
        v = end;
    }
    return count;
}

size_t sp_oss_decode_scalar(const sp_codec* codec, const uint64_t* codes, size_t first, size_t count, float* weights)
{
    switch (codec->influences) {
    case 2: return oss_decode_run(codec, codes, first, count, weights, 2);
    case 3: return oss_decode_run(codec, codes, first, count, weights, 3);
    case 4: return oss_decode_run(codec, codes, first, count, weights, 4);
    default: return first;
    }
}

uint64_t sp_oss_encode_one(const sp_codec* codec, const float* weights, uint8_t* significant)
{
    uint64_t q[SP_MAX_INFLUENCES] = {0};
    uint32_t k = codec->influences;
    sp_grid_quantize(weights, k, codec->scale, q);
    if (significant) *significant = sp_grid_significant(q, k);
    return sp_oss_pack(codec->n, k, q);
}

void sp_oss_decode_one(const sp_codec* codec, uint64_t code, float* weights)
{
    uint64_t q[SP_MAX_INFLUENCES] = {0};
    sp_oss_unpack(codec->n, codec->influences, code, q);
    sp_grid_to_weights(q, codec->influences, codec->scale, weights);
}
