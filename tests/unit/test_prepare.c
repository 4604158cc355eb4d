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
    CHECK(prepare(joints, weights, 3, 9, 2, 2, oj, ow, NULL, &st) == SP_ERR_INVALID_ARGUMENT);
    CHECK(prepare(joints, weights, 3, 2, 2, 5, oj, ow, NULL, &st) == SP_ERR_INVALID_ARGUMENT);
    CHECK(prepare(NULL, weights, 3, 2, 2, 2, oj, ow, NULL, &st) == SP_ERR_INVALID_ARGUMENT);
}

int main(void)
{
    sorts_prunes_and_renormalises();
    merges_duplicates();
    reports_errors_with_the_vertex();
    return check_report("test_prepare");
}
