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

/* Builds the baseline words or the skinpack words of one format. Returns 0 if not possible. */
static int build_format(vkx_context* ctx, bench_mesh* m, size_t f, const uint16_t* joints4, const float* weights4)
{
    const format_spec* spec = &FORMATS[f];
    size_t n = m->source.vertex_count;
    SpGpuCodec codec;
    memset(&codec, 0, sizeof(codec));
    if (spec->vertex_format != SP_VERTEX_FORMAT_PACKED) {
        if (m->source.joint_count > 256) return 0; /* the baselines store joints as u8 */
        size_t stride = spec->vertex_format == SP_VERTEX_FORMAT_FLOAT32 ? 5 : spec->vertex_format == SP_VERTEX_FORMAT_UNORM16 ? 3 : 2;
        uint32_t* words = calloc(n * stride, sizeof(uint32_t));
        for (size_t v = 0; v < n; ++v) {
            const float* w = weights4 + 4 * v;
            uint32_t* out = words + stride * v;
            if (spec->vertex_format == SP_VERTEX_FORMAT_FLOAT32) {
                memcpy(out, w, 4 * sizeof(float));
            } else if (spec->vertex_format == SP_VERTEX_FORMAT_UNORM16) {
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
    } else {
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
            for (size_t e = 0; e < entries; ++e) {
                lut_bytes[skin.joint_bytes * e] = (uint8_t)lut[e];
                if (skin.joint_bytes == 2) lut_bytes[2 * e + 1] = (uint8_t)(lut[e] >> 8);
            }
            m->attributes[f] = vkx_upload(ctx, words, n * skin.words_per_vertex * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
            m->luts[f] = vkx_upload(ctx, lut_bytes, entries * skin.joint_bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
            codec = sp_gpu_codec_fill(&skin.codec, skin.tuple_bits, skin.words_per_vertex, skin.joint_bytes,
                                      (uint32_t)skin.lut_size, m->source.joint_count);
            m->bits_per_vertex[f] = 32.0 * skin.words_per_vertex + skin.lut_bits_per_vertex;
        } else {
            fprintf(stderr, "%s: %s: %s\n", m->source.name, spec->name, sp_result_string(result));
        }
        free(words);
        free(lut);
        free(lut_bytes);
        free(scratch);
        if (result != SP_OK) return 0;
    }
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
    VkImageMemoryBarrier to_transfer = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER,
        .srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
        .dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT,
        .oldLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
        .newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
        .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .image = color->image,
        .subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1},
    };
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, NULL, 0,
                         NULL, 1, &to_transfer);
    VkBufferImageCopy region = {
        .imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
        .imageExtent = {width, height, 1},
    };
    vkCmdCopyImageToBuffer(cmd, color->image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback->buffer, 1, &region);
    VkMemoryBarrier to_host = {.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER,
                               .srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT,
                               .dstAccessMask = VK_ACCESS_HOST_READ_BIT};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0, NULL, 0, NULL);
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

typedef enum path { PATH_VERTEX, PATH_COMPUTE, PATH_MESH, PATH_COUNT } path;
static const char* PATH_NAMES[PATH_COUNT] = {"vertex", "compute", "mesh"};

int main(int argc, char** argv)
{
    options opt = {1024, 50, 1920, 1080, 0};
    const char* files[MAX_MESHES];
    uint32_t file_count = 0;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--instances") && i + 1 < argc) opt.instances = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--frames") && i + 1 < argc) opt.frames = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--width") && i + 1 < argc) opt.width = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--height") && i + 1 < argc) opt.height = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--smoke")) opt.smoke = 1;
        else if (argv[i][0] != '-' && file_count < MAX_MESHES) files[file_count++] = argv[i];
        else {
            fprintf(stderr, "usage: %s [--instances N] [--frames F] [--width W] [--height H] [--smoke] MESH.spskin...\n", argv[0]);
            return 2;
        }
    }
    if (file_count == 0 || opt.instances == 0 || opt.frames == 0) {
        fprintf(stderr, "need at least one mesh file, one instance and one frame\n");
        return 2;
    }
    if (opt.instances < file_count) opt.instances = file_count;
    if (opt.frames < 2) opt.frames = 2; /* one warm-up frame + at least one timed */

    vkx_context ctx;
    vkx_create(&ctx, 1);
    vkx_buffer dummy = vkx_buffer_create(&ctx, 256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, 0);
    printf("device: %s, mesh shaders: %s\n", ctx.properties.deviceName, ctx.has_mesh_shader ? "yes" : "no (path skipped)");

    bench_mesh* meshes = calloc(file_count, sizeof(bench_mesh));
    uint64_t vertices_per_frame = 0;
    float extent = 0;
    for (uint32_t i = 0; i < file_count; ++i) {
        meshes[i].instances = opt.instances / file_count + (i < opt.instances % file_count ? 1u : 0u);
        meshes[i].first_instance = i == 0 ? 0 : meshes[i - 1].first_instance + meshes[i - 1].instances;
        load_mesh(&ctx, &meshes[i], files[i], &dummy);
        vertices_per_frame += (uint64_t)meshes[i].source.vertex_count * meshes[i].instances;
        for (size_t c = 0; c < (size_t)meshes[i].source.vertex_count * 3; ++c)
            extent = fmaxf(extent, fabsf(meshes[i].source.positions[c]));
        printf("mesh %s: %u vertices, %u triangles, %u joints, %u instances, %u meshlets\n", meshes[i].source.name,
               meshes[i].source.vertex_count, meshes[i].source.triangle_count, meshes[i].source.joint_count,
               meshes[i].instances, meshes[i].meshlet_count);
    }
    printf("scene: %u instances, %.2f M skinned vertices per frame, %ux%u, %u frames per measurement\n", opt.instances,
           (double)vertices_per_frame / 1e6, opt.width, opt.height, opt.frames);

    SpSkinParameters params;
    memset(&params, 0, sizeof(params));
    uint32_t columns = (uint32_t)ceil(sqrt((double)opt.instances));
    /* A grid cell a little wider than the largest mesh; the camera looks down at the grid from
     * the front so that it fills most of the screen, as the Paper's crowd does. */
    float spacing = 1.25f * extent, size = spacing * (float)columns;
    float eye[3] = {0.5f * (size - spacing), -0.45f * size - 0.5f * spacing, 0.5f * size + 0.5f * spacing};
    float target[3] = {0.5f * (size - spacing), 0.35f * (size - spacing), 0.25f * extent};
    sp_gpu_camera((float)opt.width / (float)opt.height, eye, target, params.view_projection.columns);
    params.camera = (sp_gpu_vec4){eye[0], eye[1], eye[2], spacing};

    VkFormat color_format = VK_FORMAT_R8G8B8A8_UNORM, depth_format = VK_FORMAT_D32_SFLOAT;
    vkx_image color = vkx_image_create(&ctx, opt.width, opt.height, color_format, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT,
                                       VK_IMAGE_ASPECT_COLOR_BIT);
    vkx_image depth = vkx_image_create(&ctx, opt.width, opt.height, depth_format,
                                       VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, VK_IMAGE_ASPECT_DEPTH_BIT);
    vkx_buffer readback = vkx_buffer_create(&ctx, (VkDeviceSize)opt.width * opt.height * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, 1);
    uint8_t* reference_image = calloc((size_t)opt.width * opt.height, 4); /* float32's last frame, per path */
    VkQueryPoolCreateInfo query_info = {
        .sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO,
        .queryType = VK_QUERY_TYPE_TIMESTAMP,
        .queryCount = 2 * opt.frames,
    };
    VkQueryPool queries;
    VKX_CHECK(vkCreateQueryPool(ctx.device, &query_info, NULL, &queries));

    double float_ms[PATH_COUNT] = {0};
    printf("\n%-8s %-8s %12s %10s %12s\n", "path", "format", "bits/vertex", "ms/frame", "vs float32");
    for (int p = 0; p < PATH_COUNT; ++p) {
        if (p == PATH_MESH && !ctx.has_mesh_shader) continue;
        for (size_t f = 0; f < FORMAT_COUNT; ++f) {
            int ok = 1;
            for (uint32_t i = 0; i < file_count; ++i) ok &= meshes[i].available[f];
            if (!ok) {
                printf("%-8s %-8s (not available for every mesh)\n", PATH_NAMES[p], FORMATS[f].name);
                continue;
            }
            /* Pipelines specialised to the codec, as an engine would ship them. All meshes of a
             * format share method and K; a mesh needing the other decoder gets runtime choice. */
            vkx_specialization spec = sp_gpu_specialization(FORMATS[f].vertex_format, &meshes[0].codec_blocks[f]);
            for (uint32_t i = 1; i < file_count; ++i) {
                vkx_specialization other = sp_gpu_specialization(FORMATS[f].vertex_format, &meshes[i].codec_blocks[f]);
                if (memcmp(&other, &spec, sizeof(spec)) != 0) spec = sp_gpu_specialization(FORMATS[f].vertex_format, NULL);
            }
            VkPipeline pipeline = p == PATH_COMPUTE ? vkx_compute_pipeline(&ctx, "skin.comp.spv", &spec)
                                  : vkx_graphics_pipeline(&ctx, p == PATH_MESH ? "skin.mesh.spv" : "skin.vert.spv",
                                                          p == PATH_MESH, &spec, color_format, depth_format);
            VkCommandBuffer cmd = vkx_begin(&ctx);
            vkCmdResetQueryPool(cmd, queries, 0, 2 * opt.frames);
            for (uint32_t frame = 0; frame < opt.frames; ++frame) {
                vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries, 2 * frame);
                if (p == PATH_COMPUTE) {
                    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
                    for (uint32_t i = 0; i < file_count; ++i) {
                        bench_mesh* m = &meshes[i];
                        params.counts = (sp_gpu_uvec4){m->source.vertex_count, m->source.joint_count, columns, m->first_instance};
                        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, ctx.pipeline_layout, 0, 1, &m->sets[f], 0, NULL);
                        vkCmdPushConstants(cmd, ctx.pipeline_layout, VK_SHADER_STAGE_ALL, 0, sizeof(params), &params);
                        vkCmdDispatch(cmd, (m->source.vertex_count + 63) / 64, m->instances, 1);
                    }
                    VkMemoryBarrier barrier = {.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER,
                                               .srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT,
                                               .dstAccessMask = VK_ACCESS_SHADER_WRITE_BIT};
                    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1,
                                         &barrier, 0, NULL, 0, NULL);
                } else {
                    VkImageMemoryBarrier to_attachment[2] = {
                        {.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER,
                         .dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                         .oldLayout = VK_IMAGE_LAYOUT_UNDEFINED,
                         .newLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                         .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
                         .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
                         .image = color.image,
                         .subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1}},
                        {.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER,
                         .dstAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                         .oldLayout = VK_IMAGE_LAYOUT_UNDEFINED,
                         .newLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                         .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
                         .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
                         .image = depth.image,
                         .subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1}},
                    };
                    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                                         VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT,
                                         0, 0, NULL, 0, NULL, 2, to_attachment);
                    VkRenderingAttachmentInfo color_attachment = {
                        .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
                        .imageView = color.view,
                        .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                        .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
                        .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
                        .clearValue = {.color = {{0.1f, 0.1f, 0.12f, 1.0f}}},
                    };
                    VkRenderingAttachmentInfo depth_attachment = {
                        .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
                        .imageView = depth.view,
                        .imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                        .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
                        .storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE,
                        .clearValue = {.depthStencil = {1.0f, 0}},
                    };
                    VkRenderingInfo rendering = {
                        .sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
                        .renderArea = {{0, 0}, {opt.width, opt.height}},
                        .layerCount = 1,
                        .colorAttachmentCount = 1,
                        .pColorAttachments = &color_attachment,
                        .pDepthAttachment = &depth_attachment,
                    };
                    vkCmdBeginRendering(cmd, &rendering);
                    VkViewport viewport = {0, 0, (float)opt.width, (float)opt.height, 0, 1};
                    VkRect2D scissor = {{0, 0}, {opt.width, opt.height}};
                    vkCmdSetViewport(cmd, 0, 1, &viewport);
                    vkCmdSetScissor(cmd, 0, 1, &scissor);
                    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
                    for (uint32_t i = 0; i < file_count; ++i) {
                        bench_mesh* m = &meshes[i];
                        params.counts = (sp_gpu_uvec4){m->source.vertex_count, m->source.joint_count, columns, m->first_instance};
                        params.meshlet_arrays = (sp_gpu_uvec4){m->meshlet_offsets[0], m->meshlet_offsets[1],
                                                               m->meshlet_offsets[2], m->meshlet_offsets[3]};
                        params.meshlet_extra = (sp_gpu_uvec4){m->meshlet_offsets[4], m->meshlet_count, 0, 0};
                        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, ctx.pipeline_layout, 0, 1, &m->sets[f], 0, NULL);
                        vkCmdPushConstants(cmd, ctx.pipeline_layout, VK_SHADER_STAGE_ALL, 0, sizeof(params), &params);
                        if (p == PATH_MESH) {
                            if (m->meshlet_count) ctx.draw_mesh_tasks(cmd, m->meshlet_count, m->instances, 1);
                        } else {
                            vkCmdBindIndexBuffer(cmd, m->indices.buffer, 0, VK_INDEX_TYPE_UINT32);
                            vkCmdDrawIndexed(cmd, m->source.triangle_count * 3, m->instances, 0, 0, 0);
                        }
                    }
                    vkCmdEndRendering(cmd);
                }
                vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries, 2 * frame + 1);
            }
            if (p != PATH_COMPUTE) record_readback(cmd, &color, &readback, opt.width, opt.height);
            vkx_submit_and_wait(&ctx, cmd);
            uint64_t* stamps = malloc(2 * opt.frames * sizeof(uint64_t));
            VKX_CHECK(vkGetQueryPoolResults(ctx.device, queries, 0, 2 * opt.frames, 2 * opt.frames * sizeof(uint64_t), stamps,
                                            sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
            double total = 0;
            for (uint32_t frame = 1; frame < opt.frames; ++frame) total += (double)(stamps[2 * frame + 1] - stamps[2 * frame]);
            free(stamps);
            double ms = total * ctx.properties.limits.timestampPeriod * 1e-6 / (double)(opt.frames - 1);
            if (f == 0) float_ms[p] = ms;
            double bits = 0;
            for (uint32_t i = 0; i < file_count; ++i) bits += meshes[i].bits_per_vertex[f] * meshes[i].source.vertex_count;
            uint64_t distinct_vertices = 0;
            for (uint32_t i = 0; i < file_count; ++i) distinct_vertices += meshes[i].source.vertex_count;
            printf("%-8s %-8s %12.1f %10.3f %11.2fx", PATH_NAMES[p], FORMATS[f].name, bits / (double)distinct_vertices, ms,
                   float_ms[p] > 0 ? ms / float_ms[p] : 0.0);
            if (p != PATH_COMPUTE) {
                /* The scene must be on screen, or the graphics timings measure nothing; and every
                 * format must draw (nearly) the float32 picture, or its decoder is wrong. */
                size_t pixels = (size_t)opt.width * opt.height;
                size_t covered = covered_pixels(&readback, opt.width, opt.height);
                if (f == 0) memcpy(reference_image, readback.mapped, pixels * 4);
                size_t differing = 0;
                for (size_t i = 0; i < pixels; ++i)
                    for (int c = 0; c < 3; ++c)
                        if (abs((int)((const uint8_t*)readback.mapped)[4 * i + c] - (int)reference_image[4 * i + c]) >
                            MAX_CHANNEL_DIFFERENCE) {
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
            printf("\n");
            fflush(stdout);
            vkDestroyPipeline(ctx.device, pipeline, NULL);
        }
    }
    if (opt.smoke) printf("smoke run: timings are not meaningful on a CPU driver\n");

    vkDeviceWaitIdle(ctx.device);
    vkDestroyQueryPool(ctx.device, queries, NULL);
    vkx_image_destroy(&ctx, &color);
    vkx_buffer_destroy(&ctx, &readback);
    free(reference_image);
    vkx_image_destroy(&ctx, &depth);
    for (uint32_t i = 0; i < file_count; ++i) {
        bench_mesh* m = &meshes[i];
        vkx_buffer* owned[] = {&m->positions, &m->indices, &m->matrices, &m->skinned, &m->meshlets, &m->meshlet_data};
        for (size_t b = 0; b < sizeof(owned) / sizeof(owned[0]); ++b)
            if (owned[b]->buffer) vkx_buffer_destroy(&ctx, owned[b]);
        for (size_t f = 0; f < FORMAT_COUNT; ++f)
            if (m->available[f]) {
                vkx_buffer_destroy(&ctx, &m->attributes[f]);
                vkx_buffer_destroy(&ctx, &m->luts[f]);
                vkx_buffer_destroy(&ctx, &m->codecs[f]);
            }
        sp_skin_mesh_free(&m->source);
    }
    free(meshes);
    vkx_buffer_destroy(&ctx, &dummy);
    vkx_destroy(&ctx);
    printf("PASS\n");
    return 0;
}
