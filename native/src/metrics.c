/* Error metrics: per-vertex L-inf weight error and its summary (the add-on's heat map). */
#include <math.h>
#include <string.h>

#include "skinpack.h"

/* Running sums for one pass over per-vertex errors; bins span [0, histogram_max]. */
typedef struct error_accumulator {
    sp_error_stats* stats;
    double sum, sum_sq;
} error_accumulator;

static void accumulate(error_accumulator* acc, double e, size_t v)
{
    sp_error_stats* s = acc->stats;
    acc->sum += e;
    acc->sum_sq += e * e;
    if (e > s->max_error) {
        s->max_error = e;
        s->worst_vertex = v;
    }
    double at = s->histogram_max > 0 ? e / s->histogram_max * SP_ERROR_HISTOGRAM_BINS : 0;
    s->histogram[at >= SP_ERROR_HISTOGRAM_BINS ? SP_ERROR_HISTOGRAM_BINS - 1 : (size_t)at]++;
}

static void finish(error_accumulator* acc, size_t vertex_count)
{
    acc->stats->mean_error = vertex_count ? acc->sum / (double)vertex_count : 0;
    acc->stats->rms_error = vertex_count ? sqrt(acc->sum_sq / (double)vertex_count) : 0;
}

void sp_summarize_errors(const float* per_vertex, size_t vertex_count, double histogram_max, sp_error_stats* stats)
{
    memset(stats, 0, sizeof(*stats));
    /* The histogram must cover every value: widen it to the largest error if needed. */
    double largest = 0;
    for (size_t v = 0; v < vertex_count; ++v) {
        largest = fmax(largest, per_vertex[v]);
        if (per_vertex[v] > histogram_max) stats->vertices_over_bound++;
    }
    stats->histogram_max = fmax(histogram_max, largest);
    error_accumulator acc = {stats, 0, 0};
    for (size_t v = 0; v < vertex_count; ++v) accumulate(&acc, per_vertex[v], v);
    finish(&acc, vertex_count);
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
    /* One pass: the bins are fixed by the codec's bound; errors above it land in the last bin
     * and are counted (a correct encoder never produces them). */
    stats->histogram_max = codec->max_error;
    error_accumulator acc = {stats, 0, 0};
    for (size_t v = 0; v < vertex_count; ++v) {
        if (codes[v] > codec->max_code) return SP_ERR_CODE_OUT_OF_RANGE;
        float e = vertex_error(codec, reference + v * k, codes[v]);
        if (per_vertex) per_vertex[v] = e;
        if (e > codec->max_error) stats->vertices_over_bound++;
        accumulate(&acc, e, v);
    }
    finish(&acc, vertex_count);
    return SP_OK;
}
