/*
 * cli_info.c - skinpack info: per skinned primitive, what its blend attributes are and cost as
 * stored. Standard JOINTS_n/WEIGHTS_n are read and prepared as the compressor would see them;
 * SKINPACK_packed_skin primitives are fully decoded (so info doubles as a validity check) and,
 * in fallback mode, compared against the JOINTS_0/WEIGHTS_0 they carry.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli_common.h"
#include "commands.h"

typedef struct primitive_info {
    size_t mesh, primitive;
    int packed;                   /* 1 if SKINPACK_packed_skin */
    int fallback;                 /* packed and JOINTS_0/WEIGHTS_0 kept */
    size_t vertices;
    size_t joints;                /* skin joints (standard) or jointCount (packed) */
    uint32_t influences;          /* K: the largest influence count (standard, capped at 4) or the stored K */
    size_t histogram[SP_MAX_INPUT_INFLUENCES + 1]; /* vertices by non-zero influences */
    size_t unique_tuples;
    gltf_packed_skin ext;         /* packed only */
    sp_codec codec;               /* packed only */
    double tuple_bits, weight_bits, lut_bits_per_vertex;
    double bits_per_vertex;       /* information: tuple + weight + LUT (packed); as stored (standard) */
    double stored_bits_per_vertex; /* everything in the file for the blend attributes */
    double fallback_difference;   /* fallback: max joint-matched difference to JOINTS_0/WEIGHTS_0 */
    cli_meshlet_summary meshlets; /* packed with meshlets */
} primitive_info;

/* Standard attributes: histogram before pruning (what sp_prepare_influences counts) and the
 * unique tuples of the prepared joints, with zero-weight slots as don't-care. */
static int info_standard(const gltf_doc* doc, const gltf_skin_attributes* at, primitive_info* info, char* err,
                         size_t err_size) {
    size_t vc = at->vertex_count, stride = 4 * at->sets, k = SP_MAX_INFLUENCES;
    uint16_t* joints = malloc(vc * stride * sizeof(uint16_t));
    float* weights = malloc(vc * stride * sizeof(float));
    uint16_t* pj = malloc(vc * k * sizeof(uint16_t));
    float* pw = malloc(vc * k * sizeof(float));
    uint8_t* significant = malloc(vc);
    uint16_t* lut = malloc(vc * k * sizeof(uint16_t));
    uint32_t* index = malloc(vc * sizeof(uint32_t));
    int rc = -1;
    if (!joints || !weights || !pj || !pw || !significant || !lut || !index) {
        snprintf(err, err_size, "out of memory");
        goto done;
    }
    if (gltf_read_skin(doc, at, joints, weights, err, err_size)) goto done;
    size_t joint_count = at->joint_count;
    if (joint_count == 0)
        for (size_t i = 0; i < vc * stride; ++i)
            if (joints[i] >= joint_count) joint_count = (size_t)joints[i] + 1;
    sp_prepare_stats stats;
    memset(&stats, 0, sizeof(stats));
    sp_result r = sp_prepare_influences(joints, weights, vc, stride, joint_count, k, 1e-3f, pj, pw, NULL, &stats);
    if (r != SP_OK) {
        snprintf(err, err_size, "vertex %zu: %s", stats.error_vertex, sp_result_string(r));
        goto done;
    }
    uint32_t largest = 1;
    for (uint32_t c = 1; c <= SP_MAX_INPUT_INFLUENCES; ++c)
        if (stats.influence_histogram[c]) largest = c;
    uint32_t k_used = largest < k ? largest : (uint32_t)k;
    /* Compact the prepared arrays to k_used a vertex for the tuple table. */
    for (size_t v = 0; v < vc; ++v) {
        uint8_t s = 0;
        for (size_t i = 0; i < k_used; ++i) {
            pj[v * k_used + i] = pj[v * k + i];
            if (pw[v * k + i] > 0) s = (uint8_t)(i + 1);
        }
        significant[v] = s;
    }
    size_t scratch_size = sp_tuple_lut_scratch_bound(vc, k_used);
    void* scratch = malloc(scratch_size ? scratch_size : 1);
    if (!scratch) {
        snprintf(err, err_size, "out of memory");
        goto done;
    }
    r = sp_build_tuple_lut(pj, significant, vc, k_used, lut, &info->unique_tuples, index, scratch, scratch_size);
    free(scratch);
    if (r != SP_OK) {
        snprintf(err, err_size, "%s", sp_result_string(r));
        goto done;
    }
    info->vertices = vc;
    info->joints = joint_count;
    info->influences = k_used;
    memcpy(info->histogram, stats.influence_histogram, sizeof(info->histogram));
    info->bits_per_vertex = at->stored_bits_per_vertex;
    info->stored_bits_per_vertex = at->stored_bits_per_vertex;
    rc = 0;
done:
    free(joints);
    free(weights);
    free(pj);
    free(pw);
    free(significant);
    free(lut);
    free(index);
    return rc;
}

static int info_packed(const gltf_doc* doc, size_t mesh, size_t primitive, primitive_info* info, char* err,
                       size_t err_size) {
    cli_decoded_skin skin;
    if (cli_decode_packed(doc, mesh, primitive, &info->ext, &skin, err, err_size)) return -1;
    uint32_t k = skin.influences;
    info->packed = 1;
    info->vertices = skin.vertex_count;
    info->joints = info->ext.joint_count;
    info->influences = k;
    info->codec = skin.codec;
    info->unique_tuples = skin.lut_size;
    info->tuple_bits = info->ext.tuple_bits;
    info->weight_bits = info->ext.weight_bits;
    info->lut_bits_per_vertex = cli_lut_bits_per_vertex(skin.lut_size, k, skin.joint_bytes, skin.vertex_count);
    info->bits_per_vertex = info->tuple_bits + info->weight_bits + info->lut_bits_per_vertex;
    info->stored_bits_per_vertex = 32.0 * skin.words_per_vertex + info->lut_bits_per_vertex;
    for (size_t v = 0; v < skin.vertex_count; ++v) {
        size_t nonzero = 0;
        for (uint32_t i = 0; i < k; ++i) nonzero += skin.weights[v * k + i] > 0;
        info->histogram[nonzero]++;
    }
    info->fallback_difference = NAN;
    if (info->ext.meshlets.present) info->meshlets = skin.meshlets;

    gltf_skin_attributes at;
    int rc = 0;
    int skinned = gltf_primitive_skin(doc, mesh, primitive, &at, err, err_size);
    if (skinned < 0) rc = -1;
    if (skinned > 0 && !at.placeholder) {
        /* Fallback mode: the kept attributes must describe the same skin. */
        info->fallback = 1;
        info->stored_bits_per_vertex += at.stored_bits_per_vertex;
        size_t stride = 4 * at.sets;
        uint16_t* joints = malloc(at.vertex_count * stride * sizeof(uint16_t));
        float* weights = malloc(at.vertex_count * stride * sizeof(float));
        uint16_t* pj = malloc(at.vertex_count * k * sizeof(uint16_t));
        float* pw = malloc(at.vertex_count * k * sizeof(float));
        sp_prepare_stats stats;
        memset(&stats, 0, sizeof(stats));
        if (!joints || !weights || !pj || !pw) {
            snprintf(err, err_size, "out of memory");
            rc = -1;
        } else if (at.vertex_count != skin.vertex_count) {
            snprintf(err, err_size, "JOINTS_0 has %zu vertices, the packed skin %zu", at.vertex_count,
                     skin.vertex_count);
            rc = -1;
        } else if (gltf_read_skin(doc, &at, joints, weights, err, err_size)) {
            rc = -1;
        } else {
            size_t joint_count = at.joint_count ? at.joint_count : SP_MAX_JOINTS;
            sp_result r = sp_prepare_influences(joints, weights, at.vertex_count, stride, joint_count, k, 1e-3f, pj,
                                                pw, NULL, &stats);
            if (r != SP_OK) {
                snprintf(err, err_size, "fallback attributes, vertex %zu: %s", stats.error_vertex,
                         sp_result_string(r));
                rc = -1;
            } else {
                double worst = 0;
                for (size_t v = 0; v < at.vertex_count; ++v) {
                    double d = cli_vertex_difference(pj + v * k, pw + v * k, k, skin.joints + v * k,
                                                     skin.weights + v * k, k);
                    if (d > worst) worst = d;
                }
                info->fallback_difference = worst;
            }
        }
        free(joints);
        free(weights);
        free(pj);
        free(pw);
    }
    cli_decoded_skin_free(&skin);
    return rc;
}

static void print_json(const char* input, const primitive_info* infos, size_t count, size_t input_bytes) {
    double bits = 0;
    size_t vertices = 0;
    printf("{\n  \"input\": ");
    cli_json_string(stdout, input);
    printf(",\n  \"primitives\": [");
    for (size_t i = 0; i < count; ++i) {
        const primitive_info* p = &infos[i];
        bits += p->stored_bits_per_vertex * (double)p->vertices;
        vertices += p->vertices;
        printf("%s\n    {\"mesh\": %zu, \"primitive\": %zu, \"encoding\": \"%s\", \"vertices\": %zu, \"joints\": %zu, "
               "\"influences\": %u, \"unique_tuples\": %zu, \"influence_histogram\": [",
               i ? "," : "", p->mesh, p->primitive,
               p->packed ? (p->fallback ? GLTF_EXTENSION_NAME "+fallback" : GLTF_EXTENSION_NAME) : "standard",
               p->vertices, p->joints, p->influences, p->unique_tuples);
        for (int c = 0; c <= SP_MAX_INPUT_INFLUENCES; ++c) printf("%s%zu", c ? ", " : "", p->histogram[c]);
        printf("], \"bits_per_vertex\": ");
        cli_json_number(stdout, p->bits_per_vertex);
        printf(", \"stored_bits_per_vertex\": ");
        cli_json_number(stdout, p->stored_bits_per_vertex);
        if (p->packed) {
            printf(", \"method\": \"%s\", \"n\": %llu, \"tuple_bits\": %.0f, \"weight_bits\": %.0f, "
                   "\"lut_bits_per_vertex\": ",
                   sp_method_name((sp_method)p->codec.method), (unsigned long long)p->codec.n, p->tuple_bits,
                   p->weight_bits);
            cli_json_number(stdout, p->lut_bits_per_vertex);
            printf(", \"max_error_bound\": ");
            cli_json_number(stdout, p->codec.max_error);
            printf(", \"fallback_max_difference\": ");
            cli_json_number(stdout, p->fallback_difference);
            if (p->ext.meshlets.present) {
                const cli_meshlet_summary* ms = &p->meshlets;
                printf(", \"meshlets\": {\"count\": %zu, \"max_vertices\": %u, \"max_triangles\": %u, "
                       "\"mean_joints\": ", ms->count, ms->max_vertices, ms->max_triangles);
                cli_json_number(stdout, ms->mean_joints);
                printf(", \"max_joints\": %u, \"palette_entries\": %zu, \"global_tuple_bits\": %.0f, "
                       "\"local_tuple_bits_mean\": ", ms->max_joints, ms->palette_entries, p->tuple_bits);
                cli_json_number(stdout, ms->local_tuple_bits_mean);
                printf("}");
            }
        }
        printf("}");
    }
    printf("\n  ],\n  \"vertices\": %zu,\n  \"bits_per_vertex\": ", vertices);
    cli_json_number(stdout, vertices ? bits / (double)vertices : 0);
    printf(",\n  \"input_bytes\": %zu\n}\n", input_bytes);
}

static void print_table(const char* input, const primitive_info* infos, size_t count, size_t input_bytes) {
    printf("%s: %zu bytes, %zu skinned primitive(s)\n", input, input_bytes, count);
    if (!count) return;
    printf("%-5s %-5s %-9s %8s %6s %2s %7s %-10s %10s  %s\n", "mesh", "prim", "encoding", "vertices", "joints", "K",
           "tuples", "codec", "bits/v", "influences 0..8 (vertices)");
    for (size_t i = 0; i < count; ++i) {
        const primitive_info* p = &infos[i];
        char codec[32] = "-";
        if (p->packed)
            snprintf(codec, sizeof(codec), "%s%.0f+%.0f", sp_method_name((sp_method)p->codec.method), p->weight_bits,
                     p->tuple_bits);
        printf("%-5zu %-5zu %-9s %8zu %6zu %2u %7zu %-10s %10.1f ", p->mesh, p->primitive,
               p->packed ? (p->fallback ? "packed+fb" : "packed") : "standard", p->vertices, p->joints, p->influences,
               p->unique_tuples, codec, p->stored_bits_per_vertex);
        for (int c = 0; c <= SP_MAX_INPUT_INFLUENCES; ++c) printf(" %zu", p->histogram[c]);
        if (p->packed && isfinite(p->fallback_difference))
            printf("  (differs from fallback by <= %.2e)", p->fallback_difference);
        printf("\n");
        if (p->packed && p->ext.meshlets.present)
            printf("            meshlets: %zu, up to %u vertices / %u triangles / %u joints, %.1f joints on average, "
                   "tuple index %.0f -> %.2f bits\n", p->meshlets.count, p->meshlets.max_vertices,
                   p->meshlets.max_triangles, p->meshlets.max_joints, p->meshlets.mean_joints, p->tuple_bits,
                   p->meshlets.local_tuple_bits_mean);
    }
}

int skinpack_cmd_info(int argc, char** argv) {
    const char* input = NULL;
    int json = 0;
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--json") == 0)
            json = 1;
        else if (argv[i][0] != '-' && !input)
            input = argv[i];
        else {
            fprintf(stderr, "Error: unexpected argument '%s'\n", argv[i]);
            return 2;
        }
    }
    if (!input) {
        fprintf(stderr, "usage: skinpack info IN [--json]\n");
        return 2;
    }
    char err[CLI_ERR_SIZE];
    gltf_doc* doc = gltf_load_file(input, err, sizeof(err));
    if (!doc) {
        fprintf(stderr, "Error: %s: %s\n", input, err);
        return 1;
    }
    primitive_info* infos = NULL;
    size_t count = 0, capacity = 0;
    int rc = 1;
    for (size_t m = 0; m < gltf_mesh_count(doc); ++m) {
        for (size_t p = 0; p < gltf_primitive_count(doc, m); ++p) {
            primitive_info info;
            memset(&info, 0, sizeof(info));
            info.mesh = m;
            info.primitive = p;
            int has = gltf_get_packed(doc, m, p, &info.ext, err, sizeof(err));
            int ok = 0;
            if (has > 0) {
                ok = 1;
                for (size_t i = 0; i < count && ok; ++i)
                    ok = !infos[i].packed || cli_check_shared_vertices(&info.ext, &infos[i].ext, infos[i].mesh,
                                                                       infos[i].primitive, err, sizeof(err)) == 0;
                ok = ok && info_packed(doc, m, p, &info, err, sizeof(err)) == 0;
            } else if (has == 0) {
                gltf_skin_attributes at;
                int skinned = gltf_primitive_skin(doc, m, p, &at, err, sizeof(err));
                if (skinned == 0) continue;
                if (skinned > 0 && at.placeholder) {
                    snprintf(err, sizeof(err), "JOINTS_0/WEIGHTS_0 have no data and there is no " GLTF_EXTENSION_NAME);
                    skinned = -1;
                }
                ok = skinned > 0 && info_standard(doc, &at, &info, err, sizeof(err)) == 0;
            }
            if (!ok) {
                fprintf(stderr, "Error: %s: mesh %zu primitive %zu: %s\n", input, m, p, err);
                goto done;
            }
            primitive_info* grown = cli_grow(infos, &capacity, count, sizeof(*infos));
            if (!grown) goto done;
            infos = grown;
            infos[count++] = info;
        }
    }
    if (json)
        print_json(input, infos, count, cli_file_size(input));
    else
        print_table(input, infos, count, cli_file_size(input));
    rc = 0;
done:
    free(infos);
    gltf_free(doc);
    return rc;
}
