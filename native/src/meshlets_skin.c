/*
 * meshlets_skin.c - our skin-aware builder. Objective, in this order: as few meshlets as
 * meshoptimizer (the count drives the cost of mesh-shader skinning), then few palette entries,
 * then few local tuple bits; the palette limit max_joints is a hard cap, never exceeded.
 *
 * First, every connected part of the mesh that fits one meshlet whole is closed as one meshlet
 * and left out of growth (meshlets_parts.c). The rest grows one meshlet at a time like
 * meshopt_buildMeshlets (1.x): the next triangle is the best live triangle adjacent to the
 * meshlet's vertices that fits every limit. A candidate costs its topological priority
 * (topology_priority) plus joint_cost per joint it would add to the palette and tuple_cost per
 * tuple its new vertices would add to the local LUT; both options default to 0, because on the
 * benchmark meshes a joint term over the whole growth costs meshlets against the distance
 * tie-break. Only in a meshlet's last max_vertices / LATE_VERTICES_DIVISOR vertices, where the
 * vertex limit is about to close it anyway, does a new joint cost LATE_JOINT_COST on top: the
 * meshlet then closes along the palette it has (0-4 % fewer palette entries on the benchmark
 * meshes, no more meshlets). Ties go to the candidate nearest the centre of the meshlet's
 * triangles, its distance scaled by 1 + JOINT_DISTANCE_FACTOR per joint it would add, which
 * keeps the meshlets compact and still steers growth along the palette; on a regular
 * triangulation (is_regular: a subdivision surface) first to the fewest new joints, then to the
 * innermost hop ring from the meshlet's first vertices, which keeps them compact in the
 * topology that the vertex limit counts, whatever the triangles' shape. There, while the open
 * meshlet is compact (compact_meshlet: a short border), a new joint also costs
 * REGULAR_JOINT_COST and, where the influence bands are wide (count_influences), a triangle
 * below the meshlet's band (all its corners with fewer influences than the meshlet's most)
 * REGULAR_BAND_COST: a subdivision surface's weights form wide bands of equal influence counts,
 * and a meshlet that keeps to its band leaves the lower band's triangles to meshlets with
 * smaller palettes; once the border grows long the meshlet grows for compactness alone, which
 * keeps the count. When no adjacent
 * triangle fits, the meshlet closes, leaves seed candidates on its border, and the next meshlet
 * starts at the least enclosed seed (fewest free triangles around its corners, then nearest the
 * mesh's low corner), so meshlets sweep across the surface and leave no slivers behind; on a
 * regular mesh at the seed nearest the corner (better_seed), so they grow as one front. When
 * the surface patch runs out, the nearest free triangle (searched in a widening window of the
 * Morton order of triangle centroids, where meshoptimizer uses a k-d tree) continues it.
 * Meshlets are recorded as a plan and written at the end, after underfull ones are packed by
 * their joints (meshlets_pack.c) and merged with near ones (meshlets_merge.c) and border
 * triangles are moved where they cost fewer palette entries (meshlets_refine.c) or traded
 * between neighbours (meshlets_exchange.c).
 */
#include "meshlets_internal.h"
#include "platform.h"

#include <float.h>
#include <math.h>
#include <string.h>

#define NO_TRIANGLE UINT32_MAX
#define PROXIMITY_WINDOW 32       /* Morton neighbours searched on each side when a patch runs out, */
#define PROXIMITY_WINDOW_MAX 2048 /* widened 8x at a time up to this */
#define JUMP_JOINT_PENALTY 4.0f   /* distance factor per new joint (x joint_cost) for such jumps */
#define JOINT_DISTANCE_FACTOR 1.0f /* tie-break: distance factor per joint a candidate adds to the palette */
#define LATE_VERTICES_DIVISOR 7   /* the last max_vertices / 7 vertices of a meshlet are its "late" ones, */
#define LATE_JOINT_COST 3.0f      /* where a new palette joint costs as much as 3 new vertices */
#define SEEDS_PER_MESHLET 4       /* seed candidates a finished meshlet leaves on its border */
#define SEED_POOL 256             /* seed candidates kept at most */
#define REGULAR_VALENCE 6         /* triangles around an interior vertex of a regular triangulation */
#define REGULAR_SHARE 0.9         /* the share of such vertices from which a mesh counts as regular */
#define REGULAR_JOINT_COST 3.0f   /* regular mesh, compact meshlet: a new joint costs as much as 3 new vertices, */
#define REGULAR_BAND_COST 1.0f    /* a corner set below the meshlet's band as much as one new vertex; */
#define COMPACT_BORDER 1.0f       /* compact: border vertices <= sqrt(12 x vertices), a hexagonal disc's
                                   * (both with the seed front of better_seed: 0.5 and 0.9 before it) */
#define BANDED_SHARE 0.9          /* the band cost needs this share of triangles with equal influence counts */
#define SLOT_WORDS ((SP_MESHLET_MAX_VERTICES + 63) / 64) /* u64 words of a bit per open vertex slot */

typedef struct skin_state {
    uint32_t* adjacency_offset; /* vertex_count + 1: start of each vertex's triangle list */
    uint32_t* adjacency;        /* the triangles around each vertex; the first live[v] are not emitted yet */
    uint32_t* live;             /* vertex_count */
    uint8_t* emitted;           /* triangle_count */
    float* centroid;            /* 3 per triangle */
    uint64_t* morton;           /* Morton code << 32 | triangle, ascending */
    uint32_t* rank;             /* triangle -> position in morton[] */
    size_t seed_cursor;         /* morton[] before this position is all emitted */
    uint32_t last_rank;         /* rank of the triangle added last */
    uint32_t* seen;             /* triangle_count: the best_neighbour call that last ranked it */
    uint32_t search;            /* that call's number */
    uint32_t* vertex_tuple;     /* vertex_count: global tuple id (sp_meshlet_tuple_ids) */
    uint32_t* tuple_stamp;      /* per tuple id: open_stamp while the open meshlet has the tuple */
    uint32_t open_stamp;        /* changes with every meshlet */
    uint32_t open_tuple_count;  /* distinct tuples of the open meshlet's vertices */
    float corner[3];            /* low corner of the triangle centroids' box: seeds sweep away from it */
    uint32_t seeds[SEED_POOL];  /* free triangles on the borders of finished meshlets */
    uint32_t seed_count;
    sp_meshlet_plan plan;       /* the meshlets closed so far, written at the end */
    float centroid_sum[3];      /* sum of the open meshlet's triangle centroids: its centre drives proximity */
    int regular;                /* growth ranks ties by rings and prefers the meshlet's joints and band (is_regular) */
    uint8_t* influences;        /* vertex_count: used influences of each vertex (regular meshes only) */
    uint32_t open_band;         /* regular: most used influences of an open meshlet's vertex, its palette's floor */
    uint32_t open_border;       /* open meshlet vertices that still have free triangles (the bits
                                 * set in border, kept as a count: compact_meshlet reads it every
                                 * step, and a popcount there cost 1.8 % of cylinder_sub's build), */
    uint64_t border[SLOT_WORDS]; /* and their slots: only they have candidates (best_neighbour) */
    int banded;                 /* regular and its influence bands wide (count_influences): the band cost applies */
    uint16_t ring[SP_MESHLET_MAX_VERTICES]; /* per open vertex slot: edge hops from the meshlet's first vertices */
} skin_state;

size_t sp_meshlet_skin_builder_scratch_bound(size_t triangle_count, size_t vertex_count, int walk)
{
    size_t tuple_slots = sp_meshlet_tuple_set_slots(vertex_count);
    size_t per_vertex = sp_meshlet_align8((vertex_count + 1) * sizeof(uint32_t)) + /* adjacency_offset */
                        2 * sp_meshlet_align8(vertex_count * sizeof(uint32_t)) +    /* live, vertex_tuple */
                        sp_meshlet_align8(vertex_count);                            /* influences */
    size_t per_triangle = sp_meshlet_align8(triangle_count * 3 * sizeof(uint32_t)) + /* adjacency */
                          sp_meshlet_align8(triangle_count) +                        /* emitted */
                          sp_meshlet_align8(triangle_count * 3 * sizeof(float)) +    /* centroid */
                          sp_meshlet_align8(triangle_count * sizeof(uint64_t)) +     /* morton */
                          2 * sp_meshlet_align8(triangle_count * sizeof(uint32_t));  /* rank, seen */
    size_t tuples = sp_meshlet_align8((tuple_slots + 1) * sizeof(uint32_t)) + /* tuple_stamp */
                    sp_meshlet_align8(tuple_slots * sizeof(uint64_t));        /* the tuple set */
    size_t parts = sp_meshlet_parts_scratch_bound(triangle_count, vertex_count);
    size_t pack = sp_meshlet_pack_scratch_bound(triangle_count); /* after the parts step, in the same bytes */
    size_t last = walk ? sp_meshlet_walk_scratch_bound(triangle_count, vertex_count) : 0; /* after both */
    size_t shared = parts > pack ? parts : pack;
    return per_vertex + per_triangle + tuples + sp_meshlet_plan_scratch_bound(triangle_count) +
           (last > shared ? last : shared);
}

static void build_adjacency(const sp_meshlet_context* ctx, skin_state* s)
{
    memset(s->live, 0, ctx->vertex_count * sizeof(uint32_t));
    for (size_t t = 0; t < ctx->triangle_count; ++t)
        for (int c = 0; c < 3; ++c)
            if (sp_meshlet_distinct_corner(ctx->indices + t * 3, c))
                s->live[ctx->indices[t * 3 + c]]++;
    uint32_t offset = 0;
    for (size_t v = 0; v < ctx->vertex_count; ++v) {
        s->adjacency_offset[v] = offset;
        offset += s->live[v];
        s->live[v] = 0;
    }
    s->adjacency_offset[ctx->vertex_count] = offset;
    for (size_t t = 0; t < ctx->triangle_count; ++t)
        for (int c = 0; c < 3; ++c)
            if (sp_meshlet_distinct_corner(ctx->indices + t * 3, c)) {
                uint32_t v = ctx->indices[t * 3 + c];
                s->adjacency[s->adjacency_offset[v] + s->live[v]++] = (uint32_t)t;
            }
}

/* Whether at least REGULAR_SHARE of the used vertices are in REGULAR_VALENCE triangles, as on a
 * subdivision surface. There, growth ranks candidates of equal cost by the fewest joints they
 * add, then by the innermost ring (edge hops from the meshlet's first vertices) of their corners,
 * then by distance: the vertex limit counts vertices, and hop rings make the meshlet a compact
 * disc of the triangulation, while distance to the centre stretches it along the short edges of
 * anisotropic triangles (cylinder_sub: 88 triangles per meshlet against 96 by rings and 98 in an
 * 8 x 8 grid). On irregular meshes, where triangle sizes vary, hop rings follow the joints worse
 * than distance (docs/benchmarks-meshlets.md), so they keep the distance tie-break alone. Needs
 * live[] as build_adjacency leaves it (triangles per vertex). */
static int is_regular(const sp_meshlet_context* ctx, const skin_state* s)
{
    size_t used = 0, regular = 0;
    for (size_t v = 0; v < ctx->vertex_count; ++v) {
        used += s->live[v] > 0;
        regular += s->live[v] == REGULAR_VALENCE;
    }
    return used > 0 && (double)regular >= REGULAR_SHARE * (double)used;
}

/* Used influences (weight > 0) of every vertex: a meshlet's palette holds at least the most of
 * its vertices', which is the band the growth on a regular mesh keeps to. Sets banded when at
 * least BANDED_SHARE of the triangles have equal counts at their three corners: the bands are
 * wide (subdivided meshes: 94-99 %), so a meshlet can keep to one. Where they are a few rows
 * wide every compact meshlet spans several, and keeping to one only makes it ragged (a grid
 * striped every 2 rows: 10 % more meshlets and 2 % more entries with the band cost). */
static void count_influences(const sp_meshlet_context* ctx, skin_state* s)
{
    for (size_t v = 0; v < ctx->vertex_count; ++v) {
        uint8_t used = 0;
        for (size_t k = 0; k < ctx->influences; ++k)
            used += ctx->weights[v * ctx->influences + k] > 0.0f;
        s->influences[v] = used;
    }
    size_t uniform = 0;
    for (size_t t = 0; t < ctx->triangle_count; ++t) {
        const uint32_t* tri = ctx->indices + t * 3;
        uniform += s->influences[tri[0]] == s->influences[tri[1]] && s->influences[tri[1]] == s->influences[tri[2]];
    }
    s->banded = (double)uniform >= BANDED_SHARE * (double)ctx->triangle_count;
}

/* 10 bits per axis interleaved: z y x z y x ... */
static uint32_t spread_bits(uint32_t x)
{
    x &= 0x3ff;
    x = (x | x << 16) & 0x030000ff;
    x = (x | x << 8) & 0x0300f00f;
    x = (x | x << 4) & 0x030c30c3;
    x = (x | x << 2) & 0x09249249;
    return x;
}

static void build_spatial_order(const sp_meshlet_context* ctx, skin_state* s)
{
    float lo[3] = {FLT_MAX, FLT_MAX, FLT_MAX}, hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
    for (size_t t = 0; t < ctx->triangle_count; ++t) {
        float* c = s->centroid + t * 3;
        c[0] = c[1] = c[2] = 0.0f;
        for (int k = 0; k < 3; ++k) {
            const float* p = sp_meshlet_position(ctx, ctx->indices[t * 3 + k]);
            for (int i = 0; i < 3; ++i)
                c[i] += p[i] / 3.0f;
        }
        for (int i = 0; i < 3; ++i) {
            lo[i] = c[i] < lo[i] ? c[i] : lo[i];
            hi[i] = c[i] > hi[i] ? c[i] : hi[i];
        }
    }
    float extent = 0.0f;
    for (int i = 0; i < 3; ++i)
        extent = hi[i] - lo[i] > extent ? hi[i] - lo[i] : extent;
    float scale = extent > 0.0f ? 1023.0f / extent : 0.0f;
    memcpy(s->corner, lo, sizeof(lo));
    for (size_t t = 0; t < ctx->triangle_count; ++t) {
        const float* c = s->centroid + t * 3;
        uint32_t code = 0;
        for (int i = 0; i < 3; ++i) {
            float q = (c[i] - lo[i]) * scale; /* NaN positions land in cell 0 */
            code |= spread_bits(q > 0.0f ? (uint32_t)(q + 0.5f) : 0u) << i;
        }
        s->morton[t] = (uint64_t)code << 32 | t;
    }
    /* the plan's sort keys are free until growth ends */
    sp_meshlet_sort_high_words(s->morton, s->plan.keys, ctx->triangle_count);
    for (size_t i = 0; i < ctx->triangle_count; ++i)
        s->rank[(uint32_t)s->morton[i]] = (uint32_t)i;
}

static void open_centroid(const sp_meshlet_context* ctx, const skin_state* s, float* point)
{
    for (int i = 0; i < 3; ++i)
        point[i] = s->centroid_sum[i] / (float)ctx->open_triangle_count;
}

static float distance_to(const skin_state* s, uint32_t t, const float* point)
{
    const float* c = s->centroid + (size_t)t * 3;
    float d[3] = {c[0] - point[0], c[1] - point[1], c[2] - point[2]};
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
}

/* The innermost ring of tri's corners in the open meshlet; UINT16_MAX if none is in it. */
static uint32_t inner_ring(const sp_meshlet_context* ctx, const skin_state* s, const uint32_t* tri)
{
    uint32_t ring = UINT16_MAX;
    for (int c = 0; c < 3; ++c) {
        uint8_t slot = ctx->vertex_slot[tri[c]];
        if (slot != SP_MESHLET_NO_SLOT && s->ring[slot] < ring)
            ring = s->ring[slot];
    }
    return ring;
}

/* Adds t to the open meshlet and takes it out of its vertices' live lists; on a regular mesh its
 * new vertices get the ring after its innermost corner's (0 when none is in the meshlet: a seed
 * or a jump). */
static void emit(sp_meshlet_context* ctx, skin_state* s, uint32_t t)
{
    uint32_t ring = s->regular ? inner_ring(ctx, s, ctx->indices + (size_t)t * 3) : 0;
    uint32_t first_new = ctx->open_vertex_count;
    for (int c = 0; c < 3; ++c) {
        uint32_t v = ctx->indices[t * 3 + c];
        if (ctx->vertex_slot[v] == SP_MESHLET_NO_SLOT && s->tuple_stamp[s->vertex_tuple[v]] != s->open_stamp) {
            s->tuple_stamp[s->vertex_tuple[v]] = s->open_stamp;
            s->open_tuple_count++;
        }
    }
    sp_meshlet_add(ctx, t);
    for (uint32_t i = first_new; s->regular && i < ctx->open_vertex_count; ++i) {
        uint32_t used = s->influences[ctx->open_vertices[i]];
        s->open_band = used > s->open_band ? used : s->open_band;
        s->ring[i] = (uint16_t)(ring == UINT16_MAX ? 0 : ring + 1);
    }
    for (int i = 0; i < 3; ++i)
        s->centroid_sum[i] += s->centroid[(size_t)t * 3 + i];
    s->emitted[t] = 1;
    s->last_rank = s->rank[t];
    for (int c = 0; c < 3; ++c) {
        if (!sp_meshlet_distinct_corner(ctx->indices + t * 3, c))
            continue;
        uint32_t v = ctx->indices[t * 3 + c];
        uint32_t* list = s->adjacency + s->adjacency_offset[v];
        for (uint32_t i = 0; i < s->live[v]; ++i)
            if (list[i] == t) {
                list[i] = list[--s->live[v]];
                list[s->live[v]] = t;
                break;
            }
        /* the border: a vertex that was in the meshlet leaves it with its last free triangle, a
         * new one joins it while it has free triangles */
        uint32_t slot = ctx->vertex_slot[v];
        uint64_t bit = (uint64_t)1 << (slot & 63), *word = s->border + (slot >> 6);
        uint32_t was = (*word & bit) != 0, now = s->live[v] > 0;
        *word = now ? *word | bit : *word & ~bit;
        s->open_border = s->open_border + now - was;
    }
}

/* How enclosed free triangle t is: the free triangles around its corners (t counted at each).
 * Low values are mesh corners and strips left between meshlets, which strand triangles unless
 * a meshlet starts there. */
static uint32_t enclosure(const sp_meshlet_context* ctx, const skin_state* s, uint32_t t)
{
    const uint32_t* tri = ctx->indices + (size_t)t * 3;
    return s->live[tri[0]] + s->live[tri[1]] + s->live[tri[2]];
}

typedef struct seed {
    uint32_t triangle, enclosure;
    float corner_distance; /* squared, to the low corner: meshlets sweep away from it (better_seed) */
} seed;

static seed make_seed(const sp_meshlet_context* ctx, const skin_state* s, uint32_t t)
{
    seed result = {t, enclosure(ctx, s, t), distance_to(s, t, s->corner)};
    return result;
}

/* Seed order. The least enclosed seed first (mesh corners and strips left between meshlets,
 * which strand triangles unless a meshlet starts there), then the nearest the mesh's low corner.
 * On a regular mesh the nearest the corner first, enclosure only breaking ties: the meshlets
 * grow as one front that advances from the corner (unit.test_meshlets: on a 128 x 128 grid 1.6 %
 * of the meshlet pairs lie out of distance order, 10.7 % with the enclosure first), which the
 * band growth's costs (REGULAR_BAND_COST, COMPACT_BORDER) are tuned with. Measured, not derived:
 * with both, fewer meshlets and palette entries on all three subdivided benchmark meshes
 * (cylinder_sub 3062 / 10226 against 3073 / 10281, docs/benchmarks-meshlets.md), within 0.6 %
 * either way on synthetic banded grids and tubes. */
static int better_seed(const skin_state* s, const seed* a, const seed* b)
{
    if (a->triangle == NO_TRIANGLE || b->triangle == NO_TRIANGLE)
        return b->triangle == NO_TRIANGLE && a->triangle != NO_TRIANGLE;
    if (s->regular && a->corner_distance != b->corner_distance)
        return a->corner_distance < b->corner_distance;
    if (a->enclosure != b->enclosure)
        return a->enclosure < b->enclosure;
    if (a->corner_distance != b->corner_distance)
        return a->corner_distance < b->corner_distance;
    return a->triangle < b->triangle;
}

/* Drops the seeds that meshlets have taken since they were added. */
static void prune_seeds(skin_state* s)
{
    uint32_t kept = 0;
    for (uint32_t i = 0; i < s->seed_count; ++i)
        if (!s->emitted[s->seeds[i]])
            s->seeds[kept++] = s->seeds[i];
    s->seed_count = kept;
}

/* Before the open meshlet closes, each of its vertices nominates its least enclosed free
 * triangle; the best SEEDS_PER_MESHLET nominees join the pool (when it has room). */
static void add_border_seeds(const sp_meshlet_context* ctx, skin_state* s)
{
    seed best[SEEDS_PER_MESHLET];
    for (int i = 0; i < SEEDS_PER_MESHLET; ++i) {
        seed none = {NO_TRIANGLE, 0, 0.0f};
        best[i] = none;
    }
    for (uint32_t i = 0; i < ctx->open_vertex_count; ++i) {
        uint32_t v = ctx->open_vertices[i];
        const uint32_t* list = s->adjacency + s->adjacency_offset[v];
        seed nominee = {NO_TRIANGLE, 0, 0.0f};
        for (uint32_t j = 0; j < s->live[v]; ++j) {
            seed c = make_seed(ctx, s, list[j]);
            if (better_seed(s, &c, &nominee))
                nominee = c;
        }
        if (nominee.triangle == NO_TRIANGLE)
            continue;
        int worst = 0, present = 0;
        for (int k = 0; k < SEEDS_PER_MESHLET; ++k) {
            present |= best[k].triangle == nominee.triangle;
            if (better_seed(s, &best[worst], &best[k]))
                worst = k;
        }
        if (!present && better_seed(s, &nominee, &best[worst]))
            best[worst] = nominee;
    }
    prune_seeds(s);
    for (int k = 0; k < SEEDS_PER_MESHLET && s->seed_count < SEED_POOL; ++k)
        if (best[k].triangle != NO_TRIANGLE)
            s->seeds[s->seed_count++] = best[k].triangle;
}

/* The least enclosed free seed of the pool, or NO_TRIANGLE. */
static uint32_t pick_seed(const sp_meshlet_context* ctx, skin_state* s)
{
    prune_seeds(s);
    seed best = {NO_TRIANGLE, 0, 0.0f};
    for (uint32_t i = 0; i < s->seed_count; ++i) {
        seed c = make_seed(ctx, s, s->seeds[i]);
        if (better_seed(s, &c, &best))
            best = c;
    }
    return best.triangle;
}

/* Closes the open meshlet, leaving seeds on its border for the next ones. */
static void flush(sp_meshlet_context* ctx, skin_state* s)
{
    add_border_seeds(ctx, s);
    sp_meshlet_plan_close(ctx, &s->plan);
    s->centroid_sum[0] = s->centroid_sum[1] = s->centroid_sum[2] = 0.0f;
    s->open_stamp++;
    s->open_tuple_count = 0;
    s->open_band = 0;
    s->open_border = 0;
    memset(s->border, 0, sizeof(s->border));
}

/* Tuples triangle t would add to the open meshlet's local LUT. */
static uint32_t new_tuples(const sp_meshlet_context* ctx, const skin_state* s, uint32_t t)
{
    const uint32_t* tri = ctx->indices + (size_t)t * 3;
    uint32_t fresh[3], count = 0;
    for (int c = 0; c < 3; ++c) {
        if (ctx->vertex_slot[tri[c]] != SP_MESHLET_NO_SLOT)
            continue;
        uint32_t id = s->vertex_tuple[tri[c]];
        if (s->tuple_stamp[id] == s->open_stamp)
            continue;
        uint32_t seen = 0;
        while (seen < count && fresh[seen] != id)
            ++seen;
        if (seen == count)
            fresh[count++] = id;
    }
    return count;
}

typedef struct candidate {
    uint32_t triangle;
    float cost;     /* priority + joint_cost * new joints + tuple_cost * new tuples: lower is better */
    uint32_t rank;  /* on a regular mesh new joints << 16 | innermost ring of its corners; else 0 */
    float distance; /* squared, centroid to the meshlet's centroid (meshopt's tie-break), x (1 + factor x new joints) */
} candidate;

static int better(const candidate* a, const candidate* b)
{
    if (b->triangle == NO_TRIANGLE)
        return 1;
    if (a->cost != b->cost)
        return a->cost < b->cost;
    if (a->rank != b->rank)
        return a->rank < b->rank;
    if (a->distance != b->distance)
        return a->distance < b->distance;
    return a->triangle < b->triangle;
}

/* Topological priority, lower first (after meshoptimizer 1.x): 0 when t adds no vertex; 1 when
 * it completes a vertex's fan (that vertex then leaves the meshlet border, and a triangle left
 * dangling would cost a later meshlet up to two vertices); new vertices + 1 when two of its
 * corners have only one other free triangle (taking t leaves that one dangling, so the border
 * stays short); else new vertices + 2. */
static float topology_priority(const skin_state* s, const uint32_t* tri, uint32_t new_vertices)
{
    if (new_vertices == 0)
        return 0.0f;
    uint32_t a = s->live[tri[0]], b = s->live[tri[1]], c = s->live[tri[2]];
    if (a == 1 || b == 1 || c == 1)
        return 1.0f;
    return (float)new_vertices + ((a == 2) + (b == 2) + (c == 2) >= 2 ? 1.0f : 2.0f);
}

/* Whether the open meshlet is still a compact patch: at most COMPACT_BORDER x sqrt(12 n) of its
 * n vertices have free triangles left (a hexagonal disc of a valence-6 triangulation with side k
 * has 3k^2 + 3k + 1 vertices, 6k of them on its border). A meshlet of 64 vertices holds 2n - b - 2
 * triangles with b border vertices, so a ragged one costs meshlets; while it is compact, growth on
 * a regular mesh can afford to prefer its joints and its band (best_neighbour). */
static int compact_meshlet(const sp_meshlet_context* ctx, const skin_state* s)
{
    return (float)s->open_border <= COMPACT_BORDER * sqrtf(12.0f * (float)ctx->open_vertex_count);
}

/* Whether every corner of tri has fewer used influences than the open meshlet's most: the
 * triangle lies in a lower band, which a meshlet of its own would cover with a smaller palette. */
static int below_band(const skin_state* s, const uint32_t* tri)
{
    return s->influences[tri[0]] < s->open_band && s->influences[tri[1]] < s->open_band &&
           s->influences[tri[2]] < s->open_band;
}

/* The open meshlet's vertices that still have free triangles, in slot order (the order does
 * matter: best_neighbour returns the first triangle that adds no vertex). Returns how many. */
static uint32_t border_vertices(const sp_meshlet_context* ctx, const skin_state* s, uint32_t* vertices)
{
    uint32_t count = 0;
    for (uint32_t w = 0; w < SLOT_WORDS; ++w)
        for (uint64_t bits = s->border[w]; bits != 0; bits &= bits - 1)
            vertices[count++] = ctx->open_vertices[w * 64 + sp_lowest_bit64(bits)];
    return count;
}

/* Whether a candidate cannot beat best whatever joints and tuples it adds: they only raise its
 * cost (at least cost_without_joints), its rank (at least its ring, the new joints ranking
 * above it) and its distance (at least near). Equal distances go to the lower triangle index,
 * so they are not decided here. */
static int cannot_win(const candidate* best, float cost_without_joints, uint32_t ring, float near)
{
    if (cost_without_joints != best->cost)
        return cost_without_joints > best->cost;
    if (ring != best->rank)
        return ring > best->rank;
    return near > best->distance;
}

/* What a search ranks candidates with: the open meshlet's centre and the costs of a new joint
 * and of a triangle below the meshlet's band at this point of its growth. */
typedef struct search_terms {
    float point[3];
    float joint_cost, band_cost;
    int require_fit;
} search_terms;

static search_terms search_terms_now(const sp_meshlet_context* ctx, const skin_state* s, int require_fit)
{
    search_terms terms;
    open_centroid(ctx, s, terms.point);
    terms.require_fit = require_fit;
    /* on a regular mesh, while the meshlet is compact, a new joint costs REGULAR_JOINT_COST and a
     * triangle below its band REGULAR_BAND_COST (see the top); in the meshlet's last vertices a
     * new joint also costs LATE_JOINT_COST */
    terms.joint_cost = ctx->options.joint_cost;
    terms.band_cost = 0.0f;
    if (s->regular && compact_meshlet(ctx, s)) {
        terms.joint_cost += REGULAR_JOINT_COST;
        terms.band_cost = s->banded ? REGULAR_BAND_COST : 0.0f;
    }
    if (ctx->open_vertex_count + ctx->options.max_vertices / LATE_VERTICES_DIVISOR >= ctx->options.max_vertices)
        terms.joint_cost += LATE_JOINT_COST;
    return terms;
}

/* Ranks live triangle t against best; returns the better one. A triangle that adds no vertex
 * is returned with cost 0: nothing beats it. The joint and tuple terms are never negative, so a
 * candidate whose topology alone is worse than the best so far, or that cannot win without them
 * (cannot_win), is dropped before they are counted; that changes no result. */
static candidate rank_candidate(const sp_meshlet_context* ctx, const skin_state* s, const search_terms* terms,
                                uint32_t t, candidate best)
{
    const uint32_t* tri = ctx->indices + (size_t)t * 3;
    uint32_t new_vertices = sp_meshlet_new_vertices(ctx, t);
    if (terms->require_fit && ctx->open_vertex_count + new_vertices > ctx->options.max_vertices)
        return best;
    float priority = topology_priority(s, tri, new_vertices);
    if (best.triangle != NO_TRIANGLE && priority > best.cost)
        return best;
    float band = 0.0f, near = distance_to(s, t, terms->point);
    uint32_t ring = 0; /* irregular meshes rank no rings */
    if (s->regular) {
        band = terms->band_cost > 0.0f && new_vertices > 0 && below_band(s, tri) ? terms->band_cost : 0.0f;
        ring = inner_ring(ctx, s, tri);
    }
    if (best.triangle != NO_TRIANGLE && cannot_win(&best, priority + band, ring, near))
        return best;
    uint32_t new_joints = sp_meshlet_new_joints(ctx, t);
    if (terms->require_fit && ctx->open_joint_count + new_joints > ctx->options.max_joints)
        return best;
    float cost = priority + terms->joint_cost * (float)new_joints;
    if (band > 0.0f)
        cost += band;
    if (ctx->options.tuple_cost > 0.0f)
        cost += ctx->options.tuple_cost * (float)new_tuples(ctx, s, t);
    if (best.triangle != NO_TRIANGLE && cost > best.cost)
        return best;
    /* among equal costs a candidate that widens the palette counts as farther */
    float distance = near * (1.0f + JOINT_DISTANCE_FACTOR * (float)new_joints);
    candidate c = {t, cost, s->regular ? new_joints << 16 | ring : 0, distance};
    /* one that adds no vertex (hence no joint) wins at once: the order in which such triangles
     * join does not change the meshlet */
    return cost == 0.0f || better(&c, &best) ? c : best;
}

/* Best live triangle next to the open meshlet; with require_fit only those that fit every
 * limit. Only the border's vertices have live triangles, and a triangle at two or three of them
 * is ranked once. */
static candidate best_neighbour(const sp_meshlet_context* ctx, skin_state* s, int require_fit)
{
    candidate best = {NO_TRIANGLE, 0.0f, 0, 0.0f};
    if (require_fit && ctx->open_triangle_count >= ctx->options.max_triangles)
        return best;
    search_terms terms = search_terms_now(ctx, s, require_fit);
    if (++s->search == 0) { /* the numbers wrapped: forget the old ones */
        memset(s->seen, 0, ctx->triangle_count * sizeof(uint32_t));
        s->search = 1;
    }
    uint32_t border[SP_MESHLET_MAX_VERTICES], border_count = border_vertices(ctx, s, border);
    for (uint32_t i = 0; i < border_count; ++i) {
        uint32_t v = border[i];
        const uint32_t* list = s->adjacency + s->adjacency_offset[v];
        for (uint32_t j = 0; j < s->live[v]; ++j) {
            uint32_t t = list[j];
            if (s->seen[t] == s->search)
                continue; /* ranked already from another of its corners */
            s->seen[t] = s->search;
            best = rank_candidate(ctx, s, &terms, t, best);
            if (best.triangle != NO_TRIANGLE && best.cost == 0.0f)
                return best;
        }
    }
    return best;
}

/* Nearest free triangle to point among the Morton neighbours of the last triangle added,
 * widening the window until one is found (or the widest window is spent); with require_fit
 * only triangles that fit the open meshlet, their distance scaled up by the joints they add. */
static uint32_t nearest_free(const sp_meshlet_context* ctx, const skin_state* s, const float* point, int require_fit)
{
    for (size_t window = PROXIMITY_WINDOW; window <= PROXIMITY_WINDOW_MAX; window *= 8) {
        size_t lo = s->last_rank > window ? s->last_rank - window : 0;
        size_t hi = s->last_rank + window + 1 < ctx->triangle_count ? s->last_rank + window + 1 : ctx->triangle_count;
        uint32_t best = NO_TRIANGLE;
        float best_distance = FLT_MAX;
        for (size_t r = lo; r < hi; ++r) {
            uint32_t t = (uint32_t)s->morton[r];
            if (s->emitted[t] || (require_fit && !sp_meshlet_fits(ctx, t)))
                continue;
            float distance = distance_to(s, t, point);
            if (require_fit) /* a jump that widens the palette counts as farther */
                distance *= 1.0f + JUMP_JOINT_PENALTY * ctx->options.joint_cost * (float)sp_meshlet_new_joints(ctx, t);
            if (distance < best_distance) { /* ties: lower Morton rank, as scanned */
                best = t;
                best_distance = distance;
            }
        }
        if (best != NO_TRIANGLE || (lo == 0 && hi == ctx->triangle_count))
            return best;
    }
    return NO_TRIANGLE;
}

/* First free triangle in Morton order: where a new meshlet starts when nothing is near. */
static uint32_t next_seed(const sp_meshlet_context* ctx, skin_state* s)
{
    while (s->seed_cursor < ctx->triangle_count && s->emitted[(uint32_t)s->morton[s->seed_cursor]])
        ++s->seed_cursor;
    return (uint32_t)s->morton[s->seed_cursor];
}

/* Carves the builder's arrays from its scratch and fills the per-mesh ones (adjacency, tuple ids,
 * influence bands, spatial order); returns the scratch left over, which the steps after growth
 * take in turn. */
static unsigned char* init_state(sp_meshlet_context* ctx, skin_state* s)
{
    unsigned char* cursor = ctx->builder_scratch;
    size_t t_count = ctx->triangle_count, v_count = ctx->vertex_count;
    s->adjacency_offset = sp_meshlet_carve(&cursor, (v_count + 1) * sizeof(uint32_t));
    s->adjacency = sp_meshlet_carve(&cursor, t_count * 3 * sizeof(uint32_t));
    s->live = sp_meshlet_carve(&cursor, v_count * sizeof(uint32_t));
    s->emitted = sp_meshlet_carve(&cursor, t_count);
    s->centroid = sp_meshlet_carve(&cursor, t_count * 3 * sizeof(float));
    s->morton = sp_meshlet_carve(&cursor, t_count * sizeof(uint64_t));
    s->rank = sp_meshlet_carve(&cursor, t_count * sizeof(uint32_t));
    s->seen = sp_meshlet_carve(&cursor, t_count * sizeof(uint32_t));
    memset(s->seen, 0, t_count * sizeof(uint32_t));
    s->search = 0;
    s->seed_cursor = 0;
    s->last_rank = 0;
    s->vertex_tuple = sp_meshlet_carve(&cursor, v_count * sizeof(uint32_t));
    size_t tuple_slots = sp_meshlet_tuple_set_slots(v_count);
    s->tuple_stamp = sp_meshlet_carve(&cursor, (tuple_slots + 1) * sizeof(uint32_t));
    uint64_t* tuple_set = sp_meshlet_carve(&cursor, tuple_slots * sizeof(uint64_t));
    ctx->global_tuples = sp_meshlet_tuple_ids(ctx, tuple_set, s->vertex_tuple);
    memset(s->tuple_stamp, 0, (tuple_slots + 1) * sizeof(uint32_t));
    s->open_stamp = 1;
    s->open_tuple_count = 0;
    s->seed_count = 0;
    s->centroid_sum[0] = s->centroid_sum[1] = s->centroid_sum[2] = 0.0f;
    s->influences = sp_meshlet_carve(&cursor, v_count);
    s->open_band = 0;
    s->open_border = 0;
    memset(s->border, 0, sizeof(s->border));
    sp_meshlet_plan_init(&s->plan, &cursor, t_count);
    memset(s->emitted, 0, t_count);
    build_adjacency(ctx, s);
    s->regular = is_regular(ctx, s);
    s->banded = 0;
    if (s->regular)
        count_influences(ctx, s);
    build_spatial_order(ctx, s);
    return cursor;
}

/* The surface patch is used up: jump to the nearest free triangle, into the open meshlet if it
 * has room for one more disconnected triangle, else into the next. */
static void jump(sp_meshlet_context* ctx, skin_state* s)
{
    float point[3];
    open_centroid(ctx, s, point);
    uint32_t near = NO_TRIANGLE;
    if (sp_meshlet_triangle_room(&ctx->options, ctx->open_vertex_count, ctx->open_triangle_count))
        near = nearest_free(ctx, s, point, 1);
    if (near == NO_TRIANGLE) {
        flush(ctx, s);
        near = nearest_free(ctx, s, point, 0);
    }
    emit(ctx, s, near != NO_TRIANGLE ? near : next_seed(ctx, s));
}

/* Grows meshlets over the triangles that the parts step left (it took `done`) and closes them
 * into the plan. */
static void grow(sp_meshlet_context* ctx, skin_state* s, size_t done)
{
    for (; done < ctx->triangle_count; ++done) {
        if (ctx->open_triangle_count == 0) {
            emit(ctx, s, next_seed(ctx, s));
            continue;
        }
        candidate fitting = best_neighbour(ctx, s, 1);
        if (fitting.triangle != NO_TRIANGLE) {
            emit(ctx, s, fitting.triangle);
            continue;
        }
        candidate any = best_neighbour(ctx, s, 0);
        if (any.triangle == NO_TRIANGLE) {
            jump(ctx, s);
            continue;
        }
        /* the patch goes on but the meshlet is full: the next meshlet starts at the least
         * enclosed border seed (so no sliver is stranded), else where this one stopped */
        flush(ctx, s);
        uint32_t next = pick_seed(ctx, s);
        emit(ctx, s, next != NO_TRIANGLE ? next : any.triangle);
    }
    sp_meshlet_plan_close(ctx, &s->plan);
}

void sp_meshlets_build_skin(sp_meshlet_context* ctx)
{
    skin_state s;
    unsigned char* cursor = init_state(ctx, &s);
    grow(ctx, &s, sp_meshlet_plan_close_parts(ctx, &s.plan, s.adjacency_offset, cursor, s.emitted));
    sp_meshlet_plan_pack(ctx, &s.plan, cursor);
    sp_meshlet_plan_merge(ctx, &s.plan, s.rank);
    sp_meshlet_plan_link(&s.plan);
    sp_meshlet_plan_refine(ctx, &s.plan, s.adjacency_offset, s.adjacency);
    /* live as the exchange step's zeroed vertex scratch (the parts closed whole never left it) */
    memset(s.live, 0, ctx->vertex_count * sizeof(uint32_t));
    sp_meshlet_plan_exchange(ctx, &s.plan, s.adjacency_offset, s.adjacency, s.live);
    if (ctx->options.palette_effort > 0) {
        /* the walk in the parts' and packing's bytes, free again; the borders it moved may give
         * the exchange new sequences (re_player at effort 10: 267 entries, then 263) */
        sp_meshlet_plan_walk(ctx, &s.plan, s.adjacency_offset, s.adjacency, cursor);
        sp_meshlet_plan_exchange(ctx, &s.plan, s.adjacency_offset, s.adjacency, s.live); /* live: left zero */
    }
    sp_meshlet_plan_write(ctx, &s.plan);
}
