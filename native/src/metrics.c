/* Error metrics: per-vertex L-inf weight error and its summary (the add-on's heat map). */
#include <math.h>
#include <string.h>

#include "skinpack.h"

void sp_summarize_errors(const float* per_vertex, size_t vertex_count, double histogram_max, sp_error_stats* stats)
{
    memset(stats, 0, sizeof(*stats));
    double sum = 0, sum_sq = 0;
    for (size_t v = 0; v < vertex_count; ++v) {
        double e = per_vertex[v];
        sum += e;
        sum_sq += e * e;
        if (e > stats->max_error) {
            stats->max_error = e;
            stats->worst_vertex = v;
        }
    }
    stats->mean_error = vertex_count ? sum / (double)vertex_count : 0;
    stats->rms_error = vertex_count ? sqrt(sum_sq / (double)vertex_count) : 0;
    stats->histogram_max = histogram_max > stats->max_error ? histogram_max : stats->max_error;
    for (size_t v = 0; v < vertex_count; ++v) {
        size_t bin = 0;
        if (stats->histogram_max > 0) {
            double at = per_vertex[v] / stats->histogram_max * SP_ERROR_HISTOGRAM_BINS;
            bin = at >= SP_ERROR_HISTOGRAM_BINS ? SP_ERROR_HISTOGRAM_BINS - 1 : (size_t)at;
        }
        stats->histogram[bin]++;
        if (per_vertex[v] > histogram_max) stats->vertices_over_bound++;
    }
}

static float vertex_error(const sp_codec* codec, const float* reference, uint64_t code)
{
    float decoded[SP_MAX_INFLUENCES];
    sp_decode_weights(codec, code, decoded);
    float worst = 0;
    for (uint32_t i = 0; i < codec->influences; ++i) worst = fmaxf(worst, fabsf(decoded[i] - reference[i]));
    return worst;
}

sp_result sp_measure_weight_errors(const sp_codec* codec, const float* reference, const uint64_t* codes,
                                   size_t vertex_count, float* per_vertex, sp_error_stats* stats)
{
    if (!codec || !reference || !codes || !stats) return SP_ERR_INVALID_ARGUMENT;
    uint32_t k = codec->influences;
    memset(stats, 0, sizeof(*stats));
    double sum = 0, sum_sq = 0;
    size_t histogram_raw[SP_ERROR_HISTOGRAM_BINS] = {0};
    double bound = codec->max_error;
    /* One pass: bins are fixed by the codec bound; errors above it land in the last bin. */
    for (size_t v = 0; v < vertex_count; ++v) {
        if (codes[v] > codec->max_code) return SP_ERR_CODE_OUT_OF_RANGE;
        float e = vertex_error(codec, reference + v * k, codes[v]);
        if (per_vertex) per_vertex[v] = e;
        sum += e;
        sum_sq += (double)e * e;
        if (e > stats->max_error) {
            stats->max_error = e;
            stats->worst_vertex = v;
        }
        if (e > bound) stats->vertices_over_bound++;
        double at = bound > 0 ? e / bound * SP_ERROR_HISTOGRAM_BINS : 0;
        histogram_raw[at >= SP_ERROR_HISTOGRAM_BINS ? SP_ERROR_HISTOGRAM_BINS - 1 : (size_t)at]++;
    }
    stats->mean_error = vertex_count ? sum / (double)vertex_count : 0;
    stats->rms_error = vertex_count ? sqrt(sum_sq / (double)vertex_count) : 0;
    stats->histogram_max = bound;
    memcpy(stats->histogram, histogram_raw, sizeof(histogram_raw));
    return SP_OK;
}
