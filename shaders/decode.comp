#version 460
// decode.comp - decode-only test shader: one skinpack code or vertex per invocation, written
// out as exact integers and floats so the C harness can compare every bit with libskinpack.
#extension GL_GOOGLE_include_directive : require

#include "skinpack_gpu_layout.h"

layout(local_size_x = 64) in;

layout(std140, set = 0, binding = SP_BINDING_CODEC) uniform CodecBlock { SpGpuCodec codec; };
layout(std430, set = 0, binding = SP_BINDING_VERTEX_WORDS) readonly buffer InputWords { uint input_words[]; };
layout(std430, set = 0, binding = SP_BINDING_TUPLE_LUT) readonly buffer TupleLut { uint tuple_lut_words[]; };
layout(std430, set = 0, binding = SP_BINDING_OUTPUT) writeonly buffer Records { SpDecodedRecord records[]; };
layout(std430, set = 0, binding = SP_BINDING_MESHLETS) readonly buffer Meshlets { uint meshlet_words[]; };
layout(std430, set = 0, binding = SP_BINDING_MESHLET_DATA) readonly buffer MeshletData { uint meshlet_data_words[]; };
// Meshlet mode: the source vertex of each triangle corner, 3 per triangle.
layout(std430, set = 0, binding = SP_BINDING_POSITIONS) writeonly buffer TriangleCorners { uint triangle_corners[]; };

layout(push_constant) uniform DecodeParameters {
    uint mode;       // SP_DECODE_MODE_*
    uint item_count; // codes or vertices; meshlet mode: meshlets (one workgroup each)
    uint force_wide; // 1: use the 64-bit decoder even where the 32-bit one is exact (cross-check)
    uint meshlet_arrays[5]; // meshlet mode: SpMeshletArrays word offsets
} parameters;

#define SP_TUPLE_LUT_WORD(i) tuple_lut_words[i]
#define SP_MESHLET_WORD(i) meshlet_words[i]
#define SP_MESHLET_DATA_WORD(i) meshlet_data_words[i]
#include "skinpack_decode.glsl"

void decode_into(uvec2 code, inout SpDecodedRecord record)
{
    if (parameters.force_wide == 0u && sp_codec_is_narrow(codec)) {
        uvec4 q;
        record.weights = sp_decode_weights32(codec, code.x, q);
        record.q_low = q;
        record.q_high = uvec4(0u);
    } else {
        record.weights = sp_decode_weights64(codec, code, record.q_low, record.q_high);
    }
}

uvec2 vertex_value(uint v)
{
    uint words = sp_codec_words_per_vertex(codec);
    return sp_vertex_value(codec, input_words[words * v], words == 2u ? input_words[words * v + 1u] : 0u);
}

// One workgroup per meshlet: every meshlet vertex through the meshlet palette and local tuple
// LUT (what skin.mesh does), records at the meshlet's vertex entries; triangle corners as
// source vertex indices.
void decode_meshlet(uint meshlet_index)
{
    SpMeshlet m = sp_load_meshlet(meshlet_index);
    SpMeshletArrays arrays = SpMeshletArrays(parameters.meshlet_arrays[0], parameters.meshlet_arrays[1],
                                             parameters.meshlet_arrays[2], parameters.meshlet_arrays[3],
                                             parameters.meshlet_arrays[4]);
    for (uint i = gl_LocalInvocationID.x; i < m.vertex_count; i += gl_WorkGroupSize.x) {
        uint v = sp_meshlet_vertex(arrays, m, i);
        SpDecodedRecord record;
        record.joints = sp_meshlet_joints(arrays, m, i, sp_codec_influences(codec));
        record.vertex = uvec4(v, 1u, m.joint_count, m.tuple_count);
        decode_into(sp_vertex_code(codec, vertex_value(v)), record);
        records[m.vertex_offset + i] = record;
    }
    for (uint t = gl_LocalInvocationID.x; t < m.triangle_count; t += gl_WorkGroupSize.x) {
        uvec3 corner = sp_meshlet_triangle(arrays, m, t);
        for (uint c = 0u; c < 3u; ++c) triangle_corners[3u * (m.triangle_offset + t) + c] = sp_meshlet_vertex(arrays, m, corner[c]);
    }
}

void main()
{
    if (parameters.mode == SP_DECODE_MODE_MESHLETS) {
        if (gl_WorkGroupID.x < parameters.item_count) decode_meshlet(gl_WorkGroupID.x);
        return;
    }
    uint item = gl_GlobalInvocationID.x;
    if (item >= parameters.item_count) return;

    SpDecodedRecord record;
    record.joints = uvec4(0u);
    record.vertex = uvec4(0u, 1u, 0u, 0u);
    uvec2 code;
    if (parameters.mode == SP_DECODE_MODE_CODES) {
        code = uvec2(input_words[2u * item], input_words[2u * item + 1u]);
    } else {
        uvec2 value = vertex_value(item);
        code = sp_vertex_code(codec, value);
        uint tuple_index = sp_vertex_tuple(codec, value);
        record.vertex.x = tuple_index;
        record.vertex.y = sp_vertex_padding_is_zero(codec, value) ? 1u : 0u;
        record.joints = sp_lut_joints(codec, tuple_index);
    }
    decode_into(code, record);
    records[item] = record;
}
