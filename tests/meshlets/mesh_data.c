/* mesh_data.c - see mesh_data.h. */
#include "mesh_data.h"

#include <skinpack.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int read_all(FILE* f, void* data, size_t bytes)
{
    return fread(data, 1, bytes, f) == bytes;
}

static int fail(const char* path, const char* why, FILE* f)
{
    fprintf(stderr, "mesh_data: %s: %s\n", path, why);
    if (f)
        fclose(f);
    return 0;
}

/* Blender leaves some vertices without any deform group; the codecs need one influence. */
static void bind_unweighted(mesh_data* m)
{
    for (size_t v = 0; v < m->vertex_count; ++v) {
        float sum = 0.0f;
        for (size_t s = 0; s < m->input_influences; ++s)
            sum += m->input_weights[v * m->input_influences + s];
        if (sum > 0.0f)
            continue;
        m->input_joints[v * m->input_influences] = 0;
        m->input_weights[v * m->input_influences] = 1.0f;
        m->unweighted_vertices++;
    }
}

int mesh_data_load(const char* path, size_t influences, mesh_data* m)
{
    memset(m, 0, sizeof(*m));
    FILE* f = fopen(path, "rb");
    if (!f)
        return fail(path, "cannot open", NULL);
    char magic[4];
    uint32_t header[5];
    if (!read_all(f, magic, 4) || memcmp(magic, "SPMD", 4) != 0 || !read_all(f, header, sizeof(header)) || header[0] != 1)
        return fail(path, "not an SPMD v1 file", f);
    m->vertex_count = header[1];
    m->index_count = header[2];
    m->joint_count = header[3];
    m->input_influences = header[4];
    if (m->input_influences < 1 || m->input_influences > SP_MAX_INPUT_INFLUENCES || m->index_count % 3 != 0)
        return fail(path, "bad header", f);
    size_t v = m->vertex_count, k = m->input_influences;
    m->positions = malloc(v * 3 * sizeof(float));
    m->indices = malloc(m->index_count * sizeof(uint32_t));
    m->input_joints = malloc(v * k * sizeof(uint16_t));
    m->input_weights = malloc(v * k * sizeof(float));
    m->influences = influences;
    m->joints = malloc(v * influences * sizeof(uint16_t));
    m->weights = malloc(v * influences * sizeof(float));
    if (!m->positions || !m->indices || !m->input_joints || !m->input_weights || !m->joints || !m->weights) {
        mesh_data_free(m);
        return fail(path, "out of memory", f);
    }
    if (!read_all(f, m->positions, v * 3 * sizeof(float)) || !read_all(f, m->indices, m->index_count * sizeof(uint32_t)) ||
        !read_all(f, m->input_joints, v * k * sizeof(uint16_t)) || !read_all(f, m->input_weights, v * k * sizeof(float))) {
        mesh_data_free(m);
        return fail(path, "truncated", f);
    }
    fclose(f);
    bind_unweighted(m);
    sp_prepare_stats stats;
    sp_result r = sp_prepare_influences(m->input_joints, m->input_weights, v, k, m->joint_count, influences, 1e-3f,
                                        m->joints, m->weights, NULL, &stats);
    if (r != SP_OK) {
        fprintf(stderr, "mesh_data: %s: sp_prepare_influences: %s (vertex %zu)\n", path, sp_result_string(r),
                stats.error_vertex);
        mesh_data_free(m);
        return 0;
    }
    return 1;
}

static size_t used_slots(const float* weights, size_t k)
{
    size_t used = 0;
    for (size_t s = 0; s < k; ++s)
        used += weights[s] > 0.0f;
    return used;
}

int mesh_data_decode_compressed(mesh_data* m)
{
    size_t v = m->vertex_count, k = m->input_influences;
    size_t scratch_size = sp_compress_scratch_bound(v, k);
    uint32_t* words = malloc(v * 2 * sizeof(uint32_t) + 1);
    uint16_t* lut = malloc(v * SP_MAX_INFLUENCES * sizeof(uint16_t) + 1);
    void* scratch = malloc(scratch_size + 1);
    m->decoded_joints = malloc(v * SP_MAX_INFLUENCES * sizeof(uint16_t) + 1);
    m->decoded_weights = malloc(v * SP_MAX_INFLUENCES * sizeof(float) + 1);
    int ok = 0;
    sp_compress_options options;
    sp_compress_options_default(&options);
    sp_compressed_skin skin;
    if (!words || !lut || !scratch || !m->decoded_joints || !m->decoded_weights) {
        fprintf(stderr, "mesh_data: compress and decode: out of memory\n");
        goto done;
    }
    sp_result r = sp_compress_skin(m->input_joints, m->input_weights, v, k, m->joint_count, &options, words, lut, NULL, NULL,
                             &skin, scratch, scratch_size);
    if (r == SP_OK)
        r = sp_decompress_skin(&skin.codec, words, v, skin.tuple_bits, lut, skin.lut_size, skin.joint_count,
                               m->decoded_joints, m->decoded_weights, NULL);
    if (r == SP_OK) {
        m->decoded_influences = skin.influences;
        m->decoded_weight_bits = skin.weight_bits;
        m->decoded_tuple_bits = skin.tuple_bits;
        m->decoded_max_error = skin.codec.max_error;
        m->decoded_lut_size = skin.lut_size;
        m->lost_influences = 0;
        for (size_t i = 0; i < v; ++i) /* a zero weight encodes as zero: decoding never adds a slot */
            m->lost_influences += used_slots(m->weights + i * m->influences, m->influences) -
                                  used_slots(m->decoded_weights + i * skin.influences, skin.influences);
        ok = 1;
    } else
        fprintf(stderr, "mesh_data: compress and decode: %s\n", sp_result_string(r));
done:
    free(words);
    free(lut);
    free(scratch);
    return ok;
}

void mesh_data_free(mesh_data* m)
{
    free(m->decoded_joints);
    free(m->decoded_weights);
    free(m->positions);
    free(m->indices);
    free(m->input_joints);
    free(m->input_weights);
    free(m->joints);
    free(m->weights);
    memset(m, 0, sizeof(*m));
}
