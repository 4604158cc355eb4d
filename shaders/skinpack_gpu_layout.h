/*
 * skinpack_gpu_layout.h - the memory layout shared by the shaders and the C host code.
 *
 * This one file is included by GLSL (where the Vulkan GLSL compiler defines VULKAN) and by C
 * (tests/shaders, tests/bench), so the codec parameter block, the descriptor bindings and the
 * meshlet record offsets exist exactly once. Library constants (method ids, limits) come from
 * native/include/skinpack.h through the generated skinpack_constants.glsl instead.
 *
 * Only 16-byte vectors are used, so std140 (uniform) and std430 (storage) agree with the plain
 * C struct: no padding rules to get wrong.
 */
#ifndef SKINPACK_GPU_LAYOUT_H
#define SKINPACK_GPU_LAYOUT_H

#ifdef VULKAN
#define SP_GPU_UVEC4 uvec4
#define SP_GPU_VEC4 vec4
#define SP_GPU_MAT4 mat4
#else
#include <stdint.h>
typedef struct sp_gpu_uvec4 { uint32_t x, y, z, w; } sp_gpu_uvec4;
typedef struct sp_gpu_vec4 { float x, y, z, w; } sp_gpu_vec4;
#define SP_GPU_UVEC4 sp_gpu_uvec4
#define SP_GPU_VEC4 sp_gpu_vec4
#define SP_GPU_MAT4 sp_gpu_mat4
typedef struct sp_gpu_mat4 { float columns[16]; } sp_gpu_mat4; /* column-major, like GLSL */
#endif

/*
 * Everything a shader needs to decode one compressed skin (docs/format.md). 64-bit library
 * values are split into (low, high) 32-bit halves. The host fills it from an sp_codec with
 * sp_gpu_codec_fill() (tests/shaders/sp_gpu.c); never by hand.
 */
#ifdef VULKAN
struct SpGpuCodec {
#else
typedef struct SpGpuCodec {
#endif
    SP_GPU_UVEC4 config;         /* method (SP_METHOD_*), K, weight code bits, tuple bits */
    SP_GPU_UVEC4 packing;        /* words per vertex (1|2), LUT bytes per joint (1|2), LUT entries, joint count */
    SP_GPU_UVEC4 n_scale;        /* n (m or N) low, high; grid denominator s low, high */
    SP_GPU_UVEC4 max_code;       /* largest code low, high; OSS: rows-or-layers limit (see fill), 0 */
    SP_GPU_UVEC4 component_bits; /* Fixed/Cube/POT: bits of each stored weight, in code order */
    SP_GPU_UVEC4 axis_low;       /* Any: q2, q3, q4 (low halves) */
    SP_GPU_UVEC4 axis_high;      /* Any: q2, q3, q4 (high halves) */
    SP_GPU_VEC4 factors;         /* 1/s (grid methods); Any: x, y, z = 1/(i (q_i - 1)) for i = 2, 3, 4 */
#ifdef VULKAN
};
#else
} SpGpuCodec;
#endif

/*
 * Push constants of the skinning shaders (skin.vert, skin.comp, skin.mesh): exactly the 128 bytes
 * every Vulkan device guarantees. "Instance" below is the instance within the draw or dispatch
 * (it selects the joint matrices); counts.w is added to it for the position on the grid.
 */
#ifdef VULKAN
struct SpSkinParameters {
#else
typedef struct SpSkinParameters {
#endif
    SP_GPU_MAT4 view_projection;
    SP_GPU_UVEC4 counts;         /* vertex count, joints per instance, grid columns, first grid cell of the draw */
    SP_GPU_VEC4 camera;          /* camera position (skin.mesh cone culling), grid spacing */
    SP_GPU_UVEC4 meshlet_arrays; /* skin.mesh: word offsets of vertices, vertex_tuples, triangles, joints */
    SP_GPU_UVEC4 meshlet_extra;  /* skin.mesh: word offset of tuples, meshlet count, 0, 0 */
#ifdef VULKAN
};
#else
} SpSkinParameters;
#endif

/*
 * When the 32-bit decoder of skinpack_decode.glsl is exact for a codec: codes, the grid
 * denominator and the Any axis sample counts fit in 32 bits, and for OSS the closed forms'
 * intermediates do too. Those stay below 9 u(k) + 9 (K = 4) and 4 s(j) + 4 (K = 3), where u(k)
 * and s(j) never exceed the largest code; the K = 3 limit also keeps N^2 + N + 1 < 2^32.
 * One macro for GLSL (sp_codec_is_narrow) and C (choosing the specialised pipeline).
 */
#define SP_OSS_NARROW_MAX_CODE_K4 477218587u  /* floor((2^32 - 9) / 9) */
#define SP_OSS_NARROW_MAX_CODE_K3 1073741822u /* floor((2^32 - 4) / 4) - 1 */
#define SP_GPU_CODEC_IS_NARROW(c)                                                                          \
    ((c).max_code.y == 0u && (c).n_scale.w == 0u &&                                                        \
     ((c).config.x == SP_METHOD_ANY ? ((c).axis_high.x | (c).axis_high.y | (c).axis_high.z) == 0u          \
      : (c).config.x != SP_METHOD_OSS || (c).config.y < 3u                                                 \
          || (c).max_code.x <= ((c).config.y == 4u ? SP_OSS_NARROW_MAX_CODE_K4 : SP_OSS_NARROW_MAX_CODE_K3)))

/*
 * Specialisation constants of the skinning shaders. 0 picks the vertex format; 1-3 optionally
 * fix the codec's method, K and decoder so the compiler drops every other decoder (a GPU
 * allocates registers for the worst path of a shader, used or not). SP_SPEC_RUNTIME leaves the
 * choice to the uniform codec block.
 */
#define SP_SPEC_RUNTIME 0xffffffffu
#define SP_SPEC_DECODER_NARROW 0u
#define SP_SPEC_DECODER_WIDE 1u        /* 64-bit decoder, 64-bit row step */
#define SP_SPEC_DECODER_WIDE_ROWS32 2u /* 64-bit layer step, 32-bit row step: SP_GPU_CODEC_ROWS32 */

/* OSS K = 4 codes whose in-layer indices are below S(N) < 2^32: the 64-bit decoder may take the
 * row step in 32 bits (codes of up to 46 bits). 113511 is the largest N with S(N) < 2^32. */
#define SP_OSS_LAYER32_MAX_N 113511u
#define SP_GPU_CODEC_ROWS32(c)                                                                             \
    ((c).config.x == SP_METHOD_OSS && (c).config.y == 4u && (c).n_scale.y == 0u && (c).n_scale.x <= SP_OSS_LAYER32_MAX_N)

/* Descriptor set 0 of every skinpack shader (all storage buffers except the codec block). */
#define SP_BINDING_CODEC 0        /* uniform SpGpuCodec */
#define SP_BINDING_VERTEX_WORDS 1 /* uint[]: words per vertex x vertex count (format.md section 4) */
#define SP_BINDING_TUPLE_LUT 2    /* uint[]: the tuple LUT bytes (u8 or u16 joints), zero-padded to 4 bytes */
#define SP_BINDING_JOINT_MATRICES 3 /* vec4[]: 3 rows of a 3x4 affine matrix per joint, per instance */
#define SP_BINDING_POSITIONS 4    /* float[]: 3 floats per bind-pose vertex */
#define SP_BINDING_OUTPUT 5       /* decode.comp: SpDecodedRecord[]; skin.comp: float[] 3 per vertex;
                                     skin_meshlet_test.comp: SpMeshletOutputRecord[] */
#define SP_BINDING_BASELINE 6     /* uint[]: baseline weights and joints (SP_VERTEX_FORMAT_*) */
#define SP_BINDING_MESHLETS 7     /* uint[]: sp_meshlet records, SP_MESHLET_WORDS words each */
#define SP_BINDING_MESHLET_DATA 8 /* uint[]: the meshlet byte arrays, see SP_MESHLET_DATA_* below */
#define SP_BINDING_COUNT 9

/*
 * How per-vertex blend attributes are stored (specialisation constant 0 of the skinning
 * shaders). Baselines keep four joints as u8 and four weights uncompressed, like the Paper's
 * Table 3; PACKED is ours: one or two 32-bit words plus the tuple LUT.
 */
#define SP_VERTEX_FORMAT_FLOAT32 0 /* 4 x f32 weights, then 4 x u8 joints: 5 words per vertex */
#define SP_VERTEX_FORMAT_UNORM16 1 /* 4 x unorm16 weights, 4 x u8 joints: 3 words per vertex */
#define SP_VERTEX_FORMAT_UNORM8 2  /* 4 x unorm8 weights, 4 x u8 joints: 2 words per vertex */
#define SP_VERTEX_FORMAT_PACKED 3  /* skinpack vertex words + tuple LUT */

/* decode.comp push constant "mode": what the input words are. */
#define SP_DECODE_MODE_CODES 0    /* two words per item: a bare 64-bit weight code (low, high) */
#define SP_DECODE_MODE_VERTICES 1 /* packed vertex words (tuple index and code) + tuple LUT */
#define SP_DECODE_MODE_MESHLETS 2 /* meshlet vertices via palette + local tuple LUT, triangle corners */

/* One decode.comp result: 20 words. q is exact (64-bit, split); for Any it holds x_i. */
#ifdef VULKAN
struct SpDecodedRecord {
#else
typedef struct SpDecodedRecord {
#endif
    SP_GPU_UVEC4 q_low;   /* q1..q4 (low halves); Any: x2..x4 in y, z, w */
    SP_GPU_UVEC4 q_high;  /* q1..q4 (high halves) */
    SP_GPU_VEC4 weights;  /* w1..w4 as floats */
    SP_GPU_UVEC4 joints;  /* vertex mode: the joint of each weight slot from the tuple LUT */
    SP_GPU_UVEC4 vertex;  /* x: tuple index (vertex mode) or source vertex (meshlet mode),
                             y: 1 when the padding bits were zero; meshlet mode: z, w = palette, LUT size */
#ifdef VULKAN
};
#else
} SpDecodedRecord;
#endif

/*
 * Meshlets: the shaders read sp_meshlet records (native/include/skinpack.h) as raw words, so
 * the host uploads sp_build_meshlets' output unchanged. Word offsets inside one record
 * (tests check them against offsetof):
 */
#define SP_MESHLET_WORDS 18
#define SP_MESHLET_WORD_VERTEX_OFFSET 0
#define SP_MESHLET_WORD_TRIANGLE_OFFSET 1
#define SP_MESHLET_WORD_JOINT_OFFSET 2
#define SP_MESHLET_WORD_TUPLE_OFFSET 3
#define SP_MESHLET_WORD_COUNTS 4      /* vertex_count | triangle_count << 16 */
#define SP_MESHLET_WORD_PALETTE 5     /* joint_count | tuple_count << 16 */
#define SP_MESHLET_WORD_CENTER 7      /* 3 floats, then radius */
#define SP_MESHLET_WORD_CONE_APEX 11  /* 3 floats */
#define SP_MESHLET_WORD_CONE_AXIS 14  /* 3 floats, then cone_cutoff */

/*
 * What skin.mesh is declared for: sp_meshlet_options defaults (64 vertices, 124 triangles; the
 * host builds meshlets with them and checks that they fit) and one 32-thread workgroup.
 */
#define SP_MESH_SHADER_MAX_VERTICES 64
#define SP_MESH_SHADER_MAX_TRIANGLES 124
#define SP_MESH_SHADER_GROUP_SIZE 32

/*
 * skin_meshlet_test.comp: what one skin.mesh workgroup (meshlet m, instance i) would emit,
 * written to record i * meshlet_count + m so that lavapipe, which has no mesh shaders, can
 * check the shared body (shaders/skin_meshlet.glsl) against C. Entries past the counts are
 * left as the host filled them.
 */
#ifdef VULKAN
struct SpMeshletOutputRecord {
#else
typedef struct SpMeshletOutputRecord {
#endif
    SP_GPU_UVEC4 counts;                                   /* vertex count, triangle count (0, 0: meshlet culled), 0, 0 */
    SP_GPU_VEC4 clip[SP_MESH_SHADER_MAX_VERTICES];         /* gl_Position of each meshlet vertex */
    SP_GPU_VEC4 world[SP_MESH_SHADER_MAX_VERTICES];        /* world position (xyz), 0 */
    SP_GPU_UVEC4 triangles[SP_MESH_SHADER_MAX_TRIANGLES];  /* local corners (xyz), gl_CullPrimitiveEXT (w: 0 | 1) */
#ifdef VULKAN
};
#else
} SpMeshletOutputRecord;
#endif

/*
 * The five sp_meshlet_buffers arrays - vertices (u32), vertex_tuples (u8), triangles (u8 x 3),
 * joints (u16), tuples (u8 x K) - are concatenated into the SP_BINDING_MESHLET_DATA buffer,
 * each starting on a word; SpSkinParameters.meshlet_arrays/meshlet_extra give the offsets.
 */

#endif /* SKINPACK_GPU_LAYOUT_H */
