/* Whole-skin compression: budgets, round trip within bound, corrupt-data detection. */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "skinpack.h"

enum { V = 4000, STRIDE = 6, JOINTS = 300 };
static uint16_t in_joints[V * STRIDE];
static float in_weights[V * STRIDE];

/* A limb-like skin: each vertex near a bone of a chain, blended with its neighbours. */
static void make_skin(void)
{
    for (size_t v = 0; v < V; ++v) {
        double t = (double)v / V * (JOINTS - 1);
        size_t bone = (size_t)t;
        double sum = 0, raw[STRIDE];
        size_t count = 1 + rng_next() % STRIDE;
        for (size_t i = 0; i < STRIDE; ++i) {
            size_t joint = bone + i < JOINTS ? bone + i : bone - i;
            in_joints[v * STRIDE + i] = (uint16_t)joint;
            raw[i] = i < count ? exp(-fabs(t - (double)joint) * (1 + rng_unit())) : 0;
            sum += raw[i];
        }
        for (size_t i = 0; i < STRIDE; ++i) in_weights[v * STRIDE + i] = (float)(raw[i] / sum);
    }
}

typedef struct compressed {
    uint32_t words[2 * V];
    uint16_t lut[V * 4];
    float error[V], pruning[V];
    sp_compressed_skin info;
} compressed;

static sp_result compress(const sp_compress_options* o, compressed* out)
{
    size_t size = sp_compress_scratch_bound(V, STRIDE);
    void* scratch = malloc(size);
    sp_result r = sp_compress_skin(in_joints, in_weights, V, STRIDE, JOINTS, o, out->words, out->lut, out->error,
                                   out->pruning, &out->info, scratch, size);
    free(scratch);
    return r;
}

/* Decoded joints equal the prepared ones wherever the decoded weight is non-zero. */
static void check_round_trip(const compressed* c)
{
    static uint16_t joints[V * 4], prepared_joints[V * 4];
    static float weights[V * 4], prepared_weights[V * 4];
    uint32_t k = c->info.influences;
    size_t bad = 0;
    CHECK(sp_decompress_skin(&c->info.codec, c->words, V, c->info.tuple_bits, c->lut, c->info.lut_size, JOINTS,
                             joints, weights, &bad) == SP_OK);
    CHECK(sp_prepare_influences(in_joints, in_weights, V, STRIDE, JOINTS, k, 1e-3f, prepared_joints,
                                prepared_weights, NULL, NULL) == SP_OK);
    double worst = 0;
    for (size_t v = 0; v < V; ++v)
        for (uint32_t i = 0; i < k; ++i) {
            if (weights[v * k + i] > 0) CHECK(joints[v * k + i] == prepared_joints[v * k + i]);
            double e = fabs((double)weights[v * k + i] - prepared_weights[v * k + i]);
            worst = fmax(worst, e);
            CHECK(e <= c->info.codec.max_error);
        }
    CHECK(fabs(worst - c->info.quantization.max_error) < 1e-9);
    CHECK(c->info.quantization.vertices_over_bound == 0);
}

static void budgets(void)
{
    static compressed c;
    sp_compress_options o;
    for (int m = 0; m < SP_METHOD_COUNT; ++m)
        for (uint32_t bits = 32; bits <= 64; bits += 16) {
            sp_compress_options_default(&o);
            o.method = (sp_method)m;
            o.vertex_bits = bits;
            CHECK(compress(&o, &c) == SP_OK);
            CHECK(c.info.tuple_bits + c.info.weight_bits <= bits);
            CHECK(c.info.influences == 4 && c.info.prepare.pruned_vertices > 0);
            CHECK(c.info.words_per_vertex == (bits == 32 ? 1u : 2u));
            CHECK(c.info.joint_bytes == 2);
            check_round_trip(&c);
            /* Without don't-care merging the table can only be larger. */
            size_t merged = c.info.lut_size;
            o.merge_dont_care = 0;
            CHECK(compress(&o, &c) == SP_OK && c.info.lut_size >= merged);
            check_round_trip(&c);
        }
    sp_compress_options_default(&o);
    o.vertex_bits = 0;
    o.max_spacing = 1e-3;
    CHECK(compress(&o, &c) == SP_OK && c.info.codec.max_spacing <= 1e-3);
    check_round_trip(&c);
    o.max_spacing = 0;
    o.weight_bits = 22;
    o.max_influences = 3;
    CHECK(compress(&o, &c) == SP_OK && c.info.weight_bits <= 22 && c.info.influences == 3);
    check_round_trip(&c);
    o.vertex_bits = 32; /* two budgets at once */
    CHECK(compress(&o, &c) == SP_ERR_INVALID_ARGUMENT);
    sp_compress_options_default(&o);
    o.vertex_bits = 8; /* smaller than the tuple index alone */
    CHECK(compress(&o, &c) == SP_ERR_BITS_OUT_OF_RANGE);
}

static void corrupt_data_is_rejected(void)
{
    static compressed c;
    static uint16_t joints[V * 4];
    static float weights[V * 4];
    sp_compress_options o;
    sp_compress_options_default(&o);
    CHECK(compress(&o, &c) == SP_OK);
    const sp_codec* codec = &c.info.codec;
    uint32_t tb = c.info.tuple_bits, k = c.info.influences;
    size_t bad = 0;
    /* a code past T(N) */
    uint32_t saved = c.words[17];
    c.words[17] = (uint32_t)(codec->max_code + 1) | (c.words[17] & ~((1u << codec->bits) - 1));
    CHECK(sp_decompress_skin(codec, c.words, V, tb, c.lut, c.info.lut_size, JOINTS, joints, weights, &bad) ==
              SP_ERR_CODE_OUT_OF_RANGE &&
          bad == 17);
    c.words[17] = saved;
    /* a tuple index past the table */
    size_t lut_size = c.info.lut_size;
    CHECK(lut_size < (1u << tb));
    c.words[5] = (c.words[5] & ((1u << codec->bits) - 1)) | (uint32_t)lut_size << codec->bits;
    CHECK(sp_decompress_skin(codec, c.words, V, tb, c.lut, lut_size, JOINTS, joints, weights, &bad) ==
              SP_ERR_TUPLE_OUT_OF_RANGE &&
          bad == 5);
    c.words[5] = 0;
    /* a table joint past the skin */
    uint16_t joint = c.lut[3 * k + 1];
    c.lut[3 * k + 1] = JOINTS;
    CHECK(sp_decompress_skin(codec, c.words, V, tb, c.lut, lut_size, JOINTS, joints, weights, &bad) ==
              SP_ERR_JOINT_OUT_OF_RANGE &&
          bad == 3);
    c.lut[3 * k + 1] = joint;
    /* widths that cannot be right */
    CHECK(sp_decompress_skin(codec, c.words, V, 60, c.lut, lut_size, JOINTS, joints, weights, &bad) ==
          SP_ERR_BITS_OUT_OF_RANGE);
    CHECK(sp_decompress_skin(codec, c.words, V, 1, c.lut, lut_size, JOINTS, joints, weights, &bad) ==
          SP_ERR_BITS_OUT_OF_RANGE);
    CHECK(sp_decompress_skin(codec, c.words, V, tb, c.lut, lut_size, JOINTS, joints, weights, &bad) == SP_OK);
}

static void bad_input_names_the_vertex(void)
{
    static compressed c;
    sp_compress_options o;
    sp_compress_options_default(&o);
    float saved = in_weights[123 * STRIDE];
    in_weights[123 * STRIDE] = NAN;
    CHECK(compress(&o, &c) == SP_ERR_NONFINITE_WEIGHT && c.info.prepare.error_vertex == 123);
    in_weights[123 * STRIDE] = saved;
    size_t size = sp_compress_scratch_bound(V, STRIDE);
    void* scratch = malloc(size);
    CHECK(sp_compress_skin(in_joints, in_weights, V, STRIDE, JOINTS, &o, c.words, c.lut, NULL, NULL, &c.info,
                           scratch, size - 1) == SP_ERR_BUFFER_TOO_SMALL);
    free(scratch);
}

/* No global state: concurrent compressions give the single-threaded result bit for bit. */
static void *compress_in_thread(void* out)
{
    sp_compress_options o;
    sp_compress_options_default(&o);
    return compress(&o, (compressed*)out) == SP_OK ? out : NULL;
}

static void threads_agree(void)
{
    static compressed reference, results[4];
    pthread_t threads[4];
    CHECK(compress_in_thread(&reference) != NULL);
    for (int i = 0; i < 4; ++i) CHECK(pthread_create(&threads[i], NULL, compress_in_thread, &results[i]) == 0);
    for (int i = 0; i < 4; ++i) {
        void* ok = NULL;
        CHECK(pthread_join(threads[i], &ok) == 0 && ok != NULL);
        CHECK(memcmp(results[i].words, reference.words, sizeof(reference.words)) == 0);
        CHECK(memcmp(results[i].lut, reference.lut, sizeof(reference.lut)) == 0);
        CHECK(results[i].info.lut_size == reference.info.lut_size);
    }
}

static void summary_of_errors(void)
{
    const float errors[4] = {0, 0.25f, 0.5f, 1.0f};
    sp_error_stats s;
    sp_summarize_errors(errors, 4, 0.5, &s);
    CHECK(s.max_error == 1.0 && s.worst_vertex == 3 && s.vertices_over_bound == 1 && s.histogram_max == 1.0);
    CHECK(fabs(s.mean_error - 0.4375) < 1e-12 && fabs(s.rms_error - sqrt(1.3125 / 4)) < 1e-12);
    CHECK(s.histogram[0] == 1 && s.histogram[4] == 1 && s.histogram[8] == 1 && s.histogram[15] == 1);
}

int main(void)
{
    summary_of_errors();
    make_skin();
    threads_agree();
    budgets();
    corrupt_data_is_rejected();
    bad_input_names_the_vertex();
    return check_report("test_skin");
}
