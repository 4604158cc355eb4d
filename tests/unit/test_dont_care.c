/*
 * Don't-care tuple sharing is only sound where every slot after the significant ones decodes to
 * zero. Any AABB rounds each axis on its own grid, so a slot can decode to 0 while a later one
 * keeps weight: that vertex must not share a tuple that differs in the later slot (regression:
 * `--method any --weight-bits 4` sent piglet vertex 140's 0.25 of joint 12 to joint 3).
 */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "skinpack.h"

enum { K = 4, JOINTS = 16 };

/* Vertex 0 registers the full tuple (3, 4, 5, 6); vertex 1 starts with the same two joints,
 * and Any at 4 bits decodes its weights to (0.5, 0.25, 0, 0.25): weight on slot 3 after a zero. */
static const uint16_t in_joints[2 * K] = {3, 4, 5, 6, 3, 4, 7, 12};
static const float in_weights[2 * K] = {0.4f, 0.3f, 0.2f, 0.1f, 0.55f, 0.175f, 0.15f, 0.125f};

/* The encoder's significant count covers the slot that carries weight after a zero one. */
static void significant_covers_late_weight(void)
{
    sp_codec c;
    CHECK(sp_codec_from_bits(SP_METHOD_ANY, K, 4, &c) == SP_OK);
    uint64_t code;
    uint8_t significant = 0;
    float decoded[K];
    CHECK(sp_encode_weights_batch(&c, in_weights + K, 1, &code, &significant) == SP_OK);
    sp_decode_weights(&c, code, decoded);
    /* the case under test: a zero slot with weight after it (else this test proves nothing) */
    CHECK_MSG(decoded[2] == 0.0f && decoded[3] > 0.0f, "Any 4 bits decodes to %g %g %g %g", decoded[0],
              decoded[1], decoded[2], decoded[3]);
    CHECK_MSG(significant == 4, "significant %u, slot 3 carries %g", significant, decoded[3]);

    /* the sorted grids: the count is the first zero slot, as before */
    sp_codec oss;
    CHECK(sp_codec_from_bits(SP_METHOD_OSS, K, 22, &oss) == SP_OK);
    const float two[K] = {0.75f, 0.25f, 0, 0};
    CHECK(sp_encode_weights_batch(&oss, two, 1, &code, &significant) == SP_OK);
    CHECK(significant == 2);
}

/* Through the whole library: compress with merging on, decompress, and every slot that carries
 * weight names the vertex's own joint. */
static void compressed_joints_keep_late_weight(void)
{
    sp_compress_options o;
    sp_compress_options_default(&o);
    o.method = SP_METHOD_ANY;
    o.vertex_bits = 0;
    o.weight_bits = 4;
    CHECK(o.merge_dont_care);
    uint32_t words[2 * 2];
    uint16_t lut[2 * K], joints[2 * K];
    float error[2], weights[2 * K];
    sp_compressed_skin info;
    size_t size = sp_compress_scratch_bound(2, K);
    void* scratch = malloc(size);
    CHECK(sp_compress_skin(in_joints, in_weights, 2, K, JOINTS, &o, words, lut, error, NULL, &info, scratch, size) ==
          SP_OK);
    free(scratch);
    CHECK(info.influences == K);
    CHECK_MSG(info.lut_size == 2, "%zu tuples: vertex 1 shared vertex 0's", info.lut_size);
    size_t bad = 0;
    CHECK(sp_decompress_skin(&info.codec, words, 2, info.tuple_bits, lut, info.lut_size, JOINTS, joints, weights,
                             &bad) == SP_OK);
    for (size_t v = 0; v < 2; ++v)
        for (size_t i = 0; i < K; ++i)
            if (weights[v * K + i] > 0)
                CHECK_MSG(joints[v * K + i] == in_joints[v * K + i], "vertex %zu slot %zu: weight %g on joint %u, not %u",
                          v, i, weights[v * K + i], joints[v * K + i], in_joints[v * K + i]);
    CHECK(weights[K + 3] > 0); /* the late weight survived, on joint 12 */
}

int main(void)
{
    significant_covers_late_weight();
    compressed_joints_keep_late_weight();
    return check_report("test_dont_care");
}
