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

/* The extension's meshlet arrays read from the file, widened or narrowed to what
 * sp_packed_meshlets takes (each accessor's component type bounds its values). */
typedef struct meshlet_arrays {
    uint32_t *offsets, *counts, *vertices, *wide;
    uint8_t *vertex_tuples, *triangles, *tuples;
    uint16_t* joints;
    sp_packed_meshlets view;
} meshlet_arrays;

static void meshlet_arrays_free(meshlet_arrays* a) {
    free(a->offsets);
    free(a->counts);
    free(a->vertices);
    free(a->wide);
    free(a->vertex_tuples);
    free(a->triangles);
    free(a->tuples);
    free(a->joints);
    memset(a, 0, sizeof(*a));
}

/* Reads accessor `index` (component type, components) into a new u32 array; *count elements. */
static uint32_t* read_u32(const gltf_doc* doc, int index, int type, int components, size_t* count, char* err,
                          size_t err_size) {
    if (gltf_read_accessor_u32(doc, index, type, components, count, NULL, err, err_size)) return NULL;
    uint32_t* out = malloc(*count * (size_t)components * sizeof(uint32_t) + 1);
    size_t again;
    if (!out) fail(err, err_size, "out of memory");
    else if (gltf_read_accessor_u32(doc, index, type, components, &again, out, err, err_size)) {
        free(out);
        out = NULL;
    }
    return out;
}

/* The u8 or u16 copy of a u32 array read from an UNSIGNED_BYTE / UNSIGNED_SHORT accessor. */
static void* narrow(const uint32_t* values, size_t n, size_t bytes) {
    unsigned char* out = malloc(n * bytes + 1);
    for (size_t i = 0; out && i < n; ++i) {
        if (bytes == 1) out[i] = (uint8_t)values[i];
        else ((uint16_t*)out)[i] = (uint16_t)values[i];
    }
    return out;
}

/* Only the glTF layer here (accessor types, counts that must agree); every meshlet rule is the
 * library's, checked by sp_validate_packed with the decoded skin. */
static int read_meshlets(const gltf_doc* doc, const gltf_packed_skin* packed, meshlet_arrays* a, char* err,
                         size_t err_size) {
    const gltf_packed_meshlets* ml = &packed->meshlets;
    uint32_t k = packed->influences;
    size_t n = 0, n_counts = 0, n_bounds = 0, n_vertices = 0, n_vtuples = 0, n_tri = 0, n_joints = 0, n_tuples = 0;
    memset(a, 0, sizeof(*a));
    uint32_t *vtuples = NULL, *triangles = NULL, *joints = NULL, *tuples = NULL;
    int rc = -1;
    if (!(a->offsets = read_u32(doc, ml->offsets, GLTF_UNSIGNED_INT, 4, &n, err, err_size)) ||
        !(a->counts = read_u32(doc, ml->counts, GLTF_UNSIGNED_SHORT, 4, &n_counts, err, err_size)) ||
        gltf_read_accessor_u32(doc, ml->bounds, GLTF_FLOAT, 4, &n_bounds, NULL, err, err_size) ||
        !(a->vertices = read_u32(doc, ml->vertices, GLTF_UNSIGNED_INT, 1, &n_vertices, err, err_size)) ||
        !(vtuples = read_u32(doc, ml->vertex_tuples, GLTF_UNSIGNED_BYTE, 1, &n_vtuples, err, err_size)) ||
        !(triangles = read_u32(doc, ml->triangles, GLTF_UNSIGNED_BYTE, 1, &n_tri, err, err_size)) ||
        !(joints = read_u32(doc, ml->joints, GLTF_UNSIGNED_SHORT, 1, &n_joints, err, err_size)) ||
        !(tuples = read_u32(doc, ml->tuples, GLTF_UNSIGNED_BYTE, (int)k, &n_tuples, err, err_size)))
        goto done;
    if (n_counts != n || n_bounds != n || n_vtuples != n_vertices || n_tri % 3) {
        fail(err, err_size, "meshlets: accessor counts disagree");
        goto done;
    }
    a->vertex_tuples = narrow(vtuples, n_vertices, 1);
    a->triangles = narrow(triangles, n_tri, 1);
    a->joints = narrow(joints, n_joints, 2);
    a->tuples = narrow(tuples, n_tuples * k, 1);
    if (!a->vertex_tuples || !a->triangles || !a->joints || !a->tuples) {
        fail(err, err_size, "out of memory");
        goto done;
    }
    sp_packed_meshlets* v = &a->view;
    v->meshlet_count = n;
    v->offsets = a->offsets;
    v->counts = a->counts;
    v->vertex_entries = n_vertices;
    v->vertices = a->vertices;
    v->vertex_tuples = a->vertex_tuples;
    v->triangle_bytes = n_tri;
    v->triangles = a->triangles;
    v->joint_entries = n_joints;
    v->joints = a->joints;
    v->tuple_count = n_tuples;
    v->tuples = a->tuples;
    v->max_vertices = ml->max_vertices;
    v->max_triangles = ml->max_triangles;
    v->max_joints = ml->max_joints;
    rc = 0;
done:
    free(vtuples);
    free(triangles);
    free(joints);
    free(tuples);
    if (rc) meshlet_arrays_free(a);
    return rc;
}

/* What info reports of meshlets that passed validation. */
static void summarize_meshlets(const sp_packed_meshlets* v, cli_meshlet_summary* summary) {
    memset(summary, 0, sizeof(*summary));
    size_t entries = 0;
    double tuple_bits_sum = 0;
    for (size_t m = 0; m < v->meshlet_count; ++m) {
        uint32_t vc = v->counts[4 * m], tc = v->counts[4 * m + 1], jc = v->counts[4 * m + 2], uc = v->counts[4 * m + 3];
        if (vc > summary->max_vertices) summary->max_vertices = vc;
        if (tc > summary->max_triangles) summary->max_triangles = tc;
        if (jc > summary->max_joints) summary->max_joints = jc;
        summary->palette_entries += jc;
        tuple_bits_sum += (double)vc * sp_index_bits(uc);
        entries += vc;
    }
    summary->count = v->meshlet_count;
    summary->mean_joints = v->meshlet_count ? (double)summary->palette_entries / (double)v->meshlet_count : 0;
    summary->local_tuple_bits_mean = entries ? tuple_bits_sum / (double)entries : 0;
}

static void packed_params(const gltf_packed_skin* packed, sp_packed_params* p) {
    memset(p, 0, sizeof(*p));
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
}

int cli_check_shared_vertices(const gltf_packed_skin* packed, const gltf_packed_skin* earlier, size_t mesh,
                              size_t primitive, char* err, size_t err_size) {
    if (earlier->vertices != packed->vertices) return 0;
    sp_packed_params ours, theirs;
    packed_params(packed, &ours);
    packed_params(earlier, &theirs);
    if (sp_packed_params_equal(&ours, &theirs) && earlier->tuple_table == packed->tuple_table) return 0;
    snprintf(err, err_size, "shares \"vertices\" accessor %d with mesh %zu primitive %zu but declares %s",
             packed->vertices, mesh, primitive,
             earlier->tuple_table != packed->tuple_table ? "another \"tupleTable\"" : "different properties");
    return -1;
}

static int decode_arrays(const gltf_packed_skin* packed, const uint32_t* words, size_t vertex_count,
                         uint32_t words_per_vertex, size_t primitive_vertex_count, const uint16_t* lut, size_t lut_size,
                         size_t skin_joint_count, const sp_packed_meshlets* meshlets, cli_decoded_skin* out,
                         char* err, size_t err_size) {
    memset(out, 0, sizeof(*out));
    /* Every format rule is the library's (sp_validate_packed); this only passes what the file says. */
    sp_packed_primitive primitive;
    memset(&primitive, 0, sizeof(primitive));
    packed_params(packed, &primitive.params);
    primitive.words = words;
    primitive.vertex_count = vertex_count;
    primitive.words_per_vertex = words_per_vertex;
    primitive.primitive_vertex_count = primitive_vertex_count;
    primitive.lut = lut;
    primitive.lut_size = lut_size;
    primitive.lut_components = packed->influences;
    primitive.lut_component_bytes = sp_joint_bytes(packed->joint_count); /* gltf_packed_sizes checked the type */
    primitive.skin_joint_count = skin_joint_count;
    primitive.meshlets = meshlets;

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
    if (meshlets) summarize_meshlets(meshlets, &out->meshlets);
    return 0;
}

int cli_decode_packed_arrays(const gltf_packed_skin* packed, const uint32_t* words, size_t vertex_count,
                             uint32_t words_per_vertex, const uint16_t* lut, size_t lut_size,
                             size_t skin_joint_count, cli_decoded_skin* out, char* err, size_t err_size) {
    return decode_arrays(packed, words, vertex_count, words_per_vertex, vertex_count, lut, lut_size, skin_joint_count,
                         NULL, out, err, err_size);
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
    meshlet_arrays meshlets;
    memset(&meshlets, 0, sizeof(meshlets));
    if (!words || !lut)
        fail(err, err_size, "out of memory");
    else if (gltf_read_packed(doc, packed, words, lut, err, err_size) == 0 &&
             (!packed->meshlets.present || read_meshlets(doc, packed, &meshlets, err, err_size) == 0)) {
        size_t primitive_vertices = gltf_primitive_vertex_count(doc, mesh, primitive);
        rc = decode_arrays(packed, words, vertex_count, words_per_vertex, primitive_vertices ? primitive_vertices : vertex_count,
                           lut, lut_size, gltf_mesh_joint_count(doc, mesh),
                           packed->meshlets.present ? &meshlets.view : NULL, out, err, err_size);
    }
    meshlet_arrays_free(&meshlets);
    free(words);
    free(lut);
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
