/*
 * fuzz_file_reader.c - libFuzzer target for the CLI's glTF reader: gltf_load_memory (tinygltf
 * plus our bounds checks), skin attribute reading, SKINPACK_packed_skin parsing and decoding,
 * and the garbage collection + serialisation a write does. Any input must give either data or
 * an error message, never a crash or sanitizer report.
 */
#include <stdlib.h>
#include <string.h>

#include "cli_common.h"

/* Skip huge declared counts: the reader would allocate for them (a memory limit, not a bug). */
#define MAX_VERTICES (1u << 20)

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    char err[CLI_ERR_SIZE];
    err[0] = 0;
    gltf_doc* doc = gltf_load_memory(data, size, err, sizeof(err));
    if (!doc) {
        if (!err[0]) abort(); /* a failure must say why */
        return 0;
    }
    for (size_t m = 0; m < gltf_mesh_count(doc); ++m) {
        for (size_t p = 0; p < gltf_primitive_count(doc, m); ++p) {
            gltf_skin_attributes at;
            if (gltf_primitive_skin(doc, m, p, &at, err, sizeof(err)) > 0 && !at.placeholder &&
                at.vertex_count <= MAX_VERTICES) {
                size_t n = at.vertex_count * 4 * at.sets;
                uint16_t* joints = malloc(n * sizeof(uint16_t));
                float* weights = malloc(n * sizeof(float));
                if (joints && weights) gltf_read_skin(doc, &at, joints, weights, err, sizeof(err));
                free(joints);
                free(weights);
            }
            gltf_packed_skin packed;
            if (gltf_get_packed(doc, m, p, &packed, err, sizeof(err)) > 0) {
                size_t vertex_count = 0, lut_size = 0;
                uint32_t wpv = 0;
                if (gltf_packed_sizes(doc, &packed, &vertex_count, &wpv, &lut_size, err, sizeof(err)) == 0 &&
                    vertex_count <= MAX_VERTICES && lut_size <= MAX_VERTICES) {
                    cli_decoded_skin skin;
                    /* meshlets too: they are validated with the skin */
                    if (cli_decode_packed(doc, m, p, &packed, &skin, err, sizeof(err)) == 0) cli_decoded_skin_free(&skin);
                }
            }
        }
    }
    for (int binary = 0; binary < 2; ++binary) { /* the writer, both kinds */
        void* out = NULL;
        size_t out_size = 0;
        if (gltf_serialize(doc, binary, &out, &out_size, err, sizeof(err)) == 0) free(out);
    }
    gltf_free(doc);
    return 0;
}
