/*
 * Codec configuration (by bit budget, by target spacing, from stored parameters) and the
 * per-method dispatch of encode and decode.
 */
#include <math.h>

#include "codec_internal.h"

static uint64_t grid_scale(uint64_t m)
{
    return m >= 64 ? UINT64_MAX : (((uint64_t)1 << m) - 1);
}

/* Bits of stored component c (0-based, in code order) for the grid methods. */
static uint32_t grid_component_bits(sp_method method, uint32_t slot, uint64_t m)
{
    if (method != SP_METHOD_POT) return (uint32_t)m;
    /* POT: q_i <= s/i < 2^(m - floor(log2 i)), i = slot + 1 */
    uint32_t i = slot + 1, drop = 0;
    while ((2u << drop) <= i) ++drop;
    return (uint32_t)m - drop;
}

static void finish(sp_codec* codec)
{
    uint64_t top = codec->max_code;
    uint32_t bits = 0;
    while (bits < 64 && (top >> bits)) ++bits;
    codec->bits = bits;
    codec->code_bits = log2((double)top + 1.0);
}

static sp_result configure_grid(sp_method method, uint32_t k, uint64_t m, sp_codec* codec)
{
    if (m < (method == SP_METHOD_POT ? 2u : 1u) || m > 64) return SP_ERR_BITS_OUT_OF_RANGE;
    uint32_t first = method == SP_METHOD_FIXED ? 0 : 1, total = 0;
    for (uint32_t slot = first, c = 0; slot < k; ++slot, ++c) {
        codec->component_bits[c] = grid_component_bits(method, slot, m);
        total += codec->component_bits[c];
    }
    if (total > SP_MAX_WEIGHT_BITS) return SP_ERR_BITS_OUT_OF_RANGE;
    codec->n = m;
    codec->scale = grid_scale(m);
    codec->max_code = total >= 64 ? UINT64_MAX : (((uint64_t)1 << total) - 1);
    codec->max_spacing = 1.0 / (double)codec->scale;
    codec->max_error = (double)(k - 1) / ((double)k * (double)codec->scale) + SP_FLOAT_SLACK;
    return SP_OK;
}

static sp_result configure_oss(uint32_t k, uint64_t n, sp_codec* codec)
{
    if (n < 2 || n > ((uint64_t)1 << 63)) return SP_ERR_BITS_OUT_OF_RANGE;
    sp_u128 count = sp_oss_code_count(n, k);
    uint64_t low = sp_u128_low(count), high = sp_u128_high(count);
    if ((low == 0 && high == 0) || high > 1 || (high == 1 && low != 0)) return SP_ERR_BITS_OUT_OF_RANGE; /* 1..2^64 */
    codec->n = n;
    codec->scale = 2 * (n - 1);
    codec->max_code = low - 1; /* 2^64 wraps to 2^64 - 1 */
    codec->max_spacing = 1.0 / (double)codec->scale;
    codec->max_error = (double)(k - 1) / ((double)k * (double)codec->scale) + SP_FLOAT_SLACK;
    return SP_OK;
}

static sp_result start(sp_method method, uint32_t influences, sp_codec* codec)
{
    if (!codec) return SP_ERR_INVALID_ARGUMENT;
    *codec = (sp_codec){0};
    if ((unsigned)method >= SP_METHOD_COUNT) return SP_ERR_UNSUPPORTED_METHOD;
    if (influences < 1 || influences > SP_MAX_INFLUENCES) return SP_ERR_UNSUPPORTED_METHOD;
    codec->method = (uint32_t)method;
    codec->influences = influences;
    if (influences == 1) { /* one weight is always 1: nothing to store */
        codec->scale = 1;
        codec->max_error = SP_FLOAT_SLACK;
    }
    return SP_OK;
}

/* Any AABB at a target count: isotropic lambda (paper, Sec. 4.4), then refine the coarsest
 * axis while the product still fits, so no budget is left unused that could shrink Delta. */
static double any_resolution(uint32_t axis, uint64_t samples)
{
    return (double)(axis + 2) * (double)(samples - 1); /* 1 / spacing */
}

static sp_result any_from_bits(uint32_t k, uint32_t bits, sp_codec* codec)
{
    uint64_t q[SP_MAX_INFLUENCES - 1];
    uint32_t axes = k - 1;
    sp_u128 limit = sp_u128_pow2(bits); /* bits <= 64 */
    double volume = 1;
    for (uint32_t a = 0; a < axes; ++a) volume /= (double)(a + 2);
    double lambda = pow(ldexp(1.0, (int)bits) / volume, 1.0 / (double)axes);
    sp_u128 product = sp_u128_from(1);
    for (uint32_t a = 0; a < axes; ++a) {
        double qa = floor(lambda / (double)(a + 2));
        q[a] = qa < 2 ? 2 : (qa > 0x1p62 ? ((uint64_t)1 << 62) : (uint64_t)qa);
        product = sp_u128_mul_u64(product, q[a]);
    }
    for (int step = 0; step < 256; ++step) {
        uint32_t coarse = 0, second = axes; /* coarsest axis, and the next coarsest */
        for (uint32_t a = 1; a < axes; ++a)
            if (any_resolution(a, q[a]) < any_resolution(coarse, q[coarse])) coarse = a;
        for (uint32_t a = 0; a < axes; ++a)
            if (a != coarse && (second == axes || any_resolution(a, q[a]) < any_resolution(second, q[second])))
                second = a;
        sp_u128 others = sp_u128_div_u64(product, q[coarse]);
        if (sp_u128_less(limit, product)) { /* float rounding of lambda: cut the finest axis to fit */
            uint32_t fine = 0;
            for (uint32_t a = 1; a < axes; ++a)
                if (any_resolution(a, q[a]) > any_resolution(fine, q[fine])) fine = a;
            sp_u128 rest = sp_u128_div_u64(product, q[fine]);
            sp_u128 fit = sp_u128_div(limit, rest); /* <= limit < 2^65; >= 2 fits 64 bits below */
            if (sp_u128_less(fit, sp_u128_from(2))) return SP_ERR_BITS_OUT_OF_RANGE;
            q[fine] = sp_u128_high(fit) ? UINT64_MAX : sp_u128_low(fit);
            product = sp_u128_mul_u64(rest, q[fine]);
            continue;
        }
        sp_u128 room = sp_u128_div(limit, others);
        uint64_t target = sp_u128_high(room) ? UINT64_MAX : sp_u128_low(room);
        if (target <= q[coarse]) break;
        if (second < axes) { /* just past the next coarsest axis, so the two stay balanced */
            double match = any_resolution(second, q[second]) / (double)(coarse + 2) + 2;
            if (match < (double)target) target = (uint64_t)match;
            if (target <= q[coarse]) target = q[coarse] + 1;
        }
        product = sp_u128_mul_u64(others, target);
        q[coarse] = target;
    }
    return sp_any_configure(k, q, codec);
}

static sp_result oss_from_bits(uint32_t k, uint32_t bits, sp_codec* codec)
{
    sp_u128 limit = sp_u128_pow2(bits >= 64 ? 64 : bits);
    uint64_t lo = 2, hi = (uint64_t)1 << 63;
    if (k == 3) hi = (uint64_t)1 << 34;
    if (k == 4) hi = (uint64_t)1 << 23;
    if (sp_u128_less(limit, sp_oss_code_count(lo, k))) return SP_ERR_BITS_OUT_OF_RANGE;
    while (lo < hi) { /* largest N whose code count fits */
        uint64_t mid = lo + (hi - lo + 1) / 2;
        if (!sp_u128_less(limit, sp_oss_code_count(mid, k))) lo = mid;
        else hi = mid - 1;
    }
    return configure_oss(k, lo, codec);
}

sp_result sp_codec_from_bits(sp_method method, uint32_t influences, uint32_t bits, sp_codec* codec)
{
    sp_result r = start(method, influences, codec);
    if (r != SP_OK || influences == 1) return r;
    if (bits > SP_MAX_WEIGHT_BITS) return SP_ERR_BITS_OUT_OF_RANGE;
    uint32_t k = influences;
    switch (method) {
    case SP_METHOD_FIXED: r = configure_grid(method, k, bits / k, codec); break;
    case SP_METHOD_CUBE: r = configure_grid(method, k, bits / (k - 1), codec); break;
    case SP_METHOD_POT: {
        /* stored bits are (k-1)m - drop with drop = 1, 2, 4 for k = 2, 3, 4 */
        uint32_t drop = k == 2 ? 1 : (k == 3 ? 2 : 4);
        uint64_t m = (bits + drop) / (k - 1);
        r = configure_grid(method, k, m > 64 ? 64 : m, codec);
        break;
    }
    case SP_METHOD_ANY: r = any_from_bits(k, bits, codec); break;
    default: r = oss_from_bits(k, bits, codec); break;
    }
    if (r == SP_OK) finish(codec);
    return r;
}

sp_result sp_codec_from_spacing(sp_method method, uint32_t influences, double max_spacing, sp_codec* codec)
{
    sp_result r = start(method, influences, codec);
    if (r != SP_OK || influences == 1) return r;
    if (!(max_spacing > 0) || !isfinite(max_spacing)) return SP_ERR_BITS_OUT_OF_RANGE;
    uint32_t k = influences;
    if (method == SP_METHOD_ANY) {
        uint64_t q[SP_MAX_INFLUENCES - 1];
        for (uint32_t a = 0; a + 1 < k; ++a) {
            double need = ceil(1.0 / ((double)(a + 2) * max_spacing)) + 1;
            if (need > 1.8e19) return SP_ERR_BITS_OUT_OF_RANGE;
            q[a] = need < 2 ? 2 : (uint64_t)need;
            while (q[a] > 2 && 1.0 / ((double)(a + 2) * (double)(q[a] - 2)) <= max_spacing) q[a]--;
        }
        r = sp_any_configure(k, q, codec);
    } else if (method == SP_METHOD_OSS) {
        double need = ceil(1.0 / (2.0 * max_spacing)) + 1;
        if (need > 9.2e18) return SP_ERR_BITS_OUT_OF_RANGE;
        uint64_t n = need < 2 ? 2 : (uint64_t)need;
        while (n > 2 && 1.0 / (2.0 * (double)(n - 2)) <= max_spacing) n--;
        r = configure_oss(k, n, codec);
    } else {
        uint64_t m = 1;
        while (m < 64 && 1.0 / (double)grid_scale(m) > max_spacing) ++m;
        if (1.0 / (double)grid_scale(m) > max_spacing) return SP_ERR_BITS_OUT_OF_RANGE;
        if (method == SP_METHOD_POT && m < 2) m = 2;
        r = configure_grid(method, k, m, codec);
    }
    if (r == SP_OK) finish(codec);
    return r;
}

sp_result sp_codec_from_max_error(sp_method method, uint32_t influences, double max_error, sp_codec* codec)
{
    sp_result r = start(method, influences, codec);
    if (r != SP_OK) return r;
    if (!(max_error > 0) || !isfinite(max_error)) return SP_ERR_BITS_OUT_OF_RANGE;
    /* the bound falls as bits grow, but not strictly (Any/POT steps), so scan rather than bisect */
    for (uint32_t bits = 0; bits <= SP_MAX_WEIGHT_BITS; ++bits) {
        sp_codec candidate;
        if (sp_codec_from_bits(method, influences, bits, &candidate) == SP_OK && candidate.max_error <= max_error) {
            *codec = candidate;
            return SP_OK;
        }
    }
    return SP_ERR_BITS_OUT_OF_RANGE;
}

sp_result sp_codec_from_params(sp_method method, uint32_t influences, uint64_t n, const uint64_t* axis_samples,
                               sp_codec* codec)
{
    sp_result r = start(method, influences, codec);
    if (r != SP_OK) return r;
    if (influences == 1) return n == 0 ? SP_OK : SP_ERR_INVALID_ARGUMENT;
    switch (method) {
    case SP_METHOD_ANY:
        if (!axis_samples) return SP_ERR_INVALID_ARGUMENT;
        r = sp_any_configure(influences, axis_samples, codec);
        break;
    case SP_METHOD_OSS: r = configure_oss(influences, n, codec); break;
    default: r = configure_grid(method, influences, n, codec); break;
    }
    if (r == SP_OK) finish(codec);
    return r;
}

static uint32_t ceil_bits(double code_bits)
{
    double whole = ceil(code_bits - 1e-9);
    return (uint32_t)(whole < 0 ? 0 : whole);
}

sp_result sp_required_bits(sp_method method, uint32_t influences, double max_spacing, uint32_t* bits,
                           double* code_bits)
{
    sp_codec scratch;
    sp_result r = start(method, influences, &scratch);
    if (r != SP_OK) return r;
    if (!bits || !code_bits || !(max_spacing > 1e-30) || !isfinite(max_spacing)) return SP_ERR_INVALID_ARGUMENT;
    uint32_t k = influences;
    double total = 0;
    if (k == 1) {
        total = 0;
    } else if (method == SP_METHOD_ANY || method == SP_METHOD_OSS) {
        /* the same sample counts sp_codec_from_spacing picks, counted in log2 */
        if (method == SP_METHOD_OSS) {
            double n = ceil(1.0 / (2.0 * max_spacing)) + 1;
            while (n > 2 && 1.0 / (2.0 * (n - 2)) <= max_spacing) n -= 1;
            if (n > 0x1p40) return SP_ERR_BITS_OUT_OF_RANGE;
            total = log2(sp_u128_to_double(sp_oss_code_count((uint64_t)n, k)));
        } else {
            for (uint32_t a = 0; a + 1 < k; ++a) {
                double q = ceil(1.0 / ((double)(a + 2) * max_spacing)) + 1;
                while (q > 2 && 1.0 / ((double)(a + 2) * (q - 2)) <= max_spacing) q -= 1;
                total += log2(q);
            }
        }
    } else {
        int m = 1;
        while (m < 1000 && 1.0 / (ldexp(1.0, m) - 1) > max_spacing) ++m;
        if (method == SP_METHOD_POT && m < 2) m = 2;
        for (uint32_t slot = method == SP_METHOD_FIXED ? 0 : 1; slot < k; ++slot)
            total += grid_component_bits(method, slot, (uint64_t)m);
    }
    *code_bits = total;
    *bits = ceil_bits(total);
    return SP_OK;
}

/* ---- encode / decode ---------------------------------------------------------------- */

/* Inlined with a constant k by the batch loop below. */
SP_INLINE uint64_t encode_one(const sp_codec* codec, const float* weights, uint32_t k, uint8_t* significant)
{
    uint64_t q[SP_MAX_INFLUENCES] = {0};
    uint64_t code;
    if (k == 1) {
        if (significant) *significant = 1;
        return 0;
    }
    if (codec->method == SP_METHOD_ANY) {
        float decoded[SP_MAX_INFLUENCES];
        code = sp_any_encode(codec, weights);
        if (significant) {
            /* Any's axes round on grids of their own: a slot can decode to 0 with weight after it */
            sp_any_decode(codec, code, decoded);
            uint8_t count = 1;
            for (uint8_t i = 1; i < k; ++i)
                if (decoded[i] > 0) count = (uint8_t)(i + 1);
            *significant = count;
        }
        return code;
    }
    sp_grid_quantize(weights, k, codec->scale, q);
    code = codec->method == SP_METHOD_OSS ? sp_oss_pack(codec->n, k, q) : sp_grid_pack(codec, q);
    if (significant) *significant = sp_grid_significant(q, k);
    return code;
}

uint64_t sp_encode_weights(const sp_codec* codec, const float* weights)
{
    return encode_one(codec, weights, codec->influences, NULL);
}

void sp_decode_weights(const sp_codec* codec, uint64_t code, float* weights)
{
    uint32_t k = codec->influences;
    uint64_t q[SP_MAX_INFLUENCES] = {0};
    if (k == 1) {
        weights[0] = 1.0f;
    } else if (codec->method == SP_METHOD_ANY) {
        sp_any_decode(codec, code, weights);
    } else if (codec->method == SP_METHOD_OSS) {
        sp_oss_decode_one(codec, code, weights);
    } else {
        sp_grid_unpack(codec, code, q);
        sp_grid_to_weights(q, k, codec->scale, weights);
    }
}

/* Decodes one code into weights (K floats) if an encoder can have written it: in range and,
 * for the grid methods, a sorted grid point (the AABB codecs also have codes outside the
 * simplex). Unpacks once; returns 0 and leaves weights untouched for an invalid code. */
static int decode_valid(const sp_codec* codec, uint64_t code, float* weights)
{
    uint32_t k = codec->influences;
    float decoded[SP_MAX_INFLUENCES];
    if (code > codec->max_code) return 0;
    if (codec->method == SP_METHOD_OSS && k > 1) { /* a bijection: every code in range is a sorted grid point */
        sp_oss_decode_one(codec, code, weights);
        return 1;
    }
    if (k == 1) {
        decoded[0] = 1.0f;
    } else if (codec->method == SP_METHOD_ANY) {
        if (sp_any_decode(codec, code, decoded) < 0) return 0; /* the stored weights sum past 1 */
    } else {
        uint64_t q[SP_MAX_INFLUENCES] = {0};
        sp_grid_unpack(codec, code, q); /* clamps q[0] at 0, so a sum past s shows below */
        sp_u128 sum = sp_u128_from(q[0]);
        for (uint32_t i = 1; i < k; ++i) {
            if (q[i] > q[i - 1]) return 0;
            sum = sp_u128_add_u64(sum, q[i]);
        }
        if (sp_u128_high(sum) || sp_u128_low(sum) != codec->scale) return 0;
        sp_grid_to_weights(q, k, codec->scale, decoded);
    }
    for (uint32_t i = 0; i < k; ++i) weights[i] = decoded[i];
    return 1;
}

sp_result sp_encode_weights_batch_isa(const sp_codec* codec, const float* weights, size_t vertex_count,
                                      uint64_t* codes, uint8_t* significant, sp_isa widest)
{
    if (!codec || (!weights && vertex_count) || (!codes && vertex_count)) return SP_ERR_INVALID_ARGUMENT;
    uint32_t k = codec->influences;
    size_t first = sp_oss_encode_batch(codec, weights, vertex_count, codes, significant, widest); /* vector prefix */
    if (codec->method == SP_METHOD_OSS && k >= 2 && k <= 4) {
        sp_oss_encode_scalar(codec, weights, first, vertex_count, codes, significant);
        return SP_OK;
    }
#define SP_ENCODE_LOOP(K)                                                                            \
    for (size_t v = first; v < vertex_count; ++v)                                                   \
        codes[v] = encode_one(codec, weights + v * (K), (K), significant ? significant + v : NULL);
    switch (k) {
    case 2: SP_ENCODE_LOOP(2) break;
    case 3: SP_ENCODE_LOOP(3) break;
    case 4: SP_ENCODE_LOOP(4) break;
    default: SP_ENCODE_LOOP(k) break;
    }
#undef SP_ENCODE_LOOP
    return SP_OK;
}

sp_result sp_decode_weights_batch_isa(const sp_codec* codec, const uint64_t* codes, size_t vertex_count,
                                      float* weights, size_t* error_vertex, sp_isa widest)
{
    if (!codec || (!codes && vertex_count) || (!weights && vertex_count)) return SP_ERR_INVALID_ARGUMENT;
    uint32_t k = codec->influences;
    size_t first = sp_oss_decode_batch(codec, codes, vertex_count, weights, widest); /* vector prefix */
    if (codec->method == SP_METHOD_OSS && k >= 2 && k <= 4)
        first = sp_oss_decode_scalar(codec, codes, first, vertex_count, weights); /* stops at an invalid code */
    for (size_t v = first; v < vertex_count; ++v) {
        if (!decode_valid(codec, codes[v], weights + v * k)) {
            if (error_vertex) *error_vertex = v;
            return SP_ERR_CODE_OUT_OF_RANGE;
        }
    }
    return SP_OK;
}

sp_result sp_encode_weights_batch(const sp_codec* codec, const float* weights, size_t vertex_count,
                                  uint64_t* codes, uint8_t* significant)
{
    return sp_encode_weights_batch_isa(codec, weights, vertex_count, codes, significant, SP_ISA_AVX512);
}

sp_result sp_decode_weights_batch(const sp_codec* codec, const uint64_t* codes, size_t vertex_count, float* weights,
                                  size_t* error_vertex)
{
    return sp_decode_weights_batch_isa(codec, codes, vertex_count, weights, error_vertex, SP_ISA_AVX512);
}
