/*
 * packed_fixture.h - a small skinned sheet (FIXTURE_GRID^2 vertices, 40 joints, 1..K influences
 * a vertex), compressed with the library and wrapped as an sp_packed_primitive, optionally with
 * meshlets: the valid input that test_validate corrupts and make_validate_seeds writes as
 * fuzzer seeds. Define FIXTURE_GRID before including to change the size (default 32).
 */
#ifndef SKINPACK_PACKED_FIXTURE_H
#define SKINPACK_PACKED_FIXTURE_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "skinpack.h"

#ifndef FIXTURE_GRID
#define FIXTURE_GRID 32
#endif
enum { GRID = FIXTURE_GRID, V = GRID * GRID, JOINTS = 40, TRIS = (GRID - 1) * (GRID - 1) * 2 };

static uint16_t in_joints[V * 4];
static float in_weights[V * 4];
static float positions[V * 3];
static uint32_t indices[TRIS * 3];

/* A square sheet of vertices, each weighted to 1..4 joints of a chain along x. */
static void make_mesh(size_t influences)
{
    for (size_t y = 0; y < GRID; ++y)
        for (size_t x = 0; x < GRID; ++x) {
            size_t v = y * GRID + x;
            positions[v * 3] = (float)x, positions[v * 3 + 1] = (float)y, positions[v * 3 + 2] = 0;
            double t = (double)x / GRID * (JOINTS - 4), sum = 0, raw[4];
            size_t count = influences == 1 ? 1 : 1 + (x * 7 + y * 3) % influences;
            for (size_t i = 0; i < 4; ++i) {
                in_joints[v * 4 + i] = (uint16_t)((size_t)t + i);
                raw[i] = i < count ? exp(-fabs(t - (double)((size_t)t + i)) * (1.0 + 0.1 * (double)y)) : 0;
                sum += raw[i];
            }
            for (size_t i = 0; i < 4; ++i) in_weights[v * 4 + i] = (float)(raw[i] / sum);
        }
    size_t at = 0;
    for (uint32_t y = 0; y + 1 < GRID; ++y)
        for (uint32_t x = 0; x + 1 < GRID; ++x) {
            uint32_t a = y * GRID + x, b = a + 1, c = a + GRID, d = c + 1;
            uint32_t quad[6] = {a, b, d, a, d, c};
            memcpy(indices + at, quad, sizeof(quad));
            at += 6;
        }
}

typedef struct packed {
    uint32_t words[2 * V];
    uint16_t lut[4 * V];
    sp_compressed_skin info;
    sp_packed_primitive prim;
} packed;

static sp_result compress(const sp_compress_options* o, packed* p)
{
    size_t size = sp_compress_scratch_bound(V, 4);
    void* scratch = malloc(size);
    sp_result r = sp_compress_skin(in_joints, in_weights, V, 4, JOINTS, o, p->words, p->lut, NULL, NULL, &p->info,
                                   scratch, size);
    free(scratch);
    const sp_compressed_skin* s = &p->info;
    sp_packed_params params = {s->codec.method, s->influences, s->joint_count, s->weight_bits, s->tuple_bits,
                               s->codec.n, {0}, 0, 1, s->codec.max_error};
    if (s->codec.method == SP_METHOD_ANY) {
        params.axis_sample_count = s->influences - 1;
        memcpy(params.axis_samples, s->codec.axis_samples, sizeof(params.axis_samples));
    }
    sp_packed_primitive prim = {params, p->words, V, s->words_per_vertex, V, p->lut, s->lut_size, s->influences,
                                sp_joint_bytes(JOINTS), JOINTS, NULL};
    p->prim = prim;
    return r;
}

/* Meshlet arrays as sp_build_meshlets writes them, widened to the validator's types. */
typedef struct meshlet_arrays {
    sp_meshlet meshlets[TRIS];
    uint32_t vertices[TRIS * 3], offsets[TRIS * 4], counts[TRIS * 4];
    uint8_t vertex_tuples[TRIS * 3], triangles[TRIS * 3], tuples[TRIS * 3 * 4];
    uint16_t joints[TRIS * 12];
    sp_packed_meshlets view;
} meshlet_arrays;

static int build_meshlets(const packed* p, meshlet_arrays* a)
{
    static uint16_t joints[V * 4];
    static float weights[V * 4];
    uint32_t k = p->info.influences;
    if (sp_validate_packed(&p->prim, joints, weights, NULL) != SP_OK) return -1;
    sp_meshlet_options options;
    sp_meshlet_options_default(&options);
    sp_meshlet_sizes sizes;
    sp_meshlets_bound(TRIS * 3, V, k, &options, &sizes);
    if (sizes.meshlets > TRIS || sizes.vertices > TRIS * 3 || sizes.joints > TRIS * 12 || sizes.tuples > TRIS * 3)
        return -1;
    sp_meshlet_buffers out = {a->meshlets, a->vertices, a->vertex_tuples, a->triangles, a->joints, a->tuples, NULL,
                              sizes};
    void* scratch = malloc(sizes.scratch_bytes);
    sp_meshlet_stats stats;
    sp_result r = sp_build_meshlets(indices, TRIS * 3, positions, V, 12, joints, weights, k, &options, &out, scratch,
                                    sizes.scratch_bytes, &stats);
    free(scratch);
    if (r != SP_OK) return -1;
    for (size_t m = 0; m < stats.meshlet_count; ++m) {
        const sp_meshlet* ml = &a->meshlets[m];
        uint32_t o[4] = {ml->vertex_offset, ml->triangle_offset, ml->joint_offset, ml->tuple_offset};
        uint32_t c[4] = {ml->vertex_count, ml->triangle_count, ml->joint_count, ml->tuple_count};
        memcpy(a->offsets + 4 * m, o, sizeof(o));
        memcpy(a->counts + 4 * m, c, sizeof(c));
    }
    sp_packed_meshlets view = {stats.meshlet_count, a->offsets, a->counts, stats.vertex_count, a->vertices,
                               a->vertex_tuples, stats.triangle_count * 3, a->triangles, stats.joint_count, a->joints,
                               stats.tuple_count, a->tuples, options.max_vertices, options.max_triangles,
                               options.max_joints};
    a->view = view;
    return 0;
}

#endif
