#version 460
// skin.vert - linear blend skinning in the vertex shader (the Paper's Table 3 setup). Vertex
// attributes are pulled from storage buffers by gl_VertexIndex; gl_InstanceIndex picks the
// instance's joint matrices and grid cell.
#extension GL_GOOGLE_include_directive : require

#include "skin_common.glsl"

layout(location = 0) out vec3 out_world_position;

void main()
{
    uint v = uint(gl_VertexIndex);
    uint instance = uint(gl_InstanceIndex);
    vec4 weights;
    uvec4 joints;
    skin_fetch_influences(v, weights, joints);
    vec3 p = skin_position(skin_bind_position(v), weights, joints, instance) + skin_instance_offset(instance);
    out_world_position = p;
    gl_Position = skin.view_projection * vec4(p, 1.0);
}
