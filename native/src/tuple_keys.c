/*
 * The distinct keys of a mesh's vertices for the tuple table (tuple_lut.c): one pass over the
 * vertices that masks each one's joints to its significant prefix and looks the key up in an
 * open-addressing table. The table starts small and doubles, so for the few hundred keys of a
 * typical mesh it stays in L1 and nearly every vertex is one multiply, one probe and one store;
 * the table rule then runs on the distinct keys only.
 */
#include <string.h>

#include "tuple_keys.h"

/* The smallest table (slots); it doubles whenever half full. */
#define FIRST_CAPACITY 256
#define EMPTY UINT32_MAX /* the count of an empty slot: counts are <= 4 */

typedef struct key_slot {
    uint64_t key;
    uint32_t id;
    uint32_t count; /* the significant count as given; EMPTY */
} key_slot;

typedef struct key_table {
    key_slot* slots;
    size_t capacity, max_capacity;
    unsigned shift; /* 64 - log2(capacity): the hash's top bits pick the slot */
    sp_tuple_keys* keys;
} key_table;

/* A key for every vertex fits at load 1/2. */
static size_t max_capacity(size_t vertex_count)
{
    size_t capacity = FIRST_CAPACITY;
    while (capacity < 2 * vertex_count) capacity *= 2;
    return capacity;
}

size_t sp_tuple_keys_table_bytes(size_t vertex_count)
{
    return max_capacity(vertex_count) * sizeof(key_slot);
}

size_t sp_tuple_keys_record_bytes(size_t vertex_count)
{
    size_t bytes = vertex_count * (sizeof(uint64_t) + sizeof(uint32_t) + sizeof(uint8_t));
    return (bytes + 7) & ~(size_t)7;
}

SP_INLINE size_t slot_of(uint64_t key, uint32_t count, unsigned shift)
{
    return (size_t)(((key + count) * 0x9E3779B97F4A7C15ull) >> shift);
}

static void start_table(key_table* t, size_t capacity)
{
    t->capacity = capacity;
    t->shift = 64;
    for (size_t c = capacity; c > 1; c /= 2) --t->shift;
    memset(t->slots, 0xff, capacity * sizeof(key_slot)); /* count EMPTY */
}

/* Enters a key known to be absent. */
static void place(key_table* t, uint64_t key, uint32_t count, uint32_t id)
{
    size_t mask = t->capacity - 1, at = slot_of(key, count, t->shift);
    while (t->slots[at].count != EMPTY) at = (at + 1) & mask;
    t->slots[at].key = key;
    t->slots[at].id = id;
    t->slots[at].count = count;
}

/* Doubles the table and re-enters every key from the records (unique: no comparisons). */
static void grow(key_table* t)
{
    start_table(t, t->capacity * 2);
    const sp_tuple_keys* r = t->keys;
    for (size_t id = 0; id < r->size; ++id) place(t, r->keys[id], r->counts[id], (uint32_t)id);
}

/* The id of a key that is not in the slot it hashes to: further along, or a new one. */
static uint32_t find_or_add(key_table* t, uint64_t key, uint32_t count, size_t vertex)
{
    size_t mask = t->capacity - 1;
    for (size_t at = slot_of(key, count, t->shift); t->slots[at].count != EMPTY; at = (at + 1) & mask)
        if (t->slots[at].key == key && t->slots[at].count == count) return t->slots[at].id;
    sp_tuple_keys* r = t->keys;
    uint32_t id = (uint32_t)r->size++;
    r->keys[id] = key;
    r->first[id] = (uint32_t)vertex;
    r->counts[id] = (uint8_t)count;
    if (2 * r->size > t->capacity && t->capacity < t->max_capacity) grow(t);
    else place(t, key, count, id);
    return id;
}

/* The id of a key: from the slot it hashes to, else by find_or_add. */
SP_INLINE uint32_t key_id(key_table* t, uint64_t key, uint32_t count, size_t vertex)
{
    const key_slot* slot = &t->slots[slot_of(key, count, t->shift)];
    return slot->key == key && slot->count == count ? slot->id : find_or_add(t, key, count, vertex);
}

/*
 * Inlined per K and with or without counts, so that a key is one masked load. Each count keeps
 * the last key it saw and that key's id: along a mesh, neighbouring vertices share their joints
 * while their counts vary, so nearly every vertex is one compare with the last key of its count
 * and the table is looked up once a run. A cache starts on a key no vertex of its count has:
 * all ones for a prefix shorter than 4 joints (its top joint is masked to 0), and for full
 * 4-joint tuples anything but the first one's.
 */
SP_INLINE void collect(key_table* t, const uint16_t* joints, const uint8_t* significant, size_t vertex_count,
                       size_t k, uint32_t* ids)
{
    static const uint64_t prefix_mask[5] = {0xffff, 0xffff, 0xffffffff, 0xffffffffffff, ~(uint64_t)0};
    uint64_t last_key[5] = {~(uint64_t)0, ~(uint64_t)0, ~(uint64_t)0, ~(uint64_t)0, ~(uint64_t)0};
    uint32_t last_id[5] = {0, 0, 0, 0, 0};
    if (k == 4) {
        const uint8_t* full = significant ? memchr(significant, 4, vertex_count) : NULL;
        size_t first = significant ? (full ? (size_t)(full - significant) : vertex_count) : 0;
        if (first < vertex_count) last_key[4] = ~sp_tuple_prefix_key(joints + first * 4, 4, 4);
    }
    for (size_t v = 0; v < vertex_count; ++v) {
        uint32_t count = significant ? significant[v] : (uint32_t)k;
        uint64_t key = sp_tuple_prefix_key(joints + v * k, k, 4) & prefix_mask[count];
        if (key != last_key[count]) {
            last_key[count] = key;
            last_id[count] = key_id(t, key, count, v);
        }
        ids[v] = last_id[count];
    }
}

void sp_collect_tuple_keys(const uint16_t* joints, const uint8_t* significant, size_t vertex_count, size_t k,
                           uint32_t* ids, void* table, void* records, sp_tuple_keys* out)
{
    out->size = 0;
    out->keys = (uint64_t*)records;
    out->first = (uint32_t*)(out->keys + vertex_count);
    out->counts = (uint8_t*)(out->first + vertex_count);
    key_table t = {(key_slot*)table, 0, max_capacity(vertex_count), 64, out};
    start_table(&t, FIRST_CAPACITY);
    if (significant) {
        switch (k) {
        case 1: collect(&t, joints, significant, vertex_count, 1, ids); break;
        case 2: collect(&t, joints, significant, vertex_count, 2, ids); break;
        case 3: collect(&t, joints, significant, vertex_count, 3, ids); break;
        default: collect(&t, joints, significant, vertex_count, 4, ids); break;
        }
    } else {
        switch (k) {
        case 1: collect(&t, joints, NULL, vertex_count, 1, ids); break;
        case 2: collect(&t, joints, NULL, vertex_count, 2, ids); break;
        case 3: collect(&t, joints, NULL, vertex_count, 3, ids); break;
        default: collect(&t, joints, NULL, vertex_count, 4, ids); break;
        }
    }
}
