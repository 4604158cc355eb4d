/*
 * Whole skins ("container"): prepare -> choose the codec -> quantise -> tuple table -> pack,
 * and the validating inverse. The only place that sees a skin as a whole.
 */
#include <string.h>

#include "codec_internal.h"

void sp_compress_options_default(sp_compress_options* options)
{
    memset(options, 0, sizeof(*options));
    options->method = SP_METHOD_OSS;
    options->max_influences = 4;
    options->vertex_bits = 32;
    options->merge_dont_care = 1;
    options->sum_tolerance = 1e-3f;
}

/* Scratch layout, every part aligned to 8 bytes. */
typedef struct scratch_layout {
    size_t codes, weights, tuple_index, lut_scratch, joints, significant, total;
} scratch_layout;

static size_t align8(size_t n) { return (n + 7) & ~(size_t)7; }

static scratch_layout layout_scratch(size_t vertex_count)
{
    scratch_layout l;
    size_t v = vertex_count, at = 0;
    l.codes = at;       at += align8(v * sizeof(uint64_t));
    l.weights = at;     at += align8(v * SP_MAX_INFLUENCES * sizeof(float));
    l.tuple_index = at; at += align8(v * sizeof(uint32_t));
    l.lut_scratch = at; at += align8(sp_tuple_lut_scratch_bound(v, SP_MAX_INFLUENCES));
    l.joints = at;      at += align8(v * SP_MAX_INFLUENCES * sizeof(uint16_t));
    l.significant = at; at += align8(v);
    l.total = at;
    return l;
}

size_t sp_compress_scratch_bound(size_t vertex_count, size_t input_stride)
{
    (void)input_stride; /* the prepared copy is always K <= 4 wide */
    return layout_scratch(vertex_count).total;
}

typedef struct skin_work {
    const uint16_t* joints;  /* prepared, K per vertex */
    const float* weights;
    size_t vertex_count;
    uint32_t k;
    uint64_t* codes;
    uint8_t* significant;
    uint32_t* tuple_index;
    uint16_t* lut;
    void* lut_scratch;
    size_t lut_scratch_size;
    int merge;
} skin_work;

/* Quantise with the codec and build the tuple table; returns the tuple index width. */
static sp_result quantise_and_index(const skin_work* w, const sp_codec* codec, size_t* lut_size)
{
    sp_result r = sp_encode_weights_batch(codec, w->weights, w->vertex_count, w->codes, w->significant);
    if (r != SP_OK) return r;
    return sp_build_tuple_lut(w->joints, w->merge ? w->significant : NULL, w->vertex_count, w->k, w->lut,
                              lut_size, w->tuple_index, w->lut_scratch, w->lut_scratch_size);
}

static sp_result codec_for_weight_budget(const sp_compress_options* o, uint32_t k, int64_t bits, sp_codec* codec)
{
    if (bits < 0 && k > 1) return SP_ERR_BITS_OUT_OF_RANGE;
    if (bits > SP_MAX_WEIGHT_BITS) bits = SP_MAX_WEIGHT_BITS;
    return sp_codec_from_bits(o->method, k, (uint32_t)(bits < 0 ? 0 : bits), codec);
}

/*
 * A whole-vertex budget splits into tuple bits + weight bits, but the tuple count depends on
 * the quantisation (don't-care slots). Start from the tuple count without merging (an upper
 * bound), then give the bits merging saved back to the weights if the table still fits.
 */
static sp_result fit_vertex_budget(const skin_work* w, const sp_compress_options* o, sp_codec* codec,
                                   size_t* lut_size)
{
    size_t plain_size = 0;
    sp_result r = sp_build_tuple_lut(w->joints, NULL, w->vertex_count, w->k, w->lut, &plain_size, w->tuple_index,
                                     w->lut_scratch, w->lut_scratch_size);
    if (r != SP_OK) return r;
    uint32_t plain_bits = sp_index_bits(plain_size);
    int64_t budget = (int64_t)o->vertex_bits - plain_bits;
    if ((r = codec_for_weight_budget(o, w->k, budget, codec)) != SP_OK) return r;
    if ((r = quantise_and_index(w, codec, lut_size)) != SP_OK) return r;
    uint32_t merged_bits = sp_index_bits(*lut_size);
    if (merged_bits >= plain_bits) return SP_OK;

    sp_codec finer;
    if (codec_for_weight_budget(o, w->k, (int64_t)o->vertex_bits - merged_bits, &finer) != SP_OK) return SP_OK;
    if ((r = quantise_and_index(w, &finer, lut_size)) != SP_OK) return r;
    if (sp_index_bits(*lut_size) + finer.bits <= o->vertex_bits) {
        *codec = finer;
        return SP_OK;
    }
    return quantise_and_index(w, codec, lut_size); /* finer weights un-merged too much: go back */
}

static uint32_t used_influences(const sp_prepare_stats* prep, uint32_t max_influences)
{
    uint32_t most = 1;
    for (uint32_t n = 1; n <= SP_MAX_INPUT_INFLUENCES; ++n)
        if (prep->influence_histogram[n]) most = n;
    return most < max_influences ? most : max_influences;
}

/* Narrows K-wide prepared arrays to k wide in place (k <= K, so a forward copy is safe). */
static void narrow_influences(uint16_t* joints, float* weights, size_t vertex_count, uint32_t from, uint32_t to)
{
    for (size_t v = 0; v < vertex_count; ++v)
        for (uint32_t i = 0; i < to; ++i) {
            joints[v * to + i] = joints[v * from + i];
            weights[v * to + i] = weights[v * from + i];
        }
}

/* The option checks of sp_compress_skin: exactly one budget, no negative (or NaN) limit, K in range. */
static int compress_options_valid(const sp_compress_options* options)
{
    int budgets = (options->vertex_bits != 0) + (options->weight_bits != 0) + (options->max_spacing > 0) +
                  (options->max_error > 0);
    return budgets == 1 && options->max_error >= 0 && options->max_spacing >= 0 && options->max_influences >= 1 &&
           options->max_influences <= SP_MAX_INFLUENCES;
}

/* The codec of the options' budget, and the codes and tuple table of w under it. */
static sp_result quantise_for_budget(skin_work* w, const sp_compress_options* options, sp_codec* codec,
                                     size_t* lut_size)
{
    if (options->vertex_bits) return fit_vertex_budget(w, options, codec, lut_size);
    sp_result r;
    if (options->weight_bits) r = sp_codec_from_bits(options->method, w->k, options->weight_bits, codec);
    else if (options->max_error > 0) r = sp_codec_from_max_error(options->method, w->k, options->max_error, codec);
    else r = sp_codec_from_spacing(options->method, w->k, options->max_spacing, codec);
    return r == SP_OK ? quantise_and_index(w, codec, lut_size) : r;
}

/* The sizes and bit counts of a finished compression into result (its prepare and
 * quantization statistics are already there). */
static void fill_compressed(sp_compressed_skin* result, const sp_codec* codec, uint32_t k, uint32_t tuple_bits,
                            size_t vertex_count, size_t joint_count, size_t lut_size)
{
    result->codec = *codec;
    result->influences = k;
    result->tuple_bits = tuple_bits;
    result->weight_bits = codec->bits;
    result->words_per_vertex = sp_words_per_vertex(tuple_bits, codec->bits);
    result->joint_bytes = joint_count <= 256 ? 1 : 2;
    result->vertex_count = vertex_count;
    result->joint_count = joint_count;
    result->lut_size = lut_size;
    result->lut_bits_per_vertex = (double)lut_size * k * 8.0 * result->joint_bytes / (double)vertex_count;
    result->bits_per_vertex = tuple_bits + codec->bits + result->lut_bits_per_vertex;
}

sp_result sp_compress_skin(const uint16_t* joints, const float* weights, size_t vertex_count, size_t input_stride,
                           size_t joint_count, const sp_compress_options* options, uint32_t* words, uint16_t* lut,
                           float* per_vertex_error, float* per_vertex_pruning, sp_compressed_skin* result,
                           void* scratch, size_t scratch_size)
{
    if (!options || !result || !words || !lut || vertex_count == 0) return SP_ERR_INVALID_ARGUMENT;
    memset(result, 0, sizeof(*result));
    if (!compress_options_valid(options)) return SP_ERR_INVALID_ARGUMENT;
    scratch_layout l = layout_scratch(vertex_count);
    if (!scratch || scratch_size < l.total) return SP_ERR_BUFFER_TOO_SMALL;
    if (((uintptr_t)scratch & 7) != 0) return SP_ERR_INVALID_ARGUMENT;

    char* base = (char*)scratch;
    uint16_t* prepared_joints = (uint16_t*)(base + l.joints);
    float* prepared_weights = (float*)(base + l.weights);
    sp_result r = sp_prepare_influences(joints, weights, vertex_count, input_stride, joint_count,
                                        options->max_influences, options->sum_tolerance, prepared_joints,
                                        prepared_weights, per_vertex_pruning, &result->prepare);
    if (r != SP_OK) return r;
    uint32_t k = used_influences(&result->prepare, options->max_influences);
    narrow_influences(prepared_joints, prepared_weights, vertex_count, options->max_influences, k);

    skin_work w = {prepared_joints, prepared_weights, vertex_count, k, (uint64_t*)(base + l.codes),
                   (uint8_t*)(base + l.significant), (uint32_t*)(base + l.tuple_index), lut,
                   base + l.lut_scratch, sp_tuple_lut_scratch_bound(vertex_count, SP_MAX_INFLUENCES),
                   options->merge_dont_care};
    size_t lut_size = 0;
    sp_codec codec;
    if ((r = quantise_for_budget(&w, options, &codec, &lut_size)) != SP_OK) return r;
    uint32_t tuple_bits = sp_index_bits(lut_size);
    if ((r = sp_pack_vertices(w.tuple_index, w.codes, vertex_count, tuple_bits, codec.bits, words)) != SP_OK)
        return r;
    r = sp_measure_weight_errors(&codec, prepared_weights, w.codes, vertex_count, per_vertex_error,
                                 &result->quantization);
    if (r != SP_OK) return r;
    fill_compressed(result, &codec, k, tuple_bits, vertex_count, joint_count, lut_size);
    return SP_OK;
}

sp_result sp_decompress_skin(const sp_codec* codec, const uint32_t* words, size_t vertex_count, uint32_t tuple_bits,
                             const uint16_t* lut, size_t lut_size, size_t joint_count, uint16_t* out_joints,
                             float* out_weights, size_t* error_vertex)
{
    if (!codec || !words || !lut || !out_joints || !out_weights || lut_size == 0) return SP_ERR_INVALID_ARGUMENT;
    if (joint_count == 0 || joint_count > SP_MAX_JOINTS) return SP_ERR_TOO_MANY_JOINTS;
    uint32_t per_vertex = sp_words_per_vertex(tuple_bits, codec->bits);
    if (per_vertex == 0 || (tuple_bits < 32 && lut_size > ((size_t)1 << tuple_bits)))
        return SP_ERR_BITS_OUT_OF_RANGE;
    uint32_t k = codec->influences;
    for (size_t i = 0; i < lut_size * k; ++i)
        if (lut[i] >= joint_count) {
            if (error_vertex) *error_vertex = i / k; /* the offending table entry */
            return SP_ERR_JOINT_OUT_OF_RANGE;
        }
    for (size_t v = 0; v < vertex_count; ++v) {
        uint32_t tuple;
        uint64_t code;
        sp_result r = sp_unpack_vertices(words + v * per_vertex, 1, tuple_bits, codec->bits, &tuple, &code, NULL);
        if (r == SP_OK && tuple >= lut_size) r = SP_ERR_TUPLE_OUT_OF_RANGE;
        if (r == SP_OK) r = sp_decode_weights_batch(codec, &code, 1, out_weights + v * k, NULL);
        if (r != SP_OK) {
            if (error_vertex) *error_vertex = v;
            return r;
        }
        memcpy(out_joints + v * k, lut + (size_t)tuple * k, k * sizeof(uint16_t));
        uint32_t slot, other_slot;
        if (sp_find_duplicate_joint(out_joints + v * k, out_weights + v * k, k, &slot, &other_slot)) {
            if (error_vertex) *error_vertex = v;
            return SP_ERR_DUPLICATE_JOINT;
        }
    }
    return SP_OK;
}
