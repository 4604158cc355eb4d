/*
 * test_meshlets_refine.c - the skin builder's refine and exchange steps (meshlets_refine.c,
 * meshlets_exchange.c) on hand-made plans of two meshlets A and B (label "unit").
 *
 * Refine, on a strip of 12 triangles (triangle t = vertices t, t+1, t+2) whose vertices 0..6
 * carry joint 1 and 7..13 joint 2, split as A = triangles 0..5 (palette {1, 2}: triangle 5
 * reaches vertex 7) and B = 6..11 (palette {1, 2}: triangle 6 reaches vertex 6). Moving triangle
 * 5 to B drops joint 2 from A and adds nothing to B: 4 entries become 3. It must happen when B
 * has room for vertex 5, and must not when the vertex limit forbids it.
 *
 * Exchange, on a ring of 12 triangles (the same strip closed: vertex indices mod 12) whose
 * vertices 7..10 carry joint 2 and the others joint 1, split as A = triangles 0..5 (vertices
 * 0..7, palette {1, 2}) and B = 6..11 (vertices 6..11, 0, 1, palette {1, 2}), 8 vertices each at
 * a limit of 8. Triangle 5 alone cannot go to B (B has no room for vertex 5), so refine leaves
 * the plan; moving it and then triangle 11 from B to A (B loses vertex 1, A gains vertex 11,
 * which carries joint 1) gives A = {1}, B = {1, 2} with 8 vertices each: 3 entries. Exchange must
 * find that; with a triangle limit of 6 (B cannot take a seventh) it must leave the plan. And on
 * the strip, a sequence that needs triangles which reach the border only during it (below).
 *
 * Also the skin builder's sort of triangles by Morton code (sp_meshlet_sort_high_words): the same
 * order as qsort of the whole keys, whose low words (triangle numbers) ascend.
 */
#include "meshlets_internal.h"
#include "test_expect.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { TRIANGLES = 12, MAX_VERTICES = TRIANGLES + 2 };

typedef struct fixture {
    uint32_t indices[TRIANGLES * 3], offset[MAX_VERTICES + 1], adjacency[TRIANGLES * 3], live[MAX_VERTICES];
    float positions[MAX_VERTICES * 3], weights[MAX_VERTICES];
    uint16_t joints[MAX_VERTICES], triangle_joints[TRIANGLES * SP_MESHLET_TRIANGLE_JOINTS];
    uint8_t triangle_joint_count[TRIANGLES], vertex_slot[MAX_VERTICES];
    uint32_t open_triangles[SP_MESHLET_MAX_TRIANGLES];
    uint8_t* joint_slot;
    unsigned char* scratch;
    sp_meshlet_context ctx;
    sp_meshlet_plan plan;
} fixture;

/* The strip (ring = 0) or ring (ring = 1) above, joint 2 on vertices [joint2_first,
 * joint2_last], split into A = triangles 0..5 and B = 6..11, linked. */
static void make_plan(fixture* f, int ring, uint32_t joint2_first, uint32_t joint2_last, uint32_t max_vertices,
                      uint32_t max_triangles)
{
    memset(f, 0, sizeof(*f));
    uint32_t vertices = ring ? TRIANGLES : TRIANGLES + 2;
    for (uint32_t v = 0; v < vertices; ++v) {
        f->positions[v * 3 + 0] = (float)(v / 2);
        f->positions[v * 3 + 1] = (float)(v % 2);
        f->joints[v] = v >= joint2_first && v <= joint2_last ? 2 : 1;
        f->weights[v] = 1.0f;
    }
    for (uint32_t t = 0; t < TRIANGLES; ++t)
        for (uint32_t c = 0; c < 3; ++c)
            f->indices[t * 3 + c] = (t + c) % vertices;
    uint32_t at = 0; /* triangles around each vertex, ascending */
    for (uint32_t v = 0; v < vertices; ++v) {
        f->offset[v] = at;
        for (uint32_t t = 0; t < TRIANGLES * 3; ++t)
            if (f->indices[t] == v)
                f->adjacency[at++] = t / 3;
    }
    f->offset[vertices] = at;

    sp_meshlet_context* ctx = &f->ctx;
    ctx->indices = f->indices;
    ctx->triangle_count = TRIANGLES;
    ctx->positions = f->positions;
    ctx->position_stride = 3;
    ctx->vertex_count = vertices;
    ctx->joints = f->joints;
    ctx->weights = f->weights;
    ctx->influences = 1;
    sp_meshlet_options_default(&ctx->options);
    ctx->options.max_vertices = max_vertices;
    ctx->options.max_triangles = max_triangles;
    f->joint_slot = malloc(SP_JOINT_SLOT_COUNT);
    f->scratch = malloc(sp_meshlet_plan_scratch_bound(TRIANGLES));
    ctx->triangle_joints = f->triangle_joints;
    ctx->triangle_joint_count = f->triangle_joint_count;
    ctx->vertex_slot = f->vertex_slot;
    ctx->joint_slot = f->joint_slot;
    ctx->open_triangles = f->open_triangles;
    memset(f->vertex_slot, SP_MESHLET_NO_SLOT, sizeof(f->vertex_slot));
    memset(f->joint_slot, SP_MESHLET_NO_SLOT, SP_JOINT_SLOT_COUNT);
    size_t error_triangle = 0;
    EXPECT(sp_meshlet_collect_triangle_joints(ctx, &error_triangle) == SP_OK, "triangle joints");

    unsigned char* cursor = f->scratch;
    sp_meshlet_plan_init(&f->plan, &cursor, TRIANGLES);
    for (uint32_t t = 0; t < TRIANGLES; ++t) {
        if (t == TRIANGLES / 2)
            sp_meshlet_plan_close(ctx, &f->plan);
        sp_meshlet_add(ctx, t);
    }
    sp_meshlet_plan_close(ctx, &f->plan);
    sp_meshlet_plan_link(&f->plan);
}

static void free_plan(fixture* f)
{
    free(f->scratch);
    free(f->joint_slot);
}

/* Vertices and palette size of group g, through the open meshlet (left empty). */
static void measure(fixture* f, uint32_t g, uint32_t* vertices, uint32_t* joints)
{
    for (uint32_t t = f->plan.first_triangle[g]; t != UINT32_MAX; t = f->plan.next_triangle[t])
        sp_meshlet_add(&f->ctx, t);
    *vertices = f->ctx.open_vertex_count;
    *joints = f->ctx.open_joint_count;
    sp_meshlet_reset_open(&f->ctx);
}

/* Builds the strip plan with this vertex limit, refines it, returns the owner of triangle 5
 * and the group sizes of A and B. */
static uint32_t refine_strip(uint32_t max_vertices, uint32_t* size_a, uint32_t* size_b)
{
    fixture* f = malloc(sizeof(fixture));
    make_plan(f, 0, 7, 13, max_vertices, 124);
    sp_meshlet_plan_refine(&f->ctx, &f->plan, f->offset, f->adjacency);
    uint32_t owner = f->plan.owner[5];
    *size_a = f->plan.triangle_count[0];
    *size_b = f->plan.triangle_count[1];
    free_plan(f);
    free(f);
    return owner;
}

/* Runs exchange on the plan; returns the palette sum and checks every limit, that every
 * triangle is in A or B and that the scratch it borrowed is left clean. */
static uint32_t exchange_sum(fixture* f, int* changed)
{
    uint32_t max_vertices = f->ctx.options.max_vertices, max_triangles = f->ctx.options.max_triangles;
    sp_meshlet_plan_exchange(&f->ctx, &f->plan, f->offset, f->adjacency, f->live);
    uint32_t sum = 0;
    *changed = 0;
    for (uint32_t g = 0; g < 2; ++g) {
        uint32_t vertices = 0, joints = 0, triangles = 0;
        EXPECT(!f->plan.merged[g], "group %u kept", g);
        for (uint32_t t = f->plan.first_triangle[g]; t != UINT32_MAX; t = f->plan.next_triangle[t]) {
            EXPECT(f->plan.owner[t] == g, "triangle %u listed in group %u, owned by %u", t, g, f->plan.owner[t]);
            *changed |= (t < TRIANGLES / 2) != (g == 0);
            triangles++;
        }
        measure(f, g, &vertices, &joints);
        EXPECT(vertices <= max_vertices && triangles <= max_triangles, "group %u: %u vertices, %u triangles", g,
               vertices, triangles);
        EXPECT(f->plan.triangle_count[g] == triangles, "group %u counts %u triangles, lists %u", g,
               f->plan.triangle_count[g], triangles);
        sum += joints;
    }
    EXPECT(f->plan.triangle_count[0] + f->plan.triangle_count[1] == TRIANGLES, "every triangle in A or B");
    for (uint32_t v = 0; v < f->ctx.vertex_count; ++v)
        EXPECT(f->live[v] == 0, "vertex_local of vertex %u left at %u", v, f->live[v]);
    for (uint32_t j = 0; j < 3; ++j)
        EXPECT(f->joint_slot[j] == SP_MESHLET_NO_SLOT, "joint slot %u left in use", j);
    return sum;
}

/* The ring plan with this triangle limit: refine alone leaves it, exchange must not. */
static uint32_t exchange_ring(uint32_t max_triangles, int* changed)
{
    fixture* f = malloc(sizeof(fixture));
    make_plan(f, 1, 7, 10, 8, max_triangles);
    sp_meshlet_plan_refine(&f->ctx, &f->plan, f->offset, f->adjacency);
    EXPECT(f->plan.owner[5] == 0 && f->plan.owner[11] == 1, "refine alone moves nothing on the ring");
    uint32_t sum = exchange_sum(f, changed);
    free_plan(f);
    free(f);
    return sum;
}

/* The strip with joint 2 on vertices 4..11 (joint 1 on 0..3 and 12, 13): A = {1, 2}, B = {1, 2}.
 * A drops joint 2 only when triangles 2..5 all go to B (A keeps vertices 0..3, B holds 2..13: 12
 * vertices). Only 4 and 5 are on the border at first; 3 and 2 reach it as their neighbours move,
 * so the sequence must take in triangles that came onto the border during it. Returns the
 * palette sum and the owner of triangle 2. */
static uint32_t exchange_deep_strip(uint32_t* owner_of_2)
{
    fixture* f = malloc(sizeof(fixture));
    make_plan(f, 0, 4, 11, 12, 124);
    int changed = 0;
    uint32_t sum = exchange_sum(f, &changed);
    *owner_of_2 = f->plan.owner[2];
    free_plan(f);
    free(f);
    return sum;
}

/* Keys with many equal high words (codes under `spread`), low words ascending, against qsort. */
static int sort_matches_qsort(size_t count, uint32_t spread)
{
    uint64_t* keys = malloc(count * sizeof(uint64_t) + 1);
    uint64_t* temp = malloc(count * sizeof(uint64_t) + 1);
    uint64_t* expected = malloc(count * sizeof(uint64_t) + 1);
    uint32_t state = 12345;
    for (size_t i = 0; i < count; ++i) {
        state = state * 1664525u + 1013904223u;
        expected[i] = keys[i] = (uint64_t)(state % spread) << 32 | i;
    }
    qsort(expected, count, sizeof(uint64_t), sp_meshlet_compare_u64);
    sp_meshlet_sort_high_words(keys, temp, count);
    int same = memcmp(keys, expected, count * sizeof(uint64_t)) == 0;
    free(keys);
    free(temp);
    free(expected);
    return same;
}

int main(void)
{
    EXPECT(sort_matches_qsort(0, 1) && sort_matches_qsort(1, 1), "sort: empty or single key");
    EXPECT(sort_matches_qsort(5000, 7), "sort: 5000 keys, 7 codes");
    EXPECT(sort_matches_qsort(100000, 1u << 30), "sort: 100000 keys, 30-bit codes");
    EXPECT(sort_matches_qsort(3000, UINT32_MAX), "sort: 3000 keys, 32-bit codes");
    uint32_t a = 0, b = 0;
    /* A has vertices 0..7, B 6..13 (8 each); B takes triangle 5 only with room for vertex 5 */
    uint32_t owner = refine_strip(9, &a, &b);
    EXPECT(owner == 1 && a == 5 && b == 7, "room for vertex 5: triangle 5 in %u, sizes %u/%u (want 1, 5/7)", owner, a, b);
    owner = refine_strip(8, &a, &b);
    EXPECT(owner == 0 && a == 6 && b == 6, "no room: triangle 5 in %u, sizes %u/%u (want 0, 6/6)", owner, a, b);

    int changed = 0;
    uint32_t sum = exchange_ring(124, &changed);
    EXPECT(sum == 3 && changed, "ring: palette sum %u after exchange (want 3)", sum);
    sum = exchange_ring(6, &changed);
    EXPECT(sum == 4 && !changed, "ring at 6 triangles: palette sum %u, changed %d (want 4, unchanged)", sum, changed);
    sum = exchange_deep_strip(&owner);
    EXPECT(sum == 3 && owner == 1, "deep strip: palette sum %u, triangle 2 in %u (want 3, in B)", sum, owner);
    if (failures) {
        fprintf(stderr, "test_meshlets_refine: %d failures\n", failures);
        return 1;
    }
    printf("test_meshlets_refine: ok\n");
    return 0;
}
