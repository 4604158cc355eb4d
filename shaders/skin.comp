#version 460
// skin.comp - compute skinning: one invocation per vertex and instance, skinned positions
// written to a buffer (3 floats per vertex, instance after instance) for later passes.
#extension GL_GOOGLE_include_directive : require

#include "skin_common.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = SP_BINDING_OUTPUT) writeonly buffer SkinnedPositions { float skinned_positions[]; };

void main()
{
    uint v = gl_GlobalInvocationID.x;
    uint instance = gl_GlobalInvocationID.y;
    if (v >= skin_vertex_count()) return;
    vec4 weights;
    uvec4 joints;
    skin_fetch_influences(v, weights, joints);
    vec3 p = skin_position(skin_bind_position(v), weights, joints, instance);
    uint out_index = 3u * (instance * skin_vertex_count() + v);
    skinned_positions[out_index] = p.x;
    skinned_positions[out_index + 1u] = p.y;
    skinned_positions[out_index + 2u] = p.z;
}
