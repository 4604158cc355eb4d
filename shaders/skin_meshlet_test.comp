#version 460
// skin_meshlet_test.comp - skin.mesh's body (skin_meshlet.glsl) as a compute shader, for
// devices without VK_EXT_mesh_shader (lavapipe in CI): same workgroup layout (x = meshlet,
// y = instance, 32 threads), same shared memory and barrier, but the mesh outputs go to one
// SpMeshletOutputRecord per workgroup, which tests/shaders/harness_meshshader.c compares with C.
#extension GL_GOOGLE_include_directive : require

#include "skinpack_gpu_layout.h"

layout(std430, set = 0, binding = SP_BINDING_OUTPUT) writeonly buffer MeshletOutputs { SpMeshletOutputRecord outputs[]; };

// The record of this workgroup; skin.meshlet_extra.y is the meshlet count.
#define SKIN_MESHLET_RECORD outputs[gl_WorkGroupID.y * skin.meshlet_extra.y + gl_WorkGroupID.x]

// Macro parameters end in _ so that they never capture a field name (.clip, .world).
// SetMeshOutputsEXT is called by every thread, as in the mesh shader; one of them writes.
#define SKIN_MESHLET_SET_OUTPUTS(vertex_count_, triangle_count_)                                           \
    {                                                                                                      \
        if (gl_LocalInvocationIndex == 0u)                                                                 \
            SKIN_MESHLET_RECORD.counts = uvec4(vertex_count_, triangle_count_, 0u, 0u);                    \
    }
#define SKIN_MESHLET_VERTEX(i_, clip_, world_)                                                             \
    {                                                                                                      \
        SKIN_MESHLET_RECORD.clip[i_] = clip_;                                                              \
        SKIN_MESHLET_RECORD.world[i_] = vec4(world_, 0.0);                                                 \
    }
#define SKIN_MESHLET_TRIANGLE(t_, corners_, culled_)                                                       \
    {                                                                                                      \
        SKIN_MESHLET_RECORD.triangles[t_] = uvec4(corners_, culled_ ? 1u : 0u);                            \
    }

#include "skin_meshlet.glsl"
