/*
 * The tuple table's output (entries and per-vertex indices) is part of the file format's
 * determinism: the builder may get faster, never different. Checked two ways on inputs from
 * few to many distinct tuples, with and without don't-care merging, K = 1..4: against a
 * plain reference of the documented rule (full tuples first, then ever shorter significant
 * prefixes; a new entry registers its prefixes, the first entry with a prefix keeps it; entries
 * in order of first use), and against checksums recorded from the builder before its speed-up.
 */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "skinpack.h"

enum { V = 3000 };

/* An input family: joints from a range, runs of repeated tuples as along a real mesh. */
static void make_input(uint64_t seed, size_t k, uint32_t joint_range, int runs, uint16_t* joints, uint8_t* significant)
{
    uint64_t x = seed * 0x9E3779B97F4A7C15ull + 1;
    for (size_t v = 0; v < V; ++v) {
        x ^= x << 13, x ^= x >> 7, x ^= x << 17;
        if (runs && v > 0 && x % 4 != 0) { /* repeat the previous vertex's joints, maybe a new count */
            memcpy(joints + v * k, joints + (v - 1) * k, k * sizeof(uint16_t));
        } else {
            for (size_t i = 0; i < k; ++i) {
                x ^= x << 13, x ^= x >> 7, x ^= x << 17;
                joints[v * k + i] = (uint16_t)(x % joint_range);
            }
        }
        x ^= x << 13, x ^= x >> 7, x ^= x << 17;
        significant[v] = (uint8_t)(1 + x % k);
    }
}

/* The rule, by linear search over the registered (entry, prefix length) keys. */
static size_t reference(const uint16_t* joints, const uint8_t* significant, size_t k, uint16_t* lut,
                        uint32_t* index)
{
    static uint32_t key_entry[V * 4];
    static uint8_t key_length[V * 4];
    size_t keys = 0, entries = 0;
    for (size_t length = k; length >= 1; --length) {
        for (size_t v = 0; v < V; ++v) {
            size_t needed = significant ? significant[v] : k;
            if (needed != length) continue;
            size_t found = keys;
            for (size_t e = 0; e < keys && found == keys; ++e)
                if (key_length[e] == length && memcmp(lut + key_entry[e] * k, joints + v * k, length * 2) == 0) found = e;
            if (found < keys) {
                index[v] = key_entry[found];
                continue;
            }
            memcpy(lut + entries * k, joints + v * k, k * 2);
            for (size_t l = significant ? 1 : k; l <= k; ++l) {
                int known = 0;
                for (size_t e = 0; e < keys && !known; ++e)
                    known = key_length[e] == l && memcmp(lut + key_entry[e] * k, joints + v * k, l * 2) == 0;
                if (!known) key_entry[keys] = (uint32_t)entries, key_length[keys++] = (uint8_t)l;
            }
            index[v] = (uint32_t)entries++;
        }
        if (!significant) break;
    }
    return entries;
}

static uint64_t checksum(const uint16_t* lut, size_t size, size_t k, const uint32_t* index)
{
    uint64_t h = 1469598103934665603ull ^ size;
    for (size_t i = 0; i < size * k; ++i) h = (h ^ lut[i]) * 1099511628211ull;
    for (size_t v = 0; v < V; ++v) h = (h ^ index[v]) * 1099511628211ull;
    return h;
}

/* Recorded from the builder of commit 709f921 (hash over prefixes, k passes), case by case in
 * the loop order below. */
static const uint64_t golden[] = {
#include "test_tuple_table_golden.inc"
};

int main(void)
{
    static uint16_t joints[V * 4], lut[V * 4], ref_lut[V * 4];
    static uint8_t significant[V];
    static uint32_t index[V], ref_index[V];
    static const uint32_t ranges[] = {3, 8, 64, 1000};
    size_t scratch_size = sp_tuple_lut_scratch_bound(V, 4);
    void* scratch = malloc(scratch_size);
    size_t c = 0;
    int record = getenv("SKINPACK_RECORD_GOLDEN") != NULL;
    for (size_t k = 1; k <= 4; ++k)
        for (size_t r = 0; r < sizeof(ranges) / sizeof(ranges[0]); ++r)
            for (int runs = 0; runs < 2; ++runs)
                for (int merge = 0; merge < 2; ++merge, ++c) {
                    make_input(c + 1, k, ranges[r], runs, joints, significant);
                    const uint8_t* sig = merge ? significant : NULL;
                    size_t size = 0;
                    CHECK(sp_build_tuple_lut(joints, sig, V, k, lut, &size, index, scratch,
                                             sp_tuple_lut_scratch_bound(V, k)) == SP_OK);
                    size_t ref_size = reference(joints, sig, k, ref_lut, ref_index);
                    uint64_t sum = checksum(lut, size, k, index);
                    if (record) printf("    0x%016llxull, /* K=%zu joints<%u runs=%d merge=%d: %zu tuples */\n",
                                       (unsigned long long)sum, k, ranges[r], runs, merge, size);
                    CHECK_MSG(size == ref_size && memcmp(lut, ref_lut, size * k * 2) == 0 &&
                                  memcmp(index, ref_index, sizeof(index)) == 0,
                              "K=%zu joints<%u runs=%d merge=%d: %zu tuples, reference %zu", k, ranges[r], runs, merge,
                              size, ref_size);
                    if (!record && c < sizeof(golden) / sizeof(golden[0]))
                        CHECK_MSG(sum == golden[c], "K=%zu joints<%u runs=%d merge=%d: checksum", k, ranges[r], runs,
                                  merge);
                }
    CHECK(record || c == sizeof(golden) / sizeof(golden[0]));
    free(scratch);
    return check_report("test_tuple_table");
}
