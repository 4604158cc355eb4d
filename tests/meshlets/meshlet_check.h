/*
 * meshlet_check.h - builds meshlets into malloc'ed buffers sized by sp_meshlets_bound and checks
 * everything sp_build_meshlets promises (used by the unit tests, the asset tests and the bench).
 */
#ifndef SKINPACK_TEST_MESHLET_CHECK_H
#define SKINPACK_TEST_MESHLET_CHECK_H

#include <skinpack.h>

typedef struct meshlet_input {
    const uint32_t* indices;
    size_t index_count;
    const float* positions; /* 3 floats per vertex, tightly packed */
    size_t vertex_count;
    const uint16_t* joints; /* prepared influences, K per vertex */
    const float* weights;
    size_t influences;
} meshlet_input;

typedef struct meshlet_run {
    sp_meshlet_buffers out;
    void* scratch;
    size_t scratch_size;
    sp_meshlet_stats stats;
    sp_result result;
} meshlet_run;

/* sp_meshlet_options_default with the builder and the three limits set. */
sp_meshlet_options meshlet_options(uint32_t builder, uint32_t max_vertices, uint32_t max_triangles, uint32_t max_joints);

/* Allocates the outputs (with triangle_meshlet) and builds; returns run->result. */
sp_result meshlet_run_build(meshlet_run* run, const meshlet_input* in, const sp_meshlet_options* options);
void meshlet_run_free(meshlet_run* run);

/* 1 if both runs wrote byte-identical output. */
int meshlet_runs_equal(const meshlet_run* a, const meshlet_run* b, size_t influences, size_t triangle_count);

/* Checks limits, the triangle multiset, palettes, local tuple LUTs, bounds, cones,
 * triangle_meshlet and the stats. Returns 1, or 0 with the first violation in message. */
int meshlet_check(const meshlet_run* run, const meshlet_input* in, const sp_meshlet_options* options, char* message,
                  size_t message_size);

#endif
