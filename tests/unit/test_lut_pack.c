/* Tuple table (with and without don't-care merging) and vertex word packing. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "skinpack.h"

static void lut_unique_and_deterministic(void)
{
    enum { V = 5000, K = 4 };
    static uint16_t joints[V * K];
    static uint8_t significant[V];
    static uint16_t lut[V * K], lut2[V * K];
    static uint32_t index[V], index2[V];
    size_t scratch_size = sp_tuple_lut_scratch_bound(V, K);
    void* scratch = malloc(scratch_size);
    for (size_t v = 0; v < V; ++v) {
        for (size_t i = 0; i < K; ++i) joints[v * K + i] = (uint16_t)(rng_next() % 6);
        significant[v] = (uint8_t)(1 + rng_next() % K);
    }
    size_t size = 0, size2 = 0;
    CHECK(sp_build_tuple_lut(joints, NULL, V, K, lut, &size, index, scratch, scratch_size) == SP_OK);
    for (size_t v = 0; v < V; ++v) CHECK(index[v] < size && memcmp(lut + index[v] * K, joints + v * K, K * 2) == 0);
    for (size_t a = 0; a < size; ++a)
        for (size_t b = a + 1; b < size; ++b) CHECK(memcmp(lut + a * K, lut + b * K, K * 2) != 0);
    CHECK(sp_build_tuple_lut(joints, NULL, V, K, lut2, &size2, index2, scratch, scratch_size) == SP_OK);
    CHECK(size == size2 && memcmp(lut, lut2, size * K * 2) == 0 && memcmp(index, index2, sizeof(index)) == 0);

    /* don't care: only the significant prefix must match, and the table shrinks */
    size_t merged = 0;
    CHECK(sp_build_tuple_lut(joints, significant, V, K, lut2, &merged, index2, scratch, scratch_size) == SP_OK);
    CHECK(merged < size);
    for (size_t v = 0; v < V; ++v)
        CHECK(index2[v] < merged && memcmp(lut2 + index2[v] * K, joints + v * K, significant[v] * 2) == 0);
    CHECK(sp_build_tuple_lut(joints, NULL, V, K, lut, &size, index, scratch, 16) == SP_ERR_BUFFER_TOO_SMALL);
    CHECK(sp_index_bits(1) == 0 && sp_index_bits(2) == 1 && sp_index_bits(3) == 2 && sp_index_bits(1024) == 10 &&
          sp_index_bits(1025) == 11);
    free(scratch);
}

static void packing_round_trip(void)
{
    enum { V = 1000 };
    static uint32_t tuple[V], tuple_out[V], words[2 * V];
    static uint64_t codes[V], codes_out[V];
    const uint32_t layouts[][2] = {{0, 0}, {10, 22}, {0, 32}, {16, 16}, {10, 38}, {1, 63}, {0, 64}, {32, 32}};
    for (size_t l = 0; l < sizeof(layouts) / sizeof(layouts[0]); ++l) {
        uint32_t tb = layouts[l][0], wb = layouts[l][1];
        uint32_t per = sp_words_per_vertex(tb, wb);
        CHECK(per == (tb + wb <= 32 ? 1u : 2u));
        for (size_t v = 0; v < V; ++v) {
            tuple[v] = tb ? (uint32_t)(rng_next() & ((1ull << tb) - 1)) : 0;
            codes[v] = wb ? rng_next() >> (64 - wb) : 0;
        }
        CHECK(sp_pack_vertices(tuple, codes, V, tb, wb, words) == SP_OK);
        size_t bad = 0;
        CHECK(sp_unpack_vertices(words, V, tb, wb, tuple_out, codes_out, &bad) == SP_OK);
        CHECK(memcmp(tuple, tuple_out, sizeof(tuple)) == 0 && memcmp(codes, codes_out, sizeof(codes)) == 0);
        if (l == 1) { /* layout of docs/format.md: code low, tuple above it */
            CHECK(words[0] == ((uint32_t)codes[0] | tuple[0] << 22));
            words[7] |= 0x80000000u; /* bit 31 is used by 10 + 22: no padding to corrupt */
        }
        if (tb + wb < 32 || (tb + wb > 32 && tb + wb < 64)) {
            words[per * 3 + per - 1] |= 0x80000000u; /* a padding bit of vertex 3 */
            CHECK(sp_unpack_vertices(words, V, tb, wb, tuple_out, codes_out, &bad) == SP_ERR_CORRUPT_DATA && bad == 3);
        }
    }
    CHECK(sp_words_per_vertex(10, 60) == 0 && sp_words_per_vertex(33, 0) == 0);
    CHECK(sp_pack_vertices(tuple, codes, V, 10, 60, words) == SP_ERR_BITS_OUT_OF_RANGE);
    tuple[0] = 1024;
    codes[0] = 1;
    CHECK(sp_pack_vertices(tuple, codes, 1, 10, 22, words) == SP_ERR_TUPLE_OUT_OF_RANGE);
    tuple[0] = 0;
    codes[0] = 1u << 22;
    CHECK(sp_pack_vertices(tuple, codes, 1, 10, 22, words) == SP_ERR_CODE_OUT_OF_RANGE);
}

int main(void)
{
    lut_unique_and_deterministic();
    packing_round_trip();
    return check_report("test_lut_pack");
}
