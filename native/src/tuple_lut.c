/*
 * Joint-tuple lookup table (Kuth & Meyer, Sec. 3): unique ordered joint tuples, one index per
 * vertex. Open-addressing hash over tuple prefixes so that a vertex whose trailing slots have
 * zero weight ("don't care") can reuse any tuple that starts with its significant joints.
 */
#include <string.h>

#include "skinpack.h"

typedef struct lut_builder {
    uint16_t* lut;
    size_t size;
    size_t k;
    uint32_t* slots;   /* hash slots: entry index + 1, 0 = empty */
    uint8_t* lengths;  /* prefix length the slot was registered for */
    size_t mask;
} lut_builder;

static size_t table_capacity(size_t vertex_count, size_t k)
{
    size_t keys = vertex_count * k, capacity = 16;
    while (capacity < 2 * keys) capacity *= 2;
    return capacity;
}

size_t sp_tuple_lut_scratch_bound(size_t vertex_count, size_t influences)
{
    if (influences < 1) influences = 1;
    return table_capacity(vertex_count, influences) * (sizeof(uint32_t) + 1);
}

static uint32_t hash_prefix(const uint16_t* joints, size_t length)
{
    uint32_t h = 2166136261u ^ (uint32_t)length;
    for (size_t i = 0; i < length; ++i) h = (h ^ joints[i]) * 16777619u;
    return h ^ (h >> 15);
}

/* Slot holding the given prefix, or the empty slot where it belongs. */
static size_t find_slot(const lut_builder* b, const uint16_t* joints, size_t length)
{
    size_t at = hash_prefix(joints, length) & b->mask;
    for (;;) {
        uint32_t entry = b->slots[at];
        if (entry == 0) return at;
        if (b->lengths[at] == length &&
            memcmp(b->lut + (size_t)(entry - 1) * b->k, joints, length * sizeof(uint16_t)) == 0)
            return at;
        at = (at + 1) & b->mask;
    }
}

/* Appends a tuple and registers its prefixes; the first tuple with a prefix keeps it. */
static uint32_t add_entry(lut_builder* b, const uint16_t* joints, size_t first_length)
{
    uint32_t entry = (uint32_t)b->size++;
    memcpy(b->lut + (size_t)entry * b->k, joints, b->k * sizeof(uint16_t));
    for (size_t length = first_length; length <= b->k; ++length) {
        size_t at = find_slot(b, joints, length);
        if (b->slots[at] == 0) {
            b->slots[at] = entry + 1;
            b->lengths[at] = (uint8_t)length;
        }
    }
    return entry;
}

static uint32_t lookup_or_add(lut_builder* b, const uint16_t* joints, size_t length, size_t register_from)
{
    size_t at = find_slot(b, joints, length);
    if (b->slots[at]) return b->slots[at] - 1;
    return add_entry(b, joints, register_from);
}

sp_result sp_build_tuple_lut(const uint16_t* joints, const uint8_t* significant, size_t vertex_count,
                             size_t influences, uint16_t* lut, size_t* lut_size, uint32_t* tuple_index,
                             void* scratch, size_t scratch_size)
{
    if (!joints || !lut || !lut_size || !tuple_index || influences < 1 || influences > SP_MAX_INFLUENCES ||
        vertex_count > UINT32_MAX)
        return SP_ERR_INVALID_ARGUMENT;
    size_t capacity = table_capacity(vertex_count, influences);
    if (!scratch || scratch_size < capacity * (sizeof(uint32_t) + 1)) return SP_ERR_BUFFER_TOO_SMALL;

    lut_builder b = {lut, 0, influences, (uint32_t*)scratch, (uint8_t*)scratch + capacity * sizeof(uint32_t),
                     capacity - 1};
    memset(scratch, 0, capacity * (sizeof(uint32_t) + 1));
    size_t k = influences;

    /* Full tuples first, then ever shorter significant prefixes, so that a partial tuple
     * finds every full tuple it could share. Without don't-care merging, only full tuples. */
    for (size_t length = k; length >= 1; --length) {
        for (size_t v = 0; v < vertex_count; ++v) {
            size_t needed = significant ? significant[v] : k;
            if (needed < 1) needed = 1;
            if (needed > k) return SP_ERR_INVALID_ARGUMENT;
            if (needed != length) continue;
            /* Without merging only full-length keys are registered, so equal tuples match. */
            tuple_index[v] = lookup_or_add(&b, joints + v * k, length, significant ? 1 : k);
        }
        if (!significant) break;
    }
    *lut_size = b.size;
    return SP_OK;
}
