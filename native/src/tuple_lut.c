/*
 * Joint-tuple lookup table (Kuth & Meyer, Sec. 3): unique ordered joint tuples, one index per
 * vertex. Open-addressing hash over tuple prefixes so that a vertex whose trailing slots have
 * zero weight ("don't care") can reuse any tuple that starts with its significant joints.
 *
 * The output depends only on the rule (full tuples first, then ever shorter significant
 * prefixes; entries in order of first use), never on the hash. A vertex's entry depends only on
 * its significant prefix and the prefixes before it, so one pass (tuple_keys.c) numbers the
 * distinct (count, prefix) keys in order of first use, the rule runs on those few keys, and a
 * last pass maps each vertex's key number to its entry (skipped when they are the same; without
 * merging, every distinct tuple is its own entry). The prefix table starts small and doubles, so
 * a mesh with few tuples neither clears nor misses on a table sized for the worst case.
 */
#include <string.h>

#include "skinpack.h"
#include "tuple_keys.h"

/* The smallest table (slots); it doubles whenever half full. */
#define FIRST_CAPACITY 256

typedef struct lut_builder {
    uint16_t* lut;
    size_t size;
    size_t k;
    uint32_t* slots;  /* hash slots: entry index + 1, 0 = empty */
    uint8_t* lengths; /* prefix length the slot was registered for */
    size_t capacity, used;
    unsigned shift;         /* 64 - log2(capacity): the hash's top bits pick the slot */
    size_t full;            /* the largest capacity, enough for every key at load 1/2 */
    unsigned char* regions; /* a table of capacity full at 0, one of full/2 after it */
} lut_builder;

static size_t table_capacity(size_t entries, size_t k)
{
    size_t keys = entries * k, capacity = FIRST_CAPACITY;
    while (capacity < 2 * keys) capacity *= 2;
    return capacity;
}

#define SLOT_BYTES (sizeof(uint32_t) + 1)

/* Two prefix table regions: the doubling moves between them. */
static size_t prefix_table_bytes(size_t entries, size_t k)
{
    size_t full = table_capacity(entries, k);
    return (full + full / 2) * SLOT_BYTES;
}

/* One region for the key pass's table and then the prefix tables, the key records, and each
 * key's entry. */
static size_t table_region_bytes(size_t vertex_count, size_t k)
{
    size_t keys = sp_tuple_keys_table_bytes(vertex_count), prefixes = prefix_table_bytes(vertex_count, k);
    return ((keys > prefixes ? keys : prefixes) + 7) & ~(size_t)7;
}

/* The scratch from its first 8-byte boundary on. */
static size_t scratch_bytes(size_t vertex_count, size_t k)
{
    return 7 + table_region_bytes(vertex_count, k) + sp_tuple_keys_record_bytes(vertex_count) +
           vertex_count * sizeof(uint32_t);
}

size_t sp_tuple_lut_scratch_bound(size_t vertex_count, size_t influences)
{
    if (influences < 1) influences = 1;
    if (influences > SP_MAX_INFLUENCES) influences = SP_MAX_INFLUENCES;
    return scratch_bytes(vertex_count, influences);
}

static inline size_t slot_of(const lut_builder* b, uint64_t key, size_t length)
{
    return (size_t)(((key + length) * 0x9E3779B97F4A7C15ull) >> b->shift);
}

/* Slot holding the given prefix, or the empty slot where it belongs. */
static size_t find_slot(const lut_builder* b, uint64_t key, size_t length)
{
    size_t mask = b->capacity - 1;
    for (size_t at = slot_of(b, key, length);; at = (at + 1) & mask) {
        uint32_t entry = b->slots[at];
        if (entry == 0) return at;
        if (b->lengths[at] == length && sp_tuple_prefix_key(b->lut + (size_t)(entry - 1) * b->k, b->k, length) == key) return at;
    }
}

/* Points the builder at an empty table of `capacity` slots: capacities full, full/4, ... in
 * the first region, full/2, full/8, ... in the second, so a doubling never overlaps. */
static void start_table(lut_builder* b, size_t capacity)
{
    size_t steps = 0;
    while ((capacity << steps) < b->full) ++steps;
    unsigned char* at = b->regions + (steps % 2 ? b->full * SLOT_BYTES : 0);
    b->capacity = capacity;
    b->slots = (uint32_t*)at;
    b->lengths = at + capacity * sizeof(uint32_t);
    b->shift = 64;
    for (size_t c = capacity; c > 1; c /= 2) --b->shift;
    memset(at, 0, capacity * SLOT_BYTES);
}

/* Doubles the table, moving every registered key (they are unique: no comparisons). */
static void grow(lut_builder* b)
{
    const uint32_t* old_slots = b->slots;
    const uint8_t* old_lengths = b->lengths;
    size_t old_capacity = b->capacity;
    start_table(b, old_capacity * 2);
    for (size_t i = 0; i < old_capacity; ++i) {
        uint32_t entry = old_slots[i];
        if (entry == 0) continue;
        size_t length = old_lengths[i], mask = b->capacity - 1;
        size_t at = slot_of(b, sp_tuple_prefix_key(b->lut + (size_t)(entry - 1) * b->k, b->k, length), length);
        while (b->slots[at]) at = (at + 1) & mask;
        b->slots[at] = entry;
        b->lengths[at] = (uint8_t)length;
    }
}

/* Appends a tuple and registers its prefixes; the first tuple with a prefix keeps it. */
static uint32_t add_entry(lut_builder* b, const uint16_t* joints, size_t first_length)
{
    uint32_t entry = (uint32_t)b->size++;
    memcpy(b->lut + (size_t)entry * b->k, joints, b->k * sizeof(uint16_t));
    for (size_t length = first_length; length <= b->k; ++length) {
        if (2 * (b->used + 1) > b->capacity && b->capacity < b->full) grow(b);
        size_t at = find_slot(b, sp_tuple_prefix_key(joints, b->k, length), length);
        if (b->slots[at] == 0) {
            b->slots[at] = entry + 1;
            b->lengths[at] = (uint8_t)length;
            b->used++;
        }
    }
    return entry;
}

/* Whether every significant count is at most k (<= 4), eight counts a step: a count above k
 * is 8 or more, or sets bit 3 of count + 7 - k (no carries below 8). */
static int counts_at_most(const uint8_t* significant, size_t vertex_count, size_t k)
{
    const uint64_t ones = 0x0101010101010101ull;
    uint64_t above = 0;
    size_t v = 0;
    for (; v + 8 <= vertex_count; v += 8) {
        uint64_t counts;
        memcpy(&counts, significant + v, sizeof(counts));
        above |= (counts & (0xf8 * ones)) | ((counts + (7 - k) * ones) & (0x08 * ones));
    }
    for (; v < vertex_count; ++v) above |= significant[v] > k;
    return above == 0;
}

/* The rule on the distinct keys, which stand for their vertices: full prefixes first, then ever
 * shorter ones, each length's keys in order of first use; a new entry takes the joints of the
 * key's first vertex and registers all its prefixes. Returns whether every key is its own entry. */
static int assign_entries(lut_builder* b, const uint16_t* joints, const sp_tuple_keys* keys, uint32_t* entry_of)
{
    int same = 1;
    for (size_t length = b->k; length >= 1; --length)
        for (size_t id = 0; id < keys->size; ++id) {
            size_t count = keys->counts[id] ? keys->counts[id] : 1;
            if (count != length) continue;
            size_t at = find_slot(b, keys->keys[id], length);
            entry_of[id] = b->slots[at] ? b->slots[at] - 1 : add_entry(b, joints + (size_t)keys->first[id] * b->k, 1);
            same &= entry_of[id] == id;
        }
    return same;
}

sp_result sp_build_tuple_lut(const uint16_t* joints, const uint8_t* significant, size_t vertex_count,
                             size_t influences, uint16_t* lut, size_t* lut_size, uint32_t* tuple_index,
                             void* scratch, size_t scratch_size)
{
    if (!joints || !lut || !lut_size || !tuple_index || influences < 1 || influences > SP_MAX_INFLUENCES ||
        vertex_count > UINT32_MAX)
        return SP_ERR_INVALID_ARGUMENT;
    if (!scratch || scratch_size < scratch_bytes(vertex_count, influences)) return SP_ERR_BUFFER_TOO_SMALL;
    size_t k = influences;
    if (significant && !counts_at_most(significant, vertex_count, k)) return SP_ERR_INVALID_ARGUMENT;

    unsigned char* region = (unsigned char*)scratch + (8 - (uintptr_t)scratch % 8) % 8;
    unsigned char* records = region + table_region_bytes(vertex_count, k);
    uint32_t* entry_of = (uint32_t*)(records + sp_tuple_keys_record_bytes(vertex_count));
    sp_tuple_keys keys;
    sp_collect_tuple_keys(joints, significant, vertex_count, k, tuple_index, region, records, &keys);

    if (!significant) { /* distinct full tuples, each its own entry in order of first use */
        for (size_t id = 0; id < keys.size; ++id)
            memcpy(lut + id * k, joints + (size_t)keys.first[id] * k, k * sizeof(uint16_t));
        *lut_size = keys.size;
        return SP_OK;
    }
    size_t full = table_capacity(keys.size, k);
    lut_builder b = {lut, 0, k, NULL, NULL, 0, 0, 64, full, region};
    start_table(&b, FIRST_CAPACITY < full ? FIRST_CAPACITY : full);
    if (!assign_entries(&b, joints, &keys, entry_of))
        for (size_t v = 0; v < vertex_count; ++v) tuple_index[v] = entry_of[tuple_index[v]];
    *lut_size = b.size;
    return SP_OK;
}
