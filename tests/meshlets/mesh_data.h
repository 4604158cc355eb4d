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
    /* As compressed (mesh_data_decode_compressed): what a decoder of the default compress sees */
    size_t decoded_influences;  /* K the compress used: min(4, most influences of a vertex) */
    uint16_t* decoded_joints;   /* decoded_influences per vertex, weight order */
    float* decoded_weights;
    uint32_t decoded_weight_bits, decoded_tuple_bits;
    double decoded_max_error;   /* the codec's proven L-inf bound against the prepared weights */
    size_t decoded_lut_size;
    size_t lost_influences;     /* used prepared slots whose weight decodes to 0, summed over vertices */
} mesh_data;

/* Loads path and prepares K influences per vertex. Returns 0 and prints why on failure. */
int mesh_data_load(const char* path, size_t influences, mesh_data* mesh);
/* Fills the decoded_* fields: sp_compress_skin with the default options (OSS, K = 4, 32-bit
 * vertex budget) on the loaded arrays, then sp_decompress_skin of its words, the two calls
 * `skinpack compress --meshlets` makes before it builds meshlets (native/cli/cli_compress.c).
 * A joint whose weight quantises to 0 is unused in the file, so it is in no palette there.
 * Returns 0 and prints why on failure. */
int mesh_data_decode_compressed(mesh_data* mesh);
void mesh_data_free(mesh_data* mesh);

#endif
