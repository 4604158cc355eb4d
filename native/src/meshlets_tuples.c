/*
 * meshlets_tuples.c - the mesh's unique joint tuples (global tuple ids), by the rule of the local
 * LUTs. Used by the skin builder (it tracks the open meshlet's tuples) and by the statistics
 * (global tuple count); a file of its own so that neither depends on the other.
 */
#include "meshlets_internal.h"

#include <string.h>

#define EMPTY_SLOT UINT64_MAX

size_t sp_meshlet_tuple_set_slots(size_t vertex_count)
{
    size_t slots = 16;
    while (slots < vertex_count * 2)
        slots *= 2;
    return slots;
}

size_t sp_meshlet_tuple_ids(const sp_meshlet_context* ctx, uint64_t* set, uint32_t* ids)
{
    size_t k = ctx->influences, slots = sp_meshlet_tuple_set_slots(ctx->vertex_count), unique = 0;
    int saw_empty_key = 0; /* four joints 0xffff would read as an empty slot: id `slots`, counted apart */
    memset(set, 0xff, slots * sizeof(uint64_t));
    for (size_t v = 0; v < ctx->vertex_count; ++v) {
        uint64_t key = 0;
        for (size_t s = 0; s < k; ++s)
            key = key << 16 | (ctx->weights[v * k + s] > 0.0f ? ctx->joints[v * k + s] : 0u);
        size_t at = slots;
        if (key == EMPTY_SLOT) {
            unique += !saw_empty_key;
            saw_empty_key = 1;
        } else {
            at = (size_t)((key * 0x9e3779b97f4a7c15ull) >> 32) & (slots - 1);
            while (set[at] != EMPTY_SLOT && set[at] != key)
                at = (at + 1) & (slots - 1);
            if (set[at] == EMPTY_SLOT) {
                set[at] = key;
                ++unique;
            }
        }
        if (ids)
            ids[v] = (uint32_t)at;
    }
    return unique;
}
