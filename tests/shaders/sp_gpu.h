/*
 * sp_gpu.h - host-side helpers shared by the shader harness and the GPU benchmark: the codec
 * parameter block for the shaders, the exported mesh files, and the C reference skinning.
 */
#ifndef SKINPACK_SP_GPU_H
#define SKINPACK_SP_GPU_H

#include <stddef.h>
#include <stdint.h>

#include "skinpack.h"
#include "skinpack_gpu_layout.h"
#include "vk_context.h"

/* The shaders' view of a codec and of the vertex words / LUT that go with it. */
SpGpuCodec sp_gpu_codec_fill(const sp_codec* codec, uint32_t tuple_bits, uint32_t words_per_vertex,
                             uint32_t joint_bytes, uint32_t lut_size, uint32_t joint_count);

/* sp_gpu_codec_fill for a compressed skin of joint_count joints. */
SpGpuCodec sp_gpu_skin_codec(const sp_compressed_skin* skin, uint32_t joint_count);
/* The tuple LUT as the shaders read it: joint_bytes (1 or 2) bytes an entry, little-endian. */
void sp_gpu_lut_bytes(const uint16_t* lut, size_t entries, uint32_t joint_bytes, uint8_t* out);

/* Specialisation for a vertex format; with a codec (PACKED), also its method, K and decoder,
 * so the pipeline holds only the decoder that codec needs. codec NULL: all runtime. */
vkx_specialization sp_gpu_specialization(uint32_t vertex_format, const SpGpuCodec* codec);

/*
 * A skinned mesh exported by export_skin_mesh.py (little-endian):
 *   char magic[8] = "SPSKIN01"; u32 vertex_count, triangle_count, joint_count, influences (8), pose_count
 *   f32 positions[3 V]; u32 indices[3 T]; u16 joints[8 V]; f32 weights[8 V]
 *   f32 pose_rows[pose_count][joint_count][12]   rest-to-pose 3x4 matrices, row-major, mesh space
 *   char name[64]
 */
typedef struct sp_skin_mesh {
    char name[64];
    uint32_t vertex_count, triangle_count, joint_count, influences, pose_count;
    float* positions;
    uint32_t* indices;
    uint16_t* joints;
    float* weights;
    float* pose_rows;
} sp_skin_mesh;

/* Loads a mesh file; exits with a FAIL message when it is missing or malformed. */
void sp_skin_mesh_load(const char* path, sp_skin_mesh* mesh);
void sp_skin_mesh_free(sp_skin_mesh* mesh);

/* C reference of skin_common.glsl's skin_position: K influences per vertex (weights and joints
 * dense, K each), 3x4 row-major matrices; double accumulation. out: 3 floats per vertex. */
void sp_reference_skin(const float* positions, size_t vertex_count, const uint16_t* joints, const float* weights,
                       size_t influences, const float* matrix_rows, float* out);

/* A mesh's skin compressed with the default options (OSS, K = 4, one 32-bit word a vertex), its
 * tuple LUT as the shaders read it, and what the C decoder makes of it, to compare against. */
typedef struct sp_gpu_default_skin {
    sp_compressed_skin skin;
    uint32_t* words;    /* skin.words_per_vertex per vertex */
    uint16_t* lut;      /* skin.lut_size x K joints */
    uint8_t* lut_bytes; /* the same, skin.joint_bytes each, little-endian */
    uint16_t* joints;   /* decoded: K per vertex */
    float* weights;
} sp_gpu_default_skin;

/* Compresses and decodes mesh's skin; exits with a FAIL message when the library refuses. */
void sp_gpu_default_skin_build(const sp_skin_mesh* mesh, sp_gpu_default_skin* out);
void sp_gpu_default_skin_free(sp_gpu_default_skin* packed);

/* Column-major view-projection of a perspective camera at eye looking at target, z up, 60 degree
 * vertical field of view, near/far at 0.05/4 x the distance; Vulkan clip space (y down, depth
 * 0..1). Shared by the benchmark and the mesh-shader test so both see the same camera. */
void sp_gpu_camera(float aspect, const float eye[3], const float target[3], float out[16]);

/* Meshlets of a skin at the default limits (skin.mesh's 64 vertices / 124 triangles), with the
 * library's arrays and the same arrays packed into one word buffer as skinpack_gpu_layout.h
 * describes (offsets[a] = word offset of vertices, vertex_tuples, triangles, joints, tuples). */
typedef struct sp_gpu_meshlets {
    sp_meshlet_buffers arrays;
    sp_meshlet_stats stats;
    uint32_t* data;
    size_t data_words;
    uint32_t offsets[5];
} sp_gpu_meshlets;

sp_result sp_gpu_meshlets_build(const uint32_t* indices, size_t index_count, const float* positions,
                                size_t vertex_count, size_t position_stride, const uint16_t* joints,
                                const float* weights, size_t influences, sp_gpu_meshlets* out);
void sp_gpu_meshlets_free(sp_gpu_meshlets* meshlets);

/* Seconds since an arbitrary start (CLOCK_MONOTONIC). */
double sp_seconds(void);

#endif
