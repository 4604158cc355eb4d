/*
 * The distinct keys of a mesh's vertices for the tuple table (tuple_lut.c): one pass over the
 * vertices that masks each one's joints to its significant prefix and compares the key with the
 * last one of the same count, looking it up in an open-addressing table only when it changed (or
 * on every vertex where too many change). The table starts small and doubles, so for the few
 * hundred keys of a typical mesh it stays in L1; the table rule then runs on the distinct keys.
 */
#include <string.h>

#include "tuple_keys.h"

/* The smallest table (slots). It doubles past load 1/4 while it is small, so that few keys
 * miss the slot they hash to (at load 1/2 about a fifth do, and each costs a branch miss),
 * and past load 1/2 once it has outgrown the caches anyway. */
#define FIRST_CAPACITY 256
#define SPARSE_CAPACITY 4096
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

static int overloaded(size_t keys, size_t capacity)
{
    return keys * (capacity <= SPARSE_CAPACITY ? 4 : 2) > capacity;
}

/* Enough for a key for every vertex (then at most half full). */
static size_t max_capacity(size_t vertex_count)
{
    size_t capacity = FIRST_CAPACITY;
    while (overloaded(vertex_count, capacity)) capacity *= 2;
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

/* The id of a key, found from the slot it hashes to on, or a new one. */
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
    if (overloaded(r->size, t->capacity) && t->capacity < t->max_capacity) grow(t);
    else place(t, key, count, id);
    return id;
}

/* The id of a key: from the slot it hashes to, else by find_or_add. */
SP_INLINE uint32_t key_id(key_table* t, uint64_t key, uint32_t count, size_t vertex)
{
    const key_slot* slot = &t->slots[slot_of(key, count, t->shift)];
    return slot->key == key && slot->count == count ? slot->id : find_or_add(t, key, count, vertex);
}

/* Vertices a step: each step runs as the one before it suggests. */
#define STEP 256

/* Each count's last key and its id, and its prefix mask (here, next to them, rather than in a
 * table that takes a register in the loop). */
typedef struct last_keys {
    uint64_t key[5];
    uint64_t mask[5];
    uint32_t id[5];
} last_keys;

/*
 * A cache starts on a key no vertex of its count has: all ones for a prefix shorter than 4
 * joints (its top joint is masked to 0), and for full 4-joint tuples anything but the first
 * one's.
 */
static void start_last_keys(last_keys* last, const uint16_t* joints, const uint8_t* significant,
                            size_t vertex_count, size_t k)
{
    static const uint64_t prefix_mask[5] = {0xffff, 0xffff, 0xffffffff, 0xffffffffffff, ~(uint64_t)0};
    for (size_t count = 0; count < 5; ++count)
        last->key[count] = ~(uint64_t)0, last->mask[count] = prefix_mask[count], last->id[count] = 0;
    if (k == 4) {
        const uint8_t* full = significant ? memchr(significant, 4, vertex_count) : NULL;
        size_t first = significant ? (full ? (size_t)(full - significant) : vertex_count) : 0;
        if (first < vertex_count) last->key[4] = ~sp_tuple_prefix_key(joints + first * 4, 4, 4);
    }
}

/* Vertex v's key: its joints (k of them, a constant where inlined) masked to its count (all k
 * without counts). */
SP_INLINE uint64_t vertex_key(const last_keys* last, const uint16_t* joints, const uint8_t* significant, size_t v,
                              size_t k, uint32_t* count)
{
    uint64_t key = sp_tuple_prefix_key(joints + v * k, k, 4);
    *count = significant ? significant[v] : (uint32_t)k;
    return significant ? key & last->mask[*count] : key;
}

/*
 * Vertices [first, end) by their count's last key, the table only when it changes (along a
 * mesh, neighbours share their joints while their counts vary); or, where that branch would be
 * mispredicted too often, by the table, keeping the last keys. Returns the vertices whose key
 * differs from their count's last one.
 */
SP_INLINE size_t collect_step(key_table* t, last_keys* last, const uint16_t* joints, const uint8_t* significant,
                              size_t first, size_t end, size_t k, int by_table, uint32_t* ids)
{
    size_t changes = 0;
    for (size_t v = first; v < end; ++v) {
        uint32_t count;
        uint64_t key = vertex_key(last, joints, significant, v, k, &count);
        if (by_table) {
            uint32_t id = key_id(t, key, count, v);
            changes += key != last->key[count];
            last->key[count] = key;
            last->id[count] = id;
        } else if (key != last->key[count]) { /* the call, not key_id inlined: fewer registers in the loop */
            last->key[count] = key;
            last->id[count] = find_or_add(t, key, count, v);
            ++changes;
        }
        ids[v] = last->id[count];
    }
    return changes;
}

/* Inlined per K and with or without counts. A step of vertices goes by the last keys when at
 * most one in 8 of the step before changed them, else by the table (two calls, so that each mode
 * is its own loop). */
SP_INLINE void collect(key_table* t, const uint16_t* joints, const uint8_t* significant, size_t vertex_count,
                       size_t k, uint32_t* ids)
{
    last_keys last;
    start_last_keys(&last, joints, significant, vertex_count, k);
    int by_table = 0;
    for (size_t first = 0; first < vertex_count; first += STEP) {
        size_t end = vertex_count - first < STEP ? vertex_count : first + STEP;
        if (by_table)
            by_table = 8 * collect_step(t, &last, joints, significant, first, end, k, 1, ids) > end - first;
        else
            by_table = 8 * collect_step(t, &last, joints, significant, first, end, k, 0, ids) > end - first;
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
