/*
 * meshlets_walk.c - the skin builder's optional last step (sp_meshlet_options.palette_effort):
 * a random walk of single border triangles between neighbouring meshlets on the linked plan.
 *
 * After the exchange step no single move lowers the palette sum (measured: strict descent from
 * there gains nothing), but many moves keep it: a border triangle whose new vertices carry only
 * joints the other meshlet already has can cross wherever that meshlet has room. Such moves
 * reshape the borders at no cost, and every so often the last vertex of a joint leaves a
 * meshlet and its palette shrinks. The walk proposes palette_effort x triangles such moves at
 * random (a border vertex, a triangle around it, another meshlet around it: drawn from the
 * border, no proposal is spent inside a meshlet: for the same palette sum on RE_Player 3x fewer
 * instructions than drawing any triangle at 254 entries, 1.1x at 244) and keeps every one
 * that passes no limit and adds no joint to the receiving meshlet: the palette sum never rises,
 * no palette ever grows, no limit is ever passed, and a meshlet left empty disappears. The
 * random numbers come from a fixed seed, so a build stays reproducible.
 *
 * State, exact and incremental: per vertex the meshlets around it with how many of their
 * triangles use it; per meshlet its vertex count and its palette as built, each joint with how
 * many of the meshlet's vertex slots carry it (a joint at 0 has left the palette).
 */
#include "meshlets_internal.h"

#include <string.h>

#define NO_TRIANGLE UINT32_MAX
#define WALK_SEED 0x9e3779b97f4a7c15ull

typedef struct walk {
    const uint32_t* slot_offset; /* per vertex: its first slot (the adjacency's offsets: a slot per triangle) */
    uint32_t* slot_group;        /* per slot: a meshlet around the vertex */
    uint32_t* slot_refs;         /* per slot: that meshlet's triangles around the vertex */
    uint32_t* groups_around;     /* per vertex: slots in use */
    uint32_t* border;            /* the vertices with two or more meshlets around them, in no order */
    uint32_t* border_at;         /* per vertex: its place in border */
    uint32_t border_count;
    uint32_t* palette_offset;    /* per meshlet: its first palette entry */
    uint16_t* palette;           /* joints of each meshlet's palette as built */
    uint16_t* carriers;          /* per palette entry: the meshlet's vertex slots that carry the joint */
    uint16_t* vertices;          /* per meshlet */
    uint64_t random;
} walk;

size_t sp_meshlet_walk_scratch_bound(size_t triangle_count, size_t vertex_count)
{
    size_t m = triangle_count; /* plan meshlets, at most */
    size_t entries = triangle_count * SP_MESHLET_TRIANGLE_JOINTS; /* a palette entry needs a triangle using it */
    return 2 * sp_meshlet_align8(triangle_count * 3 * sizeof(uint32_t)) + /* slot_group, slot_refs */
           3 * sp_meshlet_align8(vertex_count * sizeof(uint32_t)) +           /* groups_around, border, border_at */
           sp_meshlet_align8((m + 1) * sizeof(uint32_t)) +                    /* palette_offset */
           2 * sp_meshlet_align8(entries * sizeof(uint16_t)) +                /* palette, carriers */
           sp_meshlet_align8(m * sizeof(uint16_t));                           /* vertices */
}

static uint64_t next_random(walk* w)
{
    w->random ^= w->random << 13;
    w->random ^= w->random >> 7;
    w->random ^= w->random << 17;
    return w->random;
}

/* Palette entry of joint j in meshlet g, or -1. */
static int find_joint(const walk* w, uint32_t g, uint16_t j)
{
    for (uint32_t e = w->palette_offset[g]; e < w->palette_offset[g + 1]; ++e)
        if (w->palette[e] == j)
            return (int)e;
    return -1;
}

/* Slot of meshlet g around vertex v, or -1. */
static int find_slot(const walk* w, uint32_t v, uint32_t g)
{
    uint32_t first = w->slot_offset[v];
    for (uint32_t i = 0; i < w->groups_around[v]; ++i)
        if (w->slot_group[first + i] == g)
            return (int)(first + i);
    return -1;
}

static void add_carriers(const sp_meshlet_context* ctx, walk* w, uint32_t v, uint32_t g, int delta)
{
    for (size_t s = 0; s < ctx->influences; ++s)
        if (ctx->weights[(size_t)v * ctx->influences + s] > 0.0f)
            w->carriers[find_joint(w, g, ctx->joints[(size_t)v * ctx->influences + s])] += (uint16_t)delta;
}

/* Vertex v gains a triangle of meshlet g. */
static void enter(const sp_meshlet_context* ctx, walk* w, uint32_t v, uint32_t g)
{
    int slot = find_slot(w, v, g);
    if (slot >= 0) {
        w->slot_refs[slot]++;
        return;
    }
    uint32_t last = w->slot_offset[v] + w->groups_around[v]++;
    if (w->groups_around[v] == 2) { /* onto the border */
        w->border_at[v] = w->border_count;
        w->border[w->border_count++] = v;
    }
    w->slot_group[last] = g;
    w->slot_refs[last] = 1;
    w->vertices[g]++;
    add_carriers(ctx, w, v, g, 1);
}

/* Vertex v loses a triangle of meshlet g. */
static void leave(const sp_meshlet_context* ctx, walk* w, uint32_t v, uint32_t g)
{
    uint32_t slot = (uint32_t)find_slot(w, v, g);
    if (--w->slot_refs[slot] != 0)
        return;
    uint32_t last = w->slot_offset[v] + --w->groups_around[v];
    if (w->groups_around[v] == 1) { /* off the border: the list's last vertex takes its place */
        uint32_t moved = w->border[--w->border_count];
        w->border[w->border_at[v]] = moved;
        w->border_at[moved] = w->border_at[v];
    }
    w->slot_group[slot] = w->slot_group[last];
    w->slot_refs[slot] = w->slot_refs[last];
    w->vertices[g]--;
    add_carriers(ctx, w, v, g, -1);
}

/* Every meshlet's palette (as the common bookkeeping builds it) and vertex count, then the
 * meshlets around each vertex. */
static void init_walk(sp_meshlet_context* ctx, const sp_meshlet_plan* plan, walk* w)
{
    uint32_t entries = 0;
    for (uint32_t g = 0; g < plan->count; ++g) {
        w->palette_offset[g] = entries;
        w->vertices[g] = 0;
        if (plan->merged[g])
            continue;
        for (uint32_t t = plan->first_triangle[g]; t != NO_TRIANGLE; t = plan->next_triangle[t])
            sp_meshlet_add_joints(ctx, t);
        memcpy(w->palette + entries, ctx->open_joints, ctx->open_joint_count * sizeof(uint16_t));
        memset(w->carriers + entries, 0, ctx->open_joint_count * sizeof(uint16_t));
        entries += ctx->open_joint_count;
        sp_meshlet_reset_open(ctx);
    }
    w->palette_offset[plan->count] = entries;
    memset(w->groups_around, 0, ctx->vertex_count * sizeof(uint32_t));
    w->border_count = 0;
    for (uint32_t t = 0; t < ctx->triangle_count; ++t) {
        const uint32_t* tri = ctx->indices + (size_t)t * 3;
        for (int c = 0; c < 3; ++c)
            if (sp_meshlet_distinct_corner(tri, c))
                enter(ctx, w, tri[c], plan->owner[t]);
    }
    w->random = WALK_SEED;
}

/* Whether triangle t can join meshlet b: b has room for it, and every vertex it brings carries
 * only joints b's palette has. */
static int can_join(const sp_meshlet_context* ctx, const sp_meshlet_plan* plan, const walk* w, uint32_t t, uint32_t b)
{
    if (plan->triangle_count[b] >= ctx->options.max_triangles)
        return 0;
    const uint32_t* tri = ctx->indices + (size_t)t * 3;
    uint32_t added = 0;
    for (int c = 0; c < 3; ++c) {
        if (!sp_meshlet_distinct_corner(tri, c) || find_slot(w, tri[c], b) >= 0)
            continue;
        ++added;
        for (size_t s = 0; s < ctx->influences; ++s) {
            size_t at = (size_t)tri[c] * ctx->influences + s;
            if (!(ctx->weights[at] > 0.0f))
                continue;
            int e = find_joint(w, b, ctx->joints[at]);
            if (e < 0 || w->carriers[e] == 0)
                return 0;
        }
    }
    return w->vertices[b] + added <= ctx->options.max_vertices;
}

static void move(sp_meshlet_context* ctx, sp_meshlet_plan* plan, walk* w, uint32_t t, uint32_t b)
{
    const uint32_t* tri = ctx->indices + (size_t)t * 3;
    uint32_t a = plan->owner[t];
    for (int c = 0; c < 3; ++c)
        if (sp_meshlet_distinct_corner(tri, c)) {
            leave(ctx, w, tri[c], a);
            enter(ctx, w, tri[c], b);
        }
    plan->owner[t] = b;
    plan->triangle_count[b]++;
    if (--plan->triangle_count[a] == 0)
        plan->merged[a] = 1;
}

/* Each meshlet's triangle list again from the owners (ascending). */
static void relink(const sp_meshlet_context* ctx, sp_meshlet_plan* plan)
{
    for (uint32_t g = 0; g < plan->count; ++g)
        plan->first_triangle[g] = NO_TRIANGLE;
    for (uint32_t t = (uint32_t)ctx->triangle_count; t-- > 0;) {
        plan->next_triangle[t] = plan->first_triangle[plan->owner[t]];
        plan->first_triangle[plan->owner[t]] = t;
    }
}

void sp_meshlet_plan_walk(sp_meshlet_context* ctx, sp_meshlet_plan* plan, const uint32_t* vertex_adjacency_offset,
                          const uint32_t* vertex_adjacency, unsigned char* scratch)
{
    walk w;
    size_t t_count = ctx->triangle_count;
    w.slot_offset = vertex_adjacency_offset;
    w.slot_group = sp_meshlet_carve(&scratch, t_count * 3 * sizeof(uint32_t));
    w.slot_refs = sp_meshlet_carve(&scratch, t_count * 3 * sizeof(uint32_t));
    w.groups_around = sp_meshlet_carve(&scratch, ctx->vertex_count * sizeof(uint32_t));
    w.border = sp_meshlet_carve(&scratch, ctx->vertex_count * sizeof(uint32_t));
    w.border_at = sp_meshlet_carve(&scratch, ctx->vertex_count * sizeof(uint32_t));
    w.palette_offset = sp_meshlet_carve(&scratch, (t_count + 1) * sizeof(uint32_t));
    w.palette = sp_meshlet_carve(&scratch, t_count * SP_MESHLET_TRIANGLE_JOINTS * sizeof(uint16_t));
    w.carriers = sp_meshlet_carve(&scratch, t_count * SP_MESHLET_TRIANGLE_JOINTS * sizeof(uint16_t));
    w.vertices = sp_meshlet_carve(&scratch, t_count * sizeof(uint16_t));
    init_walk(ctx, plan, &w);
    uint64_t proposals = (uint64_t)ctx->options.palette_effort * t_count;
    for (uint64_t i = 0; i < proposals && w.border_count > 0; ++i) {
        /* a border vertex, a triangle around it, another meshlet around it */
        uint32_t v = w.border[next_random(&w) % w.border_count];
        uint32_t first = w.slot_offset[v], valence = w.slot_offset[v + 1] - first;
        uint32_t t = vertex_adjacency[first + (uint32_t)(next_random(&w) % valence)];
        uint32_t b = w.slot_group[first + (uint32_t)(next_random(&w) % w.groups_around[v])];
        if (b != plan->owner[t] && can_join(ctx, plan, &w, t, b))
            move(ctx, plan, &w, t, b);
    }
    relink(ctx, plan);
}
