/* cli_common.c - decoding and accounting shared by the glTF commands (see cli_common.h). */
#include "cli_common.h"

#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static int fail(char* err, size_t err_size, const char* format, ...) {
    va_list args;
    va_start(args, format);
    vsnprintf(err, err_size, format, args);
    va_end(args);
    return -1;
}

static int decode_arrays(const gltf_packed_skin* packed, const uint32_t* words, size_t vertex_count,
                         uint32_t words_per_vertex, size_t primitive_vertex_count, const uint16_t* lut, size_t lut_size,
                         size_t skin_joint_count, cli_decoded_skin* out, char* err, size_t err_size) {
    memset(out, 0, sizeof(*out));
    /* Every format rule is the library's (sp_validate_packed); this only passes what the file says. */
    sp_packed_primitive primitive;
    memset(&primitive, 0, sizeof(primitive));
    sp_packed_params* p = &primitive.params;
    p->method = packed->method;
    p->influences = packed->influences;
    p->joint_count = packed->joint_count;
    p->weight_bits = packed->weight_bits;
    p->tuple_bits = packed->tuple_bits;
    p->n = packed->n;
    p->axis_sample_count = packed->axis_sample_count;
    for (uint32_t i = 0; i < packed->axis_sample_count && i < SP_MAX_INFLUENCES - 1; ++i)
        p->axis_samples[i] = packed->axis_samples[i];
    p->has_max_error = isfinite(packed->max_error);
    p->max_error = p->has_max_error ? packed->max_error : 0;
    primitive.words = words;
    primitive.vertex_count = vertex_count;
    primitive.words_per_vertex = words_per_vertex;
    primitive.primitive_vertex_count = primitive_vertex_count;
    primitive.lut = lut;
    primitive.lut_size = lut_size;
    primitive.lut_components = packed->influences;
    primitive.lut_component_bytes = sp_joint_bytes(packed->joint_count); /* gltf_packed_sizes checked the type */
    primitive.skin_joint_count = skin_joint_count;

    uint32_t k = packed->influences;
    out->joints = (uint16_t*)malloc(vertex_count * k * sizeof(uint16_t) + 1);
    out->weights = (float*)malloc(vertex_count * k * sizeof(float) + 1);
    if (!out->joints || !out->weights) {
        cli_decoded_skin_free(out);
        return fail(err, err_size, "out of memory");
    }
    sp_validation report;
    if (sp_validate_packed(&primitive, out->joints, out->weights, &report) != SP_OK) {
        cli_decoded_skin_free(out);
        sp_format_validation(&report, err, err_size);
        return -1;
    }
    out->codec = report.codec;
    out->vertex_count = vertex_count;
    out->lut_size = lut_size;
    out->influences = k;
    out->words_per_vertex = words_per_vertex;
    out->joint_bytes = primitive.lut_component_bytes;
    return 0;
}

int cli_decode_packed_arrays(const gltf_packed_skin* packed, const uint32_t* words, size_t vertex_count,
                             uint32_t words_per_vertex, const uint16_t* lut, size_t lut_size,
                             size_t skin_joint_count, cli_decoded_skin* out, char* err, size_t err_size) {
    return decode_arrays(packed, words, vertex_count, words_per_vertex, vertex_count, lut, lut_size, skin_joint_count,
                         out, err, err_size);
}

int cli_decode_packed(const gltf_doc* doc, size_t mesh, size_t primitive, const gltf_packed_skin* packed,
                      cli_decoded_skin* out, char* err, size_t err_size) {
    size_t vertex_count = 0, lut_size = 0;
    uint32_t words_per_vertex = 0;
    memset(out, 0, sizeof(*out));
    if (gltf_packed_sizes(doc, packed, &vertex_count, &words_per_vertex, &lut_size, err, err_size)) return -1;
    uint32_t* words = (uint32_t*)malloc(vertex_count * words_per_vertex * sizeof(uint32_t));
    uint16_t* lut = (uint16_t*)malloc(lut_size * packed->influences * sizeof(uint16_t));
    int rc = -1;
    if (!words || !lut)
        fail(err, err_size, "out of memory");
    else if (gltf_read_packed(doc, packed, words, lut, err, err_size) == 0) {
        size_t primitive_vertices = gltf_primitive_vertex_count(doc, mesh, primitive);
        rc = decode_arrays(packed, words, vertex_count, words_per_vertex, primitive_vertices ? primitive_vertices : vertex_count,
                           lut, lut_size, gltf_mesh_joint_count(doc, mesh), out, err, err_size);
    }
    free(words);
    free(lut);
    return rc;
}

int cli_check_meshlets(const gltf_doc* doc, const gltf_packed_skin* packed, size_t vertex_count,
                       cli_meshlet_summary* summary, char* err, size_t err_size) {
    const gltf_packed_meshlets* ml = &packed->meshlets;
    uint32_t k = packed->influences;
    size_t n = 0, n_counts = 0, n_bounds = 0, n_vertices = 0, n_vtuples = 0, n_tri = 0, n_joints = 0, n_tuples = 0;
    memset(summary, 0, sizeof(*summary));
    if (gltf_read_accessor_u32(doc, ml->offsets, GLTF_UNSIGNED_INT, 4, &n, NULL, err, err_size) ||
        gltf_read_accessor_u32(doc, ml->counts, GLTF_UNSIGNED_SHORT, 4, &n_counts, NULL, err, err_size) ||
        gltf_read_accessor_u32(doc, ml->bounds, GLTF_FLOAT, 4, &n_bounds, NULL, err, err_size) ||
        gltf_read_accessor_u32(doc, ml->vertices, GLTF_UNSIGNED_INT, 1, &n_vertices, NULL, err, err_size) ||
        gltf_read_accessor_u32(doc, ml->vertex_tuples, GLTF_UNSIGNED_BYTE, 1, &n_vtuples, NULL, err, err_size) ||
        gltf_read_accessor_u32(doc, ml->triangles, GLTF_UNSIGNED_BYTE, 1, &n_tri, NULL, err, err_size) ||
        gltf_read_accessor_u32(doc, ml->joints, GLTF_UNSIGNED_SHORT, 1, &n_joints, NULL, err, err_size) ||
        gltf_read_accessor_u32(doc, ml->tuples, GLTF_UNSIGNED_BYTE, (int)k, &n_tuples, NULL, err, err_size))
        return -1;
    if (n_counts != n || n_bounds != n || n_vtuples != n_vertices || n_tri % 3)
        return fail(err, err_size, "meshlets: accessor counts disagree");
    uint32_t* offsets = malloc(n * 4 * sizeof(uint32_t));
    uint32_t* counts = malloc(n * 4 * sizeof(uint32_t));
    uint32_t* vertices = malloc(n_vertices * sizeof(uint32_t));
    uint32_t* vtuples = malloc(n_vertices * sizeof(uint32_t));
    uint32_t* triangles = malloc(n_tri * sizeof(uint32_t));
    uint32_t* joints = malloc(n_joints * sizeof(uint32_t));
    uint32_t* tuples = malloc(n_tuples * k * sizeof(uint32_t));
    int rc = -1;
    size_t t;
    if (!offsets || !counts || !vertices || !vtuples || !triangles || !joints || !tuples) {
        fail(err, err_size, "out of memory");
        goto done;
    }
    if (gltf_read_accessor_u32(doc, ml->offsets, GLTF_UNSIGNED_INT, 4, &t, offsets, err, err_size) ||
        gltf_read_accessor_u32(doc, ml->counts, GLTF_UNSIGNED_SHORT, 4, &t, counts, err, err_size) ||
        gltf_read_accessor_u32(doc, ml->vertices, GLTF_UNSIGNED_INT, 1, &t, vertices, err, err_size) ||
        gltf_read_accessor_u32(doc, ml->vertex_tuples, GLTF_UNSIGNED_BYTE, 1, &t, vtuples, err, err_size) ||
        gltf_read_accessor_u32(doc, ml->triangles, GLTF_UNSIGNED_BYTE, 1, &t, triangles, err, err_size) ||
        gltf_read_accessor_u32(doc, ml->joints, GLTF_UNSIGNED_SHORT, 1, &t, joints, err, err_size) ||
        gltf_read_accessor_u32(doc, ml->tuples, GLTF_UNSIGNED_BYTE, (int)k, &t, tuples, err, err_size))
        goto done;
    double joint_sum = 0, tuple_bits_sum = 0;
    size_t entries = 0;
    for (size_t m = 0; m < n; ++m) {
        uint64_t vo = offsets[4 * m], to = offsets[4 * m + 1], jo = offsets[4 * m + 2], uo = offsets[4 * m + 3];
        uint32_t vc = counts[4 * m], tc = counts[4 * m + 1], jc = counts[4 * m + 2], uc = counts[4 * m + 3];
        if (vo + vc > n_vertices || (to + tc) * 3 > n_tri || jo + jc > n_joints || uo + uc > n_tuples || !vc || !tc ||
            !jc || !uc || (ml->max_vertices && vc > ml->max_vertices) ||
            (ml->max_triangles && tc > ml->max_triangles) || (ml->max_joints && jc > ml->max_joints)) {
            fail(err, err_size, "meshlet %zu: offsets or counts out of range", m);
            goto done;
        }
        for (uint32_t i = 0; i < vc; ++i)
            if (vertices[vo + i] >= vertex_count || vtuples[vo + i] >= uc) {
                fail(err, err_size, "meshlet %zu vertex %u: source vertex or local tuple out of range", m, i);
                goto done;
            }
        for (uint32_t i = 0; i < 3 * tc; ++i)
            if (triangles[3 * to + i] >= vc) {
                fail(err, err_size, "meshlet %zu: triangle index %u out of range", m, triangles[3 * to + i]);
                goto done;
            }
        for (uint32_t i = 0; i < jc; ++i)
            if (joints[jo + i] >= packed->joint_count) {
                fail(err, err_size, "meshlet %zu: palette joint %u out of range", m, joints[jo + i]);
                goto done;
            }
        for (uint32_t i = 0; i < uc * k; ++i)
            if (tuples[uo * k + i] >= jc) {
                fail(err, err_size, "meshlet %zu: local tuple entry %u past the palette", m, tuples[uo * k + i]);
                goto done;
            }
        if (vc > summary->max_vertices) summary->max_vertices = vc;
        if (tc > summary->max_triangles) summary->max_triangles = tc;
        if (jc > summary->max_joints) summary->max_joints = jc;
        joint_sum += jc;
        tuple_bits_sum += (double)vc * sp_index_bits(uc);
        entries += vc;
    }
    summary->count = n;
    summary->mean_joints = n ? joint_sum / (double)n : 0;
    summary->local_tuple_bits_mean = entries ? tuple_bits_sum / (double)entries : 0;
    rc = 0;
done:
    free(offsets);
    free(counts);
    free(vertices);
    free(vtuples);
    free(triangles);
    free(joints);
    free(tuples);
    return rc;
}

void cli_decoded_skin_free(cli_decoded_skin* skin) {
    free(skin->joints);
    free(skin->weights);
    skin->joints = NULL;
    skin->weights = NULL;
}

double cli_lut_bits_per_vertex(size_t lut_size, uint32_t influences, uint32_t joint_bytes, size_t vertex_count) {
    return vertex_count ? (double)lut_size * influences * 8.0 * joint_bytes / (double)vertex_count : 0.0;
}

static float weight_of(const uint16_t* joints, const float* weights, size_t k, uint16_t joint) {
    float sum = 0;
    for (size_t i = 0; i < k; ++i)
        if (joints[i] == joint) sum += weights[i];
    return sum;
}

double cli_vertex_difference(const uint16_t* joints_a, const float* weights_a, size_t k_a, const uint16_t* joints_b,
                             const float* weights_b, size_t k_b) {
    double worst = 0;
    for (size_t i = 0; i < k_a; ++i) {
        if (weights_a[i] == 0) continue;
        double d = fabs((double)weight_of(joints_a, weights_a, k_a, joints_a[i]) -
                        (double)weight_of(joints_b, weights_b, k_b, joints_a[i]));
        if (d > worst) worst = d;
    }
    for (size_t i = 0; i < k_b; ++i) {
        if (weights_b[i] == 0) continue;
        double d = fabs((double)weight_of(joints_a, weights_a, k_a, joints_b[i]) -
                        (double)weight_of(joints_b, weights_b, k_b, joints_b[i]));
        if (d > worst) worst = d;
    }
    return worst;
}

size_t cli_file_size(const char* path) {
    struct stat st;
    return stat(path, &st) == 0 ? (size_t)st.st_size : 0;
}

int cli_output_is_binary(const char* path, int input_binary) {
    size_t n = strlen(path);
    if (n >= 4 && strcmp(path + n - 4, ".glb") == 0) return 1;
    if (n >= 5 && strcmp(path + n - 5, ".gltf") == 0) return 0;
    return input_binary;
}

void cli_json_string(FILE* out, const char* s) {
    fputc('"', out);
    for (; *s; ++s) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(out, "\\%c", c);
        else if (c < 0x20)
            fprintf(out, "\\u%04x", c);
        else
            fputc(c, out);
    }
    fputc('"', out);
}

void cli_json_number(FILE* out, double v) {
    if (isfinite(v))
        fprintf(out, "%.9g", v);
    else
        fputs("null", out);
}

void* cli_grow(void* array, size_t* capacity, size_t count, size_t item_size) {
    if (count < *capacity) return array;
    size_t grown = *capacity ? *capacity * 2 : 16;
    void* moved = realloc(array, grown * item_size);
    if (moved) *capacity = grown;
    return moved;
}
