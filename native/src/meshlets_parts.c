/*
 * meshlets_parts.c - the skin builder's first step: the connected parts of the mesh that fit
 * one meshlet whole.
 *
 * A model is often several separate pieces (no shared vertex): rigid parts parented to one bone
 * each (bolts, plates, eyes), cut-off pieces of clothing. Growth would take such a part, run
 * out of surface and fill the rest of its meshlet with the nearest free triangles, whatever
 * joints they bring. Instead every part that fits one meshlet within every limit (the palette
 * cap included) is closed as one meshlet of the plan before growth and taken out of it; the
 * packing step (meshlets_pack.c) then puts such underfull meshlets together by their joints.
 */
#include "meshlets_internal.h"

/* Parts under max_vertices / 8 vertices are left to growth: those are the faces of a
 * flat-shaded mesh (every face its own part), which growth's proximity jumps keep together
 * better than packing does. */
#define PART_MIN_VERTICES_DIVISOR 8

size_t sp_meshlet_parts_scratch_bound(size_t triangle_count, size_t vertex_count)
{
    return 3 * sp_meshlet_align8(vertex_count * sizeof(uint32_t)) + /* parent, part start, part fill */
           sp_meshlet_align8(triangle_count * sizeof(uint32_t));     /* triangles by part */
}

static uint32_t find_root(uint32_t* parent, uint32_t v)
{
    while (parent[v] != v) {
        parent[v] = parent[parent[v]]; /* path halving */
        v = parent[v];
    }
    return v;
}

/* Connected parts (union-find over the triangles' vertices); the parts that fit one meshlet by
 * vertices and triangles get their triangles listed part by part (part_start: per root, where
 * its triangles start in list, UINT32_MAX for a part too large; part_fill: how many). */
static void find_parts(const sp_meshlet_context* ctx, const uint32_t* adjacency_offset, uint32_t* parent,
                       uint32_t* part_start, uint32_t* part_fill, uint32_t* list)
{
    size_t v_count = ctx->vertex_count, t_count = ctx->triangle_count;
    for (size_t v = 0; v < v_count; ++v) {
        parent[v] = (uint32_t)v;
        part_start[v] = part_fill[v] = 0;
    }
    for (size_t t = 0; t < t_count; ++t) {
        const uint32_t* tri = ctx->indices + t * 3;
        uint32_t a = find_root(parent, tri[0]);
        for (int c = 1; c < 3; ++c)
            parent[find_root(parent, tri[c])] = a;
    }
    for (size_t t = 0; t < t_count; ++t)
        part_start[find_root(parent, ctx->indices[t * 3])]++; /* triangle counts for now */
    for (size_t v = 0; v < v_count; ++v)
        if (adjacency_offset[v + 1] > adjacency_offset[v]) /* used by a triangle */
            part_fill[find_root(parent, (uint32_t)v)]++;  /* vertex counts for now */
    size_t offset = 0;
    for (size_t r = 0; r < v_count; ++r) {
        uint32_t triangles = part_start[r];
        int fits = triangles > 0 && triangles <= ctx->options.max_triangles && part_fill[r] <= ctx->options.max_vertices &&
                   part_fill[r] >= ctx->options.max_vertices / PART_MIN_VERTICES_DIVISOR;
        part_start[r] = fits ? (uint32_t)offset : UINT32_MAX;
        offset += fits ? triangles : 0;
        part_fill[r] = 0;
    }
    for (size_t t = 0; t < t_count; ++t) {
        uint32_t r = find_root(parent, ctx->indices[t * 3]);
        if (part_start[r] != UINT32_MAX)
            list[part_start[r] + part_fill[r]++] = (uint32_t)t;
    }
}

size_t sp_meshlet_plan_close_parts(sp_meshlet_context* ctx, sp_meshlet_plan* plan, const uint32_t* adjacency_offset,
                                   unsigned char* scratch, uint8_t* taken)
{
    size_t v_count = ctx->vertex_count;
    uint32_t* parent = sp_meshlet_carve(&scratch, v_count * sizeof(uint32_t));
    uint32_t* part_start = sp_meshlet_carve(&scratch, v_count * sizeof(uint32_t));
    uint32_t* part_fill = sp_meshlet_carve(&scratch, v_count * sizeof(uint32_t));
    uint32_t* list = sp_meshlet_carve(&scratch, ctx->triangle_count * sizeof(uint32_t));
    find_parts(ctx, adjacency_offset, parent, part_start, part_fill, list);
    size_t closed = 0;
    for (size_t r = 0; r < v_count; ++r) {
        if (part_start[r] == UINT32_MAX) /* not a root, or a part too large or too small */
            continue;
        const uint32_t* part = list + part_start[r];
        if (!sp_meshlet_add_triangles(ctx, part, part_fill[r], 1)) {
            sp_meshlet_reset_open(ctx); /* the palette cap: a part may need more joints; growth cuts it */
            continue;
        }
        for (uint32_t k = 0; k < part_fill[r]; ++k)
            taken[part[k]] = 1;
        closed += part_fill[r];
        sp_meshlet_plan_close(ctx, plan);
    }
    return closed;
}
