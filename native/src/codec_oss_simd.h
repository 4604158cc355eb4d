/*
 * The OSS block/chunk driver, written once over per-ISA primitives (internal; included by
 * codec_oss_batch_avx2.c and codec_oss_batch_avx512.c after codec_oss_prim_avx2.h /
 * codec_oss_prim_avx512.h, the way meshoptimizer's vertexcodec
 * writes its SIMD group decoder per ISA and the driver once).
 *
 * Results are bit-identical to the scalar path (sp_grid_quantize + sp_oss_pack, and
 * sp_oss_unpack + sp_grid_to_weights): the rounding runs in double lanes with the scalar's
 * exact operation order, and the OSS index arithmetic runs in double lanes too, where every
 * intermediate is an integer or a quarter small enough (codec_oss_batch.c) to be exact in any order (Horner forms,
 * explicit FMAs); narrow codes decode in int32 / float lanes instead (see "decode in 32-bit
 * lanes"). Decode's layer and row *estimates* differ from the scalar ones (no layer square
 * root, no divisions, shifted arguments): exact integer checks decide every lane. A lane whose
 * inputs leave that exact regime (odd weights, a code the estimate misses) is redone by the
 * scalar code, so the vector code only ever has to be right where it claims to be.
 *
 * The including file defines, all SP_INLINE and compiled for its ISA (SIMD_FN):
 *   vec, mask          BLOCK double lanes and a lane mask; BLOCK, ENCODE_CHUNK, DECODE_CHUNK,
 *                      ENCODE_FUSED (1: encode's floors, rounding and indices in one stage for
 *                      K < 4, encode_fused)
 *   simd_layout        whatever load/store need per K (permute indices), from layout_for(k)
 *   v_splat v_zero v_add v_sub v_mul v_div v_sqrt v_max v_min v_floor v_trunc
 *   v_fmadd(a, b, c) = ab + c, v_fnmadd = c - ab, v_fmsub = ab - c (fused: exact forms only)
 *   m_ge m_gt m_lt (ordered compares), m_and, m_bits (lanes as bits), v_add_where(x, m, y)
 *   counter            small non-negative integer lanes for the rounding's ranks: c_splat(u),
 *                      c_inc_where, c_dec_where (by one where m); rank_start(i, k) and
 *                      rank_pair(ra, rb, &rank_a, &rank_b) (slot a < b; remainders in [+0, 1)):
 *                      with every pair's step, rank[i] counts the slots that beat i, where an
 *                      earlier slot beats a later one when its remainder is not smaller;
 *                      COUNTER_BIAS, the double that c_below(c, t) takes t = COUNTER_BIAS + d (d
 *                      integral, below 2^51) as: the lanes where c < d; c_deficit_fits(t, k): the
 *                      lanes where 0 <= d < k
 *   load_weights, store_weights (AoS floats <-> K vectors), store_pair (two blocks' weights),
 *   LOAD_ORDERED (1: the ISA has load_weights_ordered(w, x), K = 4's load_weights and
 *   weights_ordered in one),
 *   store_codes (u64), store_biased_codes (integral lanes ROUNDING_MAGIC + code as u64 code),
 *   code_check, check_start(max_code), load_codes(codes, check) (each checked <= max_code),
 *   check_passed, store_counts (lane values as bytes), codes_valid (every code of a block
 *   <= max_code)
 *   root, root_start(x), root_finish(x, r) ~ cbrt(x) + 1/cbrt(x) for the layer estimate
 *   for the edge codes' decode: u_bound(n) and u_at_least(a, bound) (the lanes of a >= n, as
 *   bits), u_compact(a, keep, out) (the lanes kept, in order, to the front of out),
 *   vertex_lanes, vertex_numbers() (0, 1, ... BLOCK - 1 in 32-bit lanes), vertex_numbers_next(a)
 *   (each BLOCK more), vertex_compact(a, keep, out) (as u_compact), store_edge_pairs(first,
 *   second, k, out) (whole rows: two weights, the rest zeros)
 * and for decode in 32-bit lanes, NBLOCK (2 BLOCK) lanes and NARROW_CHUNK blocks a stage:
 *   nvec, nint, nmask  float lanes, int32 lanes, a mask of them
 *   f_splat f_add f_sub f_mul f_sqrt f_fmadd f_fnmadd, i_splat i_add i_sub i_mullo i_max i_min,
 *   i_shr2 (arithmetic >> 2), i_div9 (floor(a / 9), 0 <= a < 2^31), i_gt, n_or, n_bits,
 *   i_to_f (convert), i_trunc (convert toward 0), f_as_i / i_as_f (reinterpret),
 *   load_codes32(codes, check) (the low halves of NBLOCK codes, each checked <= max_code,
 *   which is below 2^31 there), store_weights32 (as store_weights, of the scale)
 * and for K = 4 with the rows in 32-bit lanes (double lanes' results moved between the two):
 *   i_shr1 (arithmetic >> 1), i_add_where / i_sub_where(a, m, b) (a + b, a - b where m),
 *   i_from_pair(a, b) / f_from_pair(a, b) (two blocks of doubles as NBLOCK int32, integral and in
 *   range, or floats, rounded), v_from_i_pair(a, &first, &second) (the inverse for int32), and
 *   the wide driver's u_load and v_from_u (codes below 2^52 as doubles)
 * and SIMD_NAME(name), the entry points' names. The functions return how many leading vertices
 * they handled (whole blocks); the caller's scalar loop does the rest.
 *
 * Why stages: a block's whole encode or decode is one long dependency chain, and the core keeps
 * only a few blocks' worth of waiting operations in flight, so the work runs in stages of short
 * chains, each over all blocks of a chunk before the next: the blocks of one stage are
 * independent, and the core overlaps them (K = 4 encode ~1.5x, decode ~1.1x on AVX2).
 */

/* ---- the block walk, shared by every driver --------------------------------------------- */

/*
 * Every driver (double lanes here, 32-bit lanes for narrow decode, codec_oss_wide_simd.h's
 * 64-bit lanes) walks a batch the same way: chunks of whole blocks, each chunk's stages over all
 * its blocks, then the scalar redo of the lanes it missed. The walks are written once as macros
 * that define one walk function per chunk function, with the block size, chunk size and salvage
 * mode as literal constants: each chunk is a direct call inlined into a walk whose loop bounds
 * are known (as function parameters, folded only after inlining, decode ran 3-5% more
 * instructions under callgrind). A chunk takes (codec, constants, input, blocks, output..., k,
 * layout), constants being the driver's per-codec values, computed once a batch (NULL for the
 * double lanes).
 */

/* The scalar redo of the lanes of `blocks` blocks of `lanes` lanes set in missed[b] (a pass of
 * its own: a call among the vector stages would clobber every vector register). */
SP_INLINE SIMD_FN void redo_encode(const sp_codec* codec, const float* weights, size_t blocks, size_t lanes,
                                   const unsigned* missed, uint32_t k, uint64_t* codes, uint8_t* significant)
{
    for (size_t b = 0; b < blocks; ++b)
        for (size_t lane = b * lanes, slow = missed[b]; slow; ++lane, slow >>= 1)
            if (slow & 1) codes[lane] = sp_oss_encode_one(codec, weights + lane * k, significant ? significant + lane : NULL);
}

SP_INLINE SIMD_FN void redo_decode(const sp_codec* codec, const uint64_t* codes, size_t blocks, size_t lanes,
                                   const unsigned* missed, uint32_t k, float* weights)
{
    for (size_t b = 0; b < blocks; ++b)
        for (size_t lane = b * lanes, slow = missed[b]; slow; ++lane, slow >>= 1)
            if (slow & 1) sp_oss_decode_one(codec, codes[lane], weights + lane * k);
}

/* `name`: an encode over `chunk` (void, up to ENCODE_CHUNK blocks): full chunks with a constant
 * block count (their stage loops unrolled), then the tail's blocks; returns the vertices done. */
#define DEFINE_ENCODE_WALK(name, chunk)                                                                                  \
    SP_INLINE SIMD_FN size_t name(const sp_codec* codec, const void* constants, const float* weights, size_t count,   \
                                  uint64_t* codes, uint8_t* significant, uint32_t k)                                     \
    {                                                                                                                    \
        simd_layout layout = layout_for(k);                                                                              \
        size_t v = 0;                                                                                                    \
        for (; v + ENCODE_CHUNK * BLOCK <= count; v += ENCODE_CHUNK * BLOCK)                                             \
            chunk(codec, constants, weights + v * k, ENCODE_CHUNK, codes + v, significant ? significant + v : NULL, k,  \
                  &layout);                                                                                              \
        size_t blocks = (count - v) / BLOCK;                                                                             \
        if (blocks)                                                                                                      \
            chunk(codec, constants, weights + v * k, blocks, codes + v, significant ? significant + v : NULL, k, &layout); \
        return v + blocks * BLOCK;                                                                                       \
    }

/* `name`: a decode over `chunk` (int: 0, writing nothing, where the chunk holds a code above
 * max_code) in chunks of up to `most` blocks of `lanes` lanes from vertex v; returns where it
 * stopped. At a chunk holding an invalid code: with `salvage` (BLOCK lanes) the blocks before
 * the invalid code's block are decoded and the walk ends after them (the scalar loop reports the
 * code); without it the walk ends before the chunk (for a walk in other lanes to go on from). */
#define DEFINE_DECODE_WALK(name, chunk, lanes, most, salvage)                                                            \
    SP_INLINE SIMD_FN size_t name(const sp_codec* codec, const void* constants, const uint64_t* codes, size_t v,      \
                                  size_t count, float* weights, uint32_t k, const simd_layout* layout)                 \
    {                                                                                                                    \
        while (v + lanes <= count) {                                                                                     \
            size_t blocks = (count - v) / lanes, valid = 0;                                                              \
            if (blocks > most) blocks = most;                                                                            \
            if (!chunk(codec, constants, codes + v, blocks, weights + v * k, k, layout)) {                               \
                while (salvage && valid < blocks && codes_valid(codes + v + valid * BLOCK, codec->max_code)) ++valid;    \
                if (valid) chunk(codec, constants, codes + v, valid, weights + v * k, k, layout);                        \
                return v + valid * lanes;                                                                                \
            }                                                                                                            \
            v += blocks * lanes;                                                                                         \
        }                                                                                                                \
        return v;                                                                                                        \
    }

/* return f(arguments..., k) with the codec's k as a constant (unrolled lanes). */
#define RETURN_FOR_EACH_K(codec, f, ...)                                                                                 \
    switch ((codec)->influences) {                                                                                       \
    case 2: return f(__VA_ARGS__, 2);                                                                                    \
    case 3: return f(__VA_ARGS__, 3);                                                                                    \
    default: return f(__VA_ARGS__, 4);                                                                                   \
    }

/* s_B(j) = floor(((4B + 2 - 3j) j + 1) / 4) for rows inside the triangle (positive), as
 * floor((B + 1/2 - 3j/4) j + 1/4): every exact intermediate is a multiple of 1/4 below 2^50, so
 * each step, fused or not, is exact. */
SP_INLINE SIMD_FN vec row_base(vec b, vec j)
{
    vec quarter = v_fnmadd(j, v_splat(0.75), v_add(b, v_splat(0.5))); /* (4B + 2 - 3j) / 4 */
    return v_floor(v_fmadd(quarter, j, v_splat(0.25)));
}

/* u(k) = floor((3Nk(N - 2k + 3) + k((4k - 9)k + 6) + 2) / 9), for k <= (N + 1)/2, with the
 * numerator a in Horner form ((4k - 6N - 9) k + 3N^2 + 9N + 6) k + 2: integers below 2^50, so
 * exact, and the last step adds 1/2 as well: a = 9m + r with 0 <= r < 9 puts (a + 1/2) / 9 at
 * least 1/18 away from an integer, while the product with the rounded 1/9 is within
 * (a/9) 2^-52 < 1/36 of it, so its floor is the exact quotient m. */
SP_INLINE SIMD_FN vec layer_base(double n, vec k)
{
    vec a = v_fmadd(k, v_splat(4.0), v_splat(-(6 * n + 9)));
    vec b = v_fmadd(a, k, v_splat(3 * n * n + 9 * n + 6));
    return v_floor(v_mul(v_fmadd(b, k, v_splat(2.5)), v_splat(1.0 / 9.0)));
}

/* ---- encode ----------------------------------------------------------------------------- */

/* sp_grid_load's scale in lanes (the same sum from w0, the same division): a stage of its own, as the
 * division ends a chain. */
SP_INLINE SIMD_FN vec quantize_scale(const vec* w, uint32_t k, double s)
{
    vec sum = w[0];
    SP_UNROLL
    for (uint32_t i = 1; i < k; ++i) sum = v_add(sum, w[i]);
    return v_div(v_splat(s), sum);
}

/* The lanes whose weights are sorted and non-negative (no NaN), as bits: the only ones the
 * vector encode keeps. There w s / sum >= 0 (or NaN, where the sum is 0), so the scalar's
 * max(x, 0) is x (-0 for -0, equal for every later use), and the floors are sorted too, which
 * the rounding keeps (for equal floors the earlier remainder is not smaller, so it wins), so
 * the index is the scalar's: for unsorted q the scalar wraps around. */
SP_INLINE SIMD_FN unsigned weights_ordered(const vec* w, uint32_t k)
{
    mask ok = m_ge(w[k - 1], v_zero());
    SP_UNROLL
    for (uint32_t i = 1; i < k; ++i) ok = m_and(ok, m_ge(w[i - 1], w[i]));
    return m_bits(ok);
}

/*
 * A batch streams through the lanes faster than the core's prefetchers fetch it: 1M vertices of
 * K = 4 took AVX2 ~3.3-4 ns a vertex to encode where the same code takes ~2.5 on data in the
 * cache, and ~3.7-4.2 to decode (wide codes) where it takes ~2.9. So each block of a chunk's
 * first stage asks for the weight and code lines of the lanes STREAM_PREFETCH vertices ahead,
 * every line of them (AVX-512's K = 4 block spans two lines of weights). Encode: ~1.3x for AVX2
 * and AVX-512 alike, the output codes' lines gaining the most (their stores no longer wait for
 * each line to be read for ownership); K = 2 pair lanes ~1.15x. Decode: wide K = 4 ~1.3x (AVX2)
 * and ~1.2x (AVX-512), the rest ~1.1x. The addresses are formed as integers, as they may lie
 * past the batch (a prefetch never faults).
 */
#define STREAM_PREFETCH 128 /* vertices ahead: 64 and 256 ran up to ~10% slower (encode, AVX2, AVX-512) */

SP_INLINE SIMD_FN void prefetch_ahead(const void* lane, uint32_t lane_bytes, uint32_t lanes)
{
    uintptr_t at = (uintptr_t)lane + STREAM_PREFETCH * lane_bytes;
    for (uint32_t line = 0; line < lanes * lane_bytes; line += 64) SP_PREFETCH((const void*)(at + line));
}

SP_INLINE SIMD_FN void prefetch_lanes(const float* weights, uint32_t k, const uint64_t* codes, uint32_t lanes)
{
    prefetch_ahead(weights, k * sizeof(float), lanes);
    prefetch_ahead(codes, sizeof(uint64_t), lanes);
}

/*
 * Decode batches of at least STREAM_MIN_BYTES of weights (codec_oss_batch.c) store them by
 * streaming stores (layout->stream: the primitives' put8 and the like), as glibc's memcpy does
 * past its non-temporal threshold: each line goes to memory once, not read for ownership first
 * and then written back, and the caches keep what they held. 1M K = 4 vertices from cold memory
 * (a 32 MB copy before each run), 16-bit codes: AVX2 ~1.4x, AVX-512 ~1.5x. The weights' lines
 * are then not prefetched: a streaming store to a line in the cache evicts it, and with that
 * prefetch kept the same runs ran at 0.89x and 0.82x of the normal stores' speed.
 */
/* Whether to stream the weights from `weights` on: where asked and the start is aligned as the
 * ISA's streaming stores need (STREAM_ALIGN; codec_oss_batch.c aligns it to a line). */
SP_INLINE int stream_from(const float* weights, int stream)
{
    return stream && !((uintptr_t)weights & (STREAM_ALIGN - 1));
}

SP_INLINE SIMD_FN void prefetch_decode(const simd_layout* layout, const float* weights, uint32_t k,
                                       const uint64_t* codes, uint32_t lanes)
{
    if (!layout->stream) prefetch_ahead(weights, k * sizeof(float), lanes);
    prefetch_ahead(codes, sizeof(uint64_t), lanes);
}

/* Whether the first stage takes the products x = w s / sum too (the rounding's stage then starts
 * from x): for K = 4, whose first stage leaves the multiply pipes idle while the rounding's
 * stage is the longest (AVX2 ~1.02x; K = 3 ran ~0.98x, its first stage shorter). */
SP_INLINE int scaled_first(uint32_t k)
{
    return k == 4;
}

/* A block's weights (K vectors; times the scale where scaled_first), sp_grid_load's scale and
 * the ordered lanes (weights_ordered), the encode's first stage: the ISA's load_weights_ordered
 * where it has one (LOAD_ORDERED), which may load and check the weights in fewer operations
 * (for K = 4 on AVX2). */
SP_INLINE SIMD_FN unsigned load_block(const float* weights, uint32_t k, const simd_layout* layout, double s, vec* w,
                                      vec* scale)
{
    unsigned ordered;
#if LOAD_ORDERED
    if (k == 4) ordered = load_weights_ordered(weights, w);
    else
#endif
    {
        load_weights(weights, k, layout, w);
        ordered = weights_ordered(w, k);
    }
    *scale = quantize_scale(w, k, s);
    if (scaled_first(k)) {
        SP_UNROLL
        for (uint32_t i = 0; i < k; ++i) w[i] = v_mul(w[i], *scale);
    }
    return ordered;
}

/* sp_grid_quantize's floors x = w s / sum (w already x where scaled_first) -> q = trunc(x),
 * remainder = x - q, same operations in the same order for the ordered lanes; returns the
 * threshold COUNTER_BIAS + the deficit s - sum of q (the counters' form of it, c_below), by the
 * same running difference from COUNTER_BIAS + s (integers below 2^53: the same values, shifted,
 * wherever the deficit is in [0, k), quantize_round). */
SP_INLINE SIMD_FN vec quantize_floor(const vec* w, uint32_t k, double s, vec scale, vec* q, vec* remainder)
{
    vec threshold = v_splat(s + COUNTER_BIAS);
    SP_UNROLL
    for (uint32_t i = 0; i < k; ++i) {
        vec x = scaled_first(k) ? w[i] : v_mul(w[i], scale), floor = v_trunc(x);
        remainder[i] = v_sub(x, floor);
        threshold = v_sub(threshold, floor);
        if (i > 0) q[i] = floor; /* q[0], which neither the index nor the counts read, not even stored */
    }
    return threshold;
}

/*
 * sp_grid_quantize's last step: the deficit goes, one each, to the components with the largest
 * remainders (ties to the lower index), chosen by rank; q[0], which the index and the
 * significant count do not read, is left unrounded. Returns the lanes the fast path is exact
 * for: a deficit in [0, k) (c_deficit_fits), where the scalar takes the same path. That also
 * bounds every x by s + 1, so floors and deficit are exact: an x past that makes the deficit
 * negative, and one past 2^53 (or infinite) keeps it so under rounding. In the lanes kept (those
 * and the caller's ordered ones) every x is +0 or more, or -0 (a -0 weight; its remainder is
 * +0), so every remainder is in [+0, 1), which rank_pair may rely on: an ordered lane whose x is
 * NaN (weights all zero, or one infinite) has a NaN deficit, which fails. Other lanes get some q:
 * they are redone.
 */
SP_INLINE SIMD_FN mask quantize_round(uint32_t k, vec threshold, const vec* remainder, vec* q)
{
    counter rank[SP_MAX_INFLUENCES]; /* from 0 to k - 1, so the counters never leave their range */
    SP_UNROLL
    for (uint32_t i = 0; i < k; ++i) rank[i] = rank_start(i, k);
    SP_UNROLL
    for (uint32_t a = 0; a < k; ++a)
        SP_UNROLL
        for (uint32_t b = a + 1; b < k; ++b) rank_pair(remainder[a], remainder[b], &rank[a], &rank[b]);
    vec one = v_splat(1.0);
    SP_UNROLL
    for (uint32_t i = 1; i < k; ++i) q[i] = v_add_where(q[i], c_below(rank[i], threshold), one); /* q[0] is implied */
    return c_deficit_fits(threshold, k);
}

/*
 * Encode's floors without a floor instruction (two micro-ops on Intel's cores): every double in
 * [2^52, 2^53) is an integer, so for |v| < 2^51 an FMA that adds ROUNDING_MAGIC = 1.5 2^52 rounds
 * a b + c to ROUNDING_MAGIC + nearest(a b + c - ROUNDING_MAGIC) exactly, the integer sums after it
 * stay exact, and the bits of ROUNDING_MAGIC + m less those of ROUNDING_MAGIC are m
 * (store_biased_codes). A floor becomes a nearest where the exact value is known to sit away
 * from every half-integer:
 *   - s_B(j) = floor(((4B + 2 - 3j) j + 1) / 4): that numerator is (j + 1)^2 mod 4 (4Bj drops,
 *     -3 = 1 mod 4), 0 for odd j and 1 for even j, so with quarter = (4B + 2 - 3j) / 4,
 *     quarter j is s_B(j) (j even) or s_B(j) - 1/4 (j odd): its nearest integer is s_B(j);
 *   - u(k) = floor(a / 9) for a = 9u + r, 0 <= r < 9: (a - 4) / 9 = u + (r - 4) / 9 is within
 *     4/9 of u, and its product with the rounded 1/9 within |a| 2^-57 < 2^-6 (a < 2^51) of that,
 *     so at least 1/18 - 2^-6 from a half-integer: its nearest integer is u.
 */
#define ROUNDING_MAGIC 6755399441055744.0 /* 1.5 * 2^52 */

/* ROUNDING_MAGIC + floor(a / 9) for integral 0 <= a < 2^51 given as t = a - 4 (exact, so the
 * caller folds the -4 into a constant): one FMA. */
SP_INLINE SIMD_FN vec biased_ninth(vec t)
{
    return v_fmadd(t, v_splat(1.0 / 9.0), v_splat(ROUNDING_MAGIC));
}

/* ROUNDING_MAGIC + s_B(j) + z for `half_apex` = B + 1/2 and integral z with |s_B(j) + z| < 2^51,
 * where `biased_z` = ROUNDING_MAGIC + z: quarter = (4B + 2 - 3j) / 4 (exact: quarters below 2^50)
 * and one FMA, rounding quarter j + biased_z to the nearest integer. */
SP_INLINE SIMD_FN vec biased_row(vec half_apex, vec j, vec biased_z)
{
    return v_fmadd(v_fnmadd(j, v_splat(0.75), half_apex), j, biased_z);
}

/* ROUNDING_MAGIC + u(k) (layer_base's numerator a = ((4k - 6N - 9) k + 3N^2 + 9N + 6) k + 2
 * in Horner form, its last step taking 4 off, for biased_ninth). */
SP_INLINE SIMD_FN vec biased_layer_base(double n, vec k)
{
    vec a = v_fmadd(k, v_splat(4.0), v_splat(-(6 * n + 9)));
    vec b = v_fmadd(a, k, v_splat(3 * n * n + 9 * n + 6));
    return biased_ninth(v_fmsub(b, k, v_splat(2.0)));
}

/* sp_oss_pack on sorted lanes (the caller masks the others) for K = 3, 4, plus ROUNDING_MAGIC:
 * s_N(q2) + (q1 - q2), u(k) + s_{N-2k}(q2 - q3) + (q1 - q2) with k = q3, codes below 2^50. */
SP_INLINE SIMD_FN vec pack_block(const vec* q, uint32_t k, double n)
{
    vec offset = v_sub(q[1], q[2]);
    if (k == 3) return biased_row(v_splat(n + 0.5), q[2], v_add(offset, v_splat(ROUNDING_MAGIC)));
    vec half_apex = v_fnmadd(q[3], v_splat(2.0), v_splat(n + 0.5)); /* N - 2k + 1/2 */
    return biased_row(half_apex, v_sub(q[2], q[3]), v_add(biased_layer_base(n, q[3]), offset));
}

/* Significant counts of sorted lanes: 1 + the non-zero components after the first. */
SP_INLINE SIMD_FN void store_significant(const vec* q, uint32_t k, uint8_t* out)
{
    vec count = v_splat(1.0);
    SP_UNROLL
    for (uint32_t i = 1; i < k; ++i) count = v_add_where(count, m_gt(q[i], v_zero()), v_splat(1.0));
    store_counts(count, out);
}

/* The rounding of one block's floors: the lanes the vector code cannot prove exact (outside
 * `ordered`, or past the fast path's deficits), as bits. */
SP_INLINE SIMD_FN unsigned round_block(uint32_t k, vec threshold, const vec* remainder, vec* q, unsigned ordered)
{
    return ~(m_bits(quantize_round(k, threshold, remainder, q)) & ordered) & ((1u << BLOCK) - 1);
}

/* sp_grid_quantize of one block into q (which may be w: each floor replaces its weight after
 * the weight's last read): the lanes it cannot prove exact, as bits (round_block). The
 * remainders, which only the rounding reads, stay locals: registers, no stores. */
SP_INLINE SIMD_FN unsigned quantize_block(const vec* w, uint32_t k, double s, vec scale, unsigned ordered, vec* q)
{
    vec remainder[SP_MAX_INFLUENCES];
    vec threshold = quantize_floor(w, k, s, scale, q, remainder);
    return round_block(k, threshold, remainder, q, ordered);
}

/* The indices (and counts) of one block's sorted lanes. */
SP_INLINE SIMD_FN void store_block(const vec* q, uint32_t k, double n, uint64_t* codes, uint8_t* significant)
{
    if (k == 2) store_codes(codes, q[1]);
    else store_biased_codes(codes, pack_block(q, k, n));
    if (significant) store_significant(q, k, significant);
}

/* Whether a chunk's floors, rounding and indices run in one stage (else two: floors and
 * rounding, then the indices). One where ENCODE_FUSED (with 32 registers a block's floors stay
 * in registers through the rounding and the index: on Zen 4 AVX-512 K = 2 ~1.14x as fast as in
 * two stages, K = 3 the same) but for K = 4, whose index chain (and the wide lanes' 64-bit
 * product) makes one stage too long for the core to overlap blocks: two stages ran AVX-512
 * K = 4 ~1.07x as fast, the wide lanes ~1.1x. With 16 registers (AVX2) one stage spills (~25%
 * slower for K = 4), and two stages ran K = 2 ~1.2x, K = 3 ~1.1x, K = 4 ~1.07x as fast as
 * three with the rounding a stage of its own. */
SP_INLINE int encode_fused(uint32_t k)
{
    return ENCODE_FUSED && k < 4;
}

/* Encodes `blocks` (<= ENCODE_CHUNK) blocks in stages: the quantisation's division, then the
 * floors, rounding and indices (encode_fused), then the scalar redo of the lanes the vector code
 * cannot prove exact. The fused floors stay locals, as the remainders do (quantize_block): no
 * stores of them; unfused, the floors replace the weights. */
SP_INLINE SIMD_FN void encode_chunk(const sp_codec* codec, const void* constants, const float* weights, size_t blocks,
                                    uint64_t* codes, uint8_t* significant, uint32_t k, const simd_layout* layout)
{
    (void)constants;
    double s = (double)codec->scale, n = (double)codec->n;
    vec w[ENCODE_CHUNK][SP_MAX_INFLUENCES], scale[ENCODE_CHUNK];
    unsigned missed[ENCODE_CHUNK], ordered[ENCODE_CHUNK], any = 0; /* lanes as bits */
    for (size_t b = 0; b < blocks; ++b) {
        prefetch_lanes(weights + b * BLOCK * k, k, codes + b * BLOCK, BLOCK);
        ordered[b] = load_block(weights + b * BLOCK * k, k, layout, s, w[b], &scale[b]);
    }
    for (size_t b = 0; b < blocks; ++b) {
        vec floors[SP_MAX_INFLUENCES], *q = encode_fused(k) ? floors : w[b];
        any |= missed[b] = quantize_block(w[b], k, s, scale[b], ordered[b], q);
        if (encode_fused(k)) store_block(q, k, n, codes + b * BLOCK, significant ? significant + b * BLOCK : NULL);
    }
    if (!encode_fused(k) && significant)
        for (size_t b = 0; b < blocks; ++b) store_block(w[b], k, n, codes + b * BLOCK, significant + b * BLOCK);
    else if (!encode_fused(k)) /* the loop without the counts' test and pointer in it */
        for (size_t b = 0; b < blocks; ++b) store_block(w[b], k, n, codes + b * BLOCK, NULL);
    if (any) redo_encode(codec, weights, blocks, BLOCK, missed, k, codes, significant); /* most chunks have none */
}

DEFINE_ENCODE_WALK(encode_walk, encode_chunk)

SIMD_FN size_t SIMD_NAME(encode)(const sp_codec* codec, const float* weights, size_t count, uint64_t* codes,
                                 uint8_t* significant)
{
    RETURN_FOR_EACH_K(codec, encode_walk, codec, NULL, weights, count, codes, significant)
}

/* ---- decode ----------------------------------------------------------------------------- */

/*
 * The layer: sp_oss_unpack's estimate (2N + 3 - t) / 4 with t = c + 1/c,
 * c = cbrt(V - 1 + sqrt(V (V - 2))), for code + 17/18 instead of code, floored and clamped to
 * the layers. V = 72 (u~(k0) - code) with k0 = (N + 1)/2 and u~ the unfloored u
 * (u~(k) - u(k) in [0, 8/9]), which increases up to k0, so every code of layer k plus 17/18 lies
 * strictly between u~(k) and u~(k + 1) (the same shift as the row estimate's 7/8) and in exact
 * arithmetic the estimate is the layer; it also keeps V >= 4 for valid codes.
 * c^3 + 1/c^3 = 2(V - 1) = x, so t is the root t >= 2 of t^3 - 3t = x, and cbrt(x) + 1/cbrt(x)
 * is within c^-5/3 of it (below 1e-6 but for the last few codes, where x < 2000), which skips
 * the scalar's square root; the ISA's root_start/root_finish compute it without a division.
 * Codes within the estimate's error of a layer boundary land in the wrong layer, and the row
 * check sends them to the scalar code.
 */

/* x = 2(V - 1) for code + 17/18: an integer below 2^53 (see BATCH_MAX_N4), so the fused product is exact. */
SP_INLINE SIMD_FN vec layer_argument(double n, vec code)
{
    double m = n + 1;
    return v_fnmadd(code, v_splat(144.0), v_splat(8 * m * m * m + 12 * m * m - 106));
}

/* floor(e) clamped to [0, top]; NaN becomes 0 (max returns its second operand). */
SP_INLINE SIMD_FN vec clamp_floor(vec e, vec top)
{
    return v_min(v_max(v_floor(e), v_zero()), top);
}

SP_INLINE SIMD_FN vec layer_estimate(double n, vec t)
{
    vec estimate = v_fnmadd(t, v_splat(0.25), v_splat((2 * n + 3) / 4));
    return clamp_floor(estimate, v_splat((double)(((uint64_t)n + 1) / 2 - 1)));
}

/* The row: the mirrored square root estimate for w + 7/8 instead of w in the triangle with
 * B = `bottom` samples along its bottom edge, floored and clamped to j >= 0. s(j) = floor(s~(j))
 * with s~(j) - s(j) in {0, 1/4, 1/2, 3/4}, so w + 7/8 lies strictly between s~(j) and
 * s~(j + 1) for every w of row j, and in exact arithmetic the estimate is the row. With
 * apex = 2B + 1, 12 (w + 7/8) = 12 w + 10.5: mirrored = apex^2 + 3 - 10.5 - 12 w. The correctly
 * rounded sqrt keeps the rounding error far below the 1/8 margin up to the largest N. No clamp
 * to the last row: the estimate is at most apex / 3 < rows + 1, and row_offset rejects
 * j = rows (a row of no codes). */
SP_INLINE SIMD_FN vec row_mirrored(vec apex, vec w)
{
    return v_fnmadd(w, v_splat(12.0), v_fmsub(apex, apex, v_splat(7.5)));
}

/* The estimate from apex and the mirrored argument (0 where that is NaN or negative). */
SP_INLINE SIMD_FN vec row_from_mirrored(vec apex, vec mirrored)
{
    vec estimate = v_mul(v_sub(apex, v_sqrt(mirrored)), v_splat(1.0 / 3.0));
    return v_max(v_floor(estimate), v_zero());
}

SP_INLINE SIMD_FN vec row_estimate(vec bottom, vec w)
{
    vec apex = v_fmadd(bottom, v_splat(2.0), v_splat(1.0));
    return row_from_mirrored(apex, row_mirrored(apex, w));
}

/* i = w - s(j), and *ok the lanes where j is w's row, that is where i is in
 * [0, floor((2B - 3j) / 2)), the length of row j (none for j >= rows): for integral i that is
 * 0 <= i <= B - 1 - 3j/2. Exact: integers and halves below 2^50. */
SP_INLINE SIMD_FN vec row_offset(vec bottom, vec j, vec w, mask* ok)
{
    vec i = v_sub(w, row_base(bottom, j));
    vec last = v_fnmadd(j, v_splat(1.5), v_sub(bottom, v_splat(1.0)));
    *ok = m_and(m_ge(i, v_zero()), m_ge(last, i));
    return i;
}

/* sp_oss_unpack's sorted grid components for K = 3, 4 from the layer (0 for K = 3), row j and
 * offset i: integers below 2^50, so exact in any order. */
SP_INLINE SIMD_FN void unpacked_block(double n, uint32_t k, vec layer, vec row, vec i, vec* q)
{
    if (k == 4) q[3] = layer;
    q[2] = k == 4 ? v_add(row, layer) : row;
    q[1] = v_add(i, q[2]);
    vec sum = v_add(q[1], q[2]);
    q[0] = v_sub(v_splat(2 * (n - 1)), k == 4 ? v_add(sum, layer) : sum);
}

/* The last stage's grid components of one block (layer and bottom unused for K = 2, 3) and
 * the lanes the row check rejects, as bits. */
SP_INLINE SIMD_FN unsigned decoded_block(double n, uint32_t k, vec layer, vec bottom, vec row, vec rest, vec* q)
{
    if (k == 2) {
        q[1] = rest;
        q[0] = v_sub(v_splat(2 * (n - 1)), rest);
        return 0;
    }
    mask ok;
    vec i = row_offset(k == 4 ? bottom : v_splat(n), row, rest, &ok);
    unpacked_block(n, k, k == 4 ? layer : v_zero(), row, i, q);
    return ~m_bits(ok) & ((1u << BLOCK) - 1);
}

/* sp_oss_unpack and sp_grid_to_weights for `blocks` blocks of codes, in stages (the layer
 * root's two halves, the row, the rest), then the scalar redo of the lanes it missed. Every
 * array entry is written in a stage before a later one reads it. The codes are checked against
 * max_code as they are loaded: a chunk with an invalid one is left unwritten (returns 0).
 *
 * The layer needs no check of its own: with k clamped to the layers, the row check accepts
 * only a rest = code - u(k) inside layer k's triangle (a negative rest fails s(j) <= rest, one
 * past the triangle fails rest < s(j + 1) for every row, row j >= rows has s(j + 1) <= s(j)),
 * and then (k, row, i) is the one tuple whose index is code. */
/* `blocks` blocks of codes into `code`, each checked against max_code: 0 where one is above it;
 * the lines of the codes (and of the weights they decode to, unless streamed) asked for ahead. */
SP_INLINE SIMD_FN int load_chunk(const sp_codec* codec, const uint64_t* codes, size_t blocks, const float* weights,
                                 uint32_t k, const simd_layout* layout, vec* code)
{
    code_check check = check_start(codec->max_code);
    for (size_t b = 0; b < blocks; ++b) {
        prefetch_decode(layout, weights + b * BLOCK * k, k, codes + b * BLOCK, BLOCK);
        code[b] = load_codes(codes + b * BLOCK, &check);
    }
    return check_passed(&check);
}

SP_INLINE SIMD_FN int decode_chunk(const sp_codec* codec, const void* constants, const uint64_t* codes, size_t blocks,
                                   float* weights, uint32_t k, const simd_layout* layout)
{
    (void)constants;
    double n = (double)codec->n, inverse = 1.0 / (double)codec->scale;
    vec layer[DECODE_CHUNK], rest[DECODE_CHUNK], bottom[DECODE_CHUNK], row[DECODE_CHUNK], x[DECODE_CHUNK];
    root z[DECODE_CHUNK];
    unsigned missed[DECODE_CHUNK], any = 0; /* lanes as bits */
    if (!load_chunk(codec, codes, blocks, weights, k, layout, rest)) return 0; /* nothing written yet */
    if (k == 4) {
        for (size_t b = 0; b < blocks; ++b) {
            x[b] = layer_argument(n, rest[b]);
            z[b] = root_start(x[b]);
        }
        for (size_t b = 0; b < blocks; ++b) layer[b] = layer_estimate(n, root_finish(x[b], z[b]));
    }
    if (k > 2)
        for (size_t b = 0; b < blocks; ++b) {
            if (k == 4) {
                rest[b] = v_sub(rest[b], layer_base(n, layer[b]));
                bottom[b] = v_fnmadd(layer[b], v_splat(2.0), v_splat(n));
            }
            row[b] = row_estimate(k == 4 ? bottom[b] : v_splat(n), rest[b]); /* K = 3: one triangle, constants */
        }
    size_t b = 0;
    for (; b + 1 < blocks; b += 2) { /* two blocks a step: store_pair may store them faster together */
        vec first[SP_MAX_INFLUENCES], second[SP_MAX_INFLUENCES];
        any |= missed[b] = decoded_block(n, k, layer[b], bottom[b], row[b], rest[b], first);
        any |= missed[b + 1] = decoded_block(n, k, layer[b + 1], bottom[b + 1], row[b + 1], rest[b + 1], second);
        store_pair(first, second, k, inverse, layout, weights + b * BLOCK * k);
    }
    if (b < blocks) {
        vec q[SP_MAX_INFLUENCES];
        any |= missed[b] = decoded_block(n, k, layer[b], bottom[b], row[b], rest[b], q);
        store_weights(q, k, inverse, layout, weights + b * BLOCK * k);
    }
    if (any) redo_decode(codec, codes, blocks, BLOCK, missed, k, weights);
    return 1;
}

DEFINE_DECODE_WALK(decode_walk, decode_chunk, BLOCK, DECODE_CHUNK, 1)

/* ---- decode in 32-bit lanes ------------------------------------------------------------- */

/*
 * Narrow codes (K = 3 up to N = NARROW_MAX_N3, K = 4 up to NARROW_MAX_N4: codes of up to 24
 * and 25 bits) decode in int32 / float lanes, twice as many a register as doubles. The exact
 * parts run in int32, where every intermediate is an integer below 2^31: the row base
 * ((4B + 2 - 3j) j + 1) / 4 < (4B + 2)^2 / 12, the row root's argument apex^2 - 12 w, the layer
 * numerator 9 u(k) + r < 2^31 (its floor by 9 through a 32 x 32-bit product, i_div9); the row
 * and layer estimates run in float, as estimates only: an estimate that misses (more often than
 * in double: ~3e-4 of random K = 3 codes at 24 bits) fails the same exact row check and is
 * redone by the scalar code. The weights are the correctly rounded q/s (store_weights32), which
 * the double product of the scalar code is too for these q and s. (The limits are in
 * codec_oss_wide.h, with the double lanes', for the tests to use.)
 */
SP_INLINE int narrow_decode(const sp_codec* codec, uint32_t k)
{
    return (k == 3 && codec->n <= NARROW_MAX_N3) || (k == 4 && codec->n <= NARROW_MAX_N4);
}

/* s_B(j) = ((4B + 2 - 3j) j + 1) / 4 (floor: the numerator is positive) with 4B + 2 = 2 apex. */
SP_INLINE SIMD_FN nint n_row_base(nint apex, nint three_j, nint j)
{
    nint slope = i_sub(i_add(apex, apex), three_j);
    return i_shr2(i_add(i_mullo(slope, j), i_splat(1)));
}

/* cbrt(x) + 1/cbrt(x) in float to ~1e-7 (x >= 1; garbage lanes for others, which the row check
 * rejects): z ~ x^(-1/3) by the exponent/3 bit trick and two third-order steps
 * z (1 + r/3 + 2r^2/9), r = 1 - x z^3 (n_root_step), then c = x z^2 and c + z. */
SP_INLINE SIMD_FN nvec n_root_step(nvec x, nvec z)
{
    nvec xz = f_mul(x, z), r = f_fnmadd(xz, f_mul(z, z), f_splat(1.0f));
    return f_fmadd(f_mul(z, r), f_fmadd(r, f_splat(2.0f / 9.0f), f_splat(1.0f / 3.0f)), z);
}

/* A first z ~ x^(-1/3) (x >= 1). */
SP_INLINE SIMD_FN nvec n_root_start(nvec x)
{
    nint third = i_trunc(f_mul(i_to_f(f_as_i(x)), f_splat(1.0f / 3.0f)));
    return n_root_step(x, i_as_f(i_sub(i_splat(1419916032), third)));
}

/* The layer root's argument x for each code (layer_argument) and a first z ~ x^(-1/3). */
SP_INLINE SIMD_FN nvec n_layer_start(double n, nint code, nvec* z)
{
    double m = n + 1;
    nvec x = f_fnmadd(i_to_f(code), f_splat(144.0f), f_splat((float)(8 * m * m * m + 12 * m * m - 106)));
    *z = n_root_start(x);
    return x;
}

/* The layer of each code from x and z, as layer_estimate, taken `low` layers lower. */
SP_INLINE SIMD_FN nint n_layer_finish(double n, nvec x, nvec z, double low)
{
    z = n_root_step(x, z);
    nvec estimate = f_fnmadd(f_fmadd(f_mul(x, z), z, z), f_splat(0.25f), f_splat((float)((2 * n + 3) / 4 - low)));
    return i_min(i_max(i_trunc(estimate), i_splat(0)), i_splat((int32_t)(((uint64_t)n + 1) / 2 - 1)));
}

/* u(k) as layer_base: 9 u(k) + r = ((4k - 6N - 9) k + 3N^2 + 9N + 6) k + 2, the inner factor
 * positive; four_k = 4k. */
SP_INLINE SIMD_FN nint n_layer_base(double n, nint layer, nint four_k)
{
    nint a = i_add(i_mullo(i_sub(four_k, i_splat((int32_t)(6 * n + 9))), layer), i_splat((int32_t)(3 * n * n + 9 * n + 6)));
    return i_div9(i_add(i_mullo(a, layer), i_splat(2)));
}

/* The row estimate (row_estimate: the mirrored root for w + 7/8, apex^2 + 3 - 10.5 - 12 w),
 * the argument exact in int32, the root in float; trunc and floor agree after the clamp. */
SP_INLINE SIMD_FN nint n_row_estimate(nint apex, nint w)
{
    nint mirrored = i_sub(i_mullo(apex, apex), i_add(i_mullo(w, i_splat(12)), i_splat(8)));
    nvec root = f_sqrt(f_add(i_to_f(mirrored), f_splat(0.5f)));
    return i_max(i_trunc(f_mul(f_sub(i_to_f(apex), root), f_splat(1.0f / 3.0f))), i_splat(0)); /* NaN: 0 */
}

/* sp_oss_unpack's sorted grid components from the layer (K = 4), row j and offset i, as
 * unpacked_block: integers below 2^31. */
SP_INLINE SIMD_FN void n_components(double n, uint32_t k, nint layer, nint row, nint i, nint* q)
{
    if (k == 4) q[3] = layer;
    q[2] = k == 4 ? i_add(row, layer) : row;
    q[1] = i_add(i, q[2]);
    nint sum = i_add(q[1], q[2]);
    q[0] = i_sub(i_splat((int32_t)(2 * (n - 1))), k == 4 ? i_add(sum, layer) : sum);
}

/* Grid components of one block from layer, row estimate and rest (row_offset's check: the lanes
 * where i = w - s_B(j) is not in [0, (2B - 3j) / 2) come back as bits). */
SP_INLINE SIMD_FN unsigned n_unpack(double n, uint32_t k, nint layer, nint apex, nint row, nint w, nint* q)
{
    nint three_j = i_add(row, i_add(row, row));
    nint i = i_sub(w, n_row_base(apex, three_j, row));
    nint last = i_sub(i_sub(apex, i_splat(3)), three_j); /* 2B - 2 - 3j */
    unsigned missed = n_bits(n_or(i_gt(i_splat(0), i), i_gt(i_add(i, i), last)));
    n_components(n, k, layer, row, i, q);
    return missed;
}

/* decode_chunk in NBLOCK-lane blocks of 32-bit lanes (up to NARROW_CHUNK), stages as there;
 * the codes are checked against max_code as they are loaded, and a chunk holding an invalid
 * one is left to the caller, unwritten (returns 0). */
SP_INLINE SIMD_FN int decode_chunk_narrow(const sp_codec* codec, const void* constants, const uint64_t* codes,
                                          size_t blocks, float* weights, uint32_t k, const simd_layout* layout)
{
    (void)constants;
    double n = (double)codec->n, scale = (double)codec->scale;
    nint layer[NARROW_CHUNK], rest[NARROW_CHUNK], apex[NARROW_CHUNK], row[NARROW_CHUNK];
    unsigned missed[NARROW_CHUNK], any = 0; /* lanes as bits */
    nvec x[NARROW_CHUNK], z[NARROW_CHUNK];
    code_check check = check_start(codec->max_code);
    for (size_t b = 0; b < blocks; ++b) {
        prefetch_decode(layout, weights + b * NBLOCK * k, k, codes + b * NBLOCK, NBLOCK);
        rest[b] = load_codes32(codes + b * NBLOCK, &check);
        if (k == 4) x[b] = n_layer_start(n, rest[b], &z[b]);
    }
    if (!check_passed(&check)) return 0; /* nothing written yet */
    if (k == 4)
        for (size_t b = 0; b < blocks; ++b) layer[b] = n_layer_finish(n, x[b], z[b], 0.0);
    for (size_t b = 0; b < blocks; ++b) { /* the layer base in a stage of its own: the root's chain is long */
        apex[b] = i_splat((int32_t)(2 * n + 1));
        if (k == 4) {
            nint four_k = i_add(i_add(layer[b], layer[b]), i_add(layer[b], layer[b]));
            rest[b] = i_sub(rest[b], n_layer_base(n, layer[b], four_k));
            apex[b] = i_sub(apex[b], four_k); /* 2(N - 2k) + 1 */
        }
        row[b] = n_row_estimate(apex[b], rest[b]);
    }
    for (size_t b = 0; b < blocks; ++b) {
        nint q[SP_MAX_INFLUENCES];
        missed[b] = n_unpack(n, k, k == 4 ? layer[b] : i_splat(0), apex[b], row[b], rest[b], q);
        any |= missed[b];
        store_weights32(q, k, scale, layout, weights + b * NBLOCK * k);
    }
    if (any) redo_decode(codec, codes, blocks, NBLOCK, missed, k, weights);
    return 1;
}

DEFINE_DECODE_WALK(decode_walk_narrow, decode_chunk_narrow, NBLOCK, NARROW_CHUNK, 0)

/* ---- K = 4 decode with the rows in 32-bit lanes ----------------------------------------- */

/*
 * Past the narrow lanes, K = 4 codes need the layer base u(k) (up to 2^45) and the rest
 * w = code - u(k) in double lanes, but the in-layer index w < S(N) = (N^2 + N + 1) / 3 fits
 * int32 up to N = SPLIT_MAX_N4 (the GPU decoders' split: the layer step wide, the in-layer
 * search narrow), so everything else runs in NBLOCK float / int32 lanes, twice as many an
 * operation as doubles:
 *   - the layer: the estimate of decode_chunk (layer_argument, exact in double, then rounded)
 *     by the narrow lanes' float root (n_root_start, n_layer_finish), ~3e-3 of a layer at the
 *     largest N: codes that close to a layer boundary land in the wrong layer, and the row check
 *     sends them to the scalar code (under callgrind, of 200 000 codes at 32/38/44 bits: 28,
 *     142, 445 of the bench's mix and 29, 87, 336 random ones, against 0, 32, 120 and 0, 56,
 *     194 of the double root's; settling them by a step up cost more than their redo);
 *   - the row: the root's argument apex^2 + 3 - 12 (w + 7/8), exact in double, rounded to
 *     float; the float root is good to ~0.02 of a row (apex < 2^18), so the estimate taken half
 *     a row low and floored is the row j or j - 1, and one exact compare going up settles it;
 *   - the exact check of the narrow lanes (0 <= i < the row's length) proves (k, j, i), as in
 *     decode_chunk, and the weights are store_weights32's (q <= s < 2^18).
 * Every int32 intermediate stays below 2^31: w is clamped to [-1, 2^31 - 1] first (a rest
 * outside the layer stays outside every layer's triangle, S(N) <= 2^31 - 1), the estimate is
 * at most rows (<= apex / 3 - 1/2 + 1/6), where the row base
 * s_B(j) = j (B - j) + floor((j + 1) / 2) ceil((j + 1) / 2) <= S(N) is a sum of two products
 * below 2^31.
 */
SP_INLINE int split_decode(const sp_codec* codec, uint32_t k)
{
    return k == 4 && codec->n > NARROW_MAX_N4 && codec->n <= SPLIT_MAX_N4;
}

/* One block's rest w = code - u(k) (exact in double: integers below 2^50), clamped to
 * [-1, 2^31 - 1], and the row root's argument apex^2 + 3 - 12 (w + 7/8) with
 * apex = 2 (N - 2k) + 1 (exact below 2^36). The float root's layer k (n_layer_finish: a quarter
 * of a float sum near 2N, good to about an ulp, 2^-8 of a layer at 44 bits) is one too high for
 * the codes that close to their layer's end (one in 400 of the bench's mix at 44 bits), where
 * w < 0: those lanes step down a layer (*stepped set), whose rest is exact as above, instead of
 * going to the scalar redo (~4 % of the decode's time at 44 bits); a lane still outside its
 * layer fails the row check. */
SP_INLINE SIMD_FN vec split_rest(double n, vec code, vec* layer, vec* mirrored, int* stepped)
{
    vec w = v_sub(code, layer_base(n, *layer));
    mask below = m_lt(w, v_zero());
    if (m_bits(below)) { /* rare: no lane in most blocks */
        *layer = v_add_where(*layer, below, v_splat(-1.0));
        w = v_sub(code, layer_base(n, *layer));
        *stepped = 1;
    }
    w = v_min(v_max(w, v_splat(-1.0)), v_splat(2147483647.0));
    vec apex = v_fnmadd(*layer, v_splat(4.0), v_splat(2 * n + 1));
    *mirrored = v_fnmadd(w, v_splat(12.0), v_fmsub(apex, apex, v_splat(7.5)));
    return w;
}

/* The row estimate of w in layer k's triangle (bottom B = N - 2k) from the float root: half a
 * row low, so the row j or j - 1 (0 for NaN, where w is past the triangle). */
SP_INLINE SIMD_FN nint split_row_estimate(nint bottom, nvec mirrored)
{
    nvec apex = f_fmadd(i_to_f(bottom), f_splat(2.0f), f_splat(1.0f));
    nvec estimate = f_fmadd(f_sub(apex, f_sqrt(mirrored)), f_splat(1.0f / 3.0f), f_splat(-0.5f));
    return i_max(i_trunc(estimate), i_splat(0));
}

/* i = w - s_B(j) in row j of the triangle with bottom B (int32 arithmetic, so exact modulo 2^32:
 * exact wherever |i| < 2^31) and *last, row j's last offset B - 1 - j - ceil(j / 2). */
SP_INLINE SIMD_FN nint n_row_offset(nint bottom, nint j, nint w, nint* last)
{
    nint one = i_splat(1), room = i_sub(bottom, j), half = i_shr1(i_add(j, one)), half_up = i_shr1(i_add(j, i_splat(2)));
    *last = i_sub(i_sub(room, one), half);
    return i_sub(w, i_add(i_mullo(j, room), i_mullo(half, half_up)));
}

/* The lanes whose offset i is outside [0, last], as bits. */
SP_INLINE SIMD_FN unsigned n_outside(nint i, nint last)
{
    return n_bits(n_or(i_gt(i_splat(0), i), i_gt(i, last)));
}

/* The row j of w from its estimate (j or j - 1) by one step up, the offset i in it and the
 * components into q; returns the lanes whose (j, i) is not proven (i outside the row), as bits. */
SP_INLINE SIMD_FN unsigned split_unpack(double n, nint layer, nint bottom, nint j, nint w, nint* q)
{
    nint one = i_splat(1), last, i = n_row_offset(bottom, j, w, &last);
    nmask above = i_gt(i, last);
    i = i_sub_where(i, above, i_add(last, one));
    j = i_add_where(j, above, one);
    last = i_sub(i_sub(i_sub(bottom, j), one), i_shr1(i_add(j, one)));
    unsigned missed = n_outside(i, last);
    n_components(n, 4, layer, j, i, q);
    return missed;
}

/* K = 4 decode of `blocks` NBLOCK-lane blocks (up to SPLIT_CHUNK, 2 BLOCK double blocks each)
 * in stages (the layer root's two halves, the rests, the row root, the rest), then the scalar
 * redo; nothing written where a code is above max_code (returns 0). */
#define SPLIT_CHUNK DECODE_CHUNK /* 8 ran ~2% slower (both ISAs), 4 ~10% */

SP_INLINE SIMD_FN int decode_chunk_split(const sp_codec* codec, const void* constants, const uint64_t* codes,
                                         size_t blocks, float* weights, uint32_t k, const simd_layout* layout)
{
    (void)constants;
    double n = (double)codec->n, scale = (double)codec->scale;
    nint rest[SPLIT_CHUNK], layers[SPLIT_CHUNK], bottom[SPLIT_CHUNK], row[SPLIT_CHUNK];
    nvec mirrored[SPLIT_CHUNK], x[SPLIT_CHUNK], z[SPLIT_CHUNK];
    unsigned missed[SPLIT_CHUNK], any = 0; /* lanes as bits */
    code_check check = check_start(codec->max_code);
    for (size_t b = 0; b < blocks; ++b) { /* loaded again for the rests: a smaller frame ran ~5% faster */
        prefetch_decode(layout, weights + b * NBLOCK * k, k, codes + b * NBLOCK, NBLOCK);
        vec first = load_codes(codes + b * NBLOCK, &check), second = load_codes(codes + b * NBLOCK + BLOCK, &check);
        x[b] = f_from_pair(layer_argument(n, first), layer_argument(n, second));
        z[b] = n_root_start(x[b]);
    }
    if (!check_passed(&check)) return 0; /* nothing written yet */
    for (size_t b = 0; b < blocks; ++b) layers[b] = n_layer_finish(n, x[b], z[b], 0.0);
    for (size_t b = 0; b < blocks; ++b) {
        vec low, high, first, second;
        int stepped = 0;
        v_from_i_pair(layers[b], &low, &high);
        rest[b] = i_from_pair(split_rest(n, v_from_u(u_load(codes + b * NBLOCK)), &low, &first, &stepped),
                              split_rest(n, v_from_u(u_load(codes + b * NBLOCK + BLOCK)), &high, &second, &stepped));
        if (stepped) layers[b] = i_from_pair(low, high);
        mirrored[b] = f_from_pair(first, second);
    }
    for (size_t b = 0; b < blocks; ++b) { /* a stage of its own: the root's chain is long */
        bottom[b] = i_sub(i_splat((int32_t)n), i_add(layers[b], layers[b])); /* B = N - 2k */
        row[b] = split_row_estimate(bottom[b], mirrored[b]);
    }
    for (size_t b = 0; b < blocks; ++b) {
        nint q[SP_MAX_INFLUENCES];
        any |= missed[b] = split_unpack(n, layers[b], bottom[b], row[b], rest[b], q);
        store_weights32(q, k, scale, layout, weights + b * NBLOCK * k);
    }
    if (any) redo_decode(codec, codes, blocks, NBLOCK, missed, k, weights);
    return 1;
}

DEFINE_DECODE_WALK(decode_walk_split, decode_chunk_split, NBLOCK, SPLIT_CHUNK, 0)

/* ---- the edge codes: vertices of one or two weights -------------------------------------- */

/*
 * For K = 3 and 4 the codes below N are the first row of the first layer, q = (2(N - 1) - c, c,
 * 0, 0): the grid points on the edge between the simplex's first two corners, every vertex with
 * at most two weights. Real meshes are mostly such vertices (the paper's mix: 73 %), and each
 * decodes by one subtraction, where the others take the layer and row roots. So a chunk of
 * EDGE_CHUNK codes whose first EDGE_SAMPLE hold at least EDGE_MIN of them is decoded in two
 * passes: every lane as if it held an edge code, into a buffer whose other weights are zeros,
 * while the other codes are compacted into a list; then the list, by the driver's own walk
 * (which checks its codes: edge codes are valid), whose weights are put over those lanes' wrong
 * ones. The buffer goes to the weights during the next chunk's first pass. Every lane's weights
 * are what the driver (so the scalar code) gives it. The bench's mix, 1M vertices, against one
 * pass: AVX2 K = 4 1.3-1.4x as fast past 32-bit codes, AVX-512 K = 4 1.2-1.3x at 52 and 64 bits
 * (docs/benchmarks.md, session 10); K = 3 in wide lanes AVX2 ~1.2x, AVX-512 ~1.1x (session 11).
 * The first pass runs through its chunk several times as fast as the walk, so at that size its
 * stores need the streaming ones (codec_oss_batch.c): with normal stores each waited on its
 * line's read for ownership, which a one-pass decode hides under its arithmetic, and K = 3's
 * wide lanes ran 0.8x as fast in two passes (session 10, before they streamed). Encode gains
 * nothing from the same split (tried: a K = 4 vertex of two weights still takes the load,
 * division and floors that most of its time goes to; AVX2 0.9x as fast, and 0.75-0.85x with
 * those codes computed in the first pass, session 12; nor from one for the vertices of one
 * weight, session 11: its first pass is bound by memory).
 */

#define EDGE_CHUNK 256
#define EDGE_SAMPLE 32
#define EDGE_MIN (EDGE_SAMPLE / 4)
#define EDGE_LIST (EDGE_CHUNK + 2 * NBLOCK) /* room for a whole block stored past the last code kept, and the padding */

/* The set bits of a block's lanes (BLOCK <= 8). */
SP_INLINE unsigned lane_count(unsigned bits)
{
    static const uint8_t nibble[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};
    return BLOCK == 4 ? nibble[bits] : nibble[bits & 15] + nibble[bits >> 4 & 15];
}

/* A hook for the tests (test_batch_edges.c), which count the chunks decoded in two passes. */
#ifndef EDGE_TWO_PASSES
#define EDGE_TWO_PASSES() ((void)0)
#endif

/*
 * Where the buffers lie. A load or store whose address matches a streaming store still in flight
 * in its low 12 bits (its page offset) waits for that store to leave, and while the first pass
 * streams, its stores queue. So each chunk's buffers are placed by page offset (edge_place),
 * EDGE_AHEAD bytes past that of the weights they serve: the filling buffer's rows and vertex
 * numbers past that of the weights they will stream to, so that when the next pass reads them
 * back, they lie just ahead of its streaming stores instead of behind them; the list past that of
 * the chunk's own weights, which is where the pass's stores end, so that the walk reading it
 * right after the pass does not meet the last of them. Left to their places on the stack, which
 * the address randomisation sets per process, a quarter (K = 4) to over half (K = 3) of the
 * places had them behind, and there the edge decode ran 0.34-0.85x as fast as at the best place
 * (AVX2 and AVX-512, the bench's mix; placed, every place runs within ~10 % of the others, K = 4
 * faster than the best place did, K = 3 about as fast: docs/benchmarks.md, session 16,
 * tests/bench/edge_stack_sweep.c). The price: areas a page larger, ~29 KB of stack in all.
 */
#define EDGE_PAGE 4096
#define EDGE_AHEAD 128

/* The 64-byte aligned address in area[0, EDGE_PAGE + 64) at (or just past) the page offset of
 * `target` + `ahead`. */
SP_INLINE void* place_at(unsigned char* area, const void* target, size_t ahead)
{
    uintptr_t offset = ((uintptr_t)target + ahead - (uintptr_t)area) & (EDGE_PAGE - 1);
    return (void*)(((uintptr_t)area + offset + 63) & ~(uintptr_t)63);
}

/* A chunk's buffer: its rows and the vertices whose rows the list's weights take (32-bit: a
 * block's compacted numbers are then one 16- or 32-byte store, where 64-bit ones took stores
 * twice as wide, most of AVX-512's across two lines; without those stores at all the edge
 * decode ran at most ~8 % faster). */
typedef struct edge_buffer {
    float* rows;  /* in `area`, placed by edge_place */
    uint32_t* at; /* right after the rows, so at the same page offsets */
    size_t count;
    unsigned char area[EDGE_CHUNK * SP_MAX_INFLUENCES * sizeof(float) + EDGE_LIST * sizeof(uint32_t) + EDGE_PAGE + 64];
} edge_buffer;

/* The other codes of a chunk, their weights, and two chunk buffers: each chunk's buffer goes to
 * the weights during the next chunk's first pass, so that its stores spread over that pass
 * instead of leaving the chunk at once (AVX2, 1M vertices streamed: ~1.1x). */
typedef struct edge_list {
    uint64_t* codes; /* in `area`, placed by edge_place; the weights follow them */
    float* weights;
    edge_buffer buffer[2];
    size_t padded;       /* codes in the list rounded up to NBLOCK lanes */
    unsigned filling;    /* the buffer the next chunk fills */
    float* pending;      /* where the other buffer's rows go, or NULL */
    unsigned char area[EDGE_LIST * (sizeof(uint64_t) + SP_MAX_INFLUENCES * sizeof(float)) + EDGE_PAGE + 64];
} edge_list;

/* The filling buffer and the list placed for the chunk whose weights start at `out`; the two
 * buffers half a page apart, so that a chunk's rows and the next one's do not share offsets. */
SP_INLINE void edge_place(edge_list* list, const float* out)
{
    edge_buffer* filling = &list->buffer[list->filling];
    filling->rows = (float*)place_at(filling->area, out, EDGE_AHEAD + list->filling * EDGE_PAGE / 2);
    filling->at = (uint32_t*)(filling->rows + EDGE_CHUNK * SP_MAX_INFLUENCES);
    list->codes = (uint64_t*)place_at(list->area, out, EDGE_AHEAD);
    list->weights = (float*)(list->codes + EDGE_LIST);
}

/* Whether edge codes are decoded apart: K = 3 and 4 past the narrow lanes. In the narrow lanes
 * the other codes' decode is too cheap to pay for the two passes (the bench's mix, 1M vertices:
 * K = 4 0.9x as fast on AVX-512); every K = 2 code is an edge code. */
SP_INLINE int edge_decode(const sp_codec* codec, uint32_t k)
{
    return k >= 3 && !narrow_decode(codec, k);
}

/* Whether a chunk's first codes hold enough edge codes. */
SP_INLINE SIMD_FN int edge_chunk_pays(const uint64_t* codes, uint64_t n)
{
    unsigned others = 0;
    uvec bound = u_bound(n);
    for (size_t v = 0; v < EDGE_SAMPLE; v += BLOCK) others += lane_count(u_at_least(u_load(codes + v), bound));
    return EDGE_SAMPLE - others >= EDGE_MIN;
}

/* The pending buffer (if any) to the weights at once (EDGE_CHUNK k floats: whole 8-float stores). */
SP_INLINE SIMD_FN void edge_flush(edge_list* list, uint32_t k, const simd_layout* layout)
{
    if (!list->pending) return;
    const float* rows = list->buffer[list->filling ^ 1].rows;
    for (size_t i = 0; i < EDGE_CHUNK * k; i += 8) put8(layout, list->pending + i, _mm256_loadu_ps(rows + i));
    list->pending = NULL;
}

/* Every lane of a chunk decoded as an edge code into the filling buffer, the other codes listed
 * with their vertices and padded with copies of the last to whole NBLOCK lanes, the pending
 * buffer sent meanwhile. The edge code's weights are sp_grid_to_weights' (c < N is exact, and so
 * is 2(N - 1) - c). No code is checked: an edge code is valid, and the driver's walk checks the
 * list. `out`: where the chunk's weights go (the buffers' places). Locals for everything the
 * stores could alias. */
SP_INLINE SIMD_FN void edge_split(const sp_codec* codec, const uint64_t* codes, float* out, uint32_t k,
                                  const simd_layout* layout, edge_list* list)
{
    edge_place(list, out);
    vec inverse = v_splat(1.0 / (double)codec->scale), scale = v_splat((double)codec->scale);
    uvec bound = u_bound(codec->n);
    vertex_lanes at = vertex_numbers();
    edge_buffer* filling = &list->buffer[list->filling];
    float *rows = filling->rows, *pending = list->pending;
    const float* sending = list->buffer[list->filling ^ 1].rows;
    uint64_t* listed_codes = list->codes;
    uint32_t* listed_at = filling->at;
    size_t listed = 0;
    for (size_t v = 0; v < EDGE_CHUNK; v += BLOCK) {
        prefetch_ahead(codes + v, sizeof(uint64_t), BLOCK);
        uvec code = u_load(codes + v);
        vec c = v_from_u(code); /* exact below 2^52, so for every edge code */
        unsigned others = u_at_least(code, bound);
        store_edge_pairs(v_mul(v_sub(scale, c), inverse), v_mul(c, inverse), k, rows + v * k);
        u_compact(code, others, listed_codes + listed);
        vertex_compact(at, others, listed_at + listed);
        listed += lane_count(others);
        at = vertex_numbers_next(at);
        if (pending && k * BLOCK % 8 == 0) /* whole stores a block (constants: the tests fold) */
            for (size_t i = 0; i < k * BLOCK; i += 8) put8(layout, pending + v * k + i, _mm256_loadu_ps(sending + v * k + i));
        else if (pending && v % (2 * BLOCK)) /* K = 3 on AVX2: whole stores every other block */
            for (size_t i = 0; i < 2 * k * BLOCK; i += 8)
                put8(layout, pending + (v - BLOCK) * k + i, _mm256_loadu_ps(sending + (v - BLOCK) * k + i));
    }
    list->pending = NULL;
    filling->count = listed;
    for (list->padded = listed; list->padded % NBLOCK; ++list->padded) list->codes[list->padded] = list->codes[listed - 1];
}

/* The list's weights (the chunk's other codes') over their rows in the filling buffer, which
 * then waits to go to out. */
SP_INLINE SIMD_FN void edge_merge(edge_list* list, uint32_t k, float* out)
{
    edge_buffer* filling = &list->buffer[list->filling];
    float* rows = filling->rows; /* locals: the rows' stores could alias the count */
    const uint32_t* at = filling->at;
    for (size_t i = 0, count = filling->count; i < count; ++i) memcpy(rows + at[i] * k, list->weights + i * k, k * sizeof(float));
    list->pending = out;
    list->filling ^= 1;
}

/* `name`: `range` (a driver's decode of count codes from codes[0], returning where it stopped)
 * over chunks of EDGE_CHUNK codes, those holding enough edge codes in two passes (above), where
 * edge_decode. */
#define DEFINE_EDGE_DECODE(name, range)                                                                                \
    SP_INLINE SIMD_FN size_t name(const sp_codec* codec, const void* constants, const uint64_t* codes, size_t count,   \
                                  float* weights, uint32_t k, const simd_layout* layout)                               \
    {                                                                                                                  \
        if (!edge_decode(codec, k) || count < EDGE_CHUNK)                                                             \
            return range(codec, constants, codes, count, weights, k, layout);                                          \
        edge_list list;                                                                                                \
        list.filling = 0, list.pending = NULL;                                                                         \
        simd_layout plain = *layout;                                                                                   \
        plain.stream = 0;                                                                                              \
        for (size_t v = 0; v < count; v += EDGE_CHUNK) {                                                               \
            size_t chunk = count - v < EDGE_CHUNK ? count - v : EDGE_CHUNK, done;                                      \
            const uint64_t* in = codes + v;                                                                            \
            if (chunk == EDGE_CHUNK && edge_chunk_pays(in, codec->n)) {                                                \
                edge_split(codec, in, weights + v * k, k, layout, &list);                                              \
                if (range(codec, constants, list.codes, list.padded, list.weights, k, &plain) == list.padded) {       \
                    edge_merge(&list, k, weights + v * k);                                                             \
                    EDGE_TWO_PASSES();                                                                                 \
                    continue;                                                                                          \
                }                                                                                                      \
            } /* else, or where the list holds an invalid code, the chunk as it is */                                 \
            edge_flush(&list, k, layout);                                                                              \
            if ((done = range(codec, constants, in, chunk, weights + v * k, k, layout)) < chunk) return v + done;      \
        }                                                                                                              \
        edge_flush(&list, k, layout);                                                                                  \
        return count;                                                                                                  \
    }

/* The narrow chunks (narrow codecs) or the split ones (K = 4 up to SPLIT_MAX_N4) up to the
 * first one holding an invalid code, then the double lanes from there to the end or to the
 * block holding it. */
SP_INLINE SIMD_FN size_t decode_range(const sp_codec* codec, const void* constants, const uint64_t* codes, size_t count,
                                      float* weights, uint32_t k, const simd_layout* layout)
{
    size_t v = 0;
    if (narrow_decode(codec, k)) v = decode_walk_narrow(codec, constants, codes, 0, count, weights, k, layout);
    else if (split_decode(codec, k)) v = decode_walk_split(codec, constants, codes, 0, count, weights, k, layout);
    return decode_walk(codec, constants, codes, v, count, weights, k, layout);
}

DEFINE_EDGE_DECODE(decode_edges, decode_range)

SP_INLINE SIMD_FN size_t decode_lanes(const sp_codec* codec, const void* constants, const uint64_t* codes,
                                      size_t count, float* weights, int stream, uint32_t k)
{
    simd_layout layout = layout_for(k);
    layout.stream = stream;
    size_t v = decode_edges(codec, constants, codes, count, weights, k, &layout);
    if (layout.stream) _mm_sfence(); /* the streamed lines ordered before whatever the caller publishes next */
    return v;
}

/* return f(codec, constants, codes, count, weights, stream, k) with stream a constant in each
 * call (stream_from's answer): the normal stores' code has no tests of it (which cost ~1
 * instruction a vertex). */
#define RETURN_STREAMING_OR_NOT(f, codec, constants, codes, count, weights, stream, k) \
    if (stream_from(weights, stream)) return f(codec, constants, codes, count, weights, 1, k); \
    return f(codec, constants, codes, count, weights, 0, k);

SP_INLINE SIMD_FN size_t decode_blocks(const sp_codec* codec, const void* constants, const uint64_t* codes,
                                       size_t count, float* weights, int stream, uint32_t k)
{
    RETURN_STREAMING_OR_NOT(decode_lanes, codec, constants, codes, count, weights, stream, k)
}

SIMD_FN size_t SIMD_NAME(decode)(const sp_codec* codec, const uint64_t* codes, size_t count, float* weights, int stream)
{
    RETURN_FOR_EACH_K(codec, decode_blocks, codec, NULL, codes, count, weights, stream)
}
