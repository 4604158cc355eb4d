/* OSS closed forms against iterative sums, and exhaustive/sampled code identity. */
#include "check.h"
#include "../../native/src/codec_internal.h"

static void closed_forms_match_iteration(void)
{
    for (uint64_t n = 1; n <= 300; ++n) {
        /* rows j hold floor((2N - 3j)/2) codes while positive */
        uint64_t base = 0, j = 0;
        for (; (int64_t)(2 * n) - 3 * (int64_t)j > 1; ++j) {
            CHECK_MSG(sp_oss_row_base(n, j) == base, "N=%llu j=%llu", (unsigned long long)n, (unsigned long long)j);
            base += (2 * n - 3 * j) / 2;
        }
        CHECK_MSG(j == (2 * n + 1) / 3, "rows N=%llu", (unsigned long long)n);
        CHECK_MSG(sp_oss_triangle_count(n) == base, "S(N) N=%llu", (unsigned long long)n);
        uint64_t layer = 0, k = 0;
        for (; 2 * k + 1 <= n; ++k) {
            CHECK_MSG(sp_oss_layer_base(n, k) == layer, "u(k) N=%llu k=%llu", (unsigned long long)n, (unsigned long long)k);
            layer += sp_oss_triangle_count(n - 2 * k);
        }
        CHECK(k == (n + 1) / 2);
        CHECK_MSG(sp_oss_tetrahedron_count(n) == layer, "T(N) N=%llu", (unsigned long long)n);
    }
    /* The reference point: 22-bit OSS with four weights. */
    CHECK(sp_oss_tetrahedron_count(421) == 4189921);
}

/* Large N on both sides of the 64-bit forms' limits (layers 2^21, rows and the two-product
 * layer form 2^30): consecutive bases differ by the layer's triangle and the row's length, from
 * 0. Layers only while u(k + 1) < 2^64 (every k below 2^23, a few past it). */
static void closed_forms_wide(void)
{
    static const uint64_t sizes[] = {(1u << 21) - 1, 1u << 21, (1u << 21) + 1, 6924641, (1u << 30) - 1, 1u << 30,
                                     (1u << 30) + 1};
    for (size_t s = 0; s < sizeof(sizes) / sizeof(sizes[0]); ++s) {
        uint64_t n = sizes[s], layers = (n + 1) / 2, rows = (2 * n + 1) / 3;
        uint64_t probes[] = {0, 1, 2, 3, 5, n < (1u << 23) ? layers / 2 : 6, n < (1u << 23) ? layers - 2 : 7};
        CHECK(sp_oss_layer_base(n, 0) == 0 && sp_oss_row_base(n, 0) == 0);
        for (size_t p = 0; p < sizeof(probes) / sizeof(probes[0]); ++p) {
            uint64_t k = probes[p], j = p < 5 ? probes[p] : (p == 5 ? rows / 2 : rows - 2);
            CHECK_MSG(sp_oss_layer_base(n, k + 1) - sp_oss_layer_base(n, k) == sp_oss_triangle_count(n - 2 * k),
                      "u(k) N=%llu k=%llu", (unsigned long long)n, (unsigned long long)k);
            CHECK_MSG(sp_oss_row_base(n, j + 1) - sp_oss_row_base(n, j) == n - j - (j + 1) / 2, "s(j) N=%llu j=%llu",
                      (unsigned long long)n, (unsigned long long)j);
        }
    }
}

/* Every code decodes to a valid tuple and encodes back to itself. */
static void exhaustive_identity(void)
{
    for (uint32_t k = 2; k <= 4; ++k)
        for (uint64_t n = 2; n <= (k == 2 ? 400u : (k == 3 ? 300u : 200u)); ++n) {
            uint64_t count = sp_u128_low(sp_oss_code_count(n, k)), s = 2 * (n - 1);
            for (uint64_t code = 0; code < count; ++code) {
                uint64_t q[4] = {0}, sum = 0;
                sp_oss_unpack(n, k, code, q);
                for (uint32_t i = 0; i < k; ++i) sum += q[i];
                int sorted = 1;
                for (uint32_t i = 1; i < k; ++i) sorted &= q[i - 1] >= q[i];
                CHECK_MSG(sum == s && sorted, "N=%llu K=%u code=%llu", (unsigned long long)n, k, (unsigned long long)code);
                CHECK_MSG(sp_oss_pack(n, k, q) == code, "N=%llu K=%u code=%llu", (unsigned long long)n, k,
                          (unsigned long long)code);
            }
        }
}

/* Large N: sampled codes, layer and row boundaries (both sides of the 64-bit forms' limits), first and last code, up to 64-bit codes. */
static void sampled_identity_large(void)
{
    for (uint32_t k = 2; k <= 4; ++k)
        for (uint32_t bits = 20; bits <= 64; bits += 4) {
            sp_codec c;
            CHECK(sp_codec_from_bits(SP_METHOD_OSS, k, bits, &c) == SP_OK);
            CHECK(c.bits <= bits);
            for (int t = 0; t < 3000; ++t) {
                uint64_t code;
                if (t == 0) code = 0;
                else if (t == 1) code = c.max_code;
                else if (t < 40 && k == 4) { /* around layer starts */
                    uint64_t layer = rng_next() % ((c.n + 1) / 2);
                    code = sp_oss_layer_base(c.n, layer) - (t & 1 ? (layer > 0) : 0);
                } else if (t < 80 && k == 3) { /* around row starts: the row search's one-step checks */
                    uint64_t row = rng_next() % ((2 * c.n + 1) / 3);
                    code = sp_oss_row_base(c.n, row) - (t & 1 ? (row > 0) : 0);
                } else code = c.max_code == UINT64_MAX ? rng_next() : rng_next() % (c.max_code + 1);
                uint64_t q[4] = {0};
                sp_oss_unpack(c.n, k, code, q);
                CHECK_MSG(sp_oss_pack(c.n, k, q) == code, "bits=%u K=%u code=%llu", bits, k, (unsigned long long)code);
            }
        }
}

int main(void)
{
    closed_forms_match_iteration();
    closed_forms_wide();
    exhaustive_identity();
    sampled_identity_large();
    return check_report("test_oss");
}
