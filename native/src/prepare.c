/*
 * Weight preparation: validate, merge duplicate joints, sort descending, prune to K, renormalise.
 * Errors are reported, never silently fixed; only the weight sum is renormalised (and counted).
 */
#include <math.h>
#include <string.h>

#include "skinpack.h"

typedef struct influence {
    uint16_t joint;
    float weight;
} influence;

/* Descending weight, ties to the lower joint: deterministic whatever the input order. */
static int comes_before(influence a, influence b)
{
    return a.weight > b.weight || (a.weight == b.weight && a.joint < b.joint);
}

static void sort_influences(influence* items, size_t count)
{
    for (size_t i = 1; i < count; ++i) {
        influence item = items[i];
        size_t j = i;
        while (j > 0 && comes_before(item, items[j - 1])) {
            items[j] = items[j - 1];
            --j;
        }
        items[j] = item;
    }
}

/* Validates one vertex and collects its non-zero influences with duplicates merged. */
static sp_result gather_vertex(const uint16_t* joints, const float* weights, size_t stride, size_t joint_count,
                               influence* items, size_t* count, size_t* merged, uint32_t* bad_joint)
{
    size_t n = 0;
    for (size_t i = 0; i < stride; ++i) {
        float w = weights[i];
        if (!isfinite(w)) return SP_ERR_NONFINITE_WEIGHT;
        if (w < 0) return SP_ERR_NEGATIVE_WEIGHT;
        if (w == 0) continue; /* padding slots: their joint index is irrelevant */
        if (joints[i] >= joint_count) {
            *bad_joint = joints[i];
            return SP_ERR_JOINT_OUT_OF_RANGE;
        }
        size_t at = 0;
        while (at < n && items[at].joint != joints[i]) ++at;
        if (at < n) {
            items[at].weight += w;
            ++*merged;
        } else {
            items[n].joint = joints[i];
            items[n].weight = w;
            ++n;
        }
    }
    *count = n;
    return n ? SP_OK : SP_ERR_NO_INFLUENCE;
}

sp_result sp_prepare_influences(const uint16_t* joints, const float* weights, size_t vertex_count,
                                size_t input_stride, size_t joint_count, size_t max_influences, float sum_tolerance,
                                uint16_t* out_joints, float* out_weights, float* out_pruning_error,
                                sp_prepare_stats* stats)
{
    sp_prepare_stats local;
    sp_prepare_stats* st = stats ? stats : &local;
    memset(st, 0, sizeof(*st));
    st->vertex_count = vertex_count;
    if (joint_count > SP_MAX_JOINTS) return SP_ERR_TOO_MANY_JOINTS;
    if (!joints || !weights || !out_joints || !out_weights || joint_count == 0 || input_stride < 1 ||
        input_stride > SP_MAX_INPUT_INFLUENCES || max_influences < 1 || max_influences > SP_MAX_INFLUENCES)
        return SP_ERR_INVALID_ARGUMENT;

    double pruning_sq = 0;
    size_t k = max_influences;
    for (size_t v = 0; v < vertex_count; ++v) {
        influence items[SP_MAX_INPUT_INFLUENCES];
        size_t count = 0;
        sp_result r = gather_vertex(joints + v * input_stride, weights + v * input_stride, input_stride,
                                    joint_count, items, &count, &st->merged_duplicates, &st->error_joint);
        if (r != SP_OK) {
            st->error_vertex = v;
            return r;
        }
        sort_influences(items, count);
        st->influence_histogram[count]++;

        double total = 0, kept_total = 0;
        size_t kept = count < k ? count : k;
        for (size_t i = 0; i < count; ++i) total += items[i].weight;
        for (size_t i = 0; i < kept; ++i) kept_total += items[i].weight;
        if (fabs(total - 1.0) > sum_tolerance) st->renormalized_vertices++;
        if (count > k) st->pruned_vertices++;

        /* Pruning error: L-inf change of every input joint's normalised weight. */
        double pruning = 0;
        for (size_t i = 0; i < k; ++i) {
            uint16_t joint = i < kept ? items[i].joint : 0;
            float w = i < kept ? (float)(items[i].weight / kept_total) : 0.0f;
            out_joints[v * k + i] = joint;
            out_weights[v * k + i] = w;
            if (i < kept) pruning = fmax(pruning, fabs(items[i].weight / total - w));
        }
        for (size_t i = kept; i < count; ++i) pruning = fmax(pruning, items[i].weight / total);
        if (out_pruning_error) out_pruning_error[v] = (float)pruning;
        if (pruning > st->max_pruning_error) st->max_pruning_error = (float)pruning;
        pruning_sq += pruning * pruning;
    }
    st->rms_pruning_error = vertex_count ? sqrt(pruning_sq / (double)vertex_count) : 0;
    return SP_OK;
}
