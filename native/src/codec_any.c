/*
 * Any AABB (Kuth & Meyer, Sec. 4.4): axis i (i = 2..K) spans [0, 1/i] with q_i samples; the
 * per-axis counts are chosen so the grid is as isotropic as possible and their product fits
 * the budget; the code is the mixed-radix index of the sample. Not on a common grid, so each
 * axis is rounded on its own and w1 = 1 - sum.
 */
#include <math.h>

#include "codec_internal.h"

static double axis_spacing(uint32_t axis, uint64_t samples)
{
    return 1.0 / ((double)(axis + 2) * (double)(samples - 1));
}

/* w1 = 1 - w2 - ... - wK exactly as the decoder computes it (double, in axis order). */
static double any_rest(const sp_codec* codec, const uint64_t* x)
{
    double rest = 1.0;
    for (uint32_t a = 0; a + 1 < codec->influences; ++a) rest -= (double)x[a] * axis_spacing(a, codec->axis_samples[a]);
    return rest;
}

/*
 * Rounds each axis to its nearest sample. Coarse grids can round the stored weights up past a
 * sum of 1 (w1 < 0), a code the decoder rejects: then the axis rounded up the most steps down
 * until w1 >= 0, which the all-zero code always reaches.
 */
uint64_t sp_any_encode(const sp_codec* codec, const float* weights)
{
    uint64_t x[SP_MAX_INFLUENCES - 1] = {0};
    double exact[SP_MAX_INFLUENCES - 1] = {0};
    uint32_t axes = codec->influences - 1;
    for (uint32_t a = 0; a < axes; ++a) {
        uint64_t q = codec->axis_samples[a];
        exact[a] = (double)weights[a + 1] * (double)(a + 2) * (double)(q - 1);
        double r = exact[a] + 0.5;
        x[a] = r <= 0 ? 0 : (r >= (double)(q - 1) ? q - 1 : (uint64_t)r);
    }
    while (any_rest(codec, x) < 0) {
        uint32_t down = axes;
        for (uint32_t a = 0; a < axes; ++a)
            if (x[a] > 0 && (down == axes || (double)x[a] - exact[a] > (double)x[down] - exact[down])) down = a;
        x[down]--;
    }
    uint64_t code = 0, radix = 1;
    for (uint32_t a = 0; a < axes; ++a) {
        code += x[a] * radix;
        radix *= codec->axis_samples[a];
    }
    return code;
}

double sp_any_decode(const sp_codec* codec, uint64_t code, float* weights)
{
    double rest = 1.0;
    for (uint32_t a = 0; a + 1 < codec->influences; ++a) {
        uint64_t q = codec->axis_samples[a];
        double w = (double)(code % q) * axis_spacing(a, q);
        code /= q;
        weights[a + 1] = (float)w;
        rest -= w;
    }
    weights[0] = (float)rest;
    return rest;
}

sp_result sp_any_configure(uint32_t influences, const uint64_t* axis_samples, sp_codec* codec)
{
    sp_u128 count = sp_u128_from(1);
    double spacing = 0, w1_error = 0;
    for (uint32_t a = 0; a + 1 < influences; ++a) {
        uint64_t q = axis_samples[a];
        if (q < 2) return SP_ERR_INVALID_ARGUMENT;
        count = sp_u128_mul_u64(count, q);
        if (sp_u128_less(sp_u128_pow2(64), count)) return SP_ERR_BITS_OUT_OF_RANGE;
        double h = axis_spacing(a, q);
        if (h > spacing) spacing = h;
        w1_error += h / 2;
        codec->axis_samples[a] = q;
    }
    codec->n = 0;
    codec->scale = 0;
    codec->max_code = sp_u128_low(count) - 1; /* count <= 2^64 (2^64 wraps to 0, minus 1: 2^64 - 1) */
    codec->max_spacing = spacing;
    codec->max_error = w1_error + SP_FLOAT_SLACK;
    return SP_OK;
}
