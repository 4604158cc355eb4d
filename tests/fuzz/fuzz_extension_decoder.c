/*
 * fuzz_extension_decoder.c - libFuzzer target for the SKINPACK_packed_skin decoder
 * (cli_decode_packed_arrays: parameter checks + sp_codec_from_params + sp_decompress_skin).
 *
 * Input layout (little-endian), so that seeds can be made from real files (make_seeds.py):
 *   u8 method, u8 influences, u8 weight_bits, u8 tuple_bits, u16 joint_count, u16 skin_joints,
 *   u64 n, u64 axis_samples[3], u32 lut_size, u8 words_per_vertex,
 *   lut_size * influences u16 LUT joints, then the vertex words (u32) to the end.
 * The decoder must reject or decode every input without a crash, leak or sanitizer report.
 */
#include <stdlib.h>
#include <string.h>

#include "cli_common.h"

#define HEADER_SIZE 45

static uint64_t read_u64(const uint8_t* p) {
    uint64_t v = 0;
    for (int i = 7; i >= 0; --i) v = v << 8 | p[i];
    return v;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < HEADER_SIZE) return 0;
    gltf_packed_skin packed;
    memset(&packed, 0, sizeof(packed));
    packed.method = data[0];
    packed.influences = data[1];
    packed.weight_bits = data[2];
    packed.tuple_bits = data[3];
    packed.joint_count = (uint32_t)data[4] | (uint32_t)data[5] << 8;
    size_t skin_joints = (size_t)data[6] | (size_t)data[7] << 8;
    packed.n = read_u64(data + 8);
    for (int i = 0; i < 3; ++i) packed.axis_samples[i] = read_u64(data + 16 + 8 * i);
    size_t lut_size = (size_t)data[40] | (size_t)data[41] << 8 | (size_t)data[42] << 16 | (size_t)data[43] << 24;
    uint32_t words_per_vertex = data[44];
    if (packed.method >= SP_METHOD_COUNT || packed.influences < 1 || packed.influences > 4) return 0;
    if (words_per_vertex < 1 || words_per_vertex > 2) return 0;

    size_t rest = size - HEADER_SIZE;
    size_t lut_bytes = lut_size * packed.influences * 2;
    if (lut_size > rest || lut_bytes > rest) return 0;
    size_t vertex_count = (rest - lut_bytes) / (4 * words_per_vertex);
    if (vertex_count == 0) return 0;

    /* Copies: the decoder may assume aligned arrays, as gltf_read_packed gives it. */
    uint16_t* lut = malloc(lut_bytes ? lut_bytes : 1);
    uint32_t* words = malloc(vertex_count * words_per_vertex * 4);
    if (!lut || !words) {
        free(lut);
        free(words);
        return 0;
    }
    memcpy(lut, data + HEADER_SIZE, lut_bytes);
    memcpy(words, data + HEADER_SIZE + lut_bytes, vertex_count * words_per_vertex * 4);

    cli_decoded_skin skin;
    char err[CLI_ERR_SIZE];
    if (cli_decode_packed_arrays(&packed, words, vertex_count, words_per_vertex, lut, lut_size, skin_joints, &skin, err,
                                 sizeof(err)) == 0) {
        /* A decoded skin is non-negative, sums to 1 and uses joints below jointCount. (Not
         * necessarily sorted: Fixed/Cube/POT/Any codes that no encoder writes decode to valid
         * but unsorted weights, which is harmless for skinning.) */
        for (size_t v = 0; v < vertex_count; ++v) {
            float sum = 0;
            for (uint32_t i = 0; i < skin.influences; ++i) {
                float w = skin.weights[v * skin.influences + i];
                if (!(w >= 0) || skin.joints[v * skin.influences + i] >= packed.joint_count)
                    abort();
                sum += w;
            }
            if (sum < 0.999f || sum > 1.001f) abort();
        }
        cli_decoded_skin_free(&skin);
    } else if (err[0] == 0) {
        abort(); /* every rejection must say why */
    }
    free(lut);
    free(words);
    return 0;
}
