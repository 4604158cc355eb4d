/*
 * Joint-tuple lookup table (Kuth & Meyer, Sec. 3): unique ordered joint tuples, one index per
 * vertex. Open-addressing hash over tuple prefixes so that a vertex whose trailing slots have
 * zero weight ("don't care") can reuse any tuple that starts with its significant joints.
 *
 * The output depends only on the rule (full tuples first, then ever shorter significant
 * prefixes; entries in order of first use), never on the hash: the table starts small and
 * doubles, so a mesh with few tuples neither clears nor misses on a table sized for the worst
 * case; the vertices are bucketed by prefix length once, not scanned once per length; and a
 * vertex with the prefix of the one before it (runs along a mesh) takes its entry without a
 * lookup.
 */
#include <string.h>

#include "skinpack.h"

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

static size_t table_capacity(size_t vertex_count, size_t k)
{
    size_t keys = vertex_count * k, capacity = FIRST_CAPACITY;
    while (capacity < 2 * keys) capacity *= 2;
    return capacity;
}

#define SLOT_BYTES (sizeof(uint32_t) + 1)

/* Two table regions (the doubling moves between them) and the vertices bucketed by length. */
static size_t scratch_bytes(size_t vertex_count, size_t k)
{
    size_t full = table_capacity(vertex_count, k);
    return (full + full / 2) * SLOT_BYTES + vertex_count * sizeof(uint32_t);
}

size_t sp_tuple_lut_scratch_bound(size_t vertex_count, size_t influences)
{
    if (influences < 1) influences = 1;
    return scratch_bytes(vertex_count, influences);
}

/* The first `length` joints as one key (K <= 4 joints of 16 bits): all K read without a loop
 * over the length, the slots past it masked off. */
static inline uint64_t prefix_key(const uint16_t* joints, size_t k, size_t length)
{
    uint64_t key = joints[0];
    if (k > 1) key |= (uint64_t)joints[1] << 16;
    if (k > 2) key |= (uint64_t)joints[2] << 32;
    if (k > 3) key |= (uint64_t)joints[3] << 48;
    return length >= 4 ? key : key & ((((uint64_t)1) << (16 * length)) - 1);
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
        if (b->lengths[at] == length && prefix_key(b->lut + (size_t)(entry - 1) * b->k, b->k, length) == key) return at;
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
        size_t at = slot_of(b, prefix_key(b->lut + (size_t)(entry - 1) * b->k, b->k, length), length);
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
        size_t at = find_slot(b, prefix_key(joints, b->k, length), length);
        if (b->slots[at] == 0) {
            b->slots[at] = entry + 1;
            b->lengths[at] = (uint8_t)length;
            b->used++;
        }
    }
    return entry;
}

/* Finds or adds the entry of one vertex's prefix of `length`; a vertex with the same prefix as
 * the one before it in the pass reuses its entry without a lookup. */
static inline void index_vertex(lut_builder* b, const uint16_t* tuple, size_t length, size_t register_from,
                                uint64_t* last_key, uint32_t* last_entry, uint32_t* index)
{
    uint64_t key = prefix_key(tuple, b->k, length);
    if (key != *last_key || *last_entry == UINT32_MAX) {
        size_t at = find_slot(b, key, length);
        *last_entry = b->slots[at] ? b->slots[at] - 1 : add_entry(b, tuple, register_from);
        *last_key = key;
    }
    *index = *last_entry;
}

/* Vertices by prefix length (a count of 0 counts as 1), each length's in vertex order: a
 * stable counting sort, so each pass reads only its own vertices (scanning all of them once
 * per length cost a branch miss on nearly every vertex). start[l] .. start[l - 1] holds
 * length l. Fails on a count above k. */
static int bucket_by_length(const uint8_t* significant, size_t vertex_count, size_t k, uint32_t* order,
                            size_t* start)
{
    size_t count[8] = {0};
    unsigned seen = 0;
    /* one branch-free pass: eight 8-bit counters in one word (by value & 7), emptied every 255
     * vertices; values of 8 and more show in the OR of all */
    for (size_t first = 0; first < vertex_count; first += 255) {
        size_t end = vertex_count - first < 255 ? vertex_count : first + 255;
        uint64_t packed = 0;
        for (size_t v = first; v < end; ++v) {
            packed += (uint64_t)1 << ((significant[v] & 7) * 8);
            seen |= significant[v];
        }
        for (size_t value = 0; value < 8; ++value) count[value] += (size_t)(packed >> (8 * value)) & 255;
    }
    if (seen > 7) return 0;
    for (size_t value = k + 1; value < 8; ++value)
        if (count[value]) return 0;
    count[1] = vertex_count;
    for (size_t length = 2; length <= k; ++length) count[1] -= count[length];
    start[k] = 0; /* the longest prefixes first */
    for (size_t length = k; length > 1; --length) start[length - 1] = start[length] + count[length];
    start[0] = vertex_count;
    size_t at[SP_MAX_INFLUENCES + 1];
    memcpy(at, start, sizeof(at));
    for (size_t v = 0; v < vertex_count; ++v) {
        size_t needed = significant[v] < 1 ? 1 : significant[v];
        order[at[needed]++] = (uint32_t)v;
    }
    return 1;
}

sp_result sp_build_tuple_lut(const uint16_t* joints, const uint8_t* significant, size_t vertex_count,
                             size_t influences, uint16_t* lut, size_t* lut_size, uint32_t* tuple_index,
                             void* scratch, size_t scratch_size)
{
    if (!joints || !lut || !lut_size || !tuple_index || influences < 1 || influences > SP_MAX_INFLUENCES ||
        vertex_count > UINT32_MAX)
        return SP_ERR_INVALID_ARGUMENT;
    if (!scratch || scratch_size < scratch_bytes(vertex_count, influences)) return SP_ERR_BUFFER_TOO_SMALL;

    size_t k = influences, full = table_capacity(vertex_count, k);
    lut_builder b = {lut, 0, k, NULL, NULL, 0, 0, 64, full, (unsigned char*)scratch};
    uint32_t* order = (uint32_t*)((unsigned char*)scratch + (full + full / 2) * SLOT_BYTES);
    size_t start[SP_MAX_INFLUENCES + 1];
    if (significant && !bucket_by_length(significant, vertex_count, k, order, start)) return SP_ERR_INVALID_ARGUMENT;
    start_table(&b, FIRST_CAPACITY < full ? FIRST_CAPACITY : full);

    uint64_t last_key = 0;
    uint32_t last_entry = UINT32_MAX;
    if (!significant) { /* without merging only full-length keys are registered, so equal tuples match */
        for (size_t v = 0; v < vertex_count; ++v)
            index_vertex(&b, joints + v * k, k, k, &last_key, &last_entry, tuple_index + v);
    } else { /* full tuples first, then ever shorter prefixes: a partial tuple finds every full one */
        for (size_t length = k; length >= 1; --length, last_entry = UINT32_MAX)
            for (size_t i = start[length]; i < start[length - 1]; ++i)
                index_vertex(&b, joints + (size_t)order[i] * k, length, 1, &last_key, &last_entry,
                             tuple_index + order[i]);
    }
    *lut_size = b.size;
    return SP_OK;
}
