/*
 * meshlets_exchange.c - the skin builder's last step on its plan, after the refine step
 * (meshlets_refine.c): trading border triangles between two neighbouring meshlets.
 *
 * The refine step moves the few triangles that carry a joint to a neighbour, but almost every
 * meshlet is vertex-full, so the neighbour seldom has room. Here two neighbours A and B are
 * taken together and a short sequence of single-triangle moves across their border is tried,
 * in either direction (Kernighan-Lin style): each step makes the move that leaves the lowest
 * palette sum, then the fewest vertices in both, even when it is worse, so a move that frees
 * room can come before the one that drops a joint. A vertex limit may be passed by a few
 * vertices in the middle of the sequence, never the triangle limit or the palette cap; the
 * sequence is kept up to its best point where both meshlets are within every limit, if that
 * point lowers the palette sum (or keeps it with fewer vertices); the moves after it are dropped.
 *
 * Counting is exact and incremental: per pair, each vertex's and each joint's references in
 * either meshlet (a joint is in a palette while a vertex of that meshlet uses it). A pair (A, B)
 * is only tried where A has a joint on at most EXCHANGE_FEW_VERTICES of its vertices (the only
 * joints a short sequence can take out of a palette) that B already has.
 */
#include "meshlets_internal.h"
#include "platform.h"

#include <string.h>

#define NO_TRIANGLE UINT32_MAX
#define EXCHANGE_STEPS 8        /* moves per sequence (16 saves a few more entries on RE_Player for ~25 % more time) */
#define EXCHANGE_VERTEX_SLACK 6 /* vertices a meshlet may be over its limit inside a sequence */
#define EXCHANGE_FEW_VERTICES 4 /* a joint on this many vertices of a meshlet or fewer is "rare" there */
#define EXCHANGE_RARE_MAX 16    /* rare joints of one meshlet looked for in its neighbours */
#define EXCHANGE_PASSES 2
#define NO_GROUP UINT32_MAX
#define PAIR_TRIANGLES (2 * 512)
#define PAIR_VERTICES (2 * SP_MESHLET_MAX_VERTICES)
#define PAIR_JOINTS 255 /* local joint ids live in ctx->joint_slot (u8, 0xff = none) */
#define NO_CORNER 0xffff

typedef struct pair {
    uint32_t group[2];
    uint32_t triangle[PAIR_TRIANGLES];
    uint16_t corner[PAIR_TRIANGLES][3]; /* local vertex, NO_CORNER for a repeated corner */
    uint8_t side[PAIR_TRIANGLES];       /* 0: in group[0], 1: in group[1] */
    uint8_t locked[PAIR_TRIANGLES];     /* moved in this sequence */
    uint32_t vertex[PAIR_VERTICES];     /* local -> global vertex */
    uint8_t vertex_joints[PAIR_VERTICES][4];
    uint8_t vertex_joint_count[PAIR_VERTICES];
    uint16_t joint[PAIR_JOINTS]; /* local -> global joint */
    uint16_t vertex_refs[2][PAIR_VERTICES], joint_refs[2][PAIR_JOINTS];
    uint32_t count, vertex_count, joint_count;
    uint32_t vertices[2], joints[2], triangles[2]; /* per side */
    /* a sequence's candidates: the triangles around each local vertex, and a bit per triangle
     * that may be on the border (every border triangle's bit is set) */
    uint16_t incidence_offset[PAIR_VERTICES + 1];
    uint16_t incidence[3 * PAIR_TRIANGLES];
    uint64_t candidate[PAIR_TRIANGLES / 64];
} pair;

/* Local id of vertex v (registered with its used joints on first sight), or -1 when the pair
 * has more distinct joints than local ids. */
static int local_vertex(sp_meshlet_context* ctx, pair* p, uint32_t* vertex_local, uint32_t v)
{
    if (vertex_local[v] != 0)
        return (int)vertex_local[v] - 1;
    uint32_t id = p->vertex_count++;
    vertex_local[v] = id + 1;
    p->vertex[id] = v;
    p->vertex_joint_count[id] = 0;
    p->vertex_refs[0][id] = p->vertex_refs[1][id] = 0;
    for (size_t s = 0; s < ctx->influences; ++s) {
        if (!(ctx->weights[(size_t)v * ctx->influences + s] > 0.0f))
            continue;
        uint16_t j = ctx->joints[(size_t)v * ctx->influences + s];
        if (ctx->joint_slot[j] == SP_MESHLET_NO_SLOT) {
            if (p->joint_count == PAIR_JOINTS)
                return -1;
            ctx->joint_slot[j] = (uint8_t)p->joint_count;
            p->joint_refs[0][p->joint_count] = p->joint_refs[1][p->joint_count] = 0;
            p->joint[p->joint_count++] = j;
        }
        p->vertex_joints[id][p->vertex_joint_count[id]++] = ctx->joint_slot[j];
    }
    return (int)id;
}

static void place(pair* p, uint32_t i, int side)
{
    for (int c = 0; c < 3; ++c) {
        uint16_t v = p->corner[i][c];
        if (v == NO_CORNER || p->vertex_refs[side][v]++ != 0)
            continue;
        p->vertices[side]++;
        for (uint8_t k = 0; k < p->vertex_joint_count[v]; ++k)
            p->joints[side] += p->joint_refs[side][p->vertex_joints[v][k]]++ == 0;
    }
    p->triangles[side]++;
    p->side[i] = (uint8_t)side;
}

static void unplace(pair* p, uint32_t i)
{
    int side = p->side[i];
    for (int c = 0; c < 3; ++c) {
        uint16_t v = p->corner[i][c];
        if (v == NO_CORNER || --p->vertex_refs[side][v] != 0)
            continue;
        p->vertices[side]--;
        for (uint8_t k = 0; k < p->vertex_joint_count[v]; ++k)
            p->joints[side] -= --p->joint_refs[side][p->vertex_joints[v][k]] == 0;
    }
    p->triangles[side]--;
}

static void move(pair* p, uint32_t i)
{
    int to = !p->side[i];
    unplace(p, i);
    place(p, i, to);
}

/* Clears the local ids the pair gave out. */
static void release(sp_meshlet_context* ctx, const pair* p, uint32_t* vertex_local)
{
    for (uint32_t i = 0; i < p->vertex_count; ++i)
        vertex_local[p->vertex[i]] = 0;
    for (uint32_t i = 0; i < p->joint_count; ++i)
        ctx->joint_slot[p->joint[i]] = SP_MESHLET_NO_SLOT;
}

/* Adds group g's triangles to the pair as the given side; returns 0 if its joints do not fit. */
static int load_side(sp_meshlet_context* ctx, const sp_meshlet_plan* plan, pair* p, int side, uint32_t g,
                     uint32_t* vertex_local)
{
    p->group[side] = g;
    for (uint32_t t = plan->first_triangle[g]; t != NO_TRIANGLE; t = plan->next_triangle[t]) {
        uint32_t i = p->count++;
        const uint32_t* tri = ctx->indices + (size_t)t * 3;
        p->triangle[i] = t;
        p->locked[i] = 0;
        for (int c = 0; c < 3; ++c) {
            int v = sp_meshlet_distinct_corner(tri, c) ? local_vertex(ctx, p, vertex_local, tri[c]) : NO_CORNER;
            if (v < 0)
                return 0;
            p->corner[i][c] = (uint16_t)v;
        }
        place(p, i, side);
    }
    return 1;
}

/* Loads groups a and b into the pair (b = NO_GROUP: a alone); returns 0 (ids released) if
 * their joints do not fit the local ids. */
static int load_pair(sp_meshlet_context* ctx, const sp_meshlet_plan* plan, pair* p, uint32_t a, uint32_t b,
                     uint32_t* vertex_local)
{
    p->count = p->vertex_count = p->joint_count = 0;
    for (int side = 0; side < 2; ++side)
        p->vertices[side] = p->joints[side] = p->triangles[side] = 0;
    if (load_side(ctx, plan, p, 0, a, vertex_local) && (b == NO_GROUP || load_side(ctx, plan, p, 1, b, vertex_local)))
        return 1;
    release(ctx, p, vertex_local);
    return 0;
}

/* The joints of the loaded group a used by at most EXCHANGE_FEW_VERTICES of its vertices: the
 * only ones a short sequence can take out of its palette. */
static uint32_t rare_joints(const pair* p, uint16_t* rare)
{
    uint32_t count = 0;
    for (uint32_t j = 0; j < p->joint_count && count < EXCHANGE_RARE_MAX; ++j)
        if (p->joint_refs[0][j] <= EXCHANGE_FEW_VERTICES)
            rare[count++] = p->joint[j];
    return count;
}

/* Whether group b has one of the joints (moving their vertices to b then takes an entry off
 * the sum; moving them to a meshlet without it only moves the entry). */
static int group_has_joint(const sp_meshlet_context* ctx, const sp_meshlet_plan* plan, uint32_t b,
                           const uint16_t* joints, uint32_t count)
{
    for (uint32_t t = plan->first_triangle[b]; t != NO_TRIANGLE; t = plan->next_triangle[t]) {
        const uint16_t* list = ctx->triangle_joints + (size_t)t * SP_MESHLET_TRIANGLE_JOINTS;
        for (uint32_t k = 0; k < ctx->triangle_joint_count[t]; ++k)
            for (uint32_t r = 0; r < count; ++r)
                if (list[k] == joints[r])
                    return 1;
    }
    return 0;
}

/* Whether triangle i touches a vertex of the other side: only such moves keep the border short. */
static int on_border(const pair* p, uint32_t i)
{
    int other = !p->side[i];
    for (int c = 0; c < 3; ++c)
        if (p->corner[i][c] != NO_CORNER && p->vertex_refs[other][p->corner[i][c]] != 0)
            return 1;
    return 0;
}

static int within_limits(const sp_meshlet_context* ctx, const pair* p)
{
    return p->vertices[0] <= ctx->options.max_vertices && p->vertices[1] <= ctx->options.max_vertices;
}

/* What moving triangle i to the other side would add to that side (vertices, joints) and take
 * from its own, without moving it. Corners are distinct (repeats are NO_CORNER), so a vertex
 * leaves its side when this triangle is its only reference there, and a joint leaves when all
 * the vertices that carry it there leave. */
typedef struct move_change {
    uint32_t added_vertices, added_joints, removed_vertices, removed_joints;
} move_change;

static move_change change_of_move(const pair* p, uint32_t i)
{
    int from = p->side[i], to = !from;
    move_change change = {0, 0, 0, 0};
    uint8_t added[3 * 4], leaving[3 * 4], leaving_count[3 * 4];
    uint32_t leaving_joints = 0;
    for (int c = 0; c < 3; ++c) {
        uint16_t v = p->corner[i][c];
        if (v == NO_CORNER)
            continue;
        int enters = p->vertex_refs[to][v] == 0, leaves = p->vertex_refs[from][v] == 1;
        change.added_vertices += (uint32_t)enters;
        change.removed_vertices += (uint32_t)leaves;
        for (uint8_t k = 0; k < p->vertex_joint_count[v]; ++k) {
            uint8_t j = p->vertex_joints[v][k];
            uint32_t n = 0;
            if (enters && p->joint_refs[to][j] == 0) {
                while (n < change.added_joints && added[n] != j)
                    ++n;
                if (n == change.added_joints)
                    added[change.added_joints++] = j;
            }
            if (leaves) {
                for (n = 0; n < leaving_joints && leaving[n] != j; ++n)
                    ;
                if (n == leaving_joints) {
                    leaving[leaving_joints] = j;
                    leaving_count[leaving_joints++] = 0;
                }
                leaving_count[n]++;
            }
        }
    }
    for (uint32_t n = 0; n < leaving_joints; ++n)
        change.removed_joints += p->joint_refs[from][leaving[n]] == leaving_count[n];
    return change;
}

/* The triangles around each local vertex of the loaded pair (incidence lists, in triangle
 * order), and the candidate bits of the triangles on the border between its sides. */
static void find_candidates(pair* p)
{
    memset(p->incidence_offset, 0, (p->vertex_count + 1) * sizeof(uint16_t));
    for (uint32_t i = 0; i < p->count; ++i)
        for (int c = 0; c < 3; ++c)
            if (p->corner[i][c] != NO_CORNER)
                p->incidence_offset[p->corner[i][c] + 1]++;
    for (uint32_t v = 0; v < p->vertex_count; ++v)
        p->incidence_offset[v + 1] = (uint16_t)(p->incidence_offset[v + 1] + p->incidence_offset[v]);
    uint16_t fill[PAIR_VERTICES];
    memcpy(fill, p->incidence_offset, p->vertex_count * sizeof(uint16_t));
    memset(p->candidate, 0, sizeof(p->candidate));
    for (uint32_t i = 0; i < p->count; ++i) {
        for (int c = 0; c < 3; ++c)
            if (p->corner[i][c] != NO_CORNER)
                p->incidence[fill[p->corner[i][c]]++] = (uint16_t)i;
        if (on_border(p, i))
            p->candidate[i / 64] |= 1ull << (i % 64);
    }
}

/* After triangle i moved: only a triangle that shares a vertex with it can have come onto the
 * border (its vertices' references are the only ones that changed). */
static void add_candidates_around(pair* p, uint32_t i)
{
    for (int c = 0; c < 3; ++c) {
        uint16_t v = p->corner[i][c];
        if (v == NO_CORNER)
            continue;
        for (uint32_t k = p->incidence_offset[v]; k < p->incidence_offset[v + 1]; ++k)
            p->candidate[p->incidence[k] / 64] |= 1ull << (p->incidence[k] % 64);
    }
}

/* The unlocked border triangle whose move leaves the lowest (palette sum, vertex sum), within
 * the triangle limit, the palette cap and the vertex limit plus slack; NO_TRIANGLE if none.
 * Candidates are visited in triangle order, so ties go to the lowest, as a full scan would. */
static uint32_t best_move(const sp_meshlet_context* ctx, const pair* p)
{
    uint32_t best = NO_TRIANGLE, best_joints = UINT32_MAX, best_vertices = UINT32_MAX;
    for (uint32_t word = 0; word * 64 < p->count; ++word)
        for (uint64_t bits = p->candidate[word]; bits; bits &= bits - 1) {
            uint32_t i = word * 64 + sp_lowest_bit64(bits);
            int to = !p->side[i];
            if (p->locked[i] || p->triangles[to] >= ctx->options.max_triangles || p->triangles[!to] == 1 ||
                !on_border(p, i))
                continue;
            move_change change = change_of_move(p, i);
            uint32_t joints = p->joints[0] + p->joints[1] + change.added_joints - change.removed_joints;
            uint32_t vertices = p->vertices[0] + p->vertices[1] + change.added_vertices - change.removed_vertices;
            int fits = p->joints[to] + change.added_joints <= ctx->options.max_joints &&
                       p->vertices[to] + change.added_vertices <= ctx->options.max_vertices + EXCHANGE_VERTEX_SLACK;
            if (fits && (joints < best_joints || (joints == best_joints && vertices < best_vertices))) {
                best = i;
                best_joints = joints;
                best_vertices = vertices;
            }
        }
    return best;
}

/* One sequence of moves on the loaded pair; applies its best prefix to the plan. Returns 1 if
 * anything moved. */
static int exchange_pair(const sp_meshlet_context* ctx, sp_meshlet_plan* plan, pair* p)
{
    uint32_t moved[EXCHANGE_STEPS], steps = 0, keep = 0;
    uint32_t best_joints = p->joints[0] + p->joints[1], best_vertices = p->vertices[0] + p->vertices[1];
    find_candidates(p);
    while (steps < EXCHANGE_STEPS) {
        uint32_t i = best_move(ctx, p);
        if (i == NO_TRIANGLE)
            break;
        move(p, i);
        p->locked[i] = 1;
        add_candidates_around(p, i);
        moved[steps++] = i;
        uint32_t joints = p->joints[0] + p->joints[1], vertices = p->vertices[0] + p->vertices[1];
        if (within_limits(ctx, p) && (joints < best_joints || (joints == best_joints && vertices < best_vertices))) {
            best_joints = joints;
            best_vertices = vertices;
            keep = steps;
        }
    }
    for (uint32_t k = 0; k < keep; ++k) {
        uint32_t i = moved[k];
        sp_meshlet_plan_move_triangle(plan, p->triangle[i], p->group[p->side[i]]);
    }
    return keep > 0;
}

void sp_meshlet_plan_exchange(sp_meshlet_context* ctx, sp_meshlet_plan* plan, const uint32_t* vertex_adjacency_offset,
                              const uint32_t* vertex_adjacency, uint32_t* vertex_local)
{
    pair p;
    uint32_t near[SP_MESHLET_NEIGHBOUR_MAX];
    uint16_t rare[EXCHANGE_RARE_MAX];
    uint32_t* changed = plan->spatial; /* the pass + 1 that last changed each group; 0: none */
    memset(changed, 0, plan->count * sizeof(uint32_t));
    for (uint32_t pass = 0; pass < EXCHANGE_PASSES; ++pass)
        for (uint32_t a = 0; a < plan->count; ++a) {
            /* after the first pass only groups the previous pass changed can gain */
            if (plan->merged[a] || (pass > 0 && changed[a] != pass) ||
                !load_pair(ctx, plan, &p, a, NO_GROUP, vertex_local))
                continue;
            uint32_t rare_count = rare_joints(&p, rare), near_count = 0;
            if (rare_count > 0)
                near_count = sp_meshlet_plan_neighbours(ctx, plan, a, p.triangle, p.count, vertex_adjacency_offset,
                                                        vertex_adjacency, near);
            release(ctx, &p, vertex_local);
            for (uint32_t k = 0; k < near_count; ++k) {
                if (plan->merged[near[k]] || !group_has_joint(ctx, plan, near[k], rare, rare_count) ||
                    !load_pair(ctx, plan, &p, a, near[k], vertex_local))
                    continue;
                int moved = exchange_pair(ctx, plan, &p);
                release(ctx, &p, vertex_local);
                if (moved) {
                    changed[a] = changed[near[k]] = pass + 1;
                    break; /* a changed: its rare joints are found again in the next pass */
                }
            }
        }
}
