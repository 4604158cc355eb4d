/* Weight preparation: sorting, pruning, renormalising, merging, and every error case. */
#include <math.h>

#include "check.h"
#include "skinpack.h"

static sp_result prepare(const uint16_t* j, const float* w, size_t count, size_t stride, size_t joints, size_t k,
                         uint16_t* oj, float* ow, float* prune, sp_prepare_stats* st)
{
    return sp_prepare_influences(j, w, count, stride, joints, k, 1e-3f, oj, ow, prune, st);
}

static void sorts_prunes_and_renormalises(void)
{
    /* vertex 0: 6 influences, unsorted, sum 1; vertex 1: tie (lower joint first), sum 2 */
    const uint16_t joints[2 * 6] = {5, 1, 7, 3, 2, 9, 4, 2, 0, 0, 0, 0};
    const float weights[2 * 6] = {0.05f, 0.4f, 0.1f, 0.3f, 0.1f, 0.05f, 1.0f, 1.0f, 0, 0, 0, 0};
    uint16_t oj[8];
    float ow[8], prune[2];
    sp_prepare_stats st;
    CHECK(prepare(joints, weights, 2, 6, 10, 4, oj, ow, prune, &st) == SP_OK);
    CHECK(oj[0] == 1 && oj[1] == 3 && oj[2] == 2 && oj[3] == 7); /* 0.1 tie: joint 2 before 7 */
    float kept = 0.4f + 0.3f + 0.1f + 0.1f;
    CHECK(fabsf(ow[0] - 0.4f / kept) < 1e-6f && fabsf(ow[3] - 0.1f / kept) < 1e-6f);
    CHECK(fabsf(ow[0] + ow[1] + ow[2] + ow[3] - 1) < 1e-6f);
    CHECK(st.pruned_vertices == 1 && st.renormalized_vertices == 1);
    CHECK(fabsf(prune[0] - fmaxf(0.05f, 0.4f / kept - 0.4f)) < 1e-6f);
    CHECK(oj[4] == 2 && oj[5] == 4 && ow[4] == 0.5f && ow[5] == 0.5f && ow[6] == 0 && ow[7] == 0);
    CHECK(prune[1] == 0);
    CHECK(st.influence_histogram[6] == 1 && st.influence_histogram[2] == 1);
    CHECK(fabsf(st.max_pruning_error - prune[0]) < 1e-7f);
}

static void merges_duplicates(void)
{
    const uint16_t joints[4] = {3, 1, 3, 0};
    const float weights[4] = {0.25f, 0.25f, 0.5f, 0};
    uint16_t oj[4];
    float ow[4];
    sp_prepare_stats st;
    CHECK(prepare(joints, weights, 1, 4, 4, 4, oj, ow, NULL, &st) == SP_OK);
    CHECK(st.merged_duplicates == 1 && oj[0] == 3 && ow[0] == 0.75f && oj[1] == 1 && ow[1] == 0.25f);
}

static void reports_errors_with_the_vertex(void)
{
    uint16_t joints[3 * 2] = {0, 1, 0, 1, 0, 1};
    float weights[3 * 2] = {0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f};
    uint16_t oj[6];
    float ow[6];
    sp_prepare_stats st;
    weights[4] = NAN;
    CHECK(prepare(joints, weights, 3, 2, 2, 2, oj, ow, NULL, &st) == SP_ERR_NONFINITE_WEIGHT && st.error_vertex == 2);
    weights[4] = INFINITY;
    CHECK(prepare(joints, weights, 3, 2, 2, 2, oj, ow, NULL, &st) == SP_ERR_NONFINITE_WEIGHT);
    weights[4] = -0.1f;
    CHECK(prepare(joints, weights, 3, 2, 2, 2, oj, ow, NULL, &st) == SP_ERR_NEGATIVE_WEIGHT && st.error_vertex == 2);
    weights[4] = 0;
    weights[5] = 0;
    CHECK(prepare(joints, weights, 3, 2, 2, 2, oj, ow, NULL, &st) == SP_ERR_NO_INFLUENCE && st.error_vertex == 2);
    weights[4] = 0.5f;
    weights[5] = 0.5f;
    joints[3] = 7;
    CHECK(prepare(joints, weights, 3, 2, 2, 2, oj, ow, NULL, &st) == SP_ERR_JOINT_OUT_OF_RANGE &&
          st.error_vertex == 1 && st.error_joint == 7);
    joints[3] = 1;
    weights[3] = 0; /* zero-weight slots may hold any joint index */
    joints[3] = 9;
    CHECK(prepare(joints, weights, 3, 2, 2, 2, oj, ow, NULL, &st) == SP_OK);
    CHECK(prepare(joints, weights, 3, 2, 65536, 2, oj, ow, NULL, &st) == SP_ERR_TOO_MANY_JOINTS);
    CHECK(prepare(joints, weights, 3, 0, 2, 2, oj, ow, NULL, &st) == SP_ERR_INVALID_ARGUMENT);
    CHECK(prepare(joints, weights, 3, 2, 2, 5, oj, ow, NULL, &st) == SP_ERR_INVALID_ARGUMENT);
    CHECK(prepare(NULL, weights, 3, 2, 2, 2, oj, ow, NULL, &st) == SP_ERR_INVALID_ARGUMENT);
}

/* More slots than SP_MAX_INPUT_INFLUENCES (Blender exports JOINTS_0..2 for 12 influences): the
 * four strongest are kept, a joint repeated in a later slot is merged first, and the pruning
 * error is the strongest dropped weight, exactly as for a short stride. */
static void takes_any_stride(void)
{
    enum { STRIDE = 12 };
    /* vertex 0: 12 distinct joints, weights 1..12 (sum 78) in shuffled slots;
     * vertex 1: joint 9 in slots 0 and 11 (0.05 + 0.3 = the strongest), the rest padding. */
    uint16_t joints[2 * STRIDE] = {4, 11, 0, 7, 2, 9, 5, 1, 10, 3, 8, 6, 9, 1, 2, 0, 0, 0, 0, 0, 0, 0, 0, 9};
    float weights[2 * STRIDE] = {5, 12, 1, 8, 3, 10, 6, 2, 11, 4, 9, 7, 0.05f, 0.25f, 0.4f, 0, 0, 0, 0, 0, 0, 0, 0, 0.3f};
    for (int i = 0; i < STRIDE; ++i) weights[i] /= 78.0f;
    uint16_t oj[8];
    float ow[8], prune[2];
    sp_prepare_stats st;
    CHECK(prepare(joints, weights, 2, STRIDE, 12, 4, oj, ow, prune, &st) == SP_OK);
    CHECK(oj[0] == 11 && oj[1] == 10 && oj[2] == 9 && oj[3] == 8);
    CHECK(fabsf(ow[0] - 12.0f / 42.0f) < 1e-6f && fabsf(ow[3] - 9.0f / 42.0f) < 1e-6f);
    CHECK(fabsf(prune[0] - fmaxf(8.0f / 78.0f, 12.0f / 42.0f - 12.0f / 78.0f)) < 1e-6f);
    CHECK(oj[4] == 2 && oj[5] == 9 && oj[6] == 1 && ow[7] == 0 && fabsf(ow[5] - 0.35f) < 1e-6f);
    CHECK(prune[1] < 1e-7f && st.merged_duplicates == 1 && st.pruned_vertices == 1);
    CHECK(st.influence_histogram[SP_MAX_INPUT_INFLUENCES] == 1 && st.influence_histogram[3] == 1);

    /* The same vertex 0 as the compressor sees it: K = 4 kept, the tuple is the four strongest. */
    size_t scratch_size = sp_compress_scratch_bound(2, STRIDE);
    static unsigned char scratch[1 << 16];
    CHECK(scratch_size <= sizeof(scratch));
    sp_compress_options options;
    sp_compress_options_default(&options);
    uint32_t words[4];
    uint16_t lut[8];
    sp_compressed_skin info;
    CHECK(sp_compress_skin(joints, weights, 2, STRIDE, 12, &options, words, lut, NULL, NULL, &info, scratch,
                           scratch_size) == SP_OK);
    CHECK(info.influences == 4 && info.prepare.pruned_vertices == 1 && info.lut_size == 2);

    /* A bad slot beyond the eighth is still found, with its vertex. */
    weights[STRIDE + 10] = NAN;
    CHECK(prepare(joints, weights, 2, STRIDE, 12, 4, oj, ow, NULL, &st) == SP_ERR_NONFINITE_WEIGHT &&
          st.error_vertex == 1);
}

int main(void)
{
    sorts_prunes_and_renormalises();
    merges_duplicates();
    reports_errors_with_the_vertex();
    takes_any_stride();
    return check_report("test_prepare");
}
