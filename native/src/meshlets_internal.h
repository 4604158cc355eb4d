/*
 * meshlets_internal.h - state shared by the meshlet builders (private to native/src/meshlets*.c).
 *
 * Every builder decides only which triangle goes next and when a meshlet is closed; the
 * bookkeeping of the open meshlet (local vertex and palette slots) and writing it out
 * (vertices, triangles, palette, local tuple LUT, bounds) is common and lives in
 * meshlets_common_util.c. All arrays below point into the caller's scratch buffer.
 */
#ifndef SKINPACK_MESHLETS_INTERNAL_H
#define SKINPACK_MESHLETS_INTERNAL_H

#include "skinpack.h"

#define SP_MESHLET_NO_SLOT 0xff /* vertex_slot / joint_slot: not in the open meshlet */
#define SP_JOINT_SLOT_COUNT 65536 /* every joint index a u16 can hold: what a scratch bound must count */

typedef struct sp_meshlet_context {
    /* input */
    const uint32_t* indices;
    size_t triangle_count;
    const float* positions;
    size_t position_stride; /* in floats */
    size_t vertex_count;
    const uint16_t* joints;
    const float* weights;
    size_t influences;
    sp_meshlet_options options;

    /* per triangle: its distinct used joints, ascending (SP_MESHLET_TRIANGLE_JOINTS slots) */
    uint16_t* triangle_joints;
    uint8_t* triangle_joint_count;
    uint32_t joint_end; /* 1 + the largest joint a triangle uses (0: none), for arrays indexed by joint */

    /* the open meshlet */
    uint8_t* vertex_slot;  /* vertex_count entries */
    uint8_t* joint_slot;   /* SP_JOINT_SLOT_COUNT entries */
    uint32_t* open_triangles; /* max_triangles entries */
    uint32_t open_vertices[SP_MESHLET_MAX_VERTICES];
    uint16_t open_joints[SP_MESHLET_MAX_JOINTS];
    uint32_t open_triangle_count, open_vertex_count, open_joint_count;

    /* output */
    size_t global_tuples; /* the mesh's unique tuples once a builder has counted them, else 0 */
    sp_meshlet_buffers* out;
    sp_meshlet_sizes used;

    /* scratch not consumed by the common part, for the builder */
    unsigned char* builder_scratch;
    size_t builder_scratch_size;
} sp_meshlet_context;

/* Scratch is carved into blocks of 8-byte multiples, so every block stays 8-byte aligned. */
static inline size_t sp_meshlet_align8(size_t bytes)
{
    return (bytes + 7) & ~(size_t)7;
}

static inline void* sp_meshlet_carve(unsigned char** cursor, size_t bytes)
{
    void* block = *cursor;
    *cursor += sp_meshlet_align8(bytes);
    return block;
}

/* Scratch bytes the common part needs, and what each builder needs on top of it. */
size_t sp_meshlet_common_scratch_bound(size_t triangle_count, size_t vertex_count, size_t max_triangles);
size_t sp_meshlet_common_builder_scratch_bound(size_t triangle_count);
size_t sp_meshlet_skin_builder_scratch_bound(size_t triangle_count, size_t vertex_count, int walk);

/* Unique K-joint tuples over the mesh, with the same rule as the local LUTs (zero-weight slots
 * read as joint 0), in an open-addressing set of sp_meshlet_tuple_set_slots(vertex_count) u64s.
 * Returns how many; ids (optional, vertex_count entries) gets each vertex's tuple as a number
 * below slots + 1, equal for equal tuples. */
size_t sp_meshlet_tuple_set_slots(size_t vertex_count);
size_t sp_meshlet_tuple_ids(const sp_meshlet_context* ctx, uint64_t* set, uint32_t* ids);

/* Fills triangle_joints and joint_end; fails with SP_ERR_LIMIT_EXCEEDED naming the first triangle
 * over max_joints. */
sp_result sp_meshlet_collect_triangle_joints(sp_meshlet_context* ctx, size_t* error_triangle);

/* Whether corner c of tri is the first occurrence of its vertex (degenerate triangles repeat one,
 * and a vertex is counted once per triangle). */
static inline int sp_meshlet_distinct_corner(const uint32_t* tri, int c)
{
    return (c == 0) || (c == 1 && tri[1] != tri[0]) || (c == 2 && tri[2] != tri[0] && tri[2] != tri[1]);
}

/* New vertices triangle t would add to the open meshlet (inline: the builders' inner loop). */
static inline uint32_t sp_meshlet_new_vertices(const sp_meshlet_context* ctx, size_t t)
{
    uint32_t a = ctx->indices[t * 3 + 0], b = ctx->indices[t * 3 + 1], c = ctx->indices[t * 3 + 2];
    /* degenerate triangles repeat a vertex: count it once */
    return (ctx->vertex_slot[a] == SP_MESHLET_NO_SLOT) + (ctx->vertex_slot[b] == SP_MESHLET_NO_SLOT && b != a) +
           (ctx->vertex_slot[c] == SP_MESHLET_NO_SLOT && c != a && c != b);
}

/* New palette joints triangle t would add to the open meshlet. */
static inline uint32_t sp_meshlet_new_joints(const sp_meshlet_context* ctx, size_t t)
{
    const uint16_t* list = ctx->triangle_joints + t * SP_MESHLET_TRIANGLE_JOINTS;
    uint32_t count = ctx->triangle_joint_count[t], fresh = 0;
    for (uint32_t i = 0; i < count; ++i)
        fresh += ctx->joint_slot[list[i]] == SP_MESHLET_NO_SLOT;
    return fresh;
}

/* Whether a meshlet of `vertices` vertices has room for the 3 new vertices of a triangle that
 * shares none of them: the steps that move whole meshlets or jump to a disconnected triangle
 * cannot count on shared vertices, so this is their "underfull" test. */
static inline int sp_meshlet_vertex_room(const sp_meshlet_options* options, uint32_t vertices)
{
    return vertices + 3u <= options->max_vertices;
}

/* The same with the triangle limit: one more disconnected triangle fits whole. */
static inline int sp_meshlet_triangle_room(const sp_meshlet_options* options, uint32_t vertices, uint32_t triangles)
{
    return sp_meshlet_vertex_room(options, vertices) && triangles < options->max_triangles;
}

/* Whether t can join the open meshlet without breaking a limit. */
int sp_meshlet_fits(const sp_meshlet_context* ctx, size_t t);
/* Adds t to the open meshlet (the caller checked sp_meshlet_fits). */
void sp_meshlet_add(sp_meshlet_context* ctx, size_t t);
/* Adds only t's joints to the open meshlet's palette (open_joints), in the order sp_meshlet_add
 * would: for a meshlet whose vertex and triangle counts are already known. */
void sp_meshlet_add_joints(sp_meshlet_context* ctx, size_t t);
/* Adds the listed triangles to the open meshlet in order; with check, stops at the first that
 * does not fit and returns 0 (those before it stay added: the caller resets). */
int sp_meshlet_add_triangles(sp_meshlet_context* ctx, const uint32_t* triangles, uint32_t count, int check);
/* Writes the open meshlet (if it has triangles) to the output and empties it. */
void sp_meshlet_flush(sp_meshlet_context* ctx);
/* Empties the open meshlet without writing it. */
void sp_meshlet_reset_open(sp_meshlet_context* ctx);

/* A split recorded as triangle lists before it is written (meshlets_merge.c): the skin builder
 * closes its meshlets into a plan, merges underfull ones, then writes the plan. */
typedef struct sp_meshlet_plan {
    uint32_t* order;          /* triangles, meshlet by meshlet */
    uint32_t* start;          /* meshlet m: order[start[m] .. start[m + 1]) */
    uint32_t* next;           /* next meshlet merged into m's group, or UINT32_MAX */
    uint32_t* tail;           /* last meshlet of m's group */
    uint32_t* spatial;        /* scratch: underfull meshlets in Morton order (merge), then per group the
                               * exchange pass that last changed it */
    uint16_t* vertex_count;   /* as closed */
    uint16_t* triangle_count; /* of m's group */
    uint8_t* merged;          /* 1: m went into another meshlet's group */
    uint64_t* keys;           /* scratch: sort keys */
    size_t count;
    /* after sp_meshlet_plan_link: each group's triangles as a list, named by the group's first meshlet */
    uint32_t* owner;          /* per triangle: its group */
    uint32_t* next_triangle;  /* per triangle: the next one of its group, or UINT32_MAX */
    uint32_t* first_triangle; /* per group */
} sp_meshlet_plan;

size_t sp_meshlet_plan_scratch_bound(size_t triangle_count);
void sp_meshlet_plan_init(sp_meshlet_plan* plan, unsigned char** cursor, size_t triangle_count);
/* Records the open meshlet (if it has triangles) as the plan's next one and empties it. */
void sp_meshlet_plan_close(sp_meshlet_context* ctx, sp_meshlet_plan* plan);
/* qsort order of uint64_t keys, ascending. */
int sp_meshlet_compare_u64(const void* x, const void* y);
/* Sorts keys by their high 32 bits, keeping the order of keys with equal high words (temp: count
 * more entries). For keys whose low words ascend in the input, this is their qsort order. */
void sp_meshlet_sort_high_words(uint64_t* keys, uint64_t* temp, size_t count);
/* Group b absorbs group a (a is marked merged; the caller checked every limit). */
void sp_meshlet_plan_append(sp_meshlet_plan* plan, uint32_t b, uint32_t a);
/* meshlets_parts.c: scratch bytes for sp_meshlet_plan_close_parts. */
size_t sp_meshlet_parts_scratch_bound(size_t triangle_count, size_t vertex_count);
/* Closes every connected part of at least max_vertices / 8 vertices that fits one meshlet whole
 * (palette cap included) as a meshlet of the plan and sets taken[t] = 1 for its triangles;
 * returns how many triangles it took (adjacency_offset: vertex_count + 1 entries, as the skin
 * builder keeps it). */
size_t sp_meshlet_plan_close_parts(sp_meshlet_context* ctx, sp_meshlet_plan* plan, const uint32_t* adjacency_offset,
                                   unsigned char* scratch, uint8_t* taken);
/* meshlets_pack.c: packs the plan's underfull meshlets (before the merge: every meshlet is its
 * own group) into groups by their joints, never over a limit, never more meshlets. */
size_t sp_meshlet_pack_scratch_bound(size_t triangle_count);
void sp_meshlet_plan_pack(sp_meshlet_context* ctx, sp_meshlet_plan* plan, unsigned char* scratch);
/* meshlets_merge.c: merges underfull meshlets with near ones they fit with (rank: triangle ->
 * Morton position). */
void sp_meshlet_plan_merge(sp_meshlet_context* ctx, sp_meshlet_plan* plan, const uint32_t* rank);
/* meshlets_refine.c: turns the merged groups into triangle lists; then moves the few triangles
 * that bring a joint into a meshlet to a neighbour where they cost fewer palette entries, never
 * over a limit (vertex_adjacency_offset/vertex_adjacency: the triangles around each vertex, as
 * the skin builder keeps them). */
void sp_meshlet_plan_link(sp_meshlet_plan* plan);
void sp_meshlet_plan_refine(sp_meshlet_context* ctx, sp_meshlet_plan* plan, const uint32_t* vertex_adjacency_offset,
                            const uint32_t* vertex_adjacency);
/* Linked-plan helpers (meshlets_refine.c): the groups other than m (at most
 * SP_MESHLET_NEIGHBOUR_MAX, into near) that own a triangle around a vertex of the given
 * triangles; moving triangle t to group b (the caller checked every limit; a group left empty is
 * marked merged, so it is not written). */
#define SP_MESHLET_NEIGHBOUR_MAX 32
uint32_t sp_meshlet_plan_neighbours(const sp_meshlet_context* ctx, const sp_meshlet_plan* plan, uint32_t m,
                                    const uint32_t* triangles, uint32_t count, const uint32_t* offset,
                                    const uint32_t* adjacency, uint32_t* near);
void sp_meshlet_plan_move_triangle(sp_meshlet_plan* plan, uint32_t t, uint32_t b);
/* meshlets_exchange.c: between each meshlet and each neighbour, a short sequence of single
 * triangle moves (either way, a triangle once) that lowers their palette sum, kept up to its best
 * point within every limit (vertex_local: vertex_count zeros, left zero). */
void sp_meshlet_plan_exchange(sp_meshlet_context* ctx, sp_meshlet_plan* plan, const uint32_t* vertex_adjacency_offset,
                              const uint32_t* vertex_adjacency, uint32_t* vertex_local);
/* meshlets_walk.c: with options.palette_effort, random moves of border triangles between
 * neighbouring groups of the linked plan, each kept when it passes no limit and adds no joint to
 * the receiving group (scratch: sp_meshlet_walk_scratch_bound bytes). */
size_t sp_meshlet_walk_scratch_bound(size_t triangle_count, size_t vertex_count);
void sp_meshlet_plan_walk(sp_meshlet_context* ctx, sp_meshlet_plan* plan, const uint32_t* vertex_adjacency_offset,
                          const uint32_t* vertex_adjacency, unsigned char* scratch);
/* Writes every group of the linked plan as one meshlet. */
void sp_meshlet_plan_write(sp_meshlet_context* ctx, const sp_meshlet_plan* plan);

/* Greedy in the given order (NULL: index order): close the meshlet when the next triangle does
 * not fit. Flushes at the end. This is the thesis's GenerateMeshlets. */
void sp_meshlet_greedy(sp_meshlet_context* ctx, const uint32_t* order, size_t count);

/* Position of vertex v. */
static inline const float* sp_meshlet_position(const sp_meshlet_context* ctx, uint32_t v)
{
    return ctx->positions + (size_t)v * ctx->position_stride;
}

/* The builders. */
void sp_meshlets_build_naive(sp_meshlet_context* ctx);
void sp_meshlets_build_common(sp_meshlet_context* ctx);
void sp_meshlets_build_skin(sp_meshlet_context* ctx);

#endif /* SKINPACK_MESHLETS_INTERNAL_H */
