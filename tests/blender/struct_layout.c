/* Prints sizeof and offsetof of every struct the add-on mirrors with ctypes (addon/skinpack/native.py)
 * as JSON, so test_native_layout.py fails as soon as skinpack.h and the mirror drift apart. */
#include <stddef.h>
#include <stdio.h>

#include "skinpack.h"

#define FIELD(type, field) \
    do { printf("%s\"%s\": %zu", first ? "" : ", ", #field, offsetof(type, field)); first = 0; } while (0)
#define BEGIN(type) \
    do { printf("%s\"%s\": {\"size\": %zu, \"fields\": {", comma, #type, sizeof(type)); first = 1; comma = ", "; } while (0)
#define END() printf("}}")

int main(void) {
    const char* comma = "";
    int first;
    printf("{");
    BEGIN(sp_prepare_stats);
    FIELD(sp_prepare_stats, vertex_count); FIELD(sp_prepare_stats, pruned_vertices);
    FIELD(sp_prepare_stats, renormalized_vertices); FIELD(sp_prepare_stats, merged_duplicates);
    FIELD(sp_prepare_stats, influence_histogram); FIELD(sp_prepare_stats, max_pruning_error);
    FIELD(sp_prepare_stats, rms_pruning_error); FIELD(sp_prepare_stats, error_vertex);
    FIELD(sp_prepare_stats, error_joint);
    END();
    BEGIN(sp_codec);
    FIELD(sp_codec, method); FIELD(sp_codec, influences); FIELD(sp_codec, bits); FIELD(sp_codec, component_bits);
    FIELD(sp_codec, n); FIELD(sp_codec, axis_samples); FIELD(sp_codec, scale); FIELD(sp_codec, max_code);
    FIELD(sp_codec, code_bits); FIELD(sp_codec, max_spacing); FIELD(sp_codec, max_error);
    END();
    BEGIN(sp_error_stats);
    FIELD(sp_error_stats, max_error); FIELD(sp_error_stats, rms_error); FIELD(sp_error_stats, mean_error);
    FIELD(sp_error_stats, worst_vertex); FIELD(sp_error_stats, histogram_max); FIELD(sp_error_stats, histogram);
    FIELD(sp_error_stats, vertices_over_bound);
    END();
    BEGIN(sp_compress_options);
    FIELD(sp_compress_options, method); FIELD(sp_compress_options, max_influences);
    FIELD(sp_compress_options, vertex_bits); FIELD(sp_compress_options, weight_bits);
    FIELD(sp_compress_options, max_spacing); FIELD(sp_compress_options, merge_dont_care);
    FIELD(sp_compress_options, sum_tolerance); FIELD(sp_compress_options, max_error);
    END();
    BEGIN(sp_compressed_skin);
    FIELD(sp_compressed_skin, codec); FIELD(sp_compressed_skin, influences); FIELD(sp_compressed_skin, tuple_bits);
    FIELD(sp_compressed_skin, weight_bits); FIELD(sp_compressed_skin, words_per_vertex);
    FIELD(sp_compressed_skin, joint_bytes); FIELD(sp_compressed_skin, vertex_count);
    FIELD(sp_compressed_skin, joint_count); FIELD(sp_compressed_skin, lut_size);
    FIELD(sp_compressed_skin, lut_bits_per_vertex); FIELD(sp_compressed_skin, bits_per_vertex);
    FIELD(sp_compressed_skin, prepare); FIELD(sp_compressed_skin, quantization);
    END();
    BEGIN(sp_meshlet_options);
    FIELD(sp_meshlet_options, builder); FIELD(sp_meshlet_options, max_vertices);
    FIELD(sp_meshlet_options, max_triangles); FIELD(sp_meshlet_options, max_joints);
    FIELD(sp_meshlet_options, min_group_triangles); FIELD(sp_meshlet_options, joint_cost);
    FIELD(sp_meshlet_options, tuple_cost);
    END();
    BEGIN(sp_meshlet);
    FIELD(sp_meshlet, vertex_offset); FIELD(sp_meshlet, triangle_offset); FIELD(sp_meshlet, joint_offset);
    FIELD(sp_meshlet, tuple_offset); FIELD(sp_meshlet, vertex_count); FIELD(sp_meshlet, triangle_count);
    FIELD(sp_meshlet, joint_count); FIELD(sp_meshlet, tuple_count); FIELD(sp_meshlet, tuple_bits);
    FIELD(sp_meshlet, center); FIELD(sp_meshlet, radius); FIELD(sp_meshlet, cone_apex);
    FIELD(sp_meshlet, cone_axis); FIELD(sp_meshlet, cone_cutoff);
    END();
    BEGIN(sp_meshlet_sizes);
    FIELD(sp_meshlet_sizes, meshlets); FIELD(sp_meshlet_sizes, vertices); FIELD(sp_meshlet_sizes, triangles);
    FIELD(sp_meshlet_sizes, joints); FIELD(sp_meshlet_sizes, tuples); FIELD(sp_meshlet_sizes, scratch_bytes);
    END();
    BEGIN(sp_meshlet_buffers);
    FIELD(sp_meshlet_buffers, meshlets); FIELD(sp_meshlet_buffers, vertices);
    FIELD(sp_meshlet_buffers, vertex_tuples); FIELD(sp_meshlet_buffers, triangles);
    FIELD(sp_meshlet_buffers, joints); FIELD(sp_meshlet_buffers, tuples);
    FIELD(sp_meshlet_buffers, triangle_meshlet); FIELD(sp_meshlet_buffers, capacity);
    END();
    BEGIN(sp_meshlet_stats);
    FIELD(sp_meshlet_stats, meshlet_count); FIELD(sp_meshlet_stats, vertex_count);
    FIELD(sp_meshlet_stats, triangle_count); FIELD(sp_meshlet_stats, joint_count);
    FIELD(sp_meshlet_stats, tuple_count); FIELD(sp_meshlet_stats, max_vertices);
    FIELD(sp_meshlet_stats, max_triangles); FIELD(sp_meshlet_stats, max_joints);
    FIELD(sp_meshlet_stats, mean_vertices); FIELD(sp_meshlet_stats, mean_triangles);
    FIELD(sp_meshlet_stats, mean_joints); FIELD(sp_meshlet_stats, global_tuples);
    FIELD(sp_meshlet_stats, global_tuple_bits); FIELD(sp_meshlet_stats, local_tuple_bits_mean);
    FIELD(sp_meshlet_stats, local_tuple_bits_max); FIELD(sp_meshlet_stats, error_triangle);
    END();
    printf("}\n");
    return 0;
}
