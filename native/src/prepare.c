/*
 * Weight preparation: validate, merge duplicate joints, sort descending, prune to K, renormalise.
 * Errors are reported, never silently fixed; only the weight sum is renormalised (and counted).
 * Any input stride: only the K + 1 strongest influences of a vertex are kept while reading it.
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

/* Puts item into top[0..*count), kept in comes_before order and at most capacity long: the
 * strongest influences of a vertex without storing all of them (any input stride). */
static void keep_strongest(influence* top, size_t* count, size_t capacity, influence item)
{
    size_t j = *count;
    if (j == capacity) {
        if (!comes_before(item, top[capacity - 1])) return;
        --j;
    } else {
        ++*count;
    }
    while (j > 0 && comes_before(item, top[j - 1])) {
        top[j] = top[j - 1];
        --j;
    }
    top[j] = item;
}

/* Validates one vertex's slots in order; the first bad slot decides the result. */
static sp_result check_vertex(const uint16_t* joints, const float* weights, size_t stride, size_t joint_count,
                              uint32_t* bad_joint)
{
    size_t used = 0;
    for (size_t i = 0; i < stride; ++i) {
        float w = weights[i];
        if (!isfinite(w)) return SP_ERR_NONFINITE_WEIGHT;
        if (w < 0) return SP_ERR_NEGATIVE_WEIGHT;
        if (w == 0) continue; /* padding slots: their joint index is irrelevant */
        if (joints[i] >= joint_count) {
            *bad_joint = joints[i];
            return SP_ERR_JOINT_OUT_OF_RANGE;
        }
        ++used;
    }
    return used ? SP_OK : SP_ERR_NO_INFLUENCE;
}

/* The vertex's distinct non-zero joints, duplicates merged in slot order: the `capacity`
 * strongest go to top (sorted), their number to *count, all of them to *distinct and the
 * sum of every weight to *total. */
static void strongest_influences(const uint16_t* joints, const float* weights, size_t stride, influence* top,
                                 size_t capacity, size_t* count, size_t* distinct, double* total, size_t* merged)
{
    *count = *distinct = 0;
    *total = 0;
    for (size_t i = 0; i < stride; ++i) {
        if (weights[i] == 0) continue;
        size_t earlier = 0;
        while (earlier < i && !(weights[earlier] != 0 && joints[earlier] == joints[i])) ++earlier;
        if (earlier < i) { /* merged into the joint's first slot */
            ++*merged;
            continue;
        }
        influence item = {joints[i], weights[i]};
        for (size_t j = i + 1; j < stride; ++j)
            if (weights[j] != 0 && joints[j] == joints[i]) item.weight += weights[j];
        *total += item.weight;
        ++*distinct;
        keep_strongest(top, count, capacity, item);
    }
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
        max_influences < 1 || max_influences > SP_MAX_INFLUENCES)
        return SP_ERR_INVALID_ARGUMENT;

    double pruning_sq = 0;
    size_t k = max_influences;
    for (size_t v = 0; v < vertex_count; ++v) {
        const uint16_t* vertex_joints = joints + v * input_stride;
        const float* vertex_weights = weights + v * input_stride;
        sp_result r = check_vertex(vertex_joints, vertex_weights, input_stride, joint_count, &st->error_joint);
        if (r != SP_OK) {
            st->error_vertex = v;
            return r;
        }
        /* The K kept influences and the strongest pruned one (the vertex's pruning error). */
        influence items[SP_MAX_INFLUENCES + 1];
        size_t count = 0, kept = 0;
        double total = 0;
        strongest_influences(vertex_joints, vertex_weights, input_stride, items, k + 1, &kept, &count, &total,
                             &st->merged_duplicates);
        st->influence_histogram[count < SP_MAX_INPUT_INFLUENCES ? count : SP_MAX_INPUT_INFLUENCES]++;

        double kept_total = 0;
        if (kept > k) kept = k;
        for (size_t i = 0; i < kept; ++i) kept_total += items[i].weight;
        if (fabs(total - 1.0) > sum_tolerance) st->renormalized_vertices++;
        if (count > k) st->pruned_vertices++;

        /* Pruning error: L-inf change of every input joint's normalised weight; of the pruned
         * joints the strongest changes most. */
        double pruning = 0;
        for (size_t i = 0; i < k; ++i) {
            uint16_t joint = i < kept ? items[i].joint : 0;
            float w = i < kept ? (float)(items[i].weight / kept_total) : 0.0f;
            out_joints[v * k + i] = joint;
            out_weights[v * k + i] = w;
            if (i < kept) pruning = fmax(pruning, fabs(items[i].weight / total - w));
        }
        if (count > k) pruning = fmax(pruning, items[k].weight / total);
        if (out_pruning_error) out_pruning_error[v] = (float)pruning;
        if (pruning > st->max_pruning_error) st->max_pruning_error = (float)pruning;
        pruning_sq += pruning * pruning;
    }
    st->rms_pruning_error = vertex_count ? sqrt(pruning_sq / (double)vertex_count) : 0;
    return SP_OK;
}
