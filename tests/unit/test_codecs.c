/* Every codec: decode->encode identity, validity and the proven error bound, fixed-point exactness. */
#include <math.h>

#include "check.h"
#include "skinpack.h"

static const sp_method methods[] = {SP_METHOD_FIXED, SP_METHOD_CUBE, SP_METHOD_POT, SP_METHOD_ANY, SP_METHOD_OSS};

static int is_sorted(const float* w, uint32_t k)
{
    for (uint32_t i = 1; i < k; ++i)
        if (w[i - 1] < w[i]) return 0;
    return 1;
}

/* Small configurations: every code. Codes that decode to a sorted simplex point (all of them
 * for OSS) must encode back to themselves; AABB codes outside the simplex must be rejected. */
static void exhaustive_identity(void)
{
    for (size_t m = 0; m < 5; ++m)
        for (uint32_t k = 2; k <= 4; ++k)
            for (uint32_t bits = 2; bits <= 18; ++bits) {
                sp_codec c;
                if (sp_codec_from_bits(methods[m], k, bits, &c) != SP_OK) continue;
                size_t encodable = 0;
                for (uint64_t code = 0; code <= c.max_code; ++code) {
                    float w[4];
                    size_t bad = 0;
                    if (sp_decode_weights_batch(&c, &code, 1, w, &bad) != SP_OK) {
                        CHECK(methods[m] != SP_METHOD_OSS);
                        continue;
                    }
                    if (methods[m] != SP_METHOD_ANY && !is_sorted(w, k)) continue;
                    if (methods[m] == SP_METHOD_ANY && (!is_sorted(w, k) || w[k - 1] < 0)) continue;
                    ++encodable;
                    uint64_t again = sp_encode_weights(&c, w);
                    CHECK_MSG(again == code, "%s K=%u bits=%u code=%llu -> %llu", sp_method_name(methods[m]), k, bits,
                              (unsigned long long)code, (unsigned long long)again);
                }
                if (methods[m] == SP_METHOD_OSS) CHECK(encodable == c.max_code + 1);
                CHECK(encodable > 0);
            }
}

/* Any's axes round independently, so w1 = 1 - w2 - ... - wK can come out below 0; the encoder
 * then steps an axis down, and must judge w1 exactly as the decoder computes it (the
 * specification: each operation rounded), or it writes codes the decoder rejects. The hard
 * inputs are the axis weights of every code with w1 clamped to 0, where w1 is 0 or just below
 * (e.g. 0, 1/2, 1/3, 1/6 on axes 22, 23, 25). Fails where the library is built with FMA
 * contraction (GCC on AArch64 fused the encoder's check of w1 and not the decoder's). */
static void any_codes_decode(void)
{
    for (uint32_t k = 3; k <= 4; ++k)
        for (uint64_t q = 2; q <= 32; ++q) {
            uint64_t axes[3] = {q, q + 1, q + 3};
            sp_codec c;
            CHECK(sp_codec_from_params(SP_METHOD_ANY, k, 0, axes, &c) == SP_OK);
            for (uint64_t code = 0; code <= c.max_code; ++code) {
                float w[4], decoded[4];
                size_t bad = 0;
                sp_decode_weights(&c, code, w);
                w[0] = w[0] > 0 ? w[0] : 0;
                uint64_t again = sp_encode_weights(&c, w);
                CHECK_MSG(sp_decode_weights_batch(&c, &again, 1, decoded, &bad) == SP_OK,
                          "any K=%u axes %llu: code %llu -> %llu, rejected", k, (unsigned long long)q,
                          (unsigned long long)code, (unsigned long long)again);
            }
        }
}

/* Random convex weights, sorted; some with zeros, some nearly equal (the hard corners). */
static void random_weights(uint32_t k, float* w)
{
    double raw[4], sum = 0;
    uint64_t shape = rng_next() % 4;
    for (uint32_t i = 0; i < k; ++i) {
        raw[i] = shape == 0 ? 1.0 : -log(rng_unit() + 1e-12);
        if (shape == 1 && i >= 1 + rng_next() % k) raw[i] = 0;
        sum += raw[i];
    }
    for (uint32_t i = 0; i < k; ++i) w[i] = (float)(raw[i] / sum);
    for (uint32_t i = 1; i < k; ++i)
        for (uint32_t j = i; j > 0 && w[j - 1] < w[j]; --j) {
            float t = w[j];
            w[j] = w[j - 1];
            w[j - 1] = t;
        }
}

static void bound_holds_on_random_input(void)
{
    for (size_t m = 0; m < 5; ++m)
        for (uint32_t k = 1; k <= 4; ++k)
            for (uint32_t bits = 4; bits <= 64; bits += 3) {
                sp_codec c;
                if (sp_codec_from_bits(methods[m], k, bits, &c) != SP_OK) continue;
                CHECK(c.bits <= bits);
                for (int t = 0; t < 2000; ++t) {
                    float w[4], d[4];
                    random_weights(k, w);
                    uint64_t code = sp_encode_weights(&c, w);
                    size_t bad;
                    CHECK(sp_decode_weights_batch(&c, &code, 1, d, &bad) == SP_OK);
                    double sum = 0, err = 0;
                    int nonneg = 1;
                    for (uint32_t i = 0; i < k; ++i) {
                        sum += d[i];
                        nonneg &= d[i] >= 0;
                        err = fmax(err, fabs((double)d[i] - w[i]));
                    }
                    CHECK_MSG(nonneg && fabs(sum - 1) < 1e-6, "%s K=%u bits=%u", sp_method_name(methods[m]), k, bits);
                    CHECK_MSG(err <= c.max_error, "%s K=%u bits=%u err=%g bound=%g", sp_method_name(methods[m]), k, bits,
                              err, c.max_error);
                    if (methods[m] != SP_METHOD_ANY) CHECK(is_sorted(d, k));
                }
            }
}

/* m-bit fixed-point input is held exactly by Cube(m), POT(m) and OSS(N = 2^m). */
static void fixed_point_is_exact(void)
{
    for (uint32_t k = 2; k <= 4; ++k)
        for (uint64_t mbits = 4; mbits <= 16; mbits += 4) {
            sp_codec codecs[3];
            CHECK(sp_codec_from_params(SP_METHOD_CUBE, k, mbits, NULL, &codecs[0]) == SP_OK);
            CHECK(sp_codec_from_params(SP_METHOD_POT, k, mbits, NULL, &codecs[1]) == SP_OK);
            CHECK(sp_codec_from_params(SP_METHOD_OSS, k, (uint64_t)1 << mbits, NULL, &codecs[2]) == SP_OK);
            uint64_t s = ((uint64_t)1 << mbits) - 1;
            for (int t = 0; t < 3000; ++t) {
                float w[4], fixed[4];
                uint64_t q[4], left = s;
                random_weights(k, w);
                for (uint32_t i = k - 1; i > 0; --i) { /* fixed-point tuple summing to s, sorted */
                    q[i] = (uint64_t)floor(w[i] * (double)s);
                    left -= q[i];
                }
                q[0] = left;
                for (uint32_t i = 0; i < k; ++i) fixed[i] = (float)((double)q[i] / (double)s);
                for (int c = 0; c < 3; ++c) {
                    float d[4];
                    sp_decode_weights(&codecs[c], sp_encode_weights(&codecs[c], fixed), d);
                    for (uint32_t i = 0; i < k; ++i)
                        CHECK_MSG(d[i] == fixed[i], "%s K=%u m=%llu slot %u: %.9g vs %.9g",
                                  sp_method_name((sp_method)codecs[c].method), k, (unsigned long long)mbits, i, d[i],
                                  fixed[i]);
                }
            }
        }
}

/* Degenerate weights (the public encoder does not validate): a valid code, quickly. */
static void degenerate_input_is_defined(void)
{
    const float cases[][4] = {{0, 0, 0, 0}, {NAN, 0.5f, 0.25f, 0}, {INFINITY, 1, 0, 0}, {1e-45f, 0, 0, 0},
                              {-1, 2, 0, 0}, {3e38f, 3e38f, 3e38f, 3e38f}};
    for (size_t m = 0; m < 5; ++m)
        for (uint32_t bits = 20; bits <= 64; bits += 44) {
            sp_codec c;
            CHECK(sp_codec_from_bits(methods[m], 4, bits, &c) == SP_OK);
            for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); ++i) {
                uint64_t code = sp_encode_weights(&c, cases[i]);
                CHECK_MSG(code <= c.max_code, "%s case %zu", sp_method_name(methods[m]), i);
            }
        }
}

static void configuration_errors(void)
{
    sp_codec c;
    CHECK(sp_codec_from_bits(SP_METHOD_COUNT, 4, 22, &c) == SP_ERR_UNSUPPORTED_METHOD);
    CHECK(sp_codec_from_bits(SP_METHOD_OSS, 5, 22, &c) == SP_ERR_UNSUPPORTED_METHOD);
    CHECK(sp_codec_from_bits(SP_METHOD_OSS, 4, 65, &c) == SP_ERR_BITS_OUT_OF_RANGE);
    CHECK(sp_codec_from_bits(SP_METHOD_FIXED, 4, 3, &c) == SP_ERR_BITS_OUT_OF_RANGE);
    CHECK(sp_codec_from_spacing(SP_METHOD_OSS, 4, 0.0, &c) == SP_ERR_BITS_OUT_OF_RANGE);
    CHECK(sp_codec_from_spacing(SP_METHOD_FIXED, 4, 1e-30, &c) == SP_ERR_BITS_OUT_OF_RANGE);
    CHECK(sp_codec_from_params(SP_METHOD_OSS, 4, 1, NULL, &c) == SP_ERR_BITS_OUT_OF_RANGE);
    CHECK(sp_codec_from_params(SP_METHOD_ANY, 4, 0, NULL, &c) == SP_ERR_INVALID_ARGUMENT);
    uint64_t q[3] = {1, 5, 5};
    CHECK(sp_codec_from_params(SP_METHOD_ANY, 4, 0, q, &c) == SP_ERR_INVALID_ARGUMENT);
    CHECK(sp_codec_from_bits(SP_METHOD_FIXED, 4, 64, &c) == SP_OK && c.max_code == UINT64_MAX && c.bits == 64);
    CHECK(sp_codec_from_bits(SP_METHOD_OSS, 1, 0, &c) == SP_OK && c.bits == 0);
    /* spacing configuration really reaches the target and is minimal */
    for (size_t m = 0; m < 5; ++m)
        for (uint32_t k = 2; k <= 4; ++k)
            for (double delta = 0.1; delta > 1e-7; delta /= 3.7) {
                sp_result r = sp_codec_from_spacing(methods[m], k, delta, &c);
                if (r == SP_ERR_BITS_OUT_OF_RANGE) { /* only when even 64 bits cannot reach it */
                    sp_codec widest;
                    CHECK(sp_codec_from_bits(methods[m], k, 64, &widest) == SP_OK && widest.max_spacing > delta);
                    continue;
                }
                CHECK(r == SP_OK);
                CHECK_MSG(c.max_spacing <= delta, "%s K=%u delta=%g got %g", sp_method_name(methods[m]), k, delta,
                          c.max_spacing);
                if (c.bits > 1) {
                    sp_codec coarser;
                    if (sp_codec_from_bits(methods[m], k, c.bits - 1, &coarser) == SP_OK)
                        CHECK_MSG(coarser.max_spacing > delta, "%s K=%u delta=%g not minimal", sp_method_name(methods[m]), k, delta);
                }
            }
    CHECK(sp_method_from_name("oss") == SP_METHOD_OSS && sp_method_from_name("nope") == SP_METHOD_COUNT);
    for (int r = 0; r <= SP_RESULT_COUNT; ++r) CHECK(sp_result_string((sp_result)r) != NULL);
}

int main(void)
{
    exhaustive_identity();
    any_codes_decode();
    bound_holds_on_random_input();
    fixed_point_is_exact();
    configuration_errors();
    degenerate_input_is_defined();
    return check_report("test_codecs");
}
