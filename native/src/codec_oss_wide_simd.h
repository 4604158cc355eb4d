/*
 * The OSS block/chunk driver for wide codes, written once over per-ISA primitives (internal;
 * included by codec_oss_batch_avx2.c and codec_oss_batch_avx512.c after the double-lane driver,
 * codec_oss_simd.h, whose primitives, rounding and estimates it reuses).
 *
 * Past the double lanes' exact range (codec_oss_batch.c: layer and row bases past 2^50) the
 * codes run in 64-bit integer lanes. Grid coordinates and codes fit 64 bits. Encode sums the
 * bases modulo 2^64 to a final value below 2^64 (the row base s_N(j) = floor(((4N + 2 - 3j) j +
 * 1) / 4) as j (N - j) + floor((j + 1)^2 / 4), since a floor by 4 does not commute with a
 * reduction mod 2^64). Decode needs only the differences code - base, which are small where
 * they matter, so it takes them in double lanes from the code's 32-bit halves and a base split
 * into an exact FMA product and its residual (wide_biased_rest, wide_row_offset): exact wherever
 * the difference lies in or next to the row or layer, past every row's codes elsewhere.
 * The root estimates stay in double lanes: their arguments (apex^2 + 3 - 12w for rows,
 * 8M^3 + 12M^2 - 106 - 144 code for layers, up to 2^73) are summed from exact pieces
 * (wide_argument), so they are exact where small (near the apex, where a rounded code would
 * cancel) and rounded once where large (where that moves the root by far less than a step). An
 * estimate is then settled (K = 3 rows) or checked with exact compares; a lane that is still off
 * (or whose rounding leaves the exact regime, as in codec_oss_simd.h) is redone by the scalar
 * code.
 *
 * The including file defines, all SP_INLINE and compiled for its ISA (SIMD_FN), on top of the
 * double-lane primitives of codec_oss_simd.h:
 *   uvec               BLOCK unsigned 64-bit lanes
 *   u_splat u_load u_store u_add u_sub u_and, u_srl(a, n) u_sll(a, n) (immediates)
 *   u_mul32(a, b)      the low 32 bits of each lane multiplied, 64-bit products
 *   u_mul(a, b)        a b mod 2^64; WIDE_INTEGER_PRODUCT 1 where that is one instruction
 *   u_unbias           integral lanes ROUNDING_MAGIC + m as m, |m| < 2^51
 *   v_from_u (exact below 2^52), v_from_u_rounded (any, rounded to nearest as C converts),
 *   v_halves(a, &high, &low) (a's two 32-bit halves as doubles), u_from_v (integral doubles
 *   in [0, 2^52))
 *   store_pairs(q0, q1, inverse, layout, out), store_triples(q, inverse, layout, out):
 *                      store_weights for K = 2 and 3
 *   root_finish_fine   root_finish good to well below half a layer at t up to 2^24 (K = 4)
 *   root_start_pair(a, b, &ra, &rb)  root_start of two blocks (in one pass where the ISA can)
 *   load_pairs(w, &first, &second) (K = 2 weights as two component vectors), m_eq,
 *   v_keep_where(x, m) = m ? x : +0, v_below_where(x, m) (the double below x > 0 where m),
 *   u_bits (a vec's bits as they are): wide_product and K = 2 encode past 2^50 grids (wide_pair_start)
 *   i_low_pair(a, b)   two blocks' lanes' low 32 bits as NBLOCK int32 (K = 4 rows in 32-bit lanes)
 *   store_quotients32  store_weights32 by division, exact for every s < 2^24
 * and WIDE_NAME(name), the entry points' names.
 */

/* The per-codec constants of the wide lanes (mod 2^64 where marked). */
typedef struct wide_codec {
    double n, scale;          /* N and the grid 2(N - 1), rounded for K = 2 */
    double scale_rest;        /* 2(N - 1) - scale, exact (|.| <= 2^10: the grid is below 2^64) */
    uint64_t n_bits, scale_bits;
    double mirrored_high, mirrored_low; /* (2N + 1)^2 + 3 - 10.5 as two exact doubles (K = 3) */
    double apex, last_row;
    double root_high, root_low;  /* 8M^3 + 12M^2 - 106 (M = N + 1) as two exact doubles (K = 4) */
} wide_codec;

/* a < 2^73 as high + low, both exact doubles: high = a with its low 20 bits cleared (at most 53
 * significant bits), low = those 20 bits. */
static void split_exactly(sp_u128 a, double* high, double* low)
{
    uint64_t top = (sp_u128_high(a) << 44) | (sp_u128_low(a) >> 20);
    *high = (double)top * 0x1p20;
    *low = (double)(sp_u128_low(a) & 0xFFFFF);
}

static wide_codec wide_codec_for(const sp_codec* codec)
{
    uint64_t n = codec->n, m = n + 1, apex = 2 * n + 1; /* wraps for K = 2 past 2^63: unused there */
    wide_codec c;
    c.n = (double)n, c.scale = (double)codec->scale, c.n_bits = n, c.scale_bits = codec->scale;
    /* the rounded grid as an integer, mod 2^64 (it may round up to 2^64): no conversion past 2^63 */
    uint64_t rounded = c.scale >= 0x1p63 ? (uint64_t)(c.scale - 0x1p63) + ((uint64_t)1 << 63) : (uint64_t)c.scale;
    c.scale_rest = (double)(int64_t)(codec->scale - rounded);
    sp_u128 square = sp_u128_add_u64(sp_u128_mul(sp_u128_from(apex), sp_u128_from(apex)), 3);
    split_exactly(square, &c.mirrored_high, &c.mirrored_low);
    c.mirrored_low -= 10.5; /* the row estimate's w + 7/8, times 12 */
    c.apex = (double)apex, c.last_row = (double)((2 * n + 1) / 3 - 1);
    sp_u128 m2 = sp_u128_mul(sp_u128_from(m), sp_u128_from(m));
    sp_u128 root = sp_u128_sub(sp_u128_add(sp_u128_mul_u64(sp_u128_mul_u64(m2, m), 8), sp_u128_mul_u64(m2, 12)),
                               sp_u128_from(106));
    split_exactly(root, &c.root_high, &c.root_low);
    return c;
}

/* s_N(j) = floor(((4N + 2 - 3j) j + 1) / 4), K = 3: the numerator is 4 j (N - j) + (j + 1)^2, so
 * s_N(j) = j (N - j) + floor((j + 1)^2 / 4) = j (N - j) + floor((j + 1) / 2) ceil((j + 1) / 2),
 * below 2^64 inside the triangle: a product mod 2^64 (no floor of a wrapped value) and one of
 * two halves below 2^32. */
SP_INLINE SIMD_FN uvec wide_row_base(const wide_codec* c, uvec j)
{
    uvec one = u_splat(1), half = u_srl(u_add(j, one), 1), half_up = u_srl(u_add(j, u_splat(2)), 1);
    return u_add(u_mul(j, u_sub(u_splat(c->n_bits), j)), u_mul32(half, half_up));
}

/* high + low - factor a for a code a (factor 12 or 144, high + low < 2^73 from split_exactly):
 * with a = 2^32 ah + al, high - (factor 2^32) ah is exact (a multiple of 2^20 below 2^73), the
 * rest rounds only where the sum is past 2^53. So exact for small results, where the roots'
 * arguments cancel, and within 2^-52 of it otherwise. */
SP_INLINE SIMD_FN vec wide_argument(double high, double low, double factor, vec a_high, vec a_low)
{
    vec top = v_add(v_fnmadd(a_high, v_splat(factor * 0x1p32), v_splat(high)), v_splat(low));
    return v_fnmadd(a_low, v_splat(factor), top);
}

/* ---- encode ----------------------------------------------------------------------------- */

/* K = 4: the layer base u(k) = floor(a / 9), a = c k + 2 with c = (4k - 6N - 9) k + 3N^2 + 9N + 6
 * (layer_base's Horner form), for encode, split as u(k) = floor(c / 9) k + floor((r k + 2) / 9)
 * with r = c mod 9: c (below 2^46 at 64-bit codes, and positive for k <= (N + 1) / 2) and its
 * quotient are exact doubles, the quotient's floor codec_oss_simd.h's biased_ninth (of c - 4,
 * the 4 taken off the constant), and r k + 2 < 2^26. Returns A = floor(c / 9) (below 2^43);
 * *small = ROUNDING_MAGIC + floor((r k + 2) / 9). */
SP_INLINE SIMD_FN vec wide_layer_split(const wide_codec* c, vec k, vec* small)
{
    vec slope = v_fmadd(k, v_splat(4.0), v_splat(-(6 * c->n + 9)));
    vec inner = v_fmadd(slope, k, v_splat(3 * c->n * c->n + 9 * c->n + 2)); /* c - 4 */
    vec ninth = v_sub(biased_ninth(inner), v_splat(ROUNDING_MAGIC));
    vec rest = v_add(v_fnmadd(ninth, v_splat(9.0), inner), v_splat(4.0));
    *small = biased_ninth(v_fmsub(rest, k, v_splat(2.0)));
    return ninth;
}

/*
 * The product A k of wide_layer_split's A (< 2^43) and a layer k (< 2^22), up to 2^65, modulo
 * 2^64, for an index high + z (z integral, ROUNDING_MAGIC + z in [2^52, 2^53)). Where the ISA
 * has 64-bit integer products (WIDE_INTEGER_PRODUCT) one of them; else (AVX2, whose 64-bit
 * product takes five operations) high = A k rounded to a multiple of 2^32 by one FMA and the rest
 * A k - high (|.| <= 2^31) added to z: A k + SPLIT_MAGIC, with SPLIT_MAGIC = 1.5 2^84, lies in
 * [2^84, 2^85), where the doubles are the multiples of 2^32, so the FMA's t = SPLIT_MAGIC + high;
 * t - SPLIT_MAGIC = high is exact (a multiple of 2^32 below 2^66), and so is the second FMA's
 * A k - high (an integer of at most 32 bits). t's bits are those of SPLIT_MAGIC plus high / 2^32
 * (one binade), and SPLIT_MAGIC's low 32 bits are zero, so t's bits shifted left by 32 are high
 * modulo 2^64.
 */
#define SPLIT_MAGIC 0x1.8p84

SP_INLINE SIMD_FN uvec wide_product(vec a, vec k, vec* z)
{
#if WIDE_INTEGER_PRODUCT
    (void)z;
    return u_mul(u_from_v(a), u_from_v(k));
#else
    vec t = v_fmadd(a, k, v_splat(SPLIT_MAGIC));
    *z = v_add(*z, v_fmsub(a, k, v_sub(t, v_splat(SPLIT_MAGIC))));
    return u_sll(u_bits(t), 32);
#endif
}

/* sp_oss_pack on one block of sorted grid lanes (exact integers below 2^35), into 64 bits. The
 * K = 4 in-layer index s_{N-2k}(j) + i stays below 2^47: codec_oss_simd.h's biased_row, which
 * also adds the layer base's small part (wide_layer_split) and any rest of the product
 * (wide_product), |small + i + rest| < 2^36, so every sum before it is exact. */
SP_INLINE SIMD_FN uvec wide_pack(const wide_codec* c, const vec* q, uint32_t k)
{
    if (k == 2) return u_from_v(q[1]);
    if (k == 3) return u_add(wide_row_base(c, u_from_v(q[2])), u_from_v(v_sub(q[1], q[2])));
    vec half_apex = v_fnmadd(q[3], v_splat(2.0), v_splat(c->n + 0.5)), small;
    vec a = wide_layer_split(c, q[3], &small), z = v_add(small, v_sub(q[1], q[2]));
    uvec high = wide_product(a, q[3], &z);
    return u_add(high, u_unbias(biased_row(half_apex, v_sub(q[2], q[3]), z)));
}

/* The floors, rounding and index of one block: the lanes the vector code cannot prove exact,
 * as bits (the grids here are below 2^50, where sp_grid_quantize rounds in double, so
 * codec_oss_simd.h's rounding is exact). */
SP_INLINE SIMD_FN unsigned wide_encode_block(const wide_codec* c, const vec* w, vec scale, unsigned ordered, uint32_t k,
                                             uint64_t* codes, uint8_t* significant)
{
    vec q[SP_MAX_INFLUENCES];
    unsigned missed = quantize_block(w, k, c->scale, scale, ordered, q);
    u_store(codes, wide_pack(c, q, k));
    if (significant) store_significant(q, k, significant);
    return missed;
}

/* Encodes `blocks` (<= ENCODE_CHUNK) blocks in stages: the rounding's division, then the rest of
 * each block (in one stage or two, as codec_oss_simd.h's encode_fused says), then the scalar
 * redo of the missed lanes; constants: the wide_codec. */
SP_INLINE SIMD_FN void wide_encode_chunk(const sp_codec* codec, const void* constants, const float* weights,
                                         size_t blocks, uint64_t* codes, uint8_t* significant, uint32_t k,
                                         const simd_layout* layout)
{
    const wide_codec* c = (const wide_codec*)constants;
    vec w[ENCODE_CHUNK][SP_MAX_INFLUENCES], scale[ENCODE_CHUNK];
    unsigned missed[ENCODE_CHUNK], ordered[ENCODE_CHUNK], any = 0; /* lanes as bits */
    for (size_t b = 0; b < blocks; ++b) {
        prefetch_lanes(weights + b * BLOCK * k, k, codes + b * BLOCK, BLOCK);
        ordered[b] = load_block(weights + b * BLOCK * k, k, layout, c->scale, w[b], &scale[b]);
    }
    if (encode_fused(k))
        for (size_t b = 0; b < blocks; ++b)
            any |= missed[b] = wide_encode_block(c, w[b], scale[b], ordered[b], k, codes + b * BLOCK,
                                                 significant ? significant + b * BLOCK : NULL);
    else {
        for (size_t b = 0; b < blocks; ++b) /* the floors replace the weights */
            any |= missed[b] = quantize_block(w[b], k, c->scale, scale[b], ordered[b], w[b]);
        if (significant)
            for (size_t b = 0; b < blocks; ++b) {
                u_store(codes + b * BLOCK, wide_pack(c, w[b], k));
                store_significant(w[b], k, significant + b * BLOCK);
            }
        else /* the loop without the counts' test and pointer in it, as encode_chunk's */
            for (size_t b = 0; b < blocks; ++b) u_store(codes + b * BLOCK, wide_pack(c, w[b], k));
    }
    if (any) redo_encode(codec, weights, blocks, BLOCK, missed, k, codes, significant); /* most chunks have none */
}

DEFINE_ENCODE_WALK(wide_encode_walk, wide_encode_chunk)

/*
 * K = 2 on grids s >= SP_GRID_DOUBLE_LIMIT: sp_grid_round_pair's exact rounding in double lanes,
 * its 128-bit products as FMA residuals (its integer form in 64-bit lanes, which these replace,
 * ran slower than the scalar DIV on AVX2, whose 64-bit products and conversions take 32-bit
 * pieces). x = s a / d for the smaller weight a, the larger b, d = a + b, rounded to the nearest
 * integer, a tie up where a is slot 0.
 * Let u be the lower of a's and b's lowest set bits: a, b, d and every value below are multiples
 * of u, a < 2^24 u (a float has 24 significant bits and a <= b), and where d = a + b is exact
 * (checked: d - b == a) d < 2^53 u. Other lanes, and those not plain, go to the scalar code.
 *   - s = sh + sl, sh the grid rounded (wide_codec's scale), |sl| <= 2^10. s a = ph + pl + pe
 *     exactly: ph = sh a rounded, pl its FMA residual (|pl| <= 2^-53 ph < 2^35 u), pe = sl a
 *     (35 bits). ph, like every rounded product here, is a multiple of u: one below 2^53 u is
 *     exact, one above has an ulp of u or more.
 *   - y = ph (1/d) is within 2^11.8 of x (< 2^63: pl, pe move it by <= 2^10 + 2^9, the two
 *     roundings by 2^-52 x). f = F 2^12 with F = round(y / 2^12) (the bits of k = 2^52 + F) for
 *     y >= 2^13, else 0: |x - f| < 2^13.4; f d = mh + ml (FMA), and e = ph - mh is exact
 *     (Sterbenz: mh / ph is within 4 2^-53 of f / y, in [0.8, 1.34]; f = 0: e = ph).
 *   - r = s a - f d = e + c with c = pl + pe - ml exact (|c| < 2^37 u, all multiples of u).
 *     q2 = round((e + c) / d), the bits of 2^52 1.5 + q2 from one FMA: (e + c) (1/d) is within
 *     2^-38 of r / d, so |r / d - q2| <= 1/2 + 2^-38, and r2 = r - q2 d is exactly
 *     fma(-q2, d, e) + c (|e - q2 d| <= |r2| + |c| < 2^52 u + 2^38 u < 2^53 u).
 *   - x = f + q2 + r2 / d: nearest = f + q2 + 1 where r2 > d/2 (or = d/2, tie up: r2 > the
 *     double below d/2), - 1 where r2 < -d/2 (or = -d/2, tie down), as integers: F 2^12 is k's
 *     bits shifted (the exponent field leaves), plus q2 +- 1 from the bits of 2^52 1.5 + q2.
 * In two stages over a chunk's blocks (~1.15x as fast on AVX2, ~1.25x on AVX-512 as one; three
 * were slower): the loads and checks, the division and s a, then the rest.
 */
typedef struct wide_pair {
    vec d, inverse, ph, residual; /* residual: pl + pe */
    mask ties_up, ties_down;
} wide_pair;

/* The first stage of one block: returns the lanes left to the scalar code, as bits. */
SP_INLINE SIMD_FN unsigned wide_pair_start(const wide_codec* c, const float* weights, wide_pair* p)
{
    vec w0, w1;
    load_pairs(weights, &w0, &w1);
    /* min/max return the second operand where either is NaN: a is NaN where w1 is, b where w0 is */
    vec a = v_min(w0, w1), b = v_max(w1, w0), d = v_add(a, b);
    p->ties_up = m_lt(w0, w1), p->ties_down = m_ge(w0, w1);
    mask exact = m_and(m_and(m_ge(a, v_zero()), m_gt(b, v_zero())), m_eq(v_sub(d, b), a)); /* NaN, inf: d - b is NaN */
    p->d = d;
    p->inverse = v_div(v_splat(1.0), d);
    vec ph = v_mul(a, v_splat(c->scale)), pl = v_fmsub(a, v_splat(c->scale), ph);
    p->ph = ph;
    p->residual = v_add(pl, v_mul(a, v_splat(c->scale_rest)));
    return ~m_bits(exact) & ((1u << BLOCK) - 1);
}

/* The second stage: the codes and counts. */
SP_INLINE SIMD_FN void wide_pair_finish(const wide_pair* p, uint64_t* codes, uint8_t* significant)
{
    const double biased = 0x1.8p52; /* 2^52 1.5: integers of [-2^51, 2^51) as the low bits */
    vec d = p->d, inverse = p->inverse, ph = p->ph;
    vec y = v_mul(ph, inverse);
    vec k = v_fmadd(v_keep_where(y, m_ge(y, v_splat(0x1p13))), v_splat(0x1p-12), v_splat(0x1p52));
    vec f = v_fmsub(k, v_splat(0x1p12), v_splat(0x1p64)), mh = v_mul(f, d);
    vec e = v_sub(ph, mh), rest = v_sub(p->residual, v_fmsub(f, d, mh)); /* c */
    vec q2 = v_fmadd(v_add(e, rest), inverse, v_splat(biased));
    vec r2 = v_add(v_fnmadd(v_sub(q2, v_splat(biased)), d, e), rest);
    vec half = v_mul(d, v_splat(0.5)), lowest = v_sub(v_zero(), v_below_where(half, p->ties_down));
    counter low = c_dec_where(c_inc_where(q2, m_gt(r2, v_below_where(half, p->ties_up))), m_lt(r2, lowest));
    uvec nearest = u_sub(u_add(u_sll(u_bits(k), 12), u_bits(low)), u_bits(v_splat(biased)));
    u_store(codes, nearest);
    if (significant) {
        vec q[2] = {v_zero(), v_add(f, v_sub(low, v_splat(biased)))}; /* > 0 where the code is: one rounding */
        store_significant(q, 2, significant);
    }
}

/* `blocks` blocks of K = 2 past the double rounding, then the scalar redo of the missed lanes. */
SP_INLINE SIMD_FN void wide_pair_chunk(const sp_codec* codec, const void* constants, const float* weights,
                                       size_t blocks, uint64_t* codes, uint8_t* significant, uint32_t k,
                                       const simd_layout* layout)
{
    wide_pair parts[ENCODE_CHUNK];
    unsigned missed[ENCODE_CHUNK], any = 0;
    (void)layout;
    for (size_t b = 0; b < blocks; ++b) {
        prefetch_lanes(weights + b * BLOCK * 2, 2, codes + b * BLOCK, BLOCK);
        any |= missed[b] = wide_pair_start((const wide_codec*)constants, weights + b * BLOCK * 2, &parts[b]);
    }
    for (size_t b = 0; b < blocks; ++b)
        wide_pair_finish(&parts[b], codes + b * BLOCK, significant ? significant + b * BLOCK : NULL);
    if (any) redo_encode(codec, weights, blocks, BLOCK, missed, k, codes, significant);
}

DEFINE_ENCODE_WALK(wide_pair_walk, wide_pair_chunk)

SIMD_FN size_t WIDE_NAME(encode)(const sp_codec* codec, const float* weights, size_t count, uint64_t* codes,
                                 uint8_t* significant)
{
    wide_codec c = wide_codec_for(codec);
    if (codec->influences == 2 && codec->scale >= SP_GRID_DOUBLE_LIMIT)
        return wide_pair_walk(codec, &c, weights, count, codes, significant, 2);
    RETURN_FOR_EACH_K(codec, wide_encode_walk, codec, &c, weights, count, codes, significant)
}

/* ---- decode ----------------------------------------------------------------------------- */

/*
 * K = 3's row estimate is taken half a row low: the rounded root is off by far less than half a
 * step (~1e-5 of a row, from the argument's and the square root's rounding at 2^-52 of values up
 * to 2^34), so floored, it is the row or the one before it, and one compare going up settles it.
 * K = 4's layer estimate is taken as codec_oss_simd.h takes it, unbiased (AVX-512's root and
 * AVX2's root_finish_fine are off by far less than half a layer: no lane of the tests' tens of
 * millions missed by more), without a settling step: the rare code that close to a layer
 * boundary lands in the wrong layer, and the row check sends it to the scalar code (a step up
 * settled every lane but cost ~10% of the decode, on the bench's mix and on random codes alike).
 * Lanes the checks reject are redone, whatever the estimate was (checked with estimates biased
 * by -2, -1, 1, 2 and 7 steps: every output right, test_batch_wide_lanes's redo counts failing).
 */

/* K = 3: the row estimate of codec_oss_simd.h for w + 7/8 on a 64-bit code w, from its halves
 * (v_halves; the mirrored root's argument apex^2 + 3 - 12(w + 7/8) by wide_argument), half a
 * row low, floored and clamped to the rows. */
SP_INLINE SIMD_FN vec wide_row_estimate(const wide_codec* c, vec high, vec low)
{
    vec mirrored = wide_argument(c->mirrored_high, c->mirrored_low, 12.0, high, low);
    vec root = v_sqrt(v_max(mirrored, v_zero()));
    return clamp_floor(v_fmsub(v_sub(v_splat(c->apex), root), v_splat(1.0 / 3.0), v_splat(0.5)), v_splat(c->last_row));
}

/* K = 3: i = w - s_N(j) for a 64-bit code w from its halves and a row j < 2^33, in double lanes
 * (no 64-bit products, as wide_layer_rest): s_N(j) = floor(a j + 1/4) with a = N + 1/2 - 3j/4
 * (a multiple of 1/4), a j = p + e exactly (p the rounded product, e by FMA), and
 * s_N(j) - w = floor(((e - (2^32 high - p)) - low) + 1/4). The difference rounds once, to
 * itself wherever it is below 2^51 (a multiple of 1/4), and each later step is exact while its
 * sum stays below 2^51; so a step that rounds leaves a magnitude past 2^51, and i ends past 2^50
 * either way. For w in row j or j + 1 (i below 2^35) i is exact; else it is outside both. */
SP_INLINE SIMD_FN vec wide_row_offset(const wide_codec* c, vec high, vec low, vec j)
{
    vec slope = v_fnmadd(j, v_splat(0.75), v_splat(c->n + 0.5));
    vec product = v_mul(slope, j), error = v_fmsub(slope, j, product);
    vec difference = v_fmsub(high, v_splat(0x1p32), product);
    return v_sub(v_zero(), v_floor(v_add(v_sub(v_sub(error, difference), low), v_splat(0.25))));
}

/* K = 3: the row j of code w from its estimate (j or j - 1) by one step up, and i = w - s_N(j),
 * into q; returns the lanes whose (j, i) is not proven right (i outside row j, as row_offset
 * checks it: rows j >= rows have no codes), as bits. Exact: i is (wide_row_offset) wherever it
 * can pass, rows and lengths are integers and halves below 2^35. */
SP_INLINE SIMD_FN unsigned wide_unpack_rows(const wide_codec* c, vec high, vec low, vec j, vec* q)
{
    vec i = wide_row_offset(c, high, low, j), length = v_floor(v_fnmadd(j, v_splat(1.5), v_splat(c->n)));
    mask above = m_ge(i, length); /* the next row */
    j = v_add_where(j, above, v_splat(1.0));
    i = v_add_where(i, above, v_sub(v_zero(), length));
    vec last = v_fnmadd(j, v_splat(1.5), v_splat(c->n - 1.0));
    unsigned ok = m_bits(m_and(m_ge(i, v_zero()), m_ge(last, i)));
    unpacked_block(c->n, 3, v_zero(), j, i, q);
    return ~ok & ((1u << BLOCK) - 1);
}

/* K = 4: the layer argument of codec_oss_simd.h's estimate (for code + 17/18) on a 64-bit code,
 * from its halves (v_halves). */
SP_INLINE SIMD_FN vec wide_layer_argument(const wide_codec* c, vec high, vec low)
{
    return wide_argument(c->root_high, c->root_low, 144.0, high, low);
}

/* K = 4: ROUNDING_MAGIC + w for the rest w = code - u(k) of the estimated layer k, in double
 * lanes from the code's 32-bit halves (v_halves), with no 64-bit products (AVX2 builds each
 * from three 32-bit ones) and no floors. With a = c k + 2 = 9 u(k) + r (layer_base's Horner form:
 * c < 2^48 exact, k < 2^22, 0 <= r < 9), x = 9 code - c k + 2 = 9 w + 4 - r puts x / 9 within 4/9
 * of w, so one FMA rounding x / 9 + ROUNDING_MAGIC to the nearest integer gives ROUNDING_MAGIC + w
 * (codec_oss_simd.h's biased_ninth: the product with the rounded 1/9 is within 1/36 of x / 9 for
 * |x| < 2^51). x is summed from exact pieces: c k = p + e (p the rounded product, e its FMA
 * residual) and 9 code = 9 2^32 high + 9 low (both exact), x = ((9 2^32 high - p) - e) + (9 low + 2).
 * Each difference is of integers and exact wherever its value is below 2^53 (p is an integer),
 * so exact wherever x is (|e| <= 2^16, 9 low + 2 < 2^37): a rest in the layer (below 2^44) is
 * exact. Otherwise the first step that rounds leaves a magnitude past 2^53 - 2^37, and rounding
 * is monotone: x ends past 2^52.9 with the exact value's sign, and so does the rest past 2^49,
 * outside every layer (wide_layer_outside). apex = 2N + 1 - 4k (the caller's); with `whole`, low
 * is the code itself (below 2^52) and high unused. */
SP_INLINE SIMD_FN vec wide_biased_rest(const wide_codec* c, vec high, vec low, vec k, vec apex, int whole)
{
    vec slope = v_sub(v_splat(-(4 * c->n + 8)), apex); /* 4k - 6N - 9 from apex = 2N + 1 - 4k: an add, not an FMA */
    vec inner = v_fmadd(slope, k, v_splat(3 * c->n * c->n + 9 * c->n + 6)); /* c */
    vec product = v_mul(inner, k), error = v_fmsub(inner, k, product), x;
    if (whole) /* low is the code: ((9 code - p) - e) + 2, 9 code exact in the FMA, the same steps' exactness */
        x = v_add(v_sub(v_fmsub(low, v_splat(9.0), product), error), v_splat(2.0));
    else
        x = v_add(v_sub(v_fmsub(high, v_splat(9 * 0x1p32), product), error), v_fmadd(low, v_splat(9.0), v_splat(2.0)));
    return v_fmadd(x, v_splat(1.0 / 9.0), v_splat(ROUNDING_MAGIC));
}

/* K = 4: the lanes whose rest w is outside layer k's triangle (bottom B = N - 2k), as bits:
 * unless 0 <= w < S(B) = floor((B^2 + B + 1) / 3). With apex = 2B + 1 the row root's argument
 * mirrored = apex^2 - 7.5 - 12 w (row_mirrored: exact, a multiple of 1/2 below 2^52 for
 * |w| < 2^47; past that rounded, with its sign) is 4 (B (B + 1) - 3w) - 6.5, positive exactly
 * where B (B + 1) - 3w >= 2, that is 3 (w + 1) <= B^2 + B + 1, w < S(B). */
SP_INLINE SIMD_FN unsigned wide_layer_outside(vec w, vec mirrored)
{
    return ~m_bits(m_and(m_ge(w, v_zero()), m_gt(mirrored, v_zero()))) & ((1u << BLOCK) - 1);
}

/* K = 4: ROUNDING_MAGIC + the row estimate of row_from_mirrored for a rest in the layer, but
 * its floor the nearest integer to estimate - 1/2 (a tie, an estimate exactly an integer, may go
 * one row lower), and no clamp to row 0: a row j or j - 1 where row_from_mirrored gives j, whose
 * offset stays below three rows' lengths. */
SP_INLINE SIMD_FN vec wide_biased_row(vec apex, vec mirrored)
{
    vec estimate = v_fmadd(v_sub(apex, v_sqrt(mirrored)), v_splat(1.0 / 3.0), v_splat(-0.5));
    return v_add(estimate, v_splat(ROUNDING_MAGIC));
}

/*
 * K = 4 with the rows in 32-bit lanes. Past the layer and its rest (double lanes: the layer
 * root of codec_oss_simd.h, wide_biased_rest), the row estimate runs in double (row_estimate's
 * correctly rounded root: the row itself for every rest in the layer but those within its
 * rounding of a row start), and the rest in NBLOCK int32 lanes, twice as many an operation:
 * the offset i = w - s_B(j) modulo 2^32 from w's low 32 bits (the bits of ROUNDING_MAGIC + w),
 * the exact row check (0 <= i <= last), the components (q <= s < 2^24) and the weights
 * (store_quotients32's correctly rounded q / s, the scalar's double product too for s < 2^24).
 * Modulo 2^32 is exact where |i| < 2^31, which holds where w is in the layer (its row estimate
 * then is w's row or next to it, |i| below two rows' lengths, 2^25): so the layer is checked
 * first, in double (wide_layer_outside), and a rest outside it sent to the scalar code with
 * whatever the 32-bit lanes made of it. Then, as in decode_chunk, a rest in the layer that the
 * row check accepts proves (k, j, i). The stages, in order: wide_layer_start, the layer root's
 * finish, wide_biased_rest and the row estimate, the 32-bit lanes (wide_decode_pairs).
 */

/* The first stage of K = 4's wide decode over `blocks` blocks: each block's codes checked, their
 * halves (v_halves), or with `whole` (codes below WIDE_WHOLE_CODES) the codes themselves in low,
 * the layer root's argument and its float start (root_start_pair: ~5% faster on AVX2 than one by
 * one); returns whether every code passed. The whole codes' argument (root_high - 144 code) +
 * root_low is exact where small as wide_argument's is (a difference of multiples of 16 below
 * 2^57, then an integer below 2^20 added), rounded at most twice where large. */
SP_INLINE SIMD_FN int wide_layer_start(const sp_codec* codec, const wide_codec* c, const uint64_t* codes, size_t blocks,
                                       float* weights, const simd_layout* layout, int whole, vec* high, vec* low, vec* x,
                                       root* z)
{
    code_check check = check_start(codec->max_code);
    for (size_t b = 0; b < blocks; ++b) {
        prefetch_decode(layout, weights + b * BLOCK * 4, 4, codes + b * BLOCK, BLOCK);
        vec code = load_codes(codes + b * BLOCK, &check); /* exact below 2^52 */
        if (whole) {
            low[b] = code;
            x[b] = v_add(v_fnmadd(code, v_splat(144.0), v_splat(c->root_high)), v_splat(c->root_low));
        } else {
            v_halves(u_load(codes + b * BLOCK), &high[b], &low[b]);
            x[b] = wide_layer_argument(c, high[b], low[b]);
        }
        if (b % 2) root_start_pair(x[b - 1], x[b], &z[b - 1], &z[b]);
    }
    return check_passed(&check);
}

/* sp_oss_unpack and sp_grid_to_weights for K = 4 on `pairs` NBLOCK-lane blocks (2 BLOCK each) of
 * codes (whole: all below WIDE_WHOLE_CODES, a constant in each walk, wide_decode_chunk4 and
 * _whole: the codes' halves and their sums skipped, in cache ~1.07x as fast on AVX2 at 52 bits),
 * in stages: the code check, halves and the layer root's float start; the root's finish
 * and the layer; the rest, the layer check and the row estimate (one stage: moving the root's
 * finish or the row's square root into a neighbouring stage ran 10-15% slower); the rows in
 * 32-bit lanes and the weights. Then the scalar redo of the lanes it missed; nothing written
 * where a code is above max_code (returns 0); constants: the wide_codec. */
#define WIDE_WHOLE_CODES ((uint64_t)1 << 52) /* codes below it are exact doubles (load_codes) */
#define WIDE_CHUNK4 (2 * DECODE_CHUNK) /* blocks: in cache ~1.04x as fast as DECODE_CHUNK (AVX2), twice as many 1.01x more */

SP_INLINE SIMD_FN int wide_decode_pairs(const sp_codec* codec, const void* constants, const uint64_t* codes, size_t pairs,
                                        float* weights, uint32_t k, const simd_layout* layout, int whole)
{
    const wide_codec* c = (const wide_codec*)constants;
    double scale = (double)codec->scale; /* a local: the weights' stores could alias *codec, so it would be read again each pair */
    vec x[WIDE_CHUNK4], layer[WIDE_CHUNK4], biased[WIDE_CHUNK4], row[WIDE_CHUNK4];
    vec high[WIDE_CHUNK4], low[WIDE_CHUNK4]; /* the codes' 32-bit halves, or the whole codes in low */
    root z[WIDE_CHUNK4];
    unsigned outside[WIDE_CHUNK4], missed[WIDE_CHUNK4 / 2], any = 0; /* lanes as bits */
    size_t blocks = 2 * pairs;
    if (!wide_layer_start(codec, c, codes, blocks, weights, layout, whole, high, low, x, z)) return 0; /* nothing written yet */
    for (size_t b = 0; b < blocks; ++b) layer[b] = layer_estimate(c->n, root_finish_fine(x[b], z[b]));
    for (size_t b = 0; b < blocks; ++b) {
        vec apex = v_fnmadd(layer[b], v_splat(4.0), v_splat(2 * c->n + 1));
        biased[b] = wide_biased_rest(c, high[b], low[b], layer[b], apex, whole);
        vec w = v_sub(biased[b], v_splat(ROUNDING_MAGIC));
        vec mirrored = row_mirrored(apex, w);
        outside[b] = wide_layer_outside(w, mirrored);
        row[b] = wide_biased_row(apex, mirrored);
    }
    for (size_t p = 0; p < pairs; ++p) {
        nint q[SP_MAX_INFLUENCES], last;
        vec magic = v_splat(ROUNDING_MAGIC);
        nint layers = i_low_pair(v_add(layer[2 * p], magic), v_add(layer[2 * p + 1], magic));
        nint j = i_low_pair(row[2 * p], row[2 * p + 1]);
        nint bottom = i_sub(i_splat((int32_t)c->n), i_add(layers, layers));
        nint i = n_row_offset(bottom, j, i_low_pair(biased[2 * p], biased[2 * p + 1]), &last);
        any |= missed[p] = n_outside(i, last) | outside[2 * p] | outside[2 * p + 1] << BLOCK;
        n_components(c->n, 4, layers, j, i, q);
        store_quotients32(q, k, scale, layout, weights + p * NBLOCK * k);
    }
    if (any) redo_decode(codec, codes, pairs, NBLOCK, missed, k, weights); /* most chunks have none */
    return 1;
}

SP_INLINE SIMD_FN int wide_decode_chunk4(const sp_codec* codec, const void* constants, const uint64_t* codes,
                                         size_t pairs, float* weights, uint32_t k, const simd_layout* layout)
{
    return wide_decode_pairs(codec, constants, codes, pairs, weights, k, layout, 0);
}

SP_INLINE SIMD_FN int wide_decode_chunk4_whole(const sp_codec* codec, const void* constants, const uint64_t* codes,
                                               size_t pairs, float* weights, uint32_t k, const simd_layout* layout)
{
    return wide_decode_pairs(codec, constants, codes, pairs, weights, k, layout, 1);
}

DEFINE_DECODE_WALK(wide_decode_walk4, wide_decode_chunk4, NBLOCK, WIDE_CHUNK4 / 2, 0)
DEFINE_DECODE_WALK(wide_decode_walk4_whole, wide_decode_chunk4_whole, NBLOCK, WIDE_CHUNK4 / 2, 0)

/* sp_oss_unpack and sp_grid_to_weights for K = 2, 3 on `blocks` blocks of codes, in stages (K = 3:
 * the code check and the row estimate, the rest), then the scalar redo of the lanes it missed;
 * nothing written where a code is above max_code (returns 0); constants: the wide_codec. */
SP_INLINE SIMD_FN int wide_decode_chunk(const sp_codec* codec, const void* constants, const uint64_t* codes,
                                        size_t blocks, float* weights, uint32_t k, const simd_layout* layout)
{
    const wide_codec* c = (const wide_codec*)constants;
    double inverse = 1.0 / (double)codec->scale;
    vec row[DECODE_CHUNK], high[DECODE_CHUNK], low[DECODE_CHUNK]; /* the codes' 32-bit halves (K = 3) */
    unsigned missed[DECODE_CHUNK], any = 0; /* lanes as bits */
    code_check check = check_start(codec->max_code);
    for (size_t b = 0; b < blocks; ++b) {
        prefetch_decode(layout, weights + b * BLOCK * k, k, codes + b * BLOCK, BLOCK);
        load_codes(codes + b * BLOCK, &check); /* the check only: the lanes are u64 */
        if (k == 3) {
            v_halves(u_load(codes + b * BLOCK), &high[b], &low[b]);
            row[b] = wide_row_estimate(c, high[b], low[b]);
        }
    }
    if (!check_passed(&check)) return 0; /* nothing written yet */
    for (size_t b = 0; b < blocks; ++b) {
        vec q[SP_MAX_INFLUENCES];
        uvec code = u_load(codes + b * BLOCK);
        float* out = weights + b * BLOCK * k;
        missed[b] = 0;
        if (k == 2) { /* no grid vectors to build */
            store_pairs(v_from_u_rounded(u_sub(u_splat(c->scale_bits), code)), v_from_u_rounded(code), inverse, layout, out);
        } else {
            missed[b] = wide_unpack_rows(c, high[b], low[b], row[b], q);
            store_triples(q, inverse, layout, out);
        }
        any |= missed[b];
    }
    if (any) redo_decode(codec, codes, blocks, BLOCK, missed, k, weights); /* most chunks have none */
    return 1;
}

DEFINE_DECODE_WALK(wide_decode_walk, wide_decode_chunk, BLOCK, DECODE_CHUNK, 1)

/* The chunks to the end or to the block holding an invalid code. */
SP_INLINE SIMD_FN size_t wide_decode_range(const sp_codec* codec, const void* constants, const uint64_t* codes,
                                           size_t count, float* weights, uint32_t k, const simd_layout* layout)
{
    if (k == 4 && codec->max_code < WIDE_WHOLE_CODES) return wide_decode_walk4_whole(codec, constants, codes, 0, count, weights, k, layout);
    if (k == 4) return wide_decode_walk4(codec, constants, codes, 0, count, weights, k, layout);
    return wide_decode_walk(codec, constants, codes, 0, count, weights, k, layout);
}

DEFINE_EDGE_DECODE(wide_decode_edges, wide_decode_range)

/* stream a constant in each call, as in decode_blocks */
SP_INLINE SIMD_FN size_t wide_decode_lanes(const sp_codec* codec, const void* constants, const uint64_t* codes,
                                           size_t count, float* weights, int stream, uint32_t k)
{
    simd_layout layout = layout_for(k);
    layout.stream = stream;
    size_t v = wide_decode_edges(codec, constants, codes, count, weights, k, &layout);
    if (stream) _mm_sfence(); /* as decode_lanes */
    return v;
}

SP_INLINE SIMD_FN size_t wide_decode_blocks(const sp_codec* codec, const void* constants, const uint64_t* codes,
                                            size_t count, float* weights, int stream, uint32_t k)
{
    RETURN_STREAMING_OR_NOT(wide_decode_lanes, codec, constants, codes, count, weights, stream, k)
}

SIMD_FN size_t WIDE_NAME(decode)(const sp_codec* codec, const uint64_t* codes, size_t count, float* weights, int stream)
{
    wide_codec c = wide_codec_for(codec);
    RETURN_FOR_EACH_K(codec, wide_decode_blocks, codec, &c, codes, count, weights, stream)
}
