/*
 * cli_decompress.c - skinpack decompress: decodes every SKINPACK_packed_skin back to standard
 * JOINTS_0 (UNSIGNED_BYTE or UNSIGNED_SHORT) and WEIGHTS_0 (FLOAT) so any glTF tool can read
 * the file, and drops the extension.
 */
#include <stdlib.h>
#include <string.h>

#include "cli_common.h"
#include "commands.h"

typedef struct decoded_attributes {
    int vertices, tuple_table; /* the extension's accessors: primitives sharing them decode once */
    int joints, weights;       /* the new accessors */
} decoded_attributes;

/* Writes K decoded influences a vertex as VEC4 attributes; zero-weight slots get joint 0, as
 * the glTF validator expects. */
static int add_standard_attributes(gltf_doc* doc, const cli_decoded_skin* skin, uint32_t joint_count,
                                   decoded_attributes* out, char* err, size_t err_size) {
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
    if (joint_count <= 256) { /* narrow in place, as Blender and most exporters write joints */
        uint8_t* joints8 = (uint8_t*)joints16;
        for (size_t i = 0; i < vc * 4; ++i) joints8[i] = (uint8_t)joints16[i];
        out->joints = gltf_add_accessor(doc, joints8, vc, GLTF_UNSIGNED_BYTE, 4, 0, flags);
    } else {
        out->joints = gltf_add_accessor(doc, joints16, vc, GLTF_UNSIGNED_SHORT, 4, 0, flags);
    }
    out->weights = gltf_add_accessor(doc, weights, vc, GLTF_FLOAT, 4, 0, flags);
    free(joints16);
    free(weights);
    return 0;
}

int skinpack_cmd_decompress(int argc, char** argv) {
    const char* input = NULL;
    const char* output = NULL;
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "-o") == 0 && i + 1 < argc)
            output = argv[++i];
        else if (argv[i][0] != '-' && !input)
            input = argv[i];
        else {
            fprintf(stderr, "skinpack decompress: unexpected argument '%s'\n", argv[i]);
            return 2;
        }
    }
    if (!input || !output) {
        fprintf(stderr, "usage: skinpack decompress IN -o OUT   (.gltf or .glb)\n");
        return 2;
    }
    char err[CLI_ERR_SIZE];
    gltf_doc* doc = gltf_load_file(input, err, sizeof(err));
    if (!doc) {
        fprintf(stderr, "skinpack decompress: %s: %s\n", input, err);
        return 1;
    }
    int rc = 1;
    size_t count = 0, capacity = 0, decoded_primitives = 0;
    decoded_attributes* done_list = NULL;
    for (size_t m = 0; m < gltf_mesh_count(doc); ++m) {
        for (size_t p = 0; p < gltf_primitive_count(doc, m); ++p) {
            gltf_packed_skin packed;
            int has = gltf_get_packed(doc, m, p, &packed, err, sizeof(err));
            if (has < 0) {
                fprintf(stderr, "skinpack decompress: %s: mesh %zu primitive %zu: %s\n", input, m, p, err);
                goto done;
            }
            if (has == 0) {
                gltf_skin_attributes at;
                if (gltf_primitive_skin(doc, m, p, &at, err, sizeof(err)) > 0 && at.placeholder) {
                    fprintf(stderr, "skinpack decompress: %s: mesh %zu primitive %zu: JOINTS_0/WEIGHTS_0 have no data "
                            "and there is no " GLTF_EXTENSION_NAME "\n", input, m, p);
                    goto done;
                }
                continue;
            }
            decoded_attributes* d = NULL;
            for (size_t i = 0; i < count; ++i)
                if (done_list[i].vertices == packed.vertices && done_list[i].tuple_table == packed.tuple_table)
                    d = &done_list[i];
            if (!d) {
                if (count == capacity) {
                    capacity = capacity ? capacity * 2 : 16;
                    decoded_attributes* grown = realloc(done_list, capacity * sizeof(*done_list));
                    if (!grown) goto done;
                    done_list = grown;
                }
                d = &done_list[count];
                d->vertices = packed.vertices;
                d->tuple_table = packed.tuple_table;
                cli_decoded_skin skin;
                if (cli_decode_packed(doc, m, &packed, &skin, err, sizeof(err)) ||
                    add_standard_attributes(doc, &skin, packed.joint_count, d, err, sizeof(err))) {
                    cli_decoded_skin_free(&skin);
                    fprintf(stderr, "skinpack decompress: %s: mesh %zu primitive %zu: %s\n", input, m, p, err);
                    goto done;
                }
                cli_decoded_skin_free(&skin);
                ++count;
            }
            gltf_set_skin_attributes(doc, m, p, d->joints, d->weights);
            gltf_remove_packed(doc, m, p);
            ++decoded_primitives;
        }
    }
    gltf_declare_extension(doc, 0, 0);
    /* The packed arrays (and a fallback's old JOINTS_0/WEIGHTS_0) are now unused. If the file
     * uses extensions whose references we cannot follow, keep them: still a valid file. */
    if (gltf_collect_garbage(doc, err, sizeof(err)))
        fprintf(stderr, "skinpack decompress: note: unused data kept: %s\n", err);
    size_t bytes = 0;
    if (gltf_write_file(doc, output, cli_output_is_binary(output, gltf_is_binary(doc)), &bytes, err, sizeof(err))) {
        fprintf(stderr, "skinpack decompress: %s\n", err);
        goto done;
    }
    printf("decoded %zu primitive(s) (%zu packed skin(s)); wrote %s (%zu bytes)\n", decoded_primitives, count, output,
           bytes);
    rc = 0;
done:
    free(done_list);
    gltf_free(doc);
    return rc;
}
