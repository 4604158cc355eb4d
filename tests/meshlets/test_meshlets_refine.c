/*
 * test_meshlets_refine.c - the skin builder's refine step (meshlets_refine.c) on a hand-made plan
 * (label "unit"): a strip of 12 triangles whose vertices 0..6 carry joint 1 and 7..13 joint 2,
 * split as A = triangles 0..5 (palette {1, 2}: triangle 5 reaches vertex 7) and B = 6..11
 * (palette {1, 2}: triangle 6 reaches vertex 6). Moving triangle 5 to B drops joint 2 from A and
 * adds nothing to B: 4 entries become 3. It must happen when B has room for vertex 5, and must
 * not when the vertex limit forbids it.
 */
#include "meshlets_internal.h"
#include "test_expect.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { TRIANGLES = 12, VERTICES = TRIANGLES + 2 };

/* Builds the plan above with this vertex limit, refines it, returns the owner of triangle 5
 * and the group sizes of A and B. */
static uint32_t refine_strip(uint32_t max_vertices, uint32_t* size_a, uint32_t* size_b)
{
    uint32_t indices[TRIANGLES * 3], offset[VERTICES + 1], adjacency[TRIANGLES * 3];
    float positions[VERTICES * 3], weights[VERTICES];
    uint16_t joints[VERTICES];
    for (uint32_t v = 0; v < VERTICES; ++v) {
        positions[v * 3 + 0] = (float)(v / 2);
        positions[v * 3 + 1] = (float)(v % 2);
        positions[v * 3 + 2] = 0.0f;
        joints[v] = v <= 6 ? 1 : 2;
        weights[v] = 1.0f;
    }
    for (uint32_t t = 0; t < TRIANGLES; ++t)
        for (uint32_t c = 0; c < 3; ++c)
            indices[t * 3 + c] = t + c;
    uint32_t at = 0; /* triangles around each vertex, ascending */
    for (uint32_t v = 0; v < VERTICES; ++v) {
        offset[v] = at;
        for (uint32_t t = 0; t < TRIANGLES; ++t)
            if (v >= t && v <= t + 2)
                adjacency[at++] = t;
    }
    offset[VERTICES] = at;

    sp_meshlet_context ctx;
    memset(&ctx, 0, sizeof(ctx));
    ctx.indices = indices;
    ctx.triangle_count = TRIANGLES;
    ctx.positions = positions;
    ctx.position_stride = 3;
    ctx.vertex_count = VERTICES;
    ctx.joints = joints;
    ctx.weights = weights;
    ctx.influences = 1;
    sp_meshlet_options_default(&ctx.options);
    ctx.options.max_vertices = max_vertices;
    uint16_t triangle_joints[TRIANGLES * SP_MESHLET_TRIANGLE_JOINTS];
    uint8_t triangle_joint_count[TRIANGLES], vertex_slot[VERTICES];
    uint32_t open_triangles[SP_MESHLET_MAX_TRIANGLES];
    uint8_t* joint_slot = malloc(SP_JOINT_SLOT_COUNT);
    unsigned char* scratch = malloc(sp_meshlet_plan_scratch_bound(TRIANGLES));
    ctx.triangle_joints = triangle_joints;
    ctx.triangle_joint_count = triangle_joint_count;
    ctx.vertex_slot = vertex_slot;
    ctx.joint_slot = joint_slot;
    ctx.open_triangles = open_triangles;
    memset(vertex_slot, SP_MESHLET_NO_SLOT, sizeof(vertex_slot));
    memset(joint_slot, SP_MESHLET_NO_SLOT, SP_JOINT_SLOT_COUNT);
    size_t error_triangle = 0;
    EXPECT(sp_meshlet_collect_triangle_joints(&ctx, &error_triangle) == SP_OK, "triangle joints");

    sp_meshlet_plan plan;
    unsigned char* cursor = scratch;
    sp_meshlet_plan_init(&plan, &cursor, TRIANGLES);
    for (uint32_t t = 0; t < TRIANGLES; ++t) {
        if (t == TRIANGLES / 2)
            sp_meshlet_plan_close(&ctx, &plan);
        sp_meshlet_add(&ctx, t);
    }
    sp_meshlet_plan_close(&ctx, &plan);
    sp_meshlet_plan_link(&plan);
    sp_meshlet_plan_refine(&ctx, &plan, offset, adjacency);
    uint32_t owner = plan.owner[5];
    *size_a = plan.triangle_count[0];
    *size_b = plan.triangle_count[1];
    free(scratch);
    free(joint_slot);
    return owner;
}

int main(void)
{
    uint32_t a = 0, b = 0;
    /* A has vertices 0..7, B 6..13 (8 each); B takes triangle 5 only with room for vertex 5 */
    uint32_t owner = refine_strip(9, &a, &b);
    EXPECT(owner == 1 && a == 5 && b == 7, "room for vertex 5: triangle 5 in %u, sizes %u/%u (want 1, 5/7)", owner, a, b);
    owner = refine_strip(8, &a, &b);
    EXPECT(owner == 0 && a == 6 && b == 6, "no room: triangle 5 in %u, sizes %u/%u (want 0, 6/6)", owner, a, b);
    if (failures) {
        fprintf(stderr, "test_meshlets_refine: %d failures\n", failures);
        return 1;
    }
    printf("test_meshlets_refine: ok\n");
    return 0;
}
