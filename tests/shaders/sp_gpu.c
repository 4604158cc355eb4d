/* sp_gpu.c - see sp_gpu.h. */
#define _POSIX_C_SOURCE 199309L
#include "sp_gpu.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

SpGpuCodec sp_gpu_codec_fill(const sp_codec* codec, uint32_t tuple_bits, uint32_t words_per_vertex,
                             uint32_t joint_bytes, uint32_t lut_size, uint32_t joint_count)
{
    SpGpuCodec g;
    memset(&g, 0, sizeof(g));
    g.config = (sp_gpu_uvec4){codec->method, codec->influences, codec->bits, tuple_bits};
    g.packing = (sp_gpu_uvec4){words_per_vertex, joint_bytes, lut_size, joint_count};
    g.n_scale = (sp_gpu_uvec4){(uint32_t)codec->n, (uint32_t)(codec->n >> 32), (uint32_t)codec->scale,
                               (uint32_t)(codec->scale >> 32)};
    g.max_code = (sp_gpu_uvec4){(uint32_t)codec->max_code, (uint32_t)(codec->max_code >> 32), 0, 0};
    g.component_bits = (sp_gpu_uvec4){codec->component_bits[0], codec->component_bits[1], codec->component_bits[2],
                                      codec->component_bits[3]};
    uint32_t axis_low[3] = {0}, axis_high[3] = {0};
    float factors[4] = {0};
    if (codec->method == SP_METHOD_ANY) {
        /* Axis i = 2..K spans [0, 1/i] with q_i samples: w_i = x_i / (i (q_i - 1)). */
        for (uint32_t a = 0; a + 1 < codec->influences; ++a) {
            axis_low[a] = (uint32_t)codec->axis_samples[a];
            axis_high[a] = (uint32_t)(codec->axis_samples[a] >> 32);
            factors[a] = (float)(1.0 / ((double)(a + 2) * ((double)codec->axis_samples[a] - 1.0)));
        }
    } else if (codec->scale) {
        factors[0] = (float)(1.0 / (double)codec->scale);
    }
    g.axis_low = (sp_gpu_uvec4){axis_low[0], axis_low[1], axis_low[2], 0};
    g.axis_high = (sp_gpu_uvec4){axis_high[0], axis_high[1], axis_high[2], 0};
    g.factors = (sp_gpu_vec4){factors[0], factors[1], factors[2], factors[3]};
    return g;
}

vkx_specialization sp_gpu_specialization(uint32_t vertex_format, const SpGpuCodec* codec)
{
    vkx_specialization spec = {vertex_format, SP_SPEC_RUNTIME, SP_SPEC_RUNTIME, SP_SPEC_RUNTIME};
    if (codec && vertex_format == SP_VERTEX_FORMAT_PACKED) {
        spec.method = codec->config.x;
        spec.influences = codec->config.y;
        spec.decoder = SP_GPU_CODEC_IS_NARROW(*codec) ? SP_SPEC_DECODER_NARROW
                       : SP_GPU_CODEC_ROWS32(*codec)  ? SP_SPEC_DECODER_WIDE_ROWS32
                                                      : SP_SPEC_DECODER_WIDE;
    }
    return spec;
}

static void read_exact(FILE* file, void* data, size_t size, const char* path)
{
    if (size && fread(data, 1, size, file) != size) {
        fprintf(stderr, "FAIL: %s is truncated\n", path);
        exit(1);
    }
}

void sp_skin_mesh_load(const char* path, sp_skin_mesh* mesh)
{
    memset(mesh, 0, sizeof(*mesh));
    FILE* file = fopen(path, "rb");
    if (!file) {
        fprintf(stderr, "FAIL: cannot open mesh file %s (the export fixture writes it)\n", path);
        exit(1);
    }
    char magic[8];
    uint32_t header[5];
    read_exact(file, magic, 8, path);
    read_exact(file, header, sizeof(header), path);
    if (memcmp(magic, "SPSKIN01", 8) != 0 || header[3] != SP_MAX_INPUT_INFLUENCES || header[0] == 0 || header[2] == 0) {
        fprintf(stderr, "FAIL: %s is not an SPSKIN01 mesh with 8 influences\n", path);
        exit(1);
    }
    mesh->vertex_count = header[0];
    mesh->triangle_count = header[1];
    mesh->joint_count = header[2];
    mesh->influences = header[3];
    mesh->pose_count = header[4];
    size_t v = mesh->vertex_count, t = mesh->triangle_count, j = mesh->joint_count;
    mesh->positions = malloc(v * 3 * sizeof(float));
    mesh->indices = malloc((t ? t : 1) * 3 * sizeof(uint32_t));
    mesh->joints = malloc(v * 8 * sizeof(uint16_t));
    mesh->weights = malloc(v * 8 * sizeof(float));
    mesh->pose_rows = malloc((mesh->pose_count ? mesh->pose_count : 1) * j * 12 * sizeof(float));
    read_exact(file, mesh->positions, v * 3 * sizeof(float), path);
    read_exact(file, mesh->indices, t * 3 * sizeof(uint32_t), path);
    read_exact(file, mesh->joints, v * 8 * sizeof(uint16_t), path);
    read_exact(file, mesh->weights, v * 8 * sizeof(float), path);
    read_exact(file, mesh->pose_rows, mesh->pose_count * j * 12 * sizeof(float), path);
    read_exact(file, mesh->name, sizeof(mesh->name), path);
    mesh->name[sizeof(mesh->name) - 1] = 0;
    fclose(file);
    for (size_t i = 0; i < t * 3; ++i)
        if (mesh->indices[i] >= mesh->vertex_count) {
            fprintf(stderr, "FAIL: %s: index %zu out of range\n", path, i);
            exit(1);
        }
}

void sp_skin_mesh_free(sp_skin_mesh* mesh)
{
    free(mesh->positions);
    free(mesh->indices);
    free(mesh->joints);
    free(mesh->weights);
    free(mesh->pose_rows);
    memset(mesh, 0, sizeof(*mesh));
}

void sp_reference_skin(const float* positions, size_t vertex_count, const uint16_t* joints, const float* weights,
                       size_t influences, const float* matrix_rows, float* out)
{
    for (size_t v = 0; v < vertex_count; ++v) {
        const float* p = positions + 3 * v;
        double result[3] = {0, 0, 0};
        for (size_t slot = 0; slot < influences; ++slot) {
            double w = weights[v * influences + slot];
            const float* m = matrix_rows + 12 * (size_t)joints[v * influences + slot];
            for (int r = 0; r < 3; ++r)
                result[r] += w * ((double)m[4 * r] * p[0] + (double)m[4 * r + 1] * p[1] + (double)m[4 * r + 2] * p[2] +
                                  (double)m[4 * r + 3]);
        }
        for (int r = 0; r < 3; ++r) out[3 * v + r] = (float)result[r];
    }
}

double sp_seconds(void)
{
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return (double)now.tv_sec + 1e-9 * (double)now.tv_nsec;
}

/* The shaders read sp_meshlet records as SP_MESHLET_WORDS raw words at these offsets. */
#include <stddef.h>
_Static_assert(sizeof(sp_meshlet) == SP_MESHLET_WORDS * 4, "sp_meshlet size changed: update skinpack_gpu_layout.h");
_Static_assert(offsetof(sp_meshlet, vertex_offset) == SP_MESHLET_WORD_VERTEX_OFFSET * 4, "sp_meshlet layout");
_Static_assert(offsetof(sp_meshlet, triangle_offset) == SP_MESHLET_WORD_TRIANGLE_OFFSET * 4, "sp_meshlet layout");
_Static_assert(offsetof(sp_meshlet, joint_offset) == SP_MESHLET_WORD_JOINT_OFFSET * 4, "sp_meshlet layout");
_Static_assert(offsetof(sp_meshlet, tuple_offset) == SP_MESHLET_WORD_TUPLE_OFFSET * 4, "sp_meshlet layout");
_Static_assert(offsetof(sp_meshlet, vertex_count) == SP_MESHLET_WORD_COUNTS * 4, "sp_meshlet layout");
_Static_assert(offsetof(sp_meshlet, triangle_count) == SP_MESHLET_WORD_COUNTS * 4 + 2, "sp_meshlet layout");
_Static_assert(offsetof(sp_meshlet, joint_count) == SP_MESHLET_WORD_PALETTE * 4, "sp_meshlet layout");
_Static_assert(offsetof(sp_meshlet, tuple_count) == SP_MESHLET_WORD_PALETTE * 4 + 2, "sp_meshlet layout");
_Static_assert(offsetof(sp_meshlet, center) == SP_MESHLET_WORD_CENTER * 4, "sp_meshlet layout");
_Static_assert(offsetof(sp_meshlet, radius) == (SP_MESHLET_WORD_CENTER + 3) * 4, "sp_meshlet layout");
_Static_assert(offsetof(sp_meshlet, cone_apex) == SP_MESHLET_WORD_CONE_APEX * 4, "sp_meshlet layout");
_Static_assert(offsetof(sp_meshlet, cone_axis) == SP_MESHLET_WORD_CONE_AXIS * 4, "sp_meshlet layout");
_Static_assert(offsetof(sp_meshlet, cone_cutoff) == (SP_MESHLET_WORD_CONE_AXIS + 3) * 4, "sp_meshlet layout");
/* The push-constant block is exactly the 128 bytes every device guarantees. */
_Static_assert(sizeof(SpSkinParameters) == 128, "SpSkinParameters must stay 128 bytes");
_Static_assert(sizeof(SpGpuCodec) == 8 * 16, "SpGpuCodec is 8 vec4s");
_Static_assert(sizeof(SpMeshletOutputRecord) == (1 + 2 * SP_MESH_SHADER_MAX_VERTICES + SP_MESH_SHADER_MAX_TRIANGLES) * 16,
               "SpMeshletOutputRecord is vec4s only, no padding");

sp_result sp_gpu_meshlets_build(const uint32_t* indices, size_t index_count, const float* positions,
                                size_t vertex_count, size_t position_stride, const uint16_t* joints,
                                const float* weights, size_t influences, sp_gpu_meshlets* out)
{
    memset(out, 0, sizeof(*out));
    sp_meshlet_options options;
    sp_meshlet_options_default(&options);
    sp_meshlet_sizes sizes;
    sp_meshlets_bound(index_count, vertex_count, influences, &options, &sizes);
    sp_meshlet_buffers* a = &out->arrays;
    a->meshlets = malloc(sizes.meshlets * sizeof(sp_meshlet));
    a->vertices = malloc(sizes.vertices * sizeof(uint32_t));
    a->vertex_tuples = malloc(sizes.vertices);
    a->triangles = malloc(sizes.triangles * 3);
    a->joints = malloc(sizes.joints * sizeof(uint16_t));
    a->tuples = malloc(sizes.tuples * influences);
    a->capacity = sizes;
    void* scratch = malloc(sizes.scratch_bytes ? sizes.scratch_bytes : 1);
    sp_result result = sp_build_meshlets(indices, index_count, positions, vertex_count, position_stride, joints,
                                         weights, influences, &options, a, scratch, sizes.scratch_bytes, &out->stats);
    free(scratch);
    if (result != SP_OK) return result;

    const sp_meshlet_stats* s = &out->stats;
    size_t bytes[5] = {s->vertex_count * 4, s->vertex_count, s->triangle_count * 3, s->joint_count * 2,
                       s->tuple_count * influences};
    const void* arrays[5] = {a->vertices, a->vertex_tuples, a->triangles, a->joints, a->tuples};
    for (int i = 0; i < 5; ++i) {
        out->offsets[i] = (uint32_t)out->data_words;
        out->data_words += (bytes[i] + 3) / 4;
    }
    out->data = calloc(out->data_words + 1, sizeof(uint32_t));
    for (int i = 0; i < 5; ++i) memcpy(out->data + out->offsets[i], arrays[i], bytes[i]);
    return SP_OK;
}

void sp_gpu_meshlets_free(sp_gpu_meshlets* meshlets)
{
    sp_meshlet_buffers* a = &meshlets->arrays;
    free(a->meshlets);
    free(a->vertices);
    free(a->vertex_tuples);
    free(a->triangles);
    free(a->joints);
    free(a->tuples);
    free(meshlets->data);
    memset(meshlets, 0, sizeof(*meshlets));
}

void sp_gpu_camera(float aspect, const float eye[3], const float target[3], float out[16])
{
    float f[3] = {target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]};
    float fl = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (int i = 0; i < 3; ++i) f[i] /= fl;
    float up[3] = {0, 0, 1};
    float s[3] = {f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2], f[0] * up[1] - f[1] * up[0]};
    float sl = sqrtf(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (int i = 0; i < 3; ++i) s[i] /= sl;
    float u[3] = {s[1] * f[2] - s[2] * f[1], s[2] * f[0] - s[0] * f[2], s[0] * f[1] - s[1] * f[0]};
    float view[16] = {s[0], u[0], -f[0], 0, s[1], u[1], -f[1], 0, s[2], u[2], -f[2], 0,
                      -(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]), -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]),
                      f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2], 1};
    float near = 0.05f * fl, far = 4.0f * fl, t = 1.0f / tanf(0.5f * 1.0471976f);
    float projection[16] = {t / aspect, 0, 0, 0, 0, -t, 0, 0, 0, 0, far / (near - far), -1, 0, 0, near * far / (near - far), 0};
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) {
            float sum = 0;
            for (int k = 0; k < 4; ++k) sum += projection[k * 4 + r] * view[c * 4 + k];
            out[c * 4 + r] = sum;
        }
}

void sp_gpu_default_skin_build(const sp_skin_mesh* mesh, sp_gpu_default_skin* out)
{
    size_t n = mesh->vertex_count;
    out->words = malloc(n * 2 * sizeof(uint32_t));
    out->lut = malloc(n * 4 * sizeof(uint16_t));
    out->lut_bytes = malloc(n * 4 * sizeof(uint16_t));
    out->joints = malloc(n * 4 * sizeof(uint16_t));
    out->weights = malloc(n * 4 * sizeof(float));
    size_t scratch_size = sp_compress_scratch_bound(n, 8);
    void* scratch = malloc(scratch_size);
    sp_compress_options options;
    sp_compress_options_default(&options);
    sp_compressed_skin* skin = &out->skin;
    if (sp_compress_skin(mesh->joints, mesh->weights, n, 8, mesh->joint_count, &options, out->words, out->lut, NULL, NULL,
                         skin, scratch, scratch_size) != SP_OK ||
        sp_decompress_skin(&skin->codec, out->words, n, skin->tuple_bits, out->lut, skin->lut_size, mesh->joint_count,
                           out->joints, out->weights, NULL) != SP_OK)
        vkx_fail("%s: compress/decompress failed", mesh->name);
    free(scratch);
    sp_gpu_lut_bytes(out->lut, skin->lut_size * skin->influences, skin->joint_bytes, out->lut_bytes);
}

void sp_gpu_lut_bytes(const uint16_t* lut, size_t entries, uint32_t joint_bytes, uint8_t* out)
{
    for (size_t e = 0; e < entries; ++e) {
        out[joint_bytes * e] = (uint8_t)lut[e];
        if (joint_bytes == 2) out[2 * e + 1] = (uint8_t)(lut[e] >> 8);
    }
}

SpGpuCodec sp_gpu_skin_codec(const sp_compressed_skin* skin, uint32_t joint_count)
{
    return sp_gpu_codec_fill(&skin->codec, skin->tuple_bits, skin->words_per_vertex, skin->joint_bytes,
                             (uint32_t)skin->lut_size, joint_count);
}

void sp_gpu_default_skin_free(sp_gpu_default_skin* packed)
{
    free(packed->words);
    free(packed->lut);
    free(packed->lut_bytes);
    free(packed->joints);
    free(packed->weights);
}
