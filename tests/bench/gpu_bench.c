/*
 * gpu_bench.c - headless Vulkan benchmark of skinning with compressed vs uncompressed blend
 * attributes: the Paper's Table 3 setup (many animated instances, vertex-shader skinning,
 * 1920x1080 target), plus compute skinning and, where VK_EXT_mesh_shader exists, mesh shaders.
 *
 *   skinpack_gpu_bench [--instances N] [--frames F] [--width W] [--height H] [--smoke] MESH.spskin...
 *
 * Meshes come from tests/shaders/export_skin_mesh.py (also its --subdivide copies). Instances
 * are spread round-robin over the meshes; each mesh is one instanced draw (or dispatch). Every
 * instance has its own copy of the joint matrices. Formats, four influences each:
 *   float32 / unorm16 / unorm8 weights + 4 x u8 joints (uncompressed baselines)
 *   oss32, pot32: one 32-bit skinpack word (tuple index + weight code) + tuple LUT
 *   oss48: a 48-bit budget, stored as two 32-bit words
 * Timing: GPU timestamps around each frame (render pass with clear, all draws), first frame
 * dropped as warm-up; the compute path times the skinning dispatches alone. Ratios are to
 * float32 on the same path. --smoke: one frame of each, nothing asserted but completion.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "skinpack.h"
#include "sp_gpu.h"
#include "vk_context.h"

#define MAX_MESHES 16
/* Formats move vertices by at most their quantisation error (below a pixel here), which flips
 * edge pixels and nudges the derivative shading: a pixel "differs" when a channel is off by more
 * than MAX_CHANNEL_DIFFERENCE, and at most MAX_DIFFERING_PIXELS of the covered pixels may. */
#define MAX_CHANNEL_DIFFERENCE 24
#define MAX_DIFFERING_PIXELS 0.1

typedef struct format_spec {
    const char* name;
    uint32_t vertex_format; /* SP_VERTEX_FORMAT_* */
    sp_method method;       /* PACKED only */
    uint32_t vertex_bits;   /* PACKED only: tuple index + weight code budget */
} format_spec;

static const format_spec FORMATS[] = {
    {"float32", SP_VERTEX_FORMAT_FLOAT32, SP_METHOD_OSS, 0},
    {"unorm16", SP_VERTEX_FORMAT_UNORM16, SP_METHOD_OSS, 0},
    {"unorm8", SP_VERTEX_FORMAT_UNORM8, SP_METHOD_OSS, 0},
    {"oss32", SP_VERTEX_FORMAT_PACKED, SP_METHOD_OSS, 32},
    {"pot32", SP_VERTEX_FORMAT_PACKED, SP_METHOD_POT, 32},
    {"oss48", SP_VERTEX_FORMAT_PACKED, SP_METHOD_OSS, 48},
};
#define FORMAT_COUNT (sizeof(FORMATS) / sizeof(FORMATS[0]))

/* One mesh on the GPU in every format. */
typedef struct bench_mesh {
    sp_skin_mesh source;
    uint32_t instances;      /* instances of this mesh */
    uint32_t first_instance; /* its first grid cell */
    vkx_buffer positions, indices, matrices, skinned;
    vkx_buffer attributes[FORMAT_COUNT]; /* baseline words or skinpack vertex words */
    vkx_buffer luts[FORMAT_COUNT];
    vkx_buffer codecs[FORMAT_COUNT];
    SpGpuCodec codec_blocks[FORMAT_COUNT]; /* what codecs[] holds */
    double bits_per_vertex[FORMAT_COUNT]; /* blend attributes incl. the LUT share */
    int available[FORMAT_COUNT];
    VkDescriptorSet sets[FORMAT_COUNT];
    /* meshlets (mesh shader path) */
    vkx_buffer meshlets, meshlet_data;
    uint32_t meshlet_count;
    uint32_t meshlet_offsets[5];
} bench_mesh;

typedef struct options {
    uint32_t instances, frames, width, height;
    int smoke;
} options;

static uint32_t pack_joints8(const uint16_t* joints)
{
    return (uint32_t)joints[0] | (uint32_t)joints[1] << 8 | (uint32_t)joints[2] << 16 | (uint32_t)joints[3] << 24;
}

/* Four weights as unorm integers summing exactly to max (largest-remainder rounding), as
 * exporters store normalised 8- and 16-bit weights: the sum stays 1 and positions do not shrink. */
static void unorm4(const float* w, uint32_t max, uint32_t* q)
{
    double remainder[4];
    uint32_t sum = 0;
    for (int i = 0; i < 4; ++i) {
        double x = fmin(fmax((double)w[i], 0.0), 1.0) * max;
        q[i] = (uint32_t)floor(x);
        remainder[i] = x - q[i];
        sum += q[i];
    }
    while (sum < max) {
        int best = 0;
        for (int i = 1; i < 4; ++i)
            if (remainder[i] > remainder[best]) best = i;
        ++q[best];
        remainder[best] = -1.0;
        ++sum;
    }
}

/* The baseline words of one uncompressed format: 4 weights (float32, unorm16 pairs or unorm8
 * quads) and then 4 x u8 joints per vertex. Returns 0 if not possible. */
static int build_baseline(vkx_context* ctx, bench_mesh* m, size_t f, const uint16_t* joints4, const float* weights4)
{
    uint32_t vertex_format = FORMATS[f].vertex_format;
    size_t n = m->source.vertex_count;
    if (m->source.joint_count > 256) return 0; /* the baselines store joints as u8 */
    size_t stride = vertex_format == SP_VERTEX_FORMAT_FLOAT32 ? 5 : vertex_format == SP_VERTEX_FORMAT_UNORM16 ? 3 : 2;
    uint32_t* words = calloc(n * stride, sizeof(uint32_t));
    for (size_t v = 0; v < n; ++v) {
        const float* w = weights4 + 4 * v;
        uint32_t* out = words + stride * v;
        if (vertex_format == SP_VERTEX_FORMAT_FLOAT32) {
            memcpy(out, w, 4 * sizeof(float));
        } else if (vertex_format == SP_VERTEX_FORMAT_UNORM16) {
            uint32_t q[4];
            unorm4(w, 65535, q);
            out[0] = q[0] | q[1] << 16;
            out[1] = q[2] | q[3] << 16;
        } else {
            uint32_t q[4];
            unorm4(w, 255, q);
            out[0] = q[0] | q[1] << 8 | q[2] << 16 | q[3] << 24;
        }
        out[stride - 1] = pack_joints8(joints4 + 4 * v);
    }
    m->attributes[f] = vkx_upload(ctx, words, n * stride * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    m->luts[f] = vkx_buffer_create(ctx, 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 0);
    m->bits_per_vertex[f] = 32.0 * (double)stride;
    free(words);
    return 1;
}

/* The skinpack vertex words and tuple LUT of one packed format; fills the codec block.
 * Returns 0 if the library refuses the mesh. */
static int build_packed(vkx_context* ctx, bench_mesh* m, size_t f, SpGpuCodec* codec)
{
    const format_spec* spec = &FORMATS[f];
    size_t n = m->source.vertex_count;
    sp_compress_options compress;
    sp_compress_options_default(&compress);
    compress.method = spec->method;
    compress.max_influences = 4;
    compress.vertex_bits = spec->vertex_bits;
    uint32_t* words = malloc(n * 2 * sizeof(uint32_t));
    uint16_t* lut = malloc(n * 4 * sizeof(uint16_t));
    uint8_t* lut_bytes = calloc(n * 8 + 4, 1);
    size_t scratch_size = sp_compress_scratch_bound(n, 8);
    void* scratch = malloc(scratch_size);
    sp_compressed_skin skin;
    sp_result result = sp_compress_skin(m->source.joints, m->source.weights, n, 8, m->source.joint_count, &compress,
                                        words, lut, NULL, NULL, &skin, scratch, scratch_size);
    if (result == SP_OK) {
        size_t entries = skin.lut_size * skin.influences;
        sp_gpu_lut_bytes(lut, entries, skin.joint_bytes, lut_bytes);
        m->attributes[f] = vkx_upload(ctx, words, n * skin.words_per_vertex * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
        m->luts[f] = vkx_upload(ctx, lut_bytes, entries * skin.joint_bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
        *codec = sp_gpu_skin_codec(&skin, m->source.joint_count);
        m->bits_per_vertex[f] = 32.0 * skin.words_per_vertex + skin.lut_bits_per_vertex;
    } else {
        fprintf(stderr, "%s: %s: %s\n", m->source.name, spec->name, sp_result_string(result));
    }
    free(words);
    free(lut);
    free(lut_bytes);
    free(scratch);
    return result == SP_OK;
}

/* Builds the baseline words or the skinpack words of one format, and its codec block (zero
 * for the baselines). Returns 0 if not possible. */
static int build_format(vkx_context* ctx, bench_mesh* m, size_t f, const uint16_t* joints4, const float* weights4)
{
    SpGpuCodec codec;
    memset(&codec, 0, sizeof(codec));
    int built = FORMATS[f].vertex_format == SP_VERTEX_FORMAT_PACKED ? build_packed(ctx, m, f, &codec)
                                                                   : build_baseline(ctx, m, f, joints4, weights4);
    if (!built) return 0;
    m->codec_blocks[f] = codec;
    m->codecs[f] = vkx_upload(ctx, &codec, sizeof(codec), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    return 1;
}

/* Concatenates the meshlet arrays into one word buffer (each array starts on a word). */
static void build_meshlets(vkx_context* ctx, bench_mesh* m, const uint16_t* joints4, const float* weights4)
{
    const sp_skin_mesh* s = &m->source;
    /* The meshlet tuples must have the compressed skin's K (sp_compress_skin keeps
     * min(4, most non-zero influences)), so build them from the influences cut to that K. */
    size_t k = 1;
    for (size_t i = 0; i < (size_t)s->vertex_count * 4; ++i)
        if (weights4[i] > 0 && i % 4 + 1 > k) k = i % 4 + 1;
    uint16_t* joints_k = malloc((size_t)s->vertex_count * k * sizeof(uint16_t));
    float* weights_k = malloc((size_t)s->vertex_count * k * sizeof(float));
    for (size_t v = 0; v < s->vertex_count; ++v)
        for (size_t slot = 0; slot < k; ++slot) {
            joints_k[v * k + slot] = joints4[v * 4 + slot];
            weights_k[v * k + slot] = weights4[v * 4 + slot];
        }
    sp_gpu_meshlets built; /* skin.mesh's limits */
    sp_result result = sp_gpu_meshlets_build(s->indices, (size_t)s->triangle_count * 3, s->positions, s->vertex_count,
                                             3 * sizeof(float), joints_k, weights_k, k, &built);
    if (result != SP_OK) {
        fprintf(stderr, "%s: sp_build_meshlets: %s (mesh-shader path skipped for it)\n", s->name, sp_result_string(result));
    } else {
        memcpy(m->meshlet_offsets, built.offsets, sizeof(built.offsets));
        m->meshlet_data = vkx_upload(ctx, built.data, built.data_words * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
        m->meshlets = vkx_upload(ctx, built.arrays.meshlets, built.stats.meshlet_count * sizeof(sp_meshlet),
                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
        m->meshlet_count = (uint32_t)built.stats.meshlet_count;
    }
    sp_gpu_meshlets_free(&built);
    free(joints_k);
    free(weights_k);
}

static void load_mesh(vkx_context* ctx, bench_mesh* m, const char* path, vkx_buffer* dummy)
{
    sp_skin_mesh_load(path, &m->source);
    const sp_skin_mesh* s = &m->source;
    size_t n = s->vertex_count;
    uint16_t* joints4 = malloc(n * 4 * sizeof(uint16_t));
    float* weights4 = malloc(n * 4 * sizeof(float));
    if (sp_prepare_influences(s->joints, s->weights, n, 8, s->joint_count, 4, 1e-3f, joints4, weights4, NULL, NULL) != SP_OK)
        vkx_fail("%s: sp_prepare_influences failed", path);

    m->positions = vkx_upload(ctx, s->positions, n * 12, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    m->indices = vkx_upload(ctx, s->indices, (size_t)s->triangle_count * 12, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
    /* Each instance gets the exported pose, so every instance reads its own matrices. */
    size_t matrix_floats = (size_t)s->joint_count * 12;
    float* matrices = malloc(matrix_floats * m->instances * sizeof(float));
    for (uint32_t i = 0; i < m->instances; ++i) memcpy(matrices + i * matrix_floats, s->pose_rows, matrix_floats * sizeof(float));
    m->matrices = vkx_upload(ctx, matrices, matrix_floats * m->instances * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    free(matrices);
    m->skinned = vkx_buffer_create(ctx, n * 12 * m->instances, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 0);

    if (ctx->has_mesh_shader) build_meshlets(ctx, m, joints4, weights4);
    for (size_t f = 0; f < FORMAT_COUNT; ++f) {
        m->available[f] = build_format(ctx, m, f, joints4, weights4);
        if (!m->available[f]) continue;
        vkx_buffer* bindings[SP_BINDING_COUNT] = {0};
        bindings[SP_BINDING_CODEC] = &m->codecs[f];
        bindings[SP_BINDING_VERTEX_WORDS] = FORMATS[f].vertex_format == SP_VERTEX_FORMAT_PACKED ? &m->attributes[f] : NULL;
        bindings[SP_BINDING_BASELINE] = FORMATS[f].vertex_format == SP_VERTEX_FORMAT_PACKED ? NULL : &m->attributes[f];
        bindings[SP_BINDING_TUPLE_LUT] = &m->luts[f];
        bindings[SP_BINDING_JOINT_MATRICES] = &m->matrices;
        bindings[SP_BINDING_POSITIONS] = &m->positions;
        bindings[SP_BINDING_OUTPUT] = &m->skinned;
        if (m->meshlet_count) {
            bindings[SP_BINDING_MESHLETS] = &m->meshlets;
            bindings[SP_BINDING_MESHLET_DATA] = &m->meshlet_data;
        }
        m->sets[f] = vkx_descriptor_set(ctx, bindings, dummy);
    }
    free(joints4);
    free(weights4);
}

/* Copies the colour attachment of the last frame into a host-visible buffer. */
static void record_readback(VkCommandBuffer cmd, const vkx_image* color, const vkx_buffer* readback, uint32_t width,
                            uint32_t height)
{
    VkImageMemoryBarrier to_transfer =
        vkx_image_barrier(color, VK_IMAGE_ASPECT_COLOR_BIT, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT,
                          VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, NULL, 0,
                         NULL, 1, &to_transfer);
    VkBufferImageCopy region = {
        .imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
        .imageExtent = {width, height, 1},
    };
    vkCmdCopyImageToBuffer(cmd, color->image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback->buffer, 1, &region);
    vkx_cmd_memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                           VK_ACCESS_HOST_READ_BIT);
}

typedef enum path { PATH_VERTEX, PATH_COMPUTE, PATH_MESH, PATH_COUNT } path;
static const char* PATH_NAMES[PATH_COUNT] = {"vertex", "compute", "mesh"};

/* Everything the measurements share: the device, the meshes, the camera and the targets. */
typedef struct bench {
    options opt;
    vkx_context ctx;
    vkx_buffer dummy; /* bound where a shader has no buffer */
    bench_mesh* meshes;
    uint32_t mesh_count;
    SpSkinParameters params; /* push constants; counts and meshlet arrays change per mesh */
    uint32_t columns;        /* of the instance grid */
    VkFormat color_format, depth_format;
    vkx_image color, depth;
    vkx_buffer readback;
    uint8_t* reference_image; /* float32's last frame, per path */
    VkQueryPool queries;      /* two timestamps per frame */
    double float_ms[PATH_COUNT];
} bench;

/* Returns 0, or the exit status (2) after a usage message. */
static int parse_options(int argc, char** argv, options* opt, const char** files, uint32_t* file_count)
{
    *opt = (options){1024, 50, 1920, 1080, 0};
    *file_count = 0;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--instances") && i + 1 < argc) opt->instances = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--frames") && i + 1 < argc) opt->frames = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--width") && i + 1 < argc) opt->width = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--height") && i + 1 < argc) opt->height = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--smoke")) opt->smoke = 1;
        else if (argv[i][0] != '-' && *file_count < MAX_MESHES) files[(*file_count)++] = argv[i];
        else {
            fprintf(stderr, "usage: %s [--instances N] [--frames F] [--width W] [--height H] [--smoke] MESH.spskin...\n", argv[0]);
            return 2;
        }
    }
    if (*file_count == 0 || opt->instances == 0 || opt->frames == 0) {
        fprintf(stderr, "need at least one mesh file, one instance and one frame\n");
        return 2;
    }
    if (opt->instances < *file_count) opt->instances = *file_count;
    if (opt->frames < 2) opt->frames = 2; /* one warm-up frame + at least one timed */
    return 0;
}

/* Loads every mesh with its share of the instances; returns the largest |coordinate|. */
static float load_meshes(bench* b, const char** files)
{
    const options* opt = &b->opt;
    uint32_t count = b->mesh_count;
    b->meshes = calloc(count, sizeof(bench_mesh));
    uint64_t vertices_per_frame = 0;
    float extent = 0;
    for (uint32_t i = 0; i < count; ++i) {
        bench_mesh* m = &b->meshes[i];
        m->instances = opt->instances / count + (i < opt->instances % count ? 1u : 0u);
        m->first_instance = i == 0 ? 0 : b->meshes[i - 1].first_instance + b->meshes[i - 1].instances;
        load_mesh(&b->ctx, m, files[i], &b->dummy);
        vertices_per_frame += (uint64_t)m->source.vertex_count * m->instances;
        for (size_t c = 0; c < (size_t)m->source.vertex_count * 3; ++c) extent = fmaxf(extent, fabsf(m->source.positions[c]));
        printf("mesh %s: %u vertices, %u triangles, %u joints, %u instances, %u meshlets\n", m->source.name,
               m->source.vertex_count, m->source.triangle_count, m->source.joint_count, m->instances, m->meshlet_count);
    }
    printf("scene: %u instances, %.2f M skinned vertices per frame, %ux%u, %u frames per measurement\n", opt->instances,
           (double)vertices_per_frame / 1e6, opt->width, opt->height, opt->frames);
    return extent;
}

/* A grid cell a little wider than the largest mesh; the camera looks down at the grid from the
 * front so that it fills most of the screen, as the Paper's crowd does. */
static void place_camera(bench* b, float extent)
{
    memset(&b->params, 0, sizeof(b->params));
    b->columns = (uint32_t)ceil(sqrt((double)b->opt.instances));
    float spacing = 1.25f * extent, size = spacing * (float)b->columns;
    float eye[3] = {0.5f * (size - spacing), -0.45f * size - 0.5f * spacing, 0.5f * size + 0.5f * spacing};
    float target[3] = {0.5f * (size - spacing), 0.35f * (size - spacing), 0.25f * extent};
    sp_gpu_camera((float)b->opt.width / (float)b->opt.height, eye, target, b->params.view_projection.columns);
    b->params.camera = (sp_gpu_vec4){eye[0], eye[1], eye[2], spacing};
}

/* The colour and depth attachments, the readback buffer and the timestamp queries. */
static void create_targets(bench* b)
{
    vkx_context* ctx = &b->ctx;
    uint32_t width = b->opt.width, height = b->opt.height;
    b->color_format = VK_FORMAT_R8G8B8A8_UNORM;
    b->depth_format = VK_FORMAT_D32_SFLOAT;
    b->color = vkx_image_create(ctx, width, height, b->color_format, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, VK_IMAGE_ASPECT_COLOR_BIT);
    b->depth = vkx_image_create(ctx, width, height, b->depth_format, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                                VK_IMAGE_ASPECT_DEPTH_BIT);
    b->readback = vkx_buffer_create(ctx, (VkDeviceSize)width * height * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, 1);
    b->reference_image = calloc((size_t)width * height, 4);
    VkQueryPoolCreateInfo query_info = {
        .sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO,
        .queryType = VK_QUERY_TYPE_TIMESTAMP,
        .queryCount = 2 * b->opt.frames,
    };
    VKX_CHECK(vkCreateQueryPool(ctx->device, &query_info, NULL, &b->queries));
}

static int available_for_every_mesh(const bench* b, size_t f)
{
    int ok = 1;
    for (uint32_t i = 0; i < b->mesh_count; ++i) ok &= b->meshes[i].available[f];
    return ok;
}

/* Pipelines specialised to the codec, as an engine would ship them. All meshes of a format
 * share method and K; a mesh needing the other decoder gets runtime choice. */
static VkPipeline create_path_pipeline(bench* b, int p, size_t f)
{
    uint32_t vertex_format = FORMATS[f].vertex_format;
    vkx_specialization spec = sp_gpu_specialization(vertex_format, &b->meshes[0].codec_blocks[f]);
    for (uint32_t i = 1; i < b->mesh_count; ++i) {
        vkx_specialization other = sp_gpu_specialization(vertex_format, &b->meshes[i].codec_blocks[f]);
        if (memcmp(&other, &spec, sizeof(spec)) != 0) spec = sp_gpu_specialization(vertex_format, NULL);
    }
    if (p == PATH_COMPUTE) return vkx_compute_pipeline(&b->ctx, "skin.comp.spv", &spec);
    return vkx_graphics_pipeline(&b->ctx, p == PATH_MESH ? "skin.mesh.spv" : "skin.vert.spv", p == PATH_MESH, &spec,
                                 b->color_format, b->depth_format);
}

/* Binds mesh m's set of format f and pushes its counts (and meshlet arrays for graphics). */
static void bind_mesh(bench* b, VkCommandBuffer cmd, VkPipelineBindPoint bind_point, const bench_mesh* m, size_t f)
{
    SpSkinParameters* params = &b->params;
    params->counts = (sp_gpu_uvec4){m->source.vertex_count, m->source.joint_count, b->columns, m->first_instance};
    if (bind_point == VK_PIPELINE_BIND_POINT_GRAPHICS) {
        params->meshlet_arrays =
            (sp_gpu_uvec4){m->meshlet_offsets[0], m->meshlet_offsets[1], m->meshlet_offsets[2], m->meshlet_offsets[3]};
        params->meshlet_extra = (sp_gpu_uvec4){m->meshlet_offsets[4], m->meshlet_count, 0, 0};
    }
    vkCmdBindDescriptorSets(cmd, bind_point, b->ctx.pipeline_layout, 0, 1, &m->sets[f], 0, NULL);
    vkCmdPushConstants(cmd, b->ctx.pipeline_layout, VK_SHADER_STAGE_ALL, 0, sizeof(*params), params);
}

/* One frame of the compute path: every mesh's skinning dispatch. The barrier orders this
 * frame's writes of the skinned buffers before the next frame's. */
static void record_compute_pass(bench* b, VkCommandBuffer cmd, size_t f, VkPipeline pipeline)
{
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    for (uint32_t i = 0; i < b->mesh_count; ++i) {
        const bench_mesh* m = &b->meshes[i];
        bind_mesh(b, cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m, f);
        vkCmdDispatch(cmd, (m->source.vertex_count + 63) / 64, m->instances, 1);
    }
    vkx_cmd_memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                           VK_ACCESS_SHADER_WRITE_BIT, VK_ACCESS_SHADER_WRITE_BIT);
}

/* Both attachments from whatever they held to attachment layouts (cleared on load). */
static void record_attachment_barrier(bench* b, VkCommandBuffer cmd)
{
    VkImageMemoryBarrier to_attachment[2] = {
        vkx_image_barrier(&b->color, VK_IMAGE_ASPECT_COLOR_BIT, 0, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                          VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL),
        vkx_image_barrier(&b->depth, VK_IMAGE_ASPECT_DEPTH_BIT, 0, VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                          VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL),
    };
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                         VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT, 0, 0,
                         NULL, 0, NULL, 2, to_attachment);
}

/* Begins dynamic rendering into both attachments, cleared, with the full-target viewport. */
static void begin_rendering(bench* b, VkCommandBuffer cmd)
{
    VkRenderingAttachmentInfo color_attachment =
        vkx_cleared_attachment(&b->color, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_ATTACHMENT_STORE_OP_STORE,
                               (VkClearValue){.color = {{0.1f, 0.1f, 0.12f, 1.0f}}});
    VkRenderingAttachmentInfo depth_attachment =
        vkx_cleared_attachment(&b->depth, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_ATTACHMENT_STORE_OP_DONT_CARE,
                               (VkClearValue){.depthStencil = {1.0f, 0}});
    VkRenderingInfo rendering = {
        .sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
        .renderArea = {{0, 0}, {b->opt.width, b->opt.height}},
        .layerCount = 1,
        .colorAttachmentCount = 1,
        .pColorAttachments = &color_attachment,
        .pDepthAttachment = &depth_attachment,
    };
    vkCmdBeginRendering(cmd, &rendering);
    VkViewport viewport = {0, 0, (float)b->opt.width, (float)b->opt.height, 0, 1};
    VkRect2D scissor = {{0, 0}, {b->opt.width, b->opt.height}};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
}

/* One frame of a graphics path: every mesh as one instanced draw (or mesh-task dispatch). */
static void record_graphics_pass(bench* b, VkCommandBuffer cmd, int p, size_t f, VkPipeline pipeline)
{
    record_attachment_barrier(b, cmd);
    begin_rendering(b, cmd);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
    for (uint32_t i = 0; i < b->mesh_count; ++i) {
        const bench_mesh* m = &b->meshes[i];
        bind_mesh(b, cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, m, f);
        if (p == PATH_MESH) {
            if (m->meshlet_count) b->ctx.draw_mesh_tasks(cmd, m->meshlet_count, m->instances, 1);
        } else {
            vkCmdBindIndexBuffer(cmd, m->indices.buffer, 0, VK_INDEX_TYPE_UINT32);
            vkCmdDrawIndexed(cmd, m->source.triangle_count * 3, m->instances, 0, 0, 0);
        }
    }
    vkCmdEndRendering(cmd);
}

/* All frames of one path and format, each between two timestamps, then (graphics) the readback
 * of the last frame; submitted and waited for. */
static void run_frames(bench* b, int p, size_t f, VkPipeline pipeline)
{
    VkCommandBuffer cmd = vkx_begin(&b->ctx);
    vkCmdResetQueryPool(cmd, b->queries, 0, 2 * b->opt.frames);
    for (uint32_t frame = 0; frame < b->opt.frames; ++frame) {
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, b->queries, 2 * frame);
        if (p == PATH_COMPUTE) record_compute_pass(b, cmd, f, pipeline);
        else record_graphics_pass(b, cmd, p, f, pipeline);
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, b->queries, 2 * frame + 1);
    }
    if (p != PATH_COMPUTE) record_readback(cmd, &b->color, &b->readback, b->opt.width, b->opt.height);
    vkx_submit_and_wait(&b->ctx, cmd);
}

/* Mean milliseconds per frame, the first (warm-up) frame dropped. */
static double frame_milliseconds(bench* b)
{
    uint32_t frames = b->opt.frames;
    uint64_t* stamps = malloc(2 * frames * sizeof(uint64_t));
    VKX_CHECK(vkGetQueryPoolResults(b->ctx.device, b->queries, 0, 2 * frames, 2 * frames * sizeof(uint64_t), stamps,
                                    sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    double total = 0;
    for (uint32_t frame = 1; frame < frames; ++frame) total += (double)(stamps[2 * frame + 1] - stamps[2 * frame]);
    free(stamps);
    return total * b->ctx.properties.limits.timestampPeriod * 1e-6 / (double)(frames - 1);
}

/* Blend attribute bits per distinct vertex, over all meshes. */
static double mean_bits_per_vertex(const bench* b, size_t f)
{
    double bits = 0;
    for (uint32_t i = 0; i < b->mesh_count; ++i) bits += b->meshes[i].bits_per_vertex[f] * b->meshes[i].source.vertex_count;
    uint64_t distinct_vertices = 0;
    for (uint32_t i = 0; i < b->mesh_count; ++i) distinct_vertices += b->meshes[i].source.vertex_count;
    return bits / (double)distinct_vertices;
}

/* Pixels that differ from the clear colour (skin.frag never writes the clear colour). */
static size_t covered_pixels(const vkx_buffer* readback, uint32_t width, uint32_t height)
{
    const uint8_t* pixels = readback->mapped;
    const uint8_t clear[4] = {26, 26, 31, 255}; /* (0.1, 0.1, 0.12, 1) in UNORM8 */
    size_t covered = 0;
    for (size_t i = 0; i < (size_t)width * height; ++i)
        covered += abs(pixels[4 * i] - clear[0]) > 1 || abs(pixels[4 * i + 1] - clear[1]) > 1 || abs(pixels[4 * i + 2] - clear[2]) > 1;
    return covered;
}

/* The scene must be on screen, or the graphics timings measure nothing; and every format must
 * draw (nearly) the float32 picture, or its decoder is wrong. float32 (f = 0) is the reference. */
static void check_picture(bench* b, int p, size_t f)
{
    const uint8_t* image = b->readback.mapped;
    size_t pixels = (size_t)b->opt.width * b->opt.height;
    size_t covered = covered_pixels(&b->readback, b->opt.width, b->opt.height);
    if (f == 0) memcpy(b->reference_image, image, pixels * 4);
    size_t differing = 0;
    for (size_t i = 0; i < pixels; ++i)
        for (int c = 0; c < 3; ++c)
            if (abs((int)image[4 * i + c] - (int)b->reference_image[4 * i + c]) > MAX_CHANNEL_DIFFERENCE) {
                ++differing;
                break;
            }
    printf(" %6.1f%% covered, %5.2f%% differ from float32's", 100.0 * (double)covered / (double)pixels,
           100.0 * (double)differing / (double)pixels);
    if (covered == 0) vkx_fail("%s path, %s: nothing was drawn", PATH_NAMES[p], FORMATS[f].name);
    if ((double)differing > MAX_DIFFERING_PIXELS * (double)covered)
        vkx_fail("%s path, %s: the picture differs from float32's in %zu of %zu covered pixels", PATH_NAMES[p],
                 FORMATS[f].name, differing, covered);
}

/* One row of the table: path p with format f. */
static void measure(bench* b, int p, size_t f)
{
    if (!available_for_every_mesh(b, f)) {
        printf("%-8s %-8s (not available for every mesh)\n", PATH_NAMES[p], FORMATS[f].name);
        return;
    }
    VkPipeline pipeline = create_path_pipeline(b, p, f);
    run_frames(b, p, f, pipeline);
    double ms = frame_milliseconds(b);
    if (f == 0) b->float_ms[p] = ms;
    printf("%-8s %-8s %12.1f %10.3f %11.2fx", PATH_NAMES[p], FORMATS[f].name, mean_bits_per_vertex(b, f), ms,
           b->float_ms[p] > 0 ? ms / b->float_ms[p] : 0.0);
    if (p != PATH_COMPUTE) check_picture(b, p, f);
    printf("\n");
    fflush(stdout);
    vkDestroyPipeline(b->ctx.device, pipeline, NULL);
}

static void destroy_mesh(vkx_context* ctx, bench_mesh* m)
{
    vkx_buffer* owned[] = {&m->positions, &m->indices, &m->matrices, &m->skinned, &m->meshlets, &m->meshlet_data};
    for (size_t b = 0; b < sizeof(owned) / sizeof(owned[0]); ++b)
        if (owned[b]->buffer) vkx_buffer_destroy(ctx, owned[b]);
    for (size_t f = 0; f < FORMAT_COUNT; ++f)
        if (m->available[f]) {
            vkx_buffer_destroy(ctx, &m->attributes[f]);
            vkx_buffer_destroy(ctx, &m->luts[f]);
            vkx_buffer_destroy(ctx, &m->codecs[f]);
        }
    sp_skin_mesh_free(&m->source);
}

static void destroy_bench(bench* b)
{
    vkx_context* ctx = &b->ctx;
    vkDeviceWaitIdle(ctx->device);
    vkDestroyQueryPool(ctx->device, b->queries, NULL);
    vkx_image_destroy(ctx, &b->color);
    vkx_buffer_destroy(ctx, &b->readback);
    free(b->reference_image);
    vkx_image_destroy(ctx, &b->depth);
    for (uint32_t i = 0; i < b->mesh_count; ++i) destroy_mesh(ctx, &b->meshes[i]);
    free(b->meshes);
    vkx_buffer_destroy(ctx, &b->dummy);
    vkx_destroy(ctx);
}

int main(int argc, char** argv)
{
    bench b;
    memset(&b, 0, sizeof(b));
    const char* files[MAX_MESHES];
    int status = parse_options(argc, argv, &b.opt, files, &b.mesh_count);
    if (status) return status;

    vkx_create(&b.ctx, 1);
    b.dummy = vkx_buffer_create(&b.ctx, 256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, 0);
    printf("device: %s, mesh shaders: %s\n", b.ctx.properties.deviceName, b.ctx.has_mesh_shader ? "yes" : "no (path skipped)");
    float extent = load_meshes(&b, files);
    place_camera(&b, extent);
    create_targets(&b);

    printf("\n%-8s %-8s %12s %10s %12s\n", "path", "format", "bits/vertex", "ms/frame", "vs float32");
    for (int p = 0; p < PATH_COUNT; ++p) {
        if (p == PATH_MESH && !b.ctx.has_mesh_shader) continue;
        for (size_t f = 0; f < FORMAT_COUNT; ++f) measure(&b, p, f);
    }
    if (b.opt.smoke) printf("smoke run: timings are not meaningful on a CPU driver\n");

    destroy_bench(&b);
    printf("PASS\n");
    return 0;
}
