/*
 * cli_common.h - what the glTF commands share: decoding a SKINPACK_packed_skin primitive
 * (all format checks in one place, also the fuzzers' entry point), the bit accounting that
 * info and compress must agree on, and small helpers.
 */
#ifndef SKINPACK_CLI_COMMON_H
#define SKINPACK_CLI_COMMON_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "gltf_io.h"
#include "skinpack.h"

#define CLI_ERR_SIZE 512

/* What info reports about stored meshlets (compress --json reports the same fields). */
typedef struct cli_meshlet_summary {
    size_t count;
    uint32_t max_vertices, max_triangles, max_joints;
    size_t palette_entries; /* palette joints summed over meshlets */
    double mean_joints;
    double local_tuple_bits_mean; /* mean over meshlet vertex entries of ceil(log2 tuple count) */
} cli_meshlet_summary;

/* A decoded packed skin: K joints and K weights a vertex, in weight order. */
typedef struct cli_decoded_skin {
    sp_codec codec;
    size_t vertex_count;
    size_t lut_size;
    uint32_t influences;
    uint32_t words_per_vertex;
    uint32_t joint_bytes;
    uint16_t* joints;
    float* weights;
    cli_meshlet_summary meshlets; /* when the primitive has meshlets (validated with the skin) */
} cli_decoded_skin;

/*
 * Validates the extension's parameters against each other and the stored arrays, then decodes
 * them with sp_decompress_skin. skin_joint_count: joints of the skin that uses the mesh (0 if
 * unknown); the extension's jointCount must not exceed it. On success out->joints/weights are
 * malloc'ed (free with cli_decoded_skin_free); on failure nothing is allocated.
 */
int cli_decode_packed_arrays(const gltf_packed_skin* packed, const uint32_t* words, size_t vertex_count,
                             uint32_t words_per_vertex, const uint16_t* lut, size_t lut_size,
                             size_t skin_joint_count, cli_decoded_skin* out, char* err, size_t err_size);

/* The same, reading the arrays from the document; the packed vertex count must be the
 * primitive's POSITION count (not checked when the primitive has no valid POSITION). */
int cli_decode_packed(const gltf_doc* doc, size_t mesh, size_t primitive, const gltf_packed_skin* packed,
                      cli_decoded_skin* out, char* err, size_t err_size);

/* Primitives that reference the same "vertices" accessor must declare identical properties
 * (spec 1.0, Accessors; the library's sp_packed_params_equal, and the same "tupleTable"):
 * checks packed against an earlier primitive's extension (at mesh, primitive). 0, or -1 with err
 * naming the earlier primitive. */
int cli_check_shared_vertices(const gltf_packed_skin* packed, const gltf_packed_skin* earlier, size_t mesh,
                              size_t primitive, char* err, size_t err_size);

void cli_decoded_skin_free(cli_decoded_skin* skin);

/* Bits a vertex of the LUT costs: lut_size * K * 8 * joint_bytes / vertex_count (as in
 * sp_compressed_skin.lut_bits_per_vertex). */
double cli_lut_bits_per_vertex(size_t lut_size, uint32_t influences, uint32_t joint_bytes, size_t vertex_count);

/* Joint-matched L-inf difference between two K-influence vertices (joints with zero weight
 * ignored; a joint missing on one side counts with weight 0). */
double cli_vertex_difference(const uint16_t* joints_a, const float* weights_a, size_t k_a, const uint16_t* joints_b,
                             const float* weights_b, size_t k_b);

/* Makes room for one more item in a malloc'ed array of count items (doubling *capacity).
 * Returns the array, moved or not, or NULL when out of memory (the old array is still valid). */
void* cli_grow(void* array, size_t* capacity, size_t count, size_t item_size);

/* Size of a file in bytes, 0 if it cannot be read. */
size_t cli_file_size(const char* path);

/* Output kind from the file name: 1 for .glb, 0 for .gltf, the input's kind otherwise. */
int cli_output_is_binary(const char* path, int input_binary);

/* Prints a JSON string (with quotes and escapes). */
void cli_json_string(FILE* out, const char* s);
/* Prints a JSON number (null for non-finite values). */
void cli_json_number(FILE* out, double v);

#endif /* SKINPACK_CLI_COMMON_H */
