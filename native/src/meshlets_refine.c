/*
 * meshlets_refine.c - the skin builder's last step on its plan, after the merge of underfull
 * meshlets (meshlets_merge.c): lowering the sum of palette entries at the same meshlet count.
 *
 * For each palette joint of a meshlet that only a few of its triangles carry, those triangles
 * move to the neighbouring meshlet where the palette sum drops most (the joints the source
 * loses minus the joints the target gains), if it drops; never over a limit (the target takes
 * them through sp_meshlet_fits, the palette cap included), never a new meshlet. Greedy growth
 * leaves such joints on meshlet borders: a triangle taken for its vertices that reaches one
 * vertex of the next part.
 *
 * Works on the plan's triangle lists (sp_meshlet_plan_link) and loads one meshlet at a time into
 * the open meshlet of the context to count and check, as the builders do.
 */
#include "meshlets_internal.h"

#include <string.h>

#define NO_TRIANGLE UINT32_MAX
#define REFINE_TRIANGLES 8    /* a joint used by more triangles of its meshlet is not moved */
#define REFINE_PASSES 2

void sp_meshlet_plan_link(sp_meshlet_plan* plan)
{
    for (uint32_t m = 0; m < plan->count; ++m) {
        if (plan->merged[m])
            continue;
        uint32_t last = NO_TRIANGLE;
        plan->first_triangle[m] = NO_TRIANGLE;
        for (uint32_t g = m; g != UINT32_MAX; g = plan->next[g])
            for (uint32_t i = plan->start[g]; i < plan->start[g + 1]; ++i) {
                uint32_t t = plan->order[i];
                plan->owner[t] = m;
                if (last == NO_TRIANGLE)
                    plan->first_triangle[m] = t;
                else
                    plan->next_triangle[last] = t;
                last = t;
            }
        if (last != NO_TRIANGLE)
            plan->next_triangle[last] = NO_TRIANGLE;
    }
}

/* Adds meshlet m's triangles to the open meshlet. */
static void load(sp_meshlet_context* ctx, const sp_meshlet_plan* plan, uint32_t m)
{
    for (uint32_t t = plan->first_triangle[m]; t != NO_TRIANGLE; t = plan->next_triangle[t])
        sp_meshlet_add(ctx, t);
}

uint32_t sp_meshlet_plan_neighbours(const sp_meshlet_context* ctx, const sp_meshlet_plan* plan, uint32_t m,
                                    const uint32_t* triangles, uint32_t count, const uint32_t* offset,
                                    const uint32_t* adjacency, uint32_t* near)
{
    uint32_t found = 0;
    for (uint32_t i = 0; i < count; ++i)
        for (int c = 0; c < 3; ++c) {
            uint32_t v = ctx->indices[(size_t)triangles[i] * 3 + c];
            for (uint32_t j = offset[v]; j < offset[v + 1]; ++j) {
                uint32_t o = plan->owner[adjacency[j]], k = 0;
                while (k < found && near[k] != o)
                    ++k;
                if (o != m && k == found && found < SP_MESHLET_NEIGHBOUR_MAX)
                    near[found++] = o;
            }
        }
    return found;
}

void sp_meshlet_plan_move_triangle(sp_meshlet_plan* plan, uint32_t t, uint32_t b)
{
    uint32_t a = plan->owner[t];
    uint32_t* link = &plan->first_triangle[a];
    while (*link != t)
        link = &plan->next_triangle[*link];
    *link = plan->next_triangle[t];
    plan->triangle_count[a]--;
    if (plan->triangle_count[a] == 0)
        plan->merged[a] = 1;
    plan->owner[t] = b;
    plan->next_triangle[t] = plan->first_triangle[b];
    plan->first_triangle[b] = t;
    plan->triangle_count[b]++;
}

/* Adds meshlet a's triangles except those of the list to the open meshlet. */
static void load_except(sp_meshlet_context* ctx, const sp_meshlet_plan* plan, uint32_t a, const uint32_t* except,
                        uint32_t except_count)
{
    for (uint32_t t = plan->first_triangle[a]; t != NO_TRIANGLE; t = plan->next_triangle[t]) {
        uint32_t i = 0;
        while (i < except_count && except[i] != t)
            ++i;
        if (i == except_count)
            sp_meshlet_add(ctx, t);
    }
}

/* The triangles of meshlet a that carry joint j (at most REFINE_TRIANGLES; returns 0 if more). */
static uint32_t joint_users(const sp_meshlet_context* ctx, const sp_meshlet_plan* plan, uint32_t a, uint16_t j,
                            uint32_t* users)
{
    uint32_t count = 0;
    for (uint32_t t = plan->first_triangle[a]; t != NO_TRIANGLE; t = plan->next_triangle[t]) {
        const uint16_t* list = ctx->triangle_joints + (size_t)t * SP_MESHLET_TRIANGLE_JOINTS;
        uint32_t k = 0;
        while (k < ctx->triangle_joint_count[t] && list[k] != j)
            ++k;
        if (k == ctx->triangle_joint_count[t])
            continue;
        if (count == REFINE_TRIANGLES)
            return 0;
        users[count++] = t;
    }
    return count;
}

/* Palette entries meshlet b gains by taking the triangles, or -1 if they do not all fit. */
static int gain_in(sp_meshlet_context* ctx, const sp_meshlet_plan* plan, uint32_t b, const uint32_t* triangles,
                   uint32_t count)
{
    load(ctx, plan, b);
    uint32_t before = ctx->open_joint_count;
    int fit = sp_meshlet_add_triangles(ctx, triangles, count, 1);
    int gained = (int)(ctx->open_joint_count - before);
    sp_meshlet_reset_open(ctx);
    return fit ? gained : -1;
}

/* Moves the few triangles of meshlet a that carry joint j to the neighbour where the palette
 * sum drops most, if it drops. Returns 1 if it moved them. */
static int evict_joint(sp_meshlet_context* ctx, sp_meshlet_plan* plan, uint32_t a, uint16_t j, uint32_t palette,
                       const uint32_t* offset, const uint32_t* adjacency)
{
    uint32_t users[REFINE_TRIANGLES], near[SP_MESHLET_NEIGHBOUR_MAX];
    uint32_t count = joint_users(ctx, plan, a, j, users);
    if (count == 0 || count >= plan->triangle_count[a])
        return 0;
    load_except(ctx, plan, a, users, count);
    int saved = (int)(palette - ctx->open_joint_count); /* at least 1: j leaves a */
    sp_meshlet_reset_open(ctx);
    uint32_t near_count = sp_meshlet_plan_neighbours(ctx, plan, a, users, count, offset, adjacency, near);
    int best_change = 0;
    uint32_t best = NO_TRIANGLE;
    for (uint32_t k = 0; k < near_count; ++k) {
        int gained = gain_in(ctx, plan, near[k], users, count);
        if (gained >= 0 && gained - saved < best_change) {
            best_change = gained - saved;
            best = near[k];
        }
    }
    if (best == NO_TRIANGLE)
        return 0;
    for (uint32_t i = 0; i < count; ++i)
        sp_meshlet_plan_move_triangle(plan, users[i], best);
    return 1;
}

void sp_meshlet_plan_refine(sp_meshlet_context* ctx, sp_meshlet_plan* plan, const uint32_t* vertex_adjacency_offset,
                            const uint32_t* vertex_adjacency)
{
    uint16_t palette[SP_MESHLET_MAX_JOINTS];
    for (int pass = 0; pass < REFINE_PASSES; ++pass)
        for (uint32_t a = 0; a < plan->count; ++a) {
            if (plan->merged[a])
                continue;
            load(ctx, plan, a);
            uint32_t palette_count = ctx->open_joint_count;
            memcpy(palette, ctx->open_joints, palette_count * sizeof(uint16_t));
            sp_meshlet_reset_open(ctx);
            for (uint32_t i = 0; i < palette_count; ++i)
                if (evict_joint(ctx, plan, a, palette[i], palette_count, vertex_adjacency_offset, vertex_adjacency))
                    break; /* a changed: its other joints wait for the next pass */
        }
}

void sp_meshlet_plan_write(sp_meshlet_context* ctx, const sp_meshlet_plan* plan)
{
    for (uint32_t m = 0; m < plan->count; ++m)
        if (!plan->merged[m]) {
            load(ctx, plan, m);
            sp_meshlet_flush(ctx);
        }
}
