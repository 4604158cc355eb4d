// skin_meshlet.glsl - the body of skin.mesh: skins one meshlet per workgroup with the meshlet's
// joint palette and decides which of its triangles (or the whole meshlet) face away. It is one
// source for two shaders: skin.mesh (the shipped mesh shader) and skin_meshlet_test.comp (a
// compute emulation that lavapipe, which has no VK_EXT_mesh_shader, runs in CI). Everything
// stage-specific goes through three output hooks, macros the including shader defines first:
//
//   SKIN_MESHLET_SET_OUTPUTS(vertex_count, triangle_count)  once per workgroup, uniform flow;
//                                                           (0, 0) when the meshlet is culled
//   SKIN_MESHLET_VERTEX(i, clip, world)     meshlet vertex i: clip-space vec4, world-space vec3
//   SKIN_MESHLET_TRIANGLE(t, corners, culled)  triangle t: local corner indices (uvec3), and
//                                              whether it faces away (bool)
//
// Group layout: gl_WorkGroupID.x = meshlet, .y = instance; SP_MESH_SHADER_GROUP_SIZE threads.
//
// Joints come from the meshlet: the vertex's local tuple (u8) indexes the meshlet's tuple LUT of
// palette indices (u8), which index its joint palette (u16) - the thesis' "common influences"
// idea, generalised to any joint set. Weight codes still come from the global vertex words
// (their tuple-index bits are simply not used here).
//
// Back faces are culled twice, as in the thesis (section 5, "per meshlet triangle culling"):
//   * whole meshlet: its normal cone (sp_meshlet.cone_*) is only valid for the bind pose, so it
//     is used when the meshlet is rigid (one palette joint) and moved by that joint's matrix -
//     exact for rotation + translation bones;
//   * every triangle: the sign of the determinant of its clip-space (x, y, w) rows, which is
//     twice its signed NDC area times w0 w1 w2 (Olano and Greer), so the rasteriser never
//     sees back faces. Front faces are counter-clockwise after the host's y-flipped projection,
//     i.e. det < 0; triangles with a vertex behind the eye (w <= 0) are kept.

#ifndef SKIN_MESHLET_GLSL
#define SKIN_MESHLET_GLSL

#if !defined(SKIN_MESHLET_SET_OUTPUTS) || !defined(SKIN_MESHLET_VERTEX) || !defined(SKIN_MESHLET_TRIANGLE)
#error "define SKIN_MESHLET_SET_OUTPUTS, SKIN_MESHLET_VERTEX and SKIN_MESHLET_TRIANGLE before including skin_meshlet.glsl"
#endif

#include "skinpack_gpu_layout.h"

layout(std430, set = 0, binding = SP_BINDING_MESHLETS) readonly buffer Meshlets { uint meshlet_words[]; };
layout(std430, set = 0, binding = SP_BINDING_MESHLET_DATA) readonly buffer MeshletData { uint meshlet_data_words[]; };
#define SP_MESHLET_WORD(i) meshlet_words[i]
#define SP_MESHLET_DATA_WORD(i) meshlet_data_words[i]

#include "skin_common.glsl"

layout(local_size_x = SP_MESH_SHADER_GROUP_SIZE) in;

shared vec4 clip_positions[SP_MESH_SHADER_MAX_VERTICES];

bool meshlet_cone_faces_away(SpMeshlet m, uint instance)
{
    if (m.joint_count != 1u || m.cone.w >= 1.0) return false;
    uint joint = sp_data_u16(skin.meshlet_arrays.w, m.joint_offset);
    uint first_row = 3u * (instance * skin_joints_per_instance() + joint);
    mat3x4 rows = mat3x4(joint_rows[first_row], joint_rows[first_row + 1u], joint_rows[first_row + 2u]);
    vec3 apex = vec4(m.cone_apex, 1.0) * rows + skin_instance_offset(instance);
    vec3 axis = normalize(vec4(m.cone.xyz, 0.0) * rows);
    return dot(normalize(apex - skin.camera.xyz), axis) >= m.cone.w;
}

// Triangle culling from the clip positions of its corners (see the header).
bool triangle_faces_away(vec4 a, vec4 b, vec4 c)
{
    bool in_front = a.w > 0.0 && b.w > 0.0 && c.w > 0.0;
    float det = determinant(mat3(a.xyw, b.xyw, c.xyw));
    return in_front && det >= 0.0;
}

void main()
{
    uint meshlet_index = gl_WorkGroupID.x;
    uint instance = gl_WorkGroupID.y;
    SpMeshlet m = sp_load_meshlet(meshlet_index);
    if (meshlet_cone_faces_away(m, instance)) {
        SKIN_MESHLET_SET_OUTPUTS(0u, 0u);
        return;
    }
    SKIN_MESHLET_SET_OUTPUTS(m.vertex_count, m.triangle_count);
    SpMeshletArrays arrays = SpMeshletArrays(skin.meshlet_arrays.x, skin.meshlet_arrays.y, skin.meshlet_arrays.z,
                                             skin.meshlet_arrays.w, skin.meshlet_extra.x);

    for (uint i = gl_LocalInvocationIndex; i < m.vertex_count; i += SP_MESH_SHADER_GROUP_SIZE) {
        uint v = sp_meshlet_vertex(arrays, m, i);
        vec4 weights;
        uvec4 joints;
        if (VERTEX_FORMAT == SP_VERTEX_FORMAT_PACKED) {
            SpGpuCodec c = skin_codec();
            uint words = sp_codec_words_per_vertex(c);
            uvec2 value = sp_vertex_value(c, vertex_words[words * v], words == 2u ? vertex_words[words * v + 1u] : 0u);
            weights = skin_decode_weights(c, sp_vertex_code(c, value));
            joints = sp_meshlet_joints(arrays, m, i, sp_codec_influences(c));
        } else {
            skin_fetch_influences(v, weights, joints);
        }
        vec3 p = skin_position(skin_bind_position(v), weights, joints, instance) + skin_instance_offset(instance);
        vec4 clip = skin.view_projection * vec4(p, 1.0);
        clip_positions[i] = clip;
        SKIN_MESHLET_VERTEX(i, clip, p);
    }
    barrier();

    for (uint t = gl_LocalInvocationIndex; t < m.triangle_count; t += SP_MESH_SHADER_GROUP_SIZE) {
        uvec3 corner = sp_meshlet_triangle(arrays, m, t);
        bool culled = triangle_faces_away(clip_positions[corner.x], clip_positions[corner.y], clip_positions[corner.z]);
        SKIN_MESHLET_TRIANGLE(t, corner, culled);
    }
}

#endif // SKIN_MESHLET_GLSL
