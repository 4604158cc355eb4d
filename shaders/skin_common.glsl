// skin_common.glsl - vertex fetch and linear blend skinning shared by skin.vert, skin.comp and
// skin.mesh. Blend attributes are pulled from storage buffers (by vertex index), so one shader
// serves the uncompressed baselines and skinpack words; specialisation constant 0 picks the
// format and the driver folds the other branches away.

#ifndef SKIN_COMMON_GLSL
#define SKIN_COMMON_GLSL

#include "skinpack_gpu_layout.h"

layout(constant_id = 0) const uint VERTEX_FORMAT = SP_VERTEX_FORMAT_PACKED;
layout(constant_id = 1) const uint SPEC_METHOD = SP_SPEC_RUNTIME;     // SP_METHOD_* or runtime
layout(constant_id = 2) const uint SPEC_INFLUENCES = SP_SPEC_RUNTIME; // K or runtime
layout(constant_id = 3) const uint SPEC_DECODER = SP_SPEC_RUNTIME;    // SP_SPEC_DECODER_* or runtime

layout(std140, set = 0, binding = SP_BINDING_CODEC) uniform CodecBlock { SpGpuCodec codec; };
layout(std430, set = 0, binding = SP_BINDING_VERTEX_WORDS) readonly buffer VertexWords { uint vertex_words[]; };
layout(std430, set = 0, binding = SP_BINDING_TUPLE_LUT) readonly buffer TupleLut { uint tuple_lut_words[]; };
layout(std430, set = 0, binding = SP_BINDING_JOINT_MATRICES) readonly buffer JointMatrices { vec4 joint_rows[]; };
layout(std430, set = 0, binding = SP_BINDING_POSITIONS) readonly buffer Positions { float bind_positions[]; };
layout(std430, set = 0, binding = SP_BINDING_BASELINE) readonly buffer Baseline { uint baseline_words[]; };

layout(push_constant) uniform SkinPushConstants { SpSkinParameters skin; };

uint skin_vertex_count() { return skin.counts.x; }
uint skin_joints_per_instance() { return skin.counts.y; }

#define SP_TUPLE_LUT_WORD(i) tuple_lut_words[i]
#include "skinpack_decode.glsl"

// The codec block with the specialised fields replaced by constants.
SpGpuCodec skin_codec()
{
    SpGpuCodec c = codec;
    if (SPEC_METHOD != SP_SPEC_RUNTIME) c.config.x = SPEC_METHOD;
    if (SPEC_INFLUENCES != SP_SPEC_RUNTIME) c.config.y = SPEC_INFLUENCES;
    return c;
}

vec4 skin_decode_weights(SpGpuCodec c, uvec2 code)
{
    bool narrow = SPEC_DECODER == SP_SPEC_RUNTIME ? sp_codec_is_narrow(c) : SPEC_DECODER == SP_SPEC_DECODER_NARROW;
    bool rows32 = SPEC_DECODER == SP_SPEC_RUNTIME ? SP_GPU_CODEC_ROWS32(c) : SPEC_DECODER == SP_SPEC_DECODER_WIDE_ROWS32;
    uvec4 q_low, q_high;
    return narrow ? sp_decode_weights32(c, code.x, q_low) : sp_decode_weights64_rows(c, code, rows32, q_low, q_high);
}

uvec4 skin_unpack_joints8(uint word)
{
    return uvec4(word & 0xffu, (word >> 8) & 0xffu, (word >> 16) & 0xffu, word >> 24);
}

// Weights (weight order for PACKED) and joints of vertex v.
void skin_fetch_influences(uint v, out vec4 weights, out uvec4 joints)
{
    if (VERTEX_FORMAT == SP_VERTEX_FORMAT_FLOAT32) {
        uint base = 5u * v;
        weights = uintBitsToFloat(uvec4(baseline_words[base], baseline_words[base + 1u],
                                        baseline_words[base + 2u], baseline_words[base + 3u]));
        joints = skin_unpack_joints8(baseline_words[base + 4u]);
    } else if (VERTEX_FORMAT == SP_VERTEX_FORMAT_UNORM16) {
        uint base = 3u * v;
        weights = vec4(unpackUnorm2x16(baseline_words[base]), unpackUnorm2x16(baseline_words[base + 1u]));
        joints = skin_unpack_joints8(baseline_words[base + 2u]);
    } else if (VERTEX_FORMAT == SP_VERTEX_FORMAT_UNORM8) {
        weights = unpackUnorm4x8(baseline_words[2u * v]);
        joints = skin_unpack_joints8(baseline_words[2u * v + 1u]);
    } else {
        SpGpuCodec c = skin_codec();
        uint words = sp_codec_words_per_vertex(c);
        uvec2 value = sp_vertex_value(c, vertex_words[words * v], words == 2u ? vertex_words[words * v + 1u] : 0u);
        weights = skin_decode_weights(c, sp_vertex_code(c, value));
        joints = sp_lut_joints(c, sp_vertex_tuple(c, value));
    }
}

vec3 skin_bind_position(uint v)
{
    return vec3(bind_positions[3u * v], bind_positions[3u * v + 1u], bind_positions[3u * v + 2u]);
}

// Linear blend skinning: sum_i w_i (M_i p) with M_i the 3x4 rest-to-pose matrix of joint i.
// The blended matrix is built first (the usual shader form: 12 FMAs per influence, one
// matrix-vector product). Zero weights contribute nothing, whatever their joint.
vec3 skin_position(vec3 p, vec4 weights, uvec4 joints, uint instance)
{
    uint base = instance * skin_joints_per_instance();
    vec4 row0 = vec4(0.0), row1 = vec4(0.0), row2 = vec4(0.0);
    for (uint slot = 0u; slot < 4u; ++slot) {
        uint first_row = 3u * (base + joints[slot]);
        row0 += weights[slot] * joint_rows[first_row];
        row1 += weights[slot] * joint_rows[first_row + 1u];
        row2 += weights[slot] * joint_rows[first_row + 2u];
    }
    vec4 h = vec4(p, 1.0);
    return vec3(dot(row0, h), dot(row1, h), dot(row2, h));
}

// Graphics paths: instances stand on a grid in the xy plane (the meshes are z-up).
vec3 skin_instance_offset(uint instance)
{
    uint cell = skin.counts.w + instance;
    uint columns = max(skin.counts.z, 1u);
    return vec3(float(cell % columns), float(cell / columns), 0.0) * skin.camera.w;
}

#endif // SKIN_COMMON_GLSL
