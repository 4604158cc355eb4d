/*
 * cli_decompress.c - skinpack decompress: decodes every SKINPACK_packed_skin back to standard
 * JOINTS_0 (UNSIGNED_BYTE or UNSIGNED_SHORT) and WEIGHTS_0 (FLOAT) so any glTF tool can read
 * the file, and drops the extension.
 */
#include <stdlib.h>
#include <string.h>

#include "cli_common.h"
#include "commands.h"

/* One SKINPACK_packed_skin primitive. Primitives with the same packed arrays decode once. */
typedef struct decoded_primitive {
    size_t mesh, primitive;
    gltf_packed_skin packed;
    long shared_with;               /* the entry that decoded the same arrays, or -1 */
    cli_decoded_skin skin;
    int joints, weights;            /* JOINTS_0/WEIGHTS_0 accessors the file has (-1: none) */
} decoded_primitive;

typedef struct decompress_settings {
    const char* input;
    const char* output;
} decompress_settings;

static int parse_settings(int argc, char** argv, decompress_settings* settings) {
    memset(settings, 0, sizeof(*settings));
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "-o") == 0 && i + 1 < argc) {
            settings->output = argv[++i];
        } else if (argv[i][0] != '-' && !settings->input) {
            settings->input = argv[i];
        } else {
            fprintf(stderr, "Error: unexpected argument '%s'\n", argv[i]);
            return -1;
        }
    }
    if (settings->input && settings->output) return 0;
    fprintf(stderr, "usage: skinpack decompress IN -o OUT   (.gltf or .glb)\n");
    return -1;
}

/* K decoded influences a vertex as VEC4 arrays; zero-weight slots get joint 0, as the glTF
 * validator expects. Joints are narrowed to bytes when jointCount allows (as Blender and most
 * exporters write them). */
static int write_standard(gltf_doc* doc, const decoded_primitive* d, int* joints_accessor, int* weights_accessor,
                          char* err, size_t err_size) {
    const cli_decoded_skin* skin = &d->skin;
    size_t vc = skin->vertex_count, k = skin->influences;
    uint16_t* joints16 = calloc(vc * 4, sizeof(uint16_t));
    float* weights = calloc(vc * 4, sizeof(float));
    if (!joints16 || !weights) {
        free(joints16);
        free(weights);
        snprintf(err, err_size, "out of memory");
        return -1;
    }
    for (size_t v = 0; v < vc; ++v)
        for (size_t i = 0; i < k; ++i) {
            float w = skin->weights[v * k + i];
            weights[v * 4 + i] = w;
            joints16[v * 4 + i] = w > 0 ? skin->joints[v * k + i] : 0;
        }
    const int flags = GLTF_ACCESSOR_VERTEX_ATTRIBUTE | GLTF_ACCESSOR_BOUNDS;
    int joint_type = sp_joint_bytes(d->packed.joint_count) == 1 ? GLTF_UNSIGNED_BYTE : GLTF_UNSIGNED_SHORT;
    if (joint_type == GLTF_UNSIGNED_BYTE) {
        uint8_t* joints8 = (uint8_t*)joints16;
        for (size_t i = 0; i < vc * 4; ++i) joints8[i] = (uint8_t)joints16[i];
    }
    /* The primitive's own JOINTS_0/WEIGHTS_0 (fallback data or compact placeholders) get the
     * decoded values in place; a primitive without them gets new accessors. */
    if (d->joints >= 0 && d->weights >= 0) {
        gltf_replace_accessor_data(doc, d->joints, joints16, vc, joint_type, 4, 0, flags);
        gltf_replace_accessor_data(doc, d->weights, weights, vc, GLTF_FLOAT, 4, 0, flags);
        *joints_accessor = d->joints;
        *weights_accessor = d->weights;
    } else {
        *joints_accessor = gltf_add_accessor(doc, joints16, vc, joint_type, 4, 0, flags);
        *weights_accessor = gltf_add_accessor(doc, weights, vc, GLTF_FLOAT, 4, 0, flags);
    }
    free(joints16);
    free(weights);
    return 0;
}

/* Phase 1: every packed primitive decoded (nothing edited yet). Returns the count or -1. */
static long decode_all(gltf_doc* doc, const char* input, decoded_primitive** out) {
    char err[CLI_ERR_SIZE];
    size_t count = 0, capacity = 0;
    decoded_primitive* list = NULL;
    for (size_t m = 0; m < gltf_mesh_count(doc); ++m) {
        for (size_t p = 0; p < gltf_primitive_count(doc, m); ++p) {
            gltf_packed_skin packed;
            gltf_skin_attributes at;
            int has = gltf_get_packed(doc, m, p, &packed, err, sizeof(err));
            char skin_err[CLI_ERR_SIZE]; /* a malformed JOINTS_0 beside the extension is replaced anyway */
            int skinned = gltf_primitive_skin(doc, m, p, &at, skin_err, sizeof(skin_err));
            if (has == 0 && skinned > 0 && at.placeholder)
                snprintf(err, sizeof(err), "JOINTS_0/WEIGHTS_0 have no data and there is no " GLTF_EXTENSION_NAME);
            if (has < 0 || (has == 0 && skinned > 0 && at.placeholder)) {
                fprintf(stderr, "Error: %s: mesh %zu primitive %zu: %s\n", input, m, p, err);
                goto fail;
            }
            if (has == 0) continue;
            for (size_t i = 0; i < count; ++i)
                if (cli_check_shared_vertices(&packed, &list[i].packed, list[i].mesh, list[i].primitive, err,
                                              sizeof(err))) {
                    fprintf(stderr, "Error: %s: mesh %zu primitive %zu: %s\n", input, m, p, err);
                    goto fail;
                }
            decoded_primitive* grown = cli_grow(list, &capacity, count, sizeof(*list));
            if (!grown) goto fail;
            list = grown;
            decoded_primitive* d = &list[count];
            memset(d, 0, sizeof(*d));
            d->mesh = m;
            d->primitive = p;
            d->packed = packed;
            d->shared_with = -1;
            d->joints = skinned > 0 ? at.joints[0] : -1;
            d->weights = skinned > 0 ? at.weights[0] : -1;
            for (size_t i = 0; i < count && d->shared_with < 0; ++i)
                if (list[i].shared_with < 0 && list[i].packed.vertices == packed.vertices &&
                    list[i].packed.tuple_table == packed.tuple_table)
                    d->shared_with = (long)i;
            if (d->shared_with < 0 && cli_decode_packed(doc, m, p, &packed, &d->skin, err, sizeof(err))) {
                fprintf(stderr, "Error: %s: mesh %zu primitive %zu: %s\n", input, m, p, err);
                goto fail;
            }
            ++count;
        }
    }
    *out = list;
    return (long)count;
fail:
    for (size_t i = 0; i < count; ++i) cli_decoded_skin_free(&list[i].skin);
    free(list);
    return -1;
}

/* Phase 2: the extension goes, and with it its accessors where they end the arrays. */
static void remove_extension(gltf_doc* doc, const decoded_primitive* list, size_t count) {
    int* ours = malloc((count * 11 + 1) * sizeof(int));
    size_t n = 0;
    for (size_t i = 0; i < count; ++i) {
        const gltf_packed_skin* e = &list[i].packed;
        gltf_remove_packed(doc, list[i].mesh, list[i].primitive);
        if (!ours) continue;
        ours[n++] = e->vertices;
        ours[n++] = e->tuple_table;
        if (!e->meshlets.present) continue;
        const gltf_packed_meshlets* ml = &e->meshlets;
        int refs[] = {ml->offsets, ml->counts, ml->bounds, ml->cones, ml->vertices, ml->vertex_tuples, ml->triangles,
                      ml->joints, ml->tuples};
        for (size_t r = 0; r < sizeof(refs) / sizeof(refs[0]); ++r)
            if (refs[r] >= 0) ours[n++] = refs[r];
    }
    gltf_declare_extension(doc, 0, 0);
    if (ours) gltf_remove_unused_tail(doc, ours, n);
    free(ours);
}

int skinpack_cmd_decompress(int argc, char** argv) {
    decompress_settings settings;
    if (parse_settings(argc, argv, &settings)) return 2;
    char err[CLI_ERR_SIZE];
    gltf_doc* doc = gltf_load_file(settings.input, err, sizeof(err));
    if (!doc) {
        fprintf(stderr, "Error: %s: %s\n", settings.input, err);
        return 1;
    }
    int rc = 1, binary = cli_output_is_binary(settings.output, gltf_is_binary(doc));
    size_t bytes = 0, decoded = 0;
    decoded_primitive* list = NULL;
    long count = decode_all(doc, settings.input, &list);
    if (count < 0) goto done;
    if (count == 0) {
        if (gltf_write_unchanged(doc, settings.output, binary, &bytes, err, sizeof(err))) goto write_error;
        fprintf(stderr, "Warning: %s: no " GLTF_EXTENSION_NAME " primitives; written unchanged to %s\n",
                settings.input, settings.output);
        rc = 0;
        goto done;
    }
    remove_extension(doc, list, (size_t)count);
    for (long i = 0; i < count; ++i) {
        decoded_primitive* d = &list[i];
        if (d->shared_with < 0) {
            if (write_standard(doc, d, &d->joints, &d->weights, err, sizeof(err))) goto write_error;
            ++decoded;
        } else {
            d->joints = list[d->shared_with].joints;
            d->weights = list[d->shared_with].weights;
        }
        gltf_set_skin_attributes(doc, d->mesh, d->primitive, d->joints, d->weights);
    }
    gltf_release_fallback(doc);
    if (gltf_write_file(doc, settings.output, binary, &bytes, err, sizeof(err))) goto write_error;
    printf("decoded %ld primitive(s) (%zu packed skin(s)); wrote %s (%zu bytes)\n", count, decoded, settings.output,
           bytes);
    rc = 0;
    goto done;
write_error:
    fprintf(stderr, "Error: %s\n", err);
done:
    for (long i = 0; i < count; ++i) cli_decoded_skin_free(&list[i].skin);
    free(list);
    gltf_free(doc);
    return rc;
}
