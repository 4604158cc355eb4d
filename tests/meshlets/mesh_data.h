/*
 * mesh_data.h - test/benchmark helpers: the raw skinned meshes that export_mesh_data.py writes
 * (format in that script), and their influences prepared to K = 4 with sp_prepare_influences.
 */
#ifndef SKINPACK_TEST_MESH_DATA_H
#define SKINPACK_TEST_MESH_DATA_H

#include <stddef.h>
#include <stdint.h>

typedef struct mesh_data {
    size_t vertex_count, index_count, joint_count, input_influences;
    float* positions;       /* 3 per vertex */
    uint32_t* indices;
    uint16_t* input_joints; /* input_influences per vertex */
    float* input_weights;
    size_t influences;      /* K of the prepared arrays */
    uint16_t* joints;       /* prepared: K per vertex */
    float* weights;
    size_t unweighted_vertices; /* vertices without influence, bound to joint 0 before preparing */
} mesh_data;

/* Loads path and prepares K influences per vertex. Returns 0 and prints why on failure. */
int mesh_data_load(const char* path, size_t influences, mesh_data* mesh);
void mesh_data_free(mesh_data* mesh);

#endif
