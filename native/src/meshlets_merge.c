/*
 * meshlets_merge.c - the skin builder's last step: merging underfull meshlets.
 *
 * Greedy growth leaves a few underfull meshlets behind (slivers between finished meshlets, the
 * ends of thin parts). The builder first records its meshlets as a plan (triangle lists, nothing
 * written); after the packing by joints (meshlets_pack.c), each underfull group, smallest first,
 * is merged with the nearest underfull meshlet (in the Morton order of their first triangles, a
 * window on each side) that fits together with it within every limit, the palette cap
 * included. Every merge saves one meshlet and never adds a palette entry (the union of two
 * palettes is at most their sum). The plan is then refined and written out by meshlets_refine.c.
 */
#include "meshlets_internal.h"

#include <stdlib.h>
#include <string.h>

#define MERGE_WINDOW 8         /* underfull neighbours tried on each side */
#define NO_MESHLET UINT32_MAX

size_t sp_meshlet_plan_scratch_bound(size_t triangle_count)
{
    size_t m = triangle_count; /* a meshlet has at least one triangle */
    return sp_meshlet_align8(triangle_count * sizeof(uint32_t)) + sp_meshlet_align8((m + 1) * sizeof(uint32_t)) +
           3 * sp_meshlet_align8(m * sizeof(uint32_t)) + 2 * sp_meshlet_align8(m * sizeof(uint16_t)) +
           sp_meshlet_align8(m) + sp_meshlet_align8(m * sizeof(uint64_t)) +
           2 * sp_meshlet_align8(triangle_count * sizeof(uint32_t)) + sp_meshlet_align8(m * sizeof(uint32_t));
}

void sp_meshlet_plan_init(sp_meshlet_plan* plan, unsigned char** cursor, size_t triangle_count)
{
    size_t m = triangle_count;
    plan->order = sp_meshlet_carve(cursor, triangle_count * sizeof(uint32_t));
    plan->start = sp_meshlet_carve(cursor, (m + 1) * sizeof(uint32_t));
    plan->next = sp_meshlet_carve(cursor, m * sizeof(uint32_t));
    plan->tail = sp_meshlet_carve(cursor, m * sizeof(uint32_t));
    plan->spatial = sp_meshlet_carve(cursor, m * sizeof(uint32_t));
    plan->vertex_count = sp_meshlet_carve(cursor, m * sizeof(uint16_t));
    plan->triangle_count = sp_meshlet_carve(cursor, m * sizeof(uint16_t));
    plan->merged = sp_meshlet_carve(cursor, m);
    plan->keys = sp_meshlet_carve(cursor, m * sizeof(uint64_t));
    plan->owner = sp_meshlet_carve(cursor, triangle_count * sizeof(uint32_t));
    plan->next_triangle = sp_meshlet_carve(cursor, triangle_count * sizeof(uint32_t));
    plan->first_triangle = sp_meshlet_carve(cursor, m * sizeof(uint32_t));
    plan->count = 0;
    plan->start[0] = 0;
}

void sp_meshlet_plan_close(sp_meshlet_context* ctx, sp_meshlet_plan* plan)
{
    if (ctx->open_triangle_count == 0)
        return;
    uint32_t m = (uint32_t)plan->count++, at = plan->start[m];
    memcpy(plan->order + at, ctx->open_triangles, ctx->open_triangle_count * sizeof(uint32_t));
    plan->start[m + 1] = at + ctx->open_triangle_count;
    plan->next[m] = NO_MESHLET;
    plan->tail[m] = m;
    plan->merged[m] = 0;
    plan->vertex_count[m] = (uint16_t)ctx->open_vertex_count;
    plan->triangle_count[m] = (uint16_t)ctx->open_triangle_count;
    sp_meshlet_reset_open(ctx);
}

void sp_meshlet_plan_append(sp_meshlet_plan* plan, uint32_t b, uint32_t a)
{
    plan->next[plan->tail[b]] = a;
    plan->tail[b] = plan->tail[a];
    plan->triangle_count[b] = (uint16_t)(plan->triangle_count[b] + plan->triangle_count[a]);
    plan->merged[a] = 1;
}

/* Adds every triangle of the group that starts at meshlet m to the open meshlet; with
 * check, stops at the first that does not fit and returns 0. */
static int add_group(sp_meshlet_context* ctx, const sp_meshlet_plan* plan, uint32_t m, int check)
{
    for (; m != NO_MESHLET; m = plan->next[m])
        if (!sp_meshlet_add_triangles(ctx, plan->order + plan->start[m], plan->start[m + 1] - plan->start[m], check))
            return 0;
    return 1;
}

/* Whether the groups of a and b fit one meshlet together. */
static int groups_fit(sp_meshlet_context* ctx, const sp_meshlet_plan* plan, uint32_t a, uint32_t b)
{
    if ((uint32_t)plan->triangle_count[a] + plan->triangle_count[b] > ctx->options.max_triangles)
        return 0;
    add_group(ctx, plan, a, 0);
    int fit = add_group(ctx, plan, b, 1);
    sp_meshlet_reset_open(ctx);
    return fit;
}

int sp_meshlet_compare_u64(const void* x, const void* y)
{
    uint64_t a = *(const uint64_t*)x, b = *(const uint64_t*)y;
    return (a > b) - (a < b);
}

void sp_meshlet_sort_high_words(uint64_t* keys, uint64_t* temp, size_t count)
{
    /* LSD radix sort, 8 bits a pass, stable: the low words keep their order within equal high
     * words. An even number of passes leaves the result in keys. */
    for (int shift = 32; shift < 64; shift += 8) {
        size_t start[257] = {0};
        for (size_t i = 0; i < count; ++i)
            start[(keys[i] >> shift & 0xff) + 1]++;
        for (int b = 0; b < 256; ++b)
            start[b + 1] += start[b];
        for (size_t i = 0; i < count; ++i)
            temp[start[keys[i] >> shift & 0xff]++] = keys[i];
        uint64_t* swap = keys;
        keys = temp;
        temp = swap;
    }
}

/* The underfull meshlets (room for a disconnected triangle, or under half the triangle limit):
 * their Morton list (by first triangle) into plan->spatial, and plan->keys = (vertex count << 32
 * | position in that list), smallest first. Returns how many. */
static size_t list_underfull(const sp_meshlet_context* ctx, sp_meshlet_plan* plan, const uint32_t* rank)
{
    size_t count = 0;
    for (uint32_t m = 0; m < plan->count; ++m)
        if (!plan->merged[m] && (sp_meshlet_vertex_room(&ctx->options, plan->vertex_count[m]) ||
                                 plan->triangle_count[m] < ctx->options.max_triangles / 2))
            plan->keys[count++] = (uint64_t)rank[plan->order[plan->start[m]]] << 32 | m;
    qsort(plan->keys, count, sizeof(uint64_t), sp_meshlet_compare_u64);
    for (size_t i = 0; i < count; ++i)
        plan->spatial[i] = (uint32_t)plan->keys[i];
    for (size_t i = 0; i < count; ++i)
        plan->keys[i] = (uint64_t)plan->vertex_count[plan->spatial[i]] << 32 | i;
    qsort(plan->keys, count, sizeof(uint64_t), sp_meshlet_compare_u64);
    return count;
}

/* Merges the group at position `at` of the Morton list into the nearest one within the window
 * that it fits with. */
static void merge_into_neighbour(sp_meshlet_context* ctx, sp_meshlet_plan* plan, size_t at, size_t count)
{
    uint32_t a = plan->spatial[at];
    for (size_t d = 1; d <= MERGE_WINDOW; ++d)
        for (int side = 0; side < 2; ++side) {
            if (side == 0 ? d > at : at + d >= count)
                continue;
            uint32_t b = plan->spatial[side == 0 ? at - d : at + d];
            if (plan->merged[b] || !groups_fit(ctx, plan, b, a))
                continue;
            sp_meshlet_plan_append(plan, b, a);
            return;
        }
}

void sp_meshlet_plan_merge(sp_meshlet_context* ctx, sp_meshlet_plan* plan, const uint32_t* rank)
{
    size_t count = list_underfull(ctx, plan, rank);
    for (size_t k = 0; k < count; ++k)
        merge_into_neighbour(ctx, plan, (uint32_t)plan->keys[k], count);
}
