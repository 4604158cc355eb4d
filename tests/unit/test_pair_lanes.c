/*
 * Which lanes the K = 2 pair lanes (codec_oss_wide_simd.h's wide_pair_start, past 2^50 grids)
 * keep and which they leave to the scalar code, on chosen blocks: every other test compares
 * codes only, and the scalar redo gives the same codes, so lanes sent to it by a broken check
 * (slow, not wrong) or kept by one (wrong only where the sum happens to round) would pass there.
 * The AVX2 driver is compiled into this test under other entry-point names, its stages called
 * directly; the codes of the kept lanes are checked against sp_oss_encode_one too.
 */
#include <math.h>
#include <string.h>

#include "../../native/src/codec_internal.h"
#include "check.h"
#include "skinpack.h"

#if SP_X86_SIMD
#include "../../native/src/codec_oss_wide.h"
#include "../../native/src/codec_oss_prim_avx2.h"
#undef SIMD_NAME
#undef WIDE_NAME
#define SIMD_NAME(name) test_lanes_##name /* not the library's entry points */
#define WIDE_NAME(name) test_lanes_wide_##name
#include "../../native/src/codec_oss_simd.h"
#include "../../native/src/codec_oss_wide_simd.h"

/* One block of four pairs: the lanes left to the scalar code must be `expected_missed`, and the
 * kept lanes' codes those of the scalar encode. */
static SIMD_FN void check_block(const sp_codec* codec, const float pairs[8], unsigned expected_missed, const char* what)
{
    wide_codec c = wide_codec_for(codec);
    wide_pair parts;
    uint64_t codes[4];
    uint8_t significant[4];
    unsigned missed = wide_pair_start(&c, pairs, &parts);
    wide_pair_finish(&parts, codes, significant);
    CHECK_MSG(missed == expected_missed, "%s: %u bits: lanes missed %x, expected %x", what, codec->bits, missed,
              expected_missed);
    for (int lane = 0; lane < 4; ++lane) {
        uint8_t reference_significant;
        uint64_t reference = sp_oss_encode_one(codec, pairs + 2 * lane, &reference_significant);
        if (!(missed >> lane & 1))
            CHECK_MSG(codes[lane] == reference && significant[lane] == reference_significant, "%s: lane %d: %llu, not %llu",
                      what, lane, (unsigned long long)codes[lane], (unsigned long long)reference);
    }
}

static void check_codec(const sp_codec* codec)
{
    float denormal = 0x1p-140f, tiny = 0x1.8p-40f; /* tiny: two bits, 2^40 below 0.75: d = 0.75 + tiny is exact */
    float kept[][8] = {
        {0.75f, 0.25f, 1.0f, 0.0f, 0.5f, 0.5f, 0.3f, 0.7f},                   /* the bench's kinds, either order */
        {0.0f, 1.0f, -0.0f, 0.5f, 0.75f, tiny, tiny, 0.75f},                  /* zeros, -0, a gap of 41 that stays exact */
        {denormal, 3 * denormal, 0x1p-149f, 0x1p-126f, 2.0f, 5.0f, 0x1.fffffep-1f, 0x1p-24f}, /* denormals, sums past 1 */
        {0x1.fffffep-1f, 0x1.fffffep-29f, 0x1.fffffcp-30f, 0x1p0f, 1e30f, 1e29f, 3.0e38f, 1.0e38f}, /* gaps 28, 29 exact */
    };
    for (size_t b = 0; b < sizeof(kept) / sizeof(kept[0]); ++b) check_block(codec, kept[b], 0, "kept");
    float missed[][8] = {
        {NAN, 0.5f, 0.5f, NAN, INFINITY, 0.5f, 0.5f, -0.25f},                 /* not plain */
        {0.0f, 0.0f, -0.0f, 0.0f, 0.75f, 0x1.fffffep-31f, 0x1.fffffep-1f, 0x1.000002p-31f}, /* zero pairs; d inexact */
    };
    for (size_t b = 0; b < sizeof(missed) / sizeof(missed[0]); ++b) check_block(codec, missed[b], 0xF, "missed");
}

int main(void)
{
    if (sp_cpu_isa() < SP_ISA_AVX2) {
        printf("test_pair_lanes: no AVX2, nothing to check\n");
        return 0;
    }
    static const uint32_t widths[] = {51, 52, 56, 63};
    for (size_t i = 0; i < sizeof(widths) / sizeof(widths[0]); ++i) {
        sp_codec codec;
        CHECK(sp_codec_from_bits(SP_METHOD_OSS, 2, widths[i], &codec) == SP_OK && codec.scale >= SP_GRID_DOUBLE_LIMIT);
        check_codec(&codec);
    }
    return check_report("test_pair_lanes");
}
#else
int main(void)
{
    printf("test_pair_lanes: no x86 vector paths\n");
    return 0;
}
#endif
