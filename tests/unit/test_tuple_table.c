/*
 * The tuple table's output (entries and per-vertex indices) is part of the file format's
 * determinism: the builder may get faster, never different. Checked two ways on inputs from
 * few to many distinct tuples, with and without don't-care merging, K = 1..4: against a
 * plain reference of the documented rule (full tuples first, then ever shorter significant
 * prefixes; a new entry registers its prefixes, the first entry with a prefix keeps it; entries
 * in order of first use), and against checksums recorded from the builder before its speed-ups
 * (commit 709f921 for the first 64 cases, 3906c1f for the rest). The later cases aim at the
 * one-pass key builder: joints over the whole 16-bit range (a 4-joint key uses all 64 bits, and
 * the all-65535 tuple is the first one), counts of 0, more keys than the first table holds,
 * keys that all hash to one slot, inputs with and without runs, sizes that are not a multiple of
 * 8, and bad counts.
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
static size_t reference(const uint16_t* joints, const uint8_t* significant, size_t n, size_t k, uint16_t* lut,
                        uint32_t* index)
{
    static uint32_t key_entry[V * 4];
    static uint8_t key_length[V * 4];
    size_t keys = 0, entries = 0;
    for (size_t length = k; length >= 1; --length) {
        for (size_t v = 0; v < n; ++v) {
            size_t needed = significant ? (significant[v] ? significant[v] : 1) : k;
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

static uint64_t checksum(const uint16_t* lut, size_t size, size_t k, const uint32_t* index, size_t n)
{
    uint64_t h = 1469598103934665603ull ^ size;
    for (size_t i = 0; i < size * k; ++i) h = (h ^ lut[i]) * 1099511628211ull;
    for (size_t v = 0; v < n; ++v) h = (h ^ index[v]) * 1099511628211ull;
    return h;
}

/* Recorded from the builder of commit 709f921 (hash over prefixes, k passes), case by case in
 * the loop order of the first cases; then from the builder of commit 3906c1f for the later ones. */
static const uint64_t golden[] = {
#include "test_tuple_table_golden.inc"
#include "test_tuple_table_golden_more.inc"
};

static uint16_t joints[V * 4], lut[V * 4], ref_lut[V * 4];
static uint8_t significant[V];
static uint32_t index_[V], ref_index[V];
static size_t case_number;

/* Builds one input's table, compares it with the rule's and with the recorded checksum
 * (printed instead with SKINPACK_RECORD_GOLDEN set). */
static void check_case(const char* family, size_t n, size_t k, int merge, unsigned detail)
{
    const uint8_t* sig = merge ? significant : NULL;
    size_t bound = sp_tuple_lut_scratch_bound(n, k), size = 0, c = case_number++;
    /* the bound exactly, at any alignment, so that a sanitizer build sees an overrun */
    unsigned char* block = malloc(bound + c % 8);
    CHECK(sp_build_tuple_lut(joints, sig, n, k, lut, &size, index_, block + c % 8, bound) == SP_OK);
    free(block);
    size_t ref_size = reference(joints, sig, n, k, ref_lut, ref_index);
    uint64_t sum = checksum(lut, size, k, index_, n);
    if (getenv("SKINPACK_RECORD_GOLDEN"))
        printf("    0x%016llxull, /* K=%zu %s %u merge=%d: %zu tuples */\n", (unsigned long long)sum, k, family,
               detail, merge, size);
    else if (c < sizeof(golden) / sizeof(golden[0]))
        CHECK_MSG(sum == golden[c], "case %zu: K=%zu %s %u merge=%d: checksum", c, k, family, detail, merge);
    else
        CHECK_MSG(0, "case %zu has no recorded checksum", c);
    CHECK_MSG(size == ref_size && memcmp(lut, ref_lut, size * k * 2) == 0 &&
                  memcmp(index_, ref_index, n * sizeof(uint32_t)) == 0,
              "case %zu: K=%zu %s %u merge=%d: %zu tuples, reference %zu", c, k, family, detail, merge, size, ref_size);
}

/* Joints of only 0 and 65535 and counts of 0..K: masked keys that agree and counts that do not,
 * the all-ones key first. */
static void make_edge_input(uint64_t seed, size_t k, int runs)
{
    make_input(seed, k, 2, runs, joints, significant);
    for (size_t i = 0; i < V * k; ++i) joints[i] = joints[i] ? 65535 : 0;
    for (size_t v = 0; v < V; v += 3) significant[v] = (uint8_t)(significant[v] - 1);
    for (size_t i = 0; i < k; ++i) joints[i] = 65535;
    significant[0] = (uint8_t)k;
}

/* Distinct K-joint keys whose hash (key + K) * golden ratio has its top 13 bits 0, so that they
 * share one slot of every table up to 8192 slots of a multiplicative hash of the key and count
 * (the key builder's and the prefix table's): for K = 4 by inverting the multiplication, for
 * shorter keys by search (K = 1 has only 8). Vertices pick from them, in runs or not. */
static void make_colliding_input(uint64_t seed, size_t k, int runs)
{
    enum { WANTED = 500 };
    static uint64_t keys[WANTED];
    const uint64_t golden_ratio = 0x9E3779B97F4A7C15ull;
    uint64_t inverse = golden_ratio;
    for (int i = 0; i < 6; ++i) inverse *= 2 - golden_ratio * inverse;
    size_t found = 0;
    uint64_t x = seed;
    for (uint64_t tries = 0; found < WANTED && tries < ((uint64_t)1 << 16) * (k == 1 ? 1 : WANTED * 2); ++tries) {
        x ^= x << 13, x ^= x >> 7, x ^= x << 17;
        uint64_t key = k == 4 ? (found + 1) * inverse - 4 : (k == 1 ? tries : x) & ((((uint64_t)1) << (16 * k)) - 1);
        if (((key + k) * golden_ratio) >> 51 == 0) keys[found++] = key;
    }
    CHECK_MSG(found >= (k == 1 ? 4 : WANTED), "K=%zu: %zu colliding keys", k, found);
    size_t pick = 0;
    for (size_t v = 0; v < V; ++v) {
        x ^= x << 13, x ^= x >> 7, x ^= x << 17;
        if (!runs || x % 4 == 0) pick = (size_t)(x >> 8) % found;
        for (size_t i = 0; i < k; ++i) joints[v * k + i] = (uint16_t)(keys[pick] >> (16 * i));
        significant[v] = (uint8_t)(x % 8 ? k : 1 + (x >> 3) % k);
    }
}

/* Long runs of one tuple, then none, then long runs again: the key pass goes by its last keys,
 * then by the table, then back. */
static void make_mixed_input(uint64_t seed, size_t k)
{
    make_input(seed, k, 64, 0, joints, significant);
    for (size_t v = 0; v < V; ++v) {
        size_t from = v < V / 3 ? v - v % 500 : v < 2 * V / 3 ? v : v - v % 300;
        memcpy(joints + v * k, joints + from * k, k * sizeof(uint16_t));
    }
}

/* Counts above K anywhere (the first vertex, one inside an 8-vertex step, one in the tail after
 * the last step) fail and leave the outputs alone. */
static void check_bad_counts(void)
{
    static unsigned char scratch[V * 200];
    static const unsigned bad[] = {5, 7, 8, 128, 255};
    static const size_t where[] = {0, 9, V - 2};
    for (size_t k = 1; k <= 4; ++k)
        for (size_t b = 0; b < sizeof(bad) / sizeof(bad[0]) + 1; ++b)
            for (size_t w = 0; w < 3; ++w) {
                make_input(7, k, 64, 1, joints, significant);
                significant[where[w]] = (uint8_t)(b == 0 ? k + 1 : bad[b - 1]);
                memset(index_, 0xab, sizeof(index_));
                size_t size = 12345, bound = sp_tuple_lut_scratch_bound(V - 1, k);
                CHECK(bound <= sizeof(scratch));
                CHECK_MSG(sp_build_tuple_lut(joints, significant, V - 1, k, lut, &size, index_, scratch, bound) ==
                              SP_ERR_INVALID_ARGUMENT,
                          "K=%zu count %u at %zu", k, significant[where[w]], where[w]);
                CHECK(size == 12345 && index_[0] == 0xabababab && index_[V - 2] == 0xabababab);
                CHECK(sp_build_tuple_lut(joints, NULL, V - 1, k, lut, &size, index_, scratch, bound - 1) ==
                      SP_ERR_BUFFER_TOO_SMALL);
            }
}

int main(void)
{
    static const uint32_t ranges[] = {3, 8, 64, 1000};
    for (size_t k = 1; k <= 4; ++k)
        for (size_t r = 0; r < sizeof(ranges) / sizeof(ranges[0]); ++r)
            for (int runs = 0; runs < 2; ++runs)
                for (int merge = 0; merge < 2; ++merge) {
                    make_input(case_number + 1, k, ranges[r], runs, joints, significant);
                    check_case(runs ? "runs, joints <" : "joints <", V, k, merge, ranges[r]);
                }
    for (size_t k = 1; k <= 4; ++k)
        for (int runs = 0; runs < 2; ++runs)
            for (int merge = 0; merge < 2; ++merge) {
                make_input(case_number + 1, k, 65536, runs, joints, significant);
                check_case("16-bit joints, runs", V, k, merge, (unsigned)runs);
                make_edge_input(case_number + 1, k, runs);
                check_case("joints 0/65535 and counts 0, runs", V, k, merge, (unsigned)runs);
                make_colliding_input(case_number + 1, k, runs);
                check_case("colliding keys, runs", V, k, merge, (unsigned)runs);
            }
    for (size_t k = 1; k <= 4; ++k)
        for (int merge = 0; merge < 2; ++merge) {
            make_mixed_input(case_number + 1, k);
            check_case("runs, none, runs", V, k, merge, 0);
        }
    static const size_t sizes[] = {0, 1, 7, 9, 255, 257, V - 1};
    for (size_t k = 3; k <= 4; ++k)
        for (size_t i = 0; i < sizeof(sizes) / sizeof(sizes[0]); ++i) {
            make_input(case_number + 1, k, 64, 1, joints, significant);
            check_case("vertices", sizes[i], k, 1, (unsigned)sizes[i]);
        }
    CHECK(getenv("SKINPACK_RECORD_GOLDEN") || case_number == sizeof(golden) / sizeof(golden[0]));
    check_bad_counts();
    return check_report("test_tuple_table");
}
