/*
 * validate_input.h - the byte layout of fuzz_validate's inputs, shared with the seed writer
 * (make_validate_seeds.c). Little-endian, no padding:
 *   fuzz_header (below), then vertex_count * words_per_vertex u32 words,
 *   lut_size * lut_components u16 table joints, and when flags & FUZZ_MESHLETS:
 *   meshlet_count * 4 u32 offsets, meshlet_count * 4 u16 counts, vertex_entries u32 vertices,
 *   vertex_entries u8 vertex tuples, triangle_bytes u8 triangles, joint_entries u16 joints,
 *   tuple_count * min(influences, 4) u8 tuples.
 */
#ifndef SKINPACK_FUZZ_VALIDATE_INPUT_H
#define SKINPACK_FUZZ_VALIDATE_INPUT_H

#include <stdint.h>

#define FUZZ_MESHLETS 1u        /* meshlet arrays follow */
#define FUZZ_MAX_ERROR 2u       /* has_max_error, max_error = max_error_milli / 1000 */
#define FUZZ_COUNT_MISMATCH 4u  /* the primitive has one vertex more than the packed data */

typedef struct fuzz_header {
    uint8_t method, influences, weight_bits, tuple_bits;
    uint8_t words_per_vertex, lut_components, lut_component_bytes, axis_count;
    uint8_t flags, max_vertices, max_joints, max_error_milli;
    uint16_t joint_count, skin_joint_count, vertex_count, lut_size;
    uint16_t max_triangles, meshlet_count, vertex_entries, triangle_bytes, joint_entries, tuple_count;
    uint64_t n, axes[3];
} fuzz_header;

_Static_assert(sizeof(fuzz_header) == 64, "fuzz_header must have no padding");

#endif
