/*
 * shader_harness.c - runs the GLSL decoders on a Vulkan device (lavapipe in CI) and compares
 * them with libskinpack, bit for bit where the format has integers.
 *
 *   skinpack_shader_harness codes       every code of small configurations, every method and K
 *   skinpack_shader_harness widths      sampled codes for every weight width 1..64
 *   skinpack_shader_harness vertices    packed vertex words + tuple LUT (u8 and u16) of random skins
 *   skinpack_shader_harness mesh FILE   a real mesh skinned in a pose (skin.comp) vs C skinning
 *   skinpack_shader_harness meshlets FILE   skin.mesh's palette / local LUT / triangle fetch
 *   skinpack_shader_harness meshshader FILE skin.mesh's body (skin_meshlet.glsl) run as compute:
 *                                           skinning, triangle and normal-cone culling vs C
 *   skinpack_shader_harness conformance FILE  the spec's conformance vectors (weights.jsonl)
 *
 * Per decoded code the checks are: (1) the GPU's integers re-encode to the input code with the
 * format.md formulas (exact at every width); (2) they lie on the grid (sum q_i = s, descending;
 * Any: x_i < q_i); (3) where s <= 2^22 they equal round(w_C * s) of the C decoder's weights;
 * (4) the GPU's float weights are within 1e-6 of sp_decode_weights. Codecs that the 32-bit
 * decoder handles are decoded twice, once forced through the 64-bit decoder.
 * Exit status 1 on any mismatch or Vulkan failure.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "skinpack.h"
#include "sp_gpu.h"
#include "vk_context.h"

#define WEIGHT_TOLERANCE 1e-6f

typedef unsigned __int128 u128;

typedef struct decode_push {
    uint32_t mode, item_count, force_wide;
    uint32_t meshlet_arrays[5]; /* meshlet mode: word offsets of the five meshlet arrays */
} decode_push;

void fail_check(harness* h, const char* format, ...)
{
    if (++h->failures <= MAX_REPORTED_FAILURES) {
        va_list args;
        va_start(args, format);
        fprintf(stderr, "MISMATCH: ");
        vfprintf(stderr, format, args);
        fprintf(stderr, "\n");
        va_end(args);
    }
}

/* ---- GPU side ------------------------------------------------------------------------------ */

/* Runs decode.comp over item_count items. words: 2 per item (codes mode) or words_per_vertex per
 * vertex; lut: the tuple LUT bytes (may be NULL). Returns malloc'ed records. */
SpDecodedRecord* gpu_decode(harness* h, const SpGpuCodec* codec, uint32_t mode, const uint32_t* words,
                                   size_t word_count, size_t item_count, const void* lut, size_t lut_bytes, int force_wide)
{
    vkx_context* ctx = &h->ctx;
    vkx_buffer codec_buffer = vkx_host_buffer(ctx, codec, sizeof(*codec), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    vkx_buffer input = vkx_upload(ctx, words, word_count * sizeof(uint32_t), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    vkx_buffer lut_buffer = vkx_upload(ctx, lut, lut ? lut_bytes : 0, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    vkx_buffer output = vkx_poisoned_buffer(ctx, item_count * sizeof(SpDecodedRecord), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);

    vkx_buffer* bindings[SP_BINDING_COUNT] = {0};
    bindings[SP_BINDING_CODEC] = &codec_buffer;
    bindings[SP_BINDING_VERTEX_WORDS] = &input;
    bindings[SP_BINDING_TUPLE_LUT] = &lut_buffer;
    bindings[SP_BINDING_OUTPUT] = &output;
    VkDescriptorSet set = vkx_descriptor_set(ctx, bindings, &h->dummy);

    decode_push push = {mode, (uint32_t)item_count, (uint32_t)force_wide, {0}};
    vkx_dispatch_and_wait(ctx, h->decode_pipeline, set, &push, (uint32_t)sizeof(push), (uint32_t)((item_count + 63) / 64), 1);

    SpDecodedRecord* records = malloc(item_count * sizeof(SpDecodedRecord));
    memcpy(records, output.mapped, item_count * sizeof(SpDecodedRecord));
    vkResetDescriptorPool(ctx->device, ctx->descriptor_pool, 0);
    vkx_buffer_destroy(ctx, &codec_buffer);
    vkx_buffer_destroy(ctx, &input);
    vkx_buffer_destroy(ctx, &lut_buffer);
    vkx_buffer_destroy(ctx, &output);
    return records;
}

/* ---- C side: the format.md encoding formulas, applied to the GPU's integers ------------------- */

uint64_t record_q(const SpDecodedRecord* r, int slot)
{
    const uint32_t* low = &r->q_low.x;
    const uint32_t* high = &r->q_high.x;
    return (uint64_t)low[slot] | (uint64_t)high[slot] << 32;
}

const float* record_weights(const SpDecodedRecord* r) { return &r->weights.x; }

/* Rebuilds the code from q (x for Any) as format.md section 2 writes it. */
static u128 reencode(const sp_codec* codec, const uint64_t* q)
{
    uint32_t k = codec->influences;
    if (k == 1) return 0;
    switch (codec->method) {
    case SP_METHOD_FIXED:
    case SP_METHOD_CUBE:
    case SP_METHOD_POT: {
        uint32_t first = codec->method == SP_METHOD_FIXED ? 0 : 1, shift = 0;
        u128 code = 0;
        for (uint32_t slot = first; slot < k; ++slot) {
            code |= (u128)q[slot] << shift;
            shift += codec->component_bits[slot - first];
        }
        return code;
    }
    case SP_METHOD_ANY: {
        u128 code = 0, radix = 1;
        for (uint32_t a = 0; a + 1 < k; ++a) {
            code += (u128)q[a + 1] * radix;
            radix *= codec->axis_samples[a];
        }
        return code;
    }
    default: { /* OSS: k = q4, j = q3 - q4, i = q2 - q3 */
        uint64_t n = codec->n;
        if (k == 2) return q[1];
        uint64_t layer = k == 4 ? q[3] : 0;
        uint64_t row = q[2] - layer, i = q[1] - q[2];
        u128 base = k == 4 ? sp_oss_layer_base(n, layer) : 0;
        return base + sp_oss_row_base(n - 2 * layer, row) + i;
    }
    }
}

/* Compares one GPU record with the C decoder for `code`. */
static void check_record(harness* h, const sp_codec* codec, uint64_t code, const SpDecodedRecord* r, const char* what)
{
    uint32_t k = codec->influences;
    uint64_t q[4];
    for (int slot = 0; slot < 4; ++slot) q[slot] = record_q(r, slot);
    float expected[4] = {0, 0, 0, 0};
    sp_decode_weights(codec, code, expected);
    const float* got = record_weights(r);
    ++h->checked;

    if (k > 1 && reencode(codec, q) != (u128)code)
        fail_check(h, "%s: code %llu: GPU integers (%llu %llu %llu %llu) re-encode to another code", what,
                   (unsigned long long)code, (unsigned long long)q[0], (unsigned long long)q[1],
                   (unsigned long long)q[2], (unsigned long long)q[3]);
    if (codec->method == SP_METHOD_ANY) {
        for (uint32_t a = 0; a + 1 < k; ++a)
            if (q[a + 1] >= codec->axis_samples[a])
                fail_check(h, "%s: code %llu: x%u = %llu is off the axis", what, (unsigned long long)code, a + 2,
                           (unsigned long long)q[a + 1]);
    } else {
        u128 sum = 0;
        for (uint32_t slot = 0; slot < k; ++slot) sum += q[slot];
        /* Sorted order is the encoder's promise, not the decoder's: libskinpack accepts unsorted
         * Fixed codes, so only count them (reported once at the end). */
        for (uint32_t slot = 1; slot < k; ++slot)
            if (q[slot] > q[slot - 1]) {
                ++h->unsorted_codes;
                break;
            }
        if (sum != codec->scale)
            fail_check(h, "%s: code %llu: q = (%llu %llu %llu %llu) is not a grid point of s = %llu", what,
                       (unsigned long long)code, (unsigned long long)q[0], (unsigned long long)q[1],
                       (unsigned long long)q[2], (unsigned long long)q[3], (unsigned long long)codec->scale);
        if (codec->scale <= (1u << 22))
            for (uint32_t slot = 0; slot < k; ++slot)
                if ((uint64_t)llround((double)expected[slot] * (double)codec->scale) != q[slot])
                    fail_check(h, "%s: code %llu: q%u = %llu, C decoder's weight says %.0f", what,
                               (unsigned long long)code, slot + 1, (unsigned long long)q[slot],
                               (double)expected[slot] * (double)codec->scale);
    }
    for (uint32_t slot = 0; slot < 4; ++slot) {
        float want = slot < k ? expected[slot] : 0.0f;
        if (!(fabsf(got[slot] - want) <= WEIGHT_TOLERANCE))
            fail_check(h, "%s: code %llu: w%u = %.9g on the GPU, %.9g in C", what, (unsigned long long)code, slot + 1,
                       (double)got[slot], (double)want);
    }
}

/* Whether libskinpack accepts the code (AABB methods have codes outside the simplex). */
static int code_is_valid(const sp_codec* codec, uint64_t code)
{
    float w[SP_MAX_INFLUENCES];
    size_t error_vertex;
    return sp_decode_weights_batch(codec, &code, 1, w, &error_vertex) == SP_OK;
}

/* Decodes `codes` on the GPU with the default decoder and, when that is the 32-bit one, again
 * forced through the 64-bit decoder; checks every record. */
static void decode_and_check(harness* h, const sp_codec* codec, const uint64_t* codes, size_t count, const char* what)
{
    if (count == 0) return;
    uint32_t* words = malloc(count * 2 * sizeof(uint32_t));
    for (size_t i = 0; i < count; ++i) {
        words[2 * i] = (uint32_t)codes[i];
        words[2 * i + 1] = (uint32_t)(codes[i] >> 32);
    }
    SpGpuCodec gpu = sp_gpu_codec_fill(codec, 0, 2, 1, 1, 1);
    for (int force_wide = 0; force_wide < 2; ++force_wide) {
        SpDecodedRecord* records = gpu_decode(h, &gpu, SP_DECODE_MODE_CODES, words, count * 2, count, NULL, 0, force_wide);
        char label[160];
        snprintf(label, sizeof(label), "%s %s K=%u n=%llu bits=%u%s", what, sp_method_name((sp_method)codec->method),
                 codec->influences, (unsigned long long)codec->n, codec->bits, force_wide ? " (64-bit decoder)" : "");
        for (size_t i = 0; i < count; ++i) check_record(h, codec, codes[i], &records[i], label);
        free(records);
    }
    free(words);
}

/* ---- test: every code of small configurations ---------------------------------------------- */

static void check_all_codes(harness* h, const sp_codec* codec)
{
    size_t count = 0;
    uint64_t* codes = malloc(((size_t)codec->max_code + 1) * sizeof(uint64_t));
    for (uint64_t code = 0; code <= codec->max_code; ++code)
        if (code_is_valid(codec, code)) codes[count++] = code;
    if (count == 0) {
        fail_check(h, "%s K=%u n=%llu: no valid code", sp_method_name((sp_method)codec->method), codec->influences,
                   (unsigned long long)codec->n);
    }
    decode_and_check(h, codec, codes, count, "all codes");
    free(codes);
}

static void configure(harness* h, sp_method method, uint32_t k, uint64_t n, const uint64_t* axis, sp_codec* codec)
{
    sp_result result = sp_codec_from_params(method, k, n, axis, codec);
    if (result != SP_OK) {
        fail_check(h, "sp_codec_from_params(%s, K=%u, n=%llu): %s", sp_method_name(method), k, (unsigned long long)n,
                   sp_result_string(result));
        exit(1);
    }
}

static void test_codes(harness* h)
{
    sp_codec codec;
    /* K = 1: one code, weight 1, for every method. */
    for (int method = 0; method < SP_METHOD_COUNT; ++method) {
        if (sp_codec_from_bits((sp_method)method, 1, 0, &codec) != SP_OK) {
            fail_check(h, "sp_codec_from_bits(%s, K=1, 0 bits) failed", sp_method_name((sp_method)method));
            continue;
        }
        check_all_codes(h, &codec);
    }
    for (uint32_t k = 2; k <= 4; ++k) {
        /* Grid methods: every m whose codes number at most 2^14. */
        for (uint64_t m = 1; m * k <= 14; ++m) {
            configure(h, SP_METHOD_FIXED, k, m, NULL, &codec);
            check_all_codes(h, &codec);
        }
        for (uint64_t m = 1; m * (k - 1) <= 14; ++m) {
            configure(h, SP_METHOD_CUBE, k, m, NULL, &codec);
            check_all_codes(h, &codec);
        }
        for (uint64_t m = 2; m <= (k == 2 ? 14u : k == 3 ? 8u : 6u); ++m) {
            configure(h, SP_METHOD_POT, k, m, NULL, &codec);
            check_all_codes(h, &codec);
        }
        /* OSS: every N from 2 up to where the code count passes a few thousand. */
        for (uint64_t n = 2; n <= (k == 2 ? 64u : k == 3 ? 48u : 40u); ++n) {
            configure(h, SP_METHOD_OSS, k, n, NULL, &codec);
            check_all_codes(h, &codec);
        }
        /* Any: several anisotropic sample counts per axis. */
        static const uint64_t axis_sets[][3] = {{2, 2, 2}, {3, 2, 2}, {5, 4, 3}, {8, 6, 5}, {17, 11, 9}, {33, 21, 4}};
        for (size_t s = 0; s < sizeof(axis_sets) / sizeof(axis_sets[0]); ++s) {
            configure(h, SP_METHOD_ANY, k, 0, axis_sets[s], &codec);
            check_all_codes(h, &codec);
        }
    }
}

/* ---- test: sampled codes at every width ---------------------------------------------------- */

static uint64_t random_state = 0x9e3779b97f4a7c15ull;
static uint64_t random_next(void)
{
    random_state ^= random_state << 13;
    random_state ^= random_state >> 7;
    random_state ^= random_state << 17;
    return random_state;
}
static double random_unit(void) { return (double)(random_next() >> 11) * (1.0 / 9007199254740992.0); }

/* K weights, sorted descending, summing to 1: a random point of the simplex, sometimes with
 * zero tails and ties so the grid edges are hit too. */
static void random_weights(uint32_t k, float* w)
{
    double x[4] = {0}, sum = 0;
    uint32_t used = 1 + (uint32_t)(random_next() % k);
    for (uint32_t i = 0; i < used; ++i) sum += x[i] = -log(1.0 - random_unit());
    for (uint32_t i = 0; i < k; ++i) x[i] /= sum;
    if (random_next() % 8 == 0) x[1] = x[0]; /* ties, renormalised below */
    sum = 0;
    for (uint32_t i = 0; i < k; ++i) sum += x[i];
    for (uint32_t i = 0; i < k; ++i) w[i] = (float)(x[i] / sum);
    for (uint32_t i = 0; i < k; ++i)
        for (uint32_t j = i + 1; j < k; ++j)
            if (w[j] > w[i]) {
                float t = w[i];
                w[i] = w[j];
                w[j] = t;
            }
}

static void add_code(const sp_codec* codec, uint64_t* codes, size_t* count, u128 code)
{
    if (code <= codec->max_code && code_is_valid(codec, (uint64_t)code)) codes[(*count)++] = (uint64_t)code;
}

/* The 64-bit decoder's 32-bit row step (K = 4 while S(N) < 2^32, shaders/skinpack_decode.glsl)
 * at its limit N = 113511 and just past it (the 64-bit row step): the row boundaries of the
 * first layers, whose triangles come closest to 2^32 codes, the last codes, and random ones. */
static size_t check_in_layer_rows(harness* h)
{
    enum { MAX_CODES = 1024 };
    static const uint64_t limit = 113511; /* SP_OSS_LAYER32_MAX_N: the largest N with S(N) < 2^32 */
    uint64_t codes[MAX_CODES];
    if (sp_oss_triangle_count(limit) > UINT32_MAX || sp_oss_triangle_count(limit + 1) <= UINT32_MAX)
        fail_check(h, "S(%llu) is not the last triangle count below 2^32", (unsigned long long)limit);
    for (uint64_t n = limit; n <= limit + 1; ++n) {
        sp_codec codec;
        size_t count = 0;
        configure(h, SP_METHOD_OSS, 4, n, NULL, &codec);
        for (uint64_t layer = 0; layer < 3; ++layer) {
            uint64_t bottom = n - 2 * layer, rows = (2 * bottom + 1) / 3, base = sp_oss_layer_base(n, layer);
            for (int i = 0; i < 60; ++i) {
                uint64_t row = i < 20 ? rows - 1 - (uint64_t)i : (i < 30 ? (uint64_t)i - 20 : random_next() % rows);
                u128 start = (u128)base + sp_oss_row_base(bottom, row);
                add_code(&codec, codes, &count, start);
                add_code(&codec, codes, &count, start + 1);
                if (start > 0) add_code(&codec, codes, &count, start - 1);
            }
        }
        /* past the limit, layer 0's in-layer indices cross 2^32: the codes and rows around it */
        uint64_t crossing = 0, rows0 = (2 * n + 1) / 3;
        while (crossing + 1 < rows0 && sp_oss_row_base(n, crossing + 1) <= UINT32_MAX) ++crossing;
        for (uint64_t row = crossing; row < crossing + 3 && row < rows0; ++row) {
            add_code(&codec, codes, &count, sp_oss_row_base(n, row));
            add_code(&codec, codes, &count, (u128)sp_oss_row_base(n, row) + 1);
        }
        for (uint64_t d = 0; d < 8; ++d) add_code(&codec, codes, &count, (u128)UINT32_MAX - 3 + d);
        for (uint64_t back = 0; back < 32; ++back) add_code(&codec, codes, &count, codec.max_code - back);
        for (int i = 0; i < 256; ++i) add_code(&codec, codes, &count, random_next() % (codec.max_code + 1));
        decode_and_check(h, &codec, codes, count, n == limit ? "in-layer rows limit" : "past in-layer rows");
    }
    return 2;
}

enum { RANDOM_CODES = 256, MAX_SAMPLED_CODES = 1024 };

/* OSS layer and row boundaries, where the float estimates are off by one. */
static void add_oss_boundary_codes(const sp_codec* codec, uint32_t k, uint64_t* codes, size_t* count)
{
    uint64_t layers = k == 4 ? (codec->n + 1) / 2 : 1;
    for (int i = 0; i < 48; ++i) {
        uint64_t layer = k == 4 ? (i < 4 ? (uint64_t)i % layers : random_next() % layers) : 0;
        if (i == 5) layer = layers - 1;
        uint64_t bottom = codec->n - 2 * layer;
        uint64_t rows = (2 * bottom + 1) / 3;
        uint64_t row = i < 8 ? (uint64_t)i % rows : random_next() % rows;
        if (i == 9) row = rows - 1;
        u128 base = (k == 4 ? (u128)sp_oss_layer_base(codec->n, layer) : 0) + sp_oss_row_base(bottom, row);
        add_code(codec, codes, count, base);
        if (base > 0) add_code(codec, codes, count, base - 1);
        add_code(codec, codes, count, base + 1);
    }
}

/* The first, last and middle code, the codes of random weights and, for OSS, boundaries.
 * Returns 0 when the method has no codec of exactly this width. */
static int check_sampled_width(harness* h, sp_method method, uint32_t k, uint32_t bits)
{
    uint64_t codes[MAX_SAMPLED_CODES];
    sp_codec codec;
    if (sp_codec_from_bits(method, k, bits, &codec) != SP_OK)
        return 0; /* no configuration of this width (e.g. POT below its minimum) */
    if (codec.bits != bits) return 0; /* the same codec as a narrower width */
    size_t count = 0;
    add_code(&codec, codes, &count, 0);
    add_code(&codec, codes, &count, codec.max_code);
    add_code(&codec, codes, &count, codec.max_code / 2);
    for (int i = 0; i < RANDOM_CODES; ++i) {
        float w[4];
        random_weights(k, w);
        add_code(&codec, codes, &count, sp_encode_weights(&codec, w));
    }
    if (method == SP_METHOD_OSS && k >= 3) add_oss_boundary_codes(&codec, k, codes, &count);
    decode_and_check(h, &codec, codes, count, "sampled");
    return 1;
}

/* The 32-bit decoder at its limit: the largest OSS N whose codes it still takes (K = 3, 4),
 * top codes included, where the closed forms come closest to 2^32; N + 1 must not take it. */
static void check_narrow_limit(harness* h, uint32_t k)
{
    uint64_t codes[MAX_SAMPLED_CODES];
    uint64_t limit = k == 4 ? SP_OSS_NARROW_MAX_CODE_K4 : SP_OSS_NARROW_MAX_CODE_K3, n = 2;
    while ((k == 4 ? sp_oss_tetrahedron_count(n + 1) : sp_oss_triangle_count(n + 1)) - 1 <= limit) ++n;
    sp_codec codec;
    configure(h, SP_METHOD_OSS, k, n, NULL, &codec);
    SpGpuCodec gpu = sp_gpu_codec_fill(&codec, 0, 2, 1, 1, 1);
    if (!SP_GPU_CODEC_IS_NARROW(gpu)) fail_check(h, "OSS K=%u N=%llu should take the 32-bit decoder", k, (unsigned long long)n);
    size_t count = 0;
    for (uint64_t back = 0; back < 64; ++back) add_code(&codec, codes, &count, codec.max_code - back);
    for (int i = 0; i < RANDOM_CODES; ++i) add_code(&codec, codes, &count, random_next() % (codec.max_code + 1));
    decode_and_check(h, &codec, codes, count, "narrow limit");
    configure(h, SP_METHOD_OSS, k, n + 1, NULL, &codec);
    gpu = sp_gpu_codec_fill(&codec, 0, 2, 1, 1, 1);
    if (SP_GPU_CODEC_IS_NARROW(gpu)) fail_check(h, "OSS K=%u N=%llu should take the 64-bit decoder", k, (unsigned long long)n + 1);
}

static void test_widths(harness* h)
{
    size_t configurations = 0;
    for (int method = 0; method < SP_METHOD_COUNT; ++method)
        for (uint32_t k = 2; k <= 4; ++k)
            for (uint32_t bits = 1; bits <= 64; ++bits) configurations += (size_t)check_sampled_width(h, (sp_method)method, k, bits);
    for (uint32_t k = 3; k <= 4; ++k) {
        check_narrow_limit(h, k);
        configurations += 2;
    }
    configurations += check_in_layer_rows(h);
    printf("widths: %zu configurations\n", configurations);
}

/* ---- test: packed vertex words and tuple LUTs ------------------------------------------------- */

enum { VERTICES = 4000, STRIDE = 6 };

/* One random skin, what libskinpack makes of it and the C decoder's view of that. */
typedef struct vertex_test {
    uint32_t joint_count;
    uint16_t* joints; /* STRIDE per vertex */
    float* weights;
    uint32_t* words;
    uint16_t* lut;
    uint8_t* lut_bytes;
    uint16_t* c_joints; /* decoded: K per vertex */
    float* c_weights;
    uint32_t* tuples;
    uint64_t* codes;
    size_t scratch_size;
    void* scratch;
} vertex_test;

static void vertex_test_alloc(vertex_test* t)
{
    t->joints = malloc(VERTICES * STRIDE * sizeof(uint16_t));
    t->weights = malloc(VERTICES * STRIDE * sizeof(float));
    t->words = malloc(VERTICES * 2 * sizeof(uint32_t));
    t->lut = malloc(VERTICES * SP_MAX_INFLUENCES * sizeof(uint16_t));
    t->lut_bytes = malloc(VERTICES * SP_MAX_INFLUENCES * sizeof(uint16_t));
    t->c_joints = malloc(VERTICES * SP_MAX_INFLUENCES * sizeof(uint16_t));
    t->c_weights = malloc(VERTICES * SP_MAX_INFLUENCES * sizeof(float));
    t->tuples = malloc(VERTICES * sizeof(uint32_t));
    t->codes = malloc(VERTICES * sizeof(uint64_t));
    t->scratch_size = sp_compress_scratch_bound(VERTICES, STRIDE);
    t->scratch = malloc(t->scratch_size);
}

static void vertex_test_free(vertex_test* t)
{
    free(t->joints);
    free(t->weights);
    free(t->words);
    free(t->lut);
    free(t->lut_bytes);
    free(t->c_joints);
    free(t->c_weights);
    free(t->tuples);
    free(t->codes);
    free(t->scratch);
}

/* Skin-like data: joints clustered along the vertex index, 1..6 influences. */
static void random_skin(vertex_test* t)
{
    for (size_t v = 0; v < VERTICES; ++v) {
        uint32_t used = 1 + (uint32_t)(random_next() % STRIDE);
        for (uint32_t s = 0; s < STRIDE; ++s) {
            uint32_t joint = (uint32_t)((v * t->joint_count) / VERTICES + random_next() % 7) % t->joint_count;
            t->joints[v * STRIDE + s] = (uint16_t)joint;
            t->weights[v * STRIDE + s] = s < used ? (float)random_unit() + 0.01f : 0.0f;
        }
    }
}

/* The vertex words as decode.comp gets them, plus, when the words have padding, one corrupted
 * copy of the last vertex: its set padding bit must be reported. *items: vertices in it. */
static uint32_t* vertex_input(const vertex_test* t, const sp_compressed_skin* skin, size_t* items)
{
    uint32_t used_bits = skin->tuple_bits + skin->weight_bits;
    size_t wpv = skin->words_per_vertex;
    *items = VERTICES + (used_bits < 32 * wpv ? 1 : 0);
    uint32_t* input = malloc((VERTICES + 1) * wpv * sizeof(uint32_t));
    memcpy(input, t->words, VERTICES * wpv * sizeof(uint32_t));
    if (*items > VERTICES) {
        memcpy(input + VERTICES * wpv, t->words + (VERTICES - 1) * wpv, wpv * sizeof(uint32_t));
        input[VERTICES * wpv + used_bits / 32] |= 1u << (used_bits % 32);
    }
    return input;
}

/* Each record's code, tuple index, padding flag, joints and weights against C. */
static void check_vertex_records(harness* h, const vertex_test* t, const sp_compressed_skin* skin,
                                 const SpDecodedRecord* records, const char* label)
{
    uint32_t kk = skin->influences;
    for (size_t v = 0; v < VERTICES; ++v) {
        const SpDecodedRecord* r = &records[v];
        check_record(h, &skin->codec, t->codes[v], r, label);
        const uint32_t* got_joints = &r->joints.x;
        if (r->vertex.x != t->tuples[v] || r->vertex.y != 1)
            fail_check(h, "%s: vertex %zu: tuple %u (C %u), padding flag %u", label, v, r->vertex.x, t->tuples[v], r->vertex.y);
        for (uint32_t s = 0; s < kk; ++s)
            if (got_joints[s] != t->c_joints[v * kk + s])
                fail_check(h, "%s: vertex %zu slot %u: joint %u on the GPU, %u in C", label, v, s, got_joints[s],
                           t->c_joints[v * kk + s]);
        for (uint32_t s = 0; s < kk; ++s)
            if (!(fabsf(record_weights(r)[s] - t->c_weights[v * kk + s]) <= WEIGHT_TOLERANCE))
                fail_check(h, "%s: vertex %zu slot %u: weight %.9g on the GPU, %.9g in C", label, v, s,
                           (double)record_weights(r)[s], (double)t->c_weights[v * kk + s]);
    }
}

/* Compresses the skin with one method, K and word size, decodes it on the GPU and checks it. */
static void check_vertex_config(harness* h, vertex_test* t, sp_method method, uint32_t k, uint32_t vertex_bits)
{
    sp_compress_options options;
    sp_compress_options_default(&options);
    options.method = method;
    options.max_influences = k;
    options.vertex_bits = vertex_bits;
    sp_compressed_skin skin;
    sp_result result = sp_compress_skin(t->joints, t->weights, VERTICES, STRIDE, t->joint_count, &options, t->words, t->lut,
                                        NULL, NULL, &skin, t->scratch, t->scratch_size);
    if (result != SP_OK) return; /* e.g. a tuple index that leaves too few weight bits */
    result = sp_decompress_skin(&skin.codec, t->words, VERTICES, skin.tuple_bits, t->lut, skin.lut_size, t->joint_count,
                                t->c_joints, t->c_weights, NULL);
    if (result != SP_OK) {
        fail_check(h, "sp_decompress_skin: %s", sp_result_string(result));
        return;
    }
    sp_unpack_vertices(t->words, VERTICES, skin.tuple_bits, skin.weight_bits, t->tuples, t->codes, NULL);
    size_t lut_entries = skin.lut_size * skin.influences;
    sp_gpu_lut_bytes(t->lut, lut_entries, skin.joint_bytes, t->lut_bytes);
    SpGpuCodec gpu = sp_gpu_skin_codec(&skin, t->joint_count);
    size_t items;
    uint32_t* input = vertex_input(t, &skin, &items);
    SpDecodedRecord* records = gpu_decode(h, &gpu, SP_DECODE_MODE_VERTICES, input, items * skin.words_per_vertex, items,
                                          t->lut_bytes, lut_entries * skin.joint_bytes, 0);
    char label[160];
    snprintf(label, sizeof(label), "vertices %s K=%u %u-bit words, %u joints", sp_method_name(method), skin.influences,
             vertex_bits, t->joint_count);
    check_vertex_records(h, t, &skin, records, label);
    if (items > VERTICES && records[VERTICES].vertex.y != 0)
        fail_check(h, "%s: a set padding bit above bit %u was not reported", label, skin.tuple_bits + skin.weight_bits);
    free(records);
    free(input);
}

static void test_vertices(harness* h)
{
    static const uint32_t joint_counts[] = {40, 300}; /* u8 and u16 LUT entries */
    static const uint32_t vertex_bits[] = {32, 48, 64};
    vertex_test t;
    vertex_test_alloc(&t);
    for (size_t jc = 0; jc < 2; ++jc) {
        t.joint_count = joint_counts[jc];
        random_skin(&t);
        for (int method = 0; method < SP_METHOD_COUNT; ++method)
            for (uint32_t k = 1; k <= 4; ++k)
                for (size_t b = 0; b < 3; ++b) check_vertex_config(h, &t, (sp_method)method, k, vertex_bits[b]);
    }
    vertex_test_free(&t);
}

/* ---- test: meshlet palette and local tuple LUT fetch ------------------------------------------ */

/* What skin.mesh reads, checked on lavapipe (which has no mesh shaders) through decode.comp's
 * meshlet mode: per meshlet vertex, joints via palette + local LUT must equal the global tuple
 * LUT's joints (slots with non-zero weight), weights the C decoder's; triangle corners must be
 * the meshlet's triangles as sp_build_meshlets wrote them. */
/* What decode.comp's meshlet mode wrote: a record per meshlet vertex, three source-vertex
 * corners per meshlet triangle. */
typedef struct meshlet_fetch {
    vkx_buffer records, corners;
} meshlet_fetch;

/* One decode.comp dispatch in meshlet mode, a workgroup per meshlet. The caller destroys the
 * fetch's buffers. */
static meshlet_fetch gpu_meshlet_fetch(harness* h, const sp_gpu_default_skin* packed, const sp_gpu_meshlets* built,
                                       uint32_t joint_count, size_t vertex_count)
{
    const sp_compressed_skin* skin = &packed->skin;
    const sp_meshlet_stats* stats = &built->stats;
    /* The five arrays in one word buffer, as skinpack_gpu_layout.h describes. */
    decode_push push = {SP_DECODE_MODE_MESHLETS, (uint32_t)stats->meshlet_count, 0, {0}};
    for (int a = 0; a < 5; ++a) push.meshlet_arrays[a] = built->offsets[a];

    vkx_context* ctx = &h->ctx;
    VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    SpGpuCodec gpu_codec = sp_gpu_skin_codec(skin, joint_count);
    vkx_buffer codec_buffer = vkx_host_buffer(ctx, &gpu_codec, sizeof(gpu_codec), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    vkx_buffer words_buffer = vkx_upload(ctx, packed->words, vertex_count * skin->words_per_vertex * 4, storage);
    vkx_buffer meshlet_buffer = vkx_upload(ctx, built->arrays.meshlets, stats->meshlet_count * sizeof(sp_meshlet), storage);
    vkx_buffer data_buffer = vkx_upload(ctx, built->data, built->data_words * 4, storage);
    meshlet_fetch fetch;
    fetch.records = vkx_poisoned_buffer(ctx, stats->vertex_count * sizeof(SpDecodedRecord), storage);
    fetch.corners = vkx_poisoned_buffer(ctx, stats->triangle_count * 12, storage);
    vkx_buffer* bindings[SP_BINDING_COUNT] = {0};
    bindings[SP_BINDING_CODEC] = &codec_buffer;
    bindings[SP_BINDING_VERTEX_WORDS] = &words_buffer;
    bindings[SP_BINDING_MESHLETS] = &meshlet_buffer;
    bindings[SP_BINDING_MESHLET_DATA] = &data_buffer;
    bindings[SP_BINDING_OUTPUT] = &fetch.records;
    bindings[SP_BINDING_POSITIONS] = &fetch.corners;
    VkDescriptorSet set = vkx_descriptor_set(ctx, bindings, &h->dummy);
    vkx_dispatch_and_wait(ctx, h->decode_pipeline, set, &push, (uint32_t)sizeof(push), (uint32_t)stats->meshlet_count, 1);
    vkResetDescriptorPool(ctx->device, ctx->descriptor_pool, 0);
    vkx_buffer* inputs[] = {&codec_buffer, &words_buffer, &meshlet_buffer, &data_buffer};
    for (size_t i = 0; i < sizeof(inputs) / sizeof(inputs[0]); ++i) vkx_buffer_destroy(ctx, inputs[i]);
    return fetch;
}

/* Meshlet m's vertices: source vertex, palette and LUT sizes, joints and weights. */
static void check_meshlet_vertices(harness* h, const sp_gpu_default_skin* packed, const sp_gpu_meshlets* built, size_t m,
                                   const SpDecodedRecord* records)
{
    const sp_meshlet* meshlet = &built->arrays.meshlets[m];
    const uint16_t* joints = packed->joints;
    const float* weights = packed->weights;
    uint32_t k = packed->skin.influences;
    for (uint32_t i = 0; i < meshlet->vertex_count; ++i) {
        const SpDecodedRecord* r = &records[meshlet->vertex_offset + i];
        uint32_t v = built->arrays.vertices[meshlet->vertex_offset + i];
        ++h->checked;
        if (r->vertex.x != v || r->vertex.z != meshlet->joint_count || r->vertex.w != meshlet->tuple_count) {
            fail_check(h, "meshlet %zu vertex %u: source vertex %u (want %u), palette %u (%u), LUT %u (%u)", m, i,
                       r->vertex.x, v, r->vertex.z, meshlet->joint_count, r->vertex.w, meshlet->tuple_count);
            continue;
        }
        const uint32_t* got = &r->joints.x;
        for (uint32_t slot = 0; slot < k; ++slot) {
            if (weights[v * k + slot] > 0 && got[slot] != joints[v * k + slot])
                fail_check(h, "meshlet %zu vertex %u slot %u: joint %u via palette, %u via the tuple LUT", m, i, slot,
                           got[slot], joints[v * k + slot]);
            if (!(fabsf(record_weights(r)[slot] - weights[v * k + slot]) <= WEIGHT_TOLERANCE))
                fail_check(h, "meshlet %zu vertex %u slot %u: weight %.9g, C %.9g", m, i, slot,
                           (double)record_weights(r)[slot], (double)weights[v * k + slot]);
        }
    }
}

/* Meshlet m's triangle corners, as source vertices. */
static void check_meshlet_corners(harness* h, const sp_gpu_meshlets* built, size_t m, const uint32_t* corners)
{
    const sp_meshlet_buffers* out = &built->arrays;
    const sp_meshlet* meshlet = &out->meshlets[m];
    for (uint32_t t = 0; t < meshlet->triangle_count; ++t)
        for (int c = 0; c < 3; ++c) {
            uint32_t local = out->triangles[3 * (meshlet->triangle_offset + t) + c];
            uint32_t want = out->vertices[meshlet->vertex_offset + local];
            if (corners[3 * (meshlet->triangle_offset + t) + c] != want)
                fail_check(h, "meshlet %zu triangle %u corner %d: vertex %u, want %u", m, t, c,
                           corners[3 * (meshlet->triangle_offset + t) + c], want);
        }
}

/* What skin.mesh reads, checked on lavapipe (which has no mesh shaders) through decode.comp's
 * meshlet mode: per meshlet vertex, joints via palette + local LUT must equal the global tuple
 * LUT's joints (slots with non-zero weight), weights the C decoder's; triangle corners must be
 * the meshlet's triangles as sp_build_meshlets wrote them. */
static void test_meshlets(harness* h, const char* path)
{
    sp_skin_mesh mesh;
    sp_skin_mesh_load(path, &mesh);
    sp_gpu_default_skin packed;
    sp_gpu_default_skin_build(&mesh, &packed);
    sp_gpu_meshlets built;
    sp_result result = sp_gpu_meshlets_build(mesh.indices, (size_t)mesh.triangle_count * 3, mesh.positions, mesh.vertex_count,
                                             12, packed.joints, packed.weights, packed.skin.influences, &built);
    if (result != SP_OK) vkx_fail("sp_build_meshlets: %s", sp_result_string(result));
    const sp_meshlet_stats* stats = &built.stats;
    printf("meshlets of %s: %zu meshlets, %zu vertex entries, %zu triangles, palettes up to %u joints\n", mesh.name,
           stats->meshlet_count, stats->vertex_count, stats->triangle_count, stats->max_joints);

    meshlet_fetch fetch = gpu_meshlet_fetch(h, &packed, &built, mesh.joint_count, mesh.vertex_count);
    for (size_t m = 0; m < stats->meshlet_count; ++m) {
        check_meshlet_vertices(h, &packed, &built, m, fetch.records.mapped);
        check_meshlet_corners(h, &built, m, fetch.corners.mapped);
    }
    vkx_buffer_destroy(&h->ctx, &fetch.records);
    vkx_buffer_destroy(&h->ctx, &fetch.corners);
    sp_gpu_meshlets_free(&built);
    sp_gpu_default_skin_free(&packed);
    sp_skin_mesh_free(&mesh);
}

/* ---- test: a real mesh skinned in a pose ------------------------------------------------------- */

/* skin.comp on the GPU for one instance; returns malloc'ed skinned positions (3 per vertex). */
static float* gpu_skin(harness* h, VkPipeline pipeline, const sp_skin_mesh* mesh, const SpGpuCodec* codec,
                       const uint32_t* words, size_t word_count, const void* lut, size_t lut_bytes,
                       const uint32_t* baseline, size_t baseline_words)
{
    vkx_context* ctx = &h->ctx;
    vkx_buffer codec_buffer = vkx_host_buffer(ctx, codec, sizeof(*codec), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    vkx_buffer words_buffer = vkx_upload(ctx, words, words ? word_count * 4 : 0, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    vkx_buffer lut_buffer = vkx_upload(ctx, lut, lut ? lut_bytes : 0, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    vkx_buffer baseline_buffer = vkx_upload(ctx, baseline, baseline ? baseline_words * 4 : 0, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    vkx_buffer matrices = vkx_upload(ctx, mesh->pose_rows, (size_t)mesh->joint_count * 12 * sizeof(float),
                                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    vkx_buffer positions = vkx_upload(ctx, mesh->positions, (size_t)mesh->vertex_count * 3 * sizeof(float),
                                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    vkx_buffer output = vkx_buffer_create(ctx, (size_t)mesh->vertex_count * 3 * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 1);
    memset(output.mapped, 0xcd, output.size);
    vkx_buffer* bindings[SP_BINDING_COUNT] = {0};
    bindings[SP_BINDING_CODEC] = &codec_buffer;
    bindings[SP_BINDING_VERTEX_WORDS] = &words_buffer;
    bindings[SP_BINDING_TUPLE_LUT] = &lut_buffer;
    bindings[SP_BINDING_JOINT_MATRICES] = &matrices;
    bindings[SP_BINDING_POSITIONS] = &positions;
    bindings[SP_BINDING_OUTPUT] = &output;
    bindings[SP_BINDING_BASELINE] = &baseline_buffer;
    VkDescriptorSet set = vkx_descriptor_set(ctx, bindings, &h->dummy);

    SpSkinParameters push;
    memset(&push, 0, sizeof(push));
    push.counts = (sp_gpu_uvec4){mesh->vertex_count, mesh->joint_count, 1, 0};
    vkx_dispatch_and_wait(ctx, pipeline, set, &push, (uint32_t)sizeof(push), (uint32_t)((mesh->vertex_count + 63) / 64), 1);
    float* result = malloc((size_t)mesh->vertex_count * 3 * sizeof(float));
    memcpy(result, output.mapped, (size_t)mesh->vertex_count * 3 * sizeof(float));
    vkResetDescriptorPool(ctx->device, ctx->descriptor_pool, 0);
    vkx_buffer* all[] = {&codec_buffer, &words_buffer, &lut_buffer, &baseline_buffer, &matrices, &positions, &output};
    for (size_t i = 0; i < sizeof(all) / sizeof(all[0]); ++i) vkx_buffer_destroy(ctx, all[i]);
    return result;
}

/* Largest distance between two position arrays; fails when above tolerance. */
static double compare_positions(harness* h, const float* got, const float* want, size_t vertex_count, double tolerance,
                                const char* what)
{
    double worst = 0;
    size_t worst_vertex = 0;
    for (size_t v = 0; v < vertex_count; ++v) {
        double d = 0;
        for (int c = 0; c < 3; ++c) d = fmax(d, fabs((double)got[3 * v + c] - (double)want[3 * v + c]));
        if (!(d <= worst)) {
            worst = d;
            worst_vertex = v;
        }
    }
    h->checked += vertex_count;
    printf("  %-44s max |GPU - C| = %.3g (vertex %zu), tolerance %.3g\n", what, worst, worst_vertex, tolerance);
    if (!(worst <= tolerance)) fail_check(h, "%s: vertex %zu is %.3g away from the C reference", what, worst_vertex, worst);
    return worst;
}

/* A mesh, its K = 4 reference influences skinned in C, and the work arrays of one compressed
 * configuration. */
typedef struct mesh_test {
    sp_skin_mesh mesh;
    size_t n;
    double extent, tolerance;
    uint16_t* prepared_joints; /* sorted, pruned, renormalised: 4 per vertex */
    float* prepared_weights;
    float* reference_original; /* C skinning with the prepared influences */
    uint32_t* words;
    uint16_t* lut;
    uint8_t* lut_bytes;
    uint16_t* decoded_joints; /* the C decoder's: K per vertex */
    float* decoded_weights;
    float* reference_decoded; /* C skinning with the decoded influences */
    size_t scratch_size;
    void* scratch;
} mesh_test;

/* Loads the mesh and skins it in C with its prepared influences. */
static void mesh_test_load(harness* h, mesh_test* t, const char* path)
{
    sp_skin_mesh* mesh = &t->mesh;
    sp_skin_mesh_load(path, mesh);
    size_t n = t->n = mesh->vertex_count;
    printf("mesh %s: %zu vertices, %u triangles, %u joints\n", mesh->name, n, mesh->triangle_count, mesh->joint_count);
    t->extent = 1e-6;
    for (size_t i = 0; i < n * 3; ++i) t->extent = fmax(t->extent, fabs((double)mesh->positions[i]));
    t->tolerance = 2e-6 * t->extent; /* float accumulation vs the double C reference: a few ulps */

    t->prepared_joints = malloc(n * 4 * sizeof(uint16_t));
    t->prepared_weights = malloc(n * 4 * sizeof(float));
    if (sp_prepare_influences(mesh->joints, mesh->weights, n, 8, mesh->joint_count, 4, 1e-3f, t->prepared_joints,
                              t->prepared_weights, NULL, NULL) != SP_OK)
        vkx_fail("sp_prepare_influences failed on %s", path);
    t->reference_original = malloc(n * 3 * sizeof(float));
    sp_reference_skin(mesh->positions, n, t->prepared_joints, t->prepared_weights, 4, mesh->pose_rows, t->reference_original);
    /* How far the pose moves vertices at all: a skinning test in the rest pose would prove nothing. */
    double moved = 0;
    for (size_t i = 0; i < n * 3; ++i) moved = fmax(moved, fabs((double)t->reference_original[i] - mesh->positions[i]));
    printf("  pose moves vertices by up to %.3g (extent %.3g)\n", moved, t->extent);
    if (moved < 1e-3 * t->extent) fail_check(h, "the exported pose barely moves the mesh (%.3g)", moved);

    t->words = malloc(n * 2 * sizeof(uint32_t));
    t->lut = malloc(n * 4 * sizeof(uint16_t));
    t->lut_bytes = malloc(n * 4 * sizeof(uint16_t));
    t->decoded_joints = malloc(n * 4 * sizeof(uint16_t));
    t->decoded_weights = malloc(n * 4 * sizeof(float));
    t->reference_decoded = malloc(n * 3 * sizeof(float));
    t->scratch_size = sp_compress_scratch_bound(n, 8);
    t->scratch = malloc(t->scratch_size);
}

static void mesh_test_free(mesh_test* t)
{
    void* arrays[] = {t->words, t->lut, t->lut_bytes, t->decoded_joints, t->decoded_weights, t->reference_decoded,
                      t->reference_original, t->prepared_joints, t->prepared_weights, t->scratch};
    for (size_t i = 0; i < sizeof(arrays) / sizeof(arrays[0]); ++i) free(arrays[i]);
    sp_skin_mesh_free(&t->mesh);
}

/* Float32 baseline: the prepared weights and u8 joints on the GPU vs C. */
static void check_float32_baseline(harness* h, mesh_test* t)
{
    size_t n = t->n;
    uint32_t* baseline = malloc(n * 5 * sizeof(uint32_t));
    for (size_t v = 0; v < n; ++v) {
        memcpy(&baseline[5 * v], &t->prepared_weights[4 * v], 4 * sizeof(float));
        uint32_t packed_joints = 0;
        for (int s = 0; s < 4; ++s) packed_joints |= (uint32_t)(t->prepared_joints[4 * v + s] & 0xff) << (8 * s);
        baseline[5 * v + 4] = packed_joints;
    }
    SpGpuCodec no_codec;
    memset(&no_codec, 0, sizeof(no_codec));
    if (t->mesh.joint_count <= 256) {
        vkx_specialization spec = sp_gpu_specialization(SP_VERTEX_FORMAT_FLOAT32, NULL);
        VkPipeline float_pipeline = vkx_compute_pipeline(&h->ctx, "skin.comp.spv", &spec);
        float* gpu = gpu_skin(h, float_pipeline, &t->mesh, &no_codec, NULL, 0, NULL, 0, baseline, n * 5);
        compare_positions(h, gpu, t->reference_original, n, t->tolerance, "float32 weights (original)");
        free(gpu);
        vkDestroyPipeline(h->ctx.device, float_pipeline, NULL);
    }
    free(baseline);
}

/* max_r |M_j p| over the first k joints of vertex v (rows 12 floats a joint). */
static double pose_reach(const sp_skin_mesh* mesh, const uint16_t* joints, uint32_t k, size_t v)
{
    double reach = 0;
    const float* p = mesh->positions + 3 * v;
    for (uint32_t s = 0; s < k; ++s) {
        const float* m = mesh->pose_rows + 12 * (size_t)joints[k * v + s];
        for (int r = 0; r < 3; ++r)
            reach = fmax(reach, fabs(m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3]));
    }
    return reach;
}

/* Quantisation effect vs the original weights, bounded per vertex by
 * sum_i |dw_i| |M_i p| <= K * max_error * max_i |M_i p| (plus float rounding). */
static void check_quantisation_bound(harness* h, const mesh_test* t, const sp_compressed_skin* skin, const float* gpu,
                                     const char* label)
{
    size_t over = 0;
    double worst = 0;
    for (size_t v = 0; v < t->n; ++v) {
        double reach = fmax(pose_reach(&t->mesh, t->prepared_joints, 4, v),
                            pose_reach(&t->mesh, t->decoded_joints, skin->influences, v));
        double bound = 2.0 * 4 * skin->codec.max_error * reach * 1.7320508 + t->tolerance;
        double d = 0;
        for (int axis = 0; axis < 3; ++axis)
            d = fmax(d, fabs((double)gpu[3 * v + axis] - (double)t->reference_original[3 * v + axis]));
        worst = fmax(worst, d);
        if (d > bound) ++over;
    }
    printf("  %-44s max |decoded - original| = %.3g (codec max_error %.3g)\n", "", worst, skin->codec.max_error);
    if (over) fail_check(h, "%s: %zu vertices moved more than the codec's error bound allows", label, over);
}

/* Compresses the skin with the library's C decode of it as reference; returns 0 on failure. */
static int compress_and_decode(harness* h, mesh_test* t, sp_method method, uint32_t vertex_bits, sp_compressed_skin* skin)
{
    const sp_skin_mesh* mesh = &t->mesh;
    sp_compress_options options;
    sp_compress_options_default(&options);
    options.method = method;
    options.vertex_bits = vertex_bits;
    sp_result result = sp_compress_skin(mesh->joints, mesh->weights, t->n, 8, mesh->joint_count, &options, t->words, t->lut,
                                        NULL, NULL, skin, t->scratch, t->scratch_size);
    if (result != SP_OK) {
        fail_check(h, "sp_compress_skin(%s, %u bits): %s", sp_method_name(method), vertex_bits, sp_result_string(result));
        return 0;
    }
    result = sp_decompress_skin(&skin->codec, t->words, t->n, skin->tuple_bits, t->lut, skin->lut_size, mesh->joint_count,
                                t->decoded_joints, t->decoded_weights, NULL);
    if (result != SP_OK) {
        fail_check(h, "sp_decompress_skin: %s", sp_result_string(result));
        return 0;
    }
    sp_reference_skin(mesh->positions, t->n, t->decoded_joints, t->decoded_weights, skin->influences, mesh->pose_rows,
                      t->reference_decoded);
    return 1;
}

/* One compressed configuration: GPU decode + skin vs C decode + skin, once with the decoder
 * chosen at run time from the codec block, once with a pipeline specialised to this codec
 * (what an engine ships); both must match C. */
static void check_compressed(harness* h, mesh_test* t, VkPipeline runtime_pipeline, sp_method method, uint32_t vertex_bits)
{
    sp_compressed_skin skin;
    if (!compress_and_decode(h, t, method, vertex_bits, &skin)) return;
    size_t n = t->n, lut_entries = skin.lut_size * skin.influences;
    sp_gpu_lut_bytes(t->lut, lut_entries, skin.joint_bytes, t->lut_bytes);
    SpGpuCodec gpu_codec = sp_gpu_skin_codec(&skin, t->mesh.joint_count);
    vkx_specialization spec = sp_gpu_specialization(SP_VERTEX_FORMAT_PACKED, &gpu_codec);
    VkPipeline specialised_pipeline = vkx_compute_pipeline(&h->ctx, "skin.comp.spv", &spec);
    char label[96];
    snprintf(label, sizeof(label), "%s %u-bit budget (%u-bit code + %u-bit tuple)", sp_method_name(method), vertex_bits,
             skin.weight_bits, skin.tuple_bits);
    size_t word_count = n * skin.words_per_vertex, lut_bytes = lut_entries * skin.joint_bytes;
    float* gpu = gpu_skin(h, runtime_pipeline, &t->mesh, &gpu_codec, t->words, word_count, t->lut_bytes, lut_bytes, NULL, 0);
    compare_positions(h, gpu, t->reference_decoded, n, t->tolerance, label);
    free(gpu);
    gpu = gpu_skin(h, specialised_pipeline, &t->mesh, &gpu_codec, t->words, word_count, t->lut_bytes, lut_bytes, NULL, 0);
    compare_positions(h, gpu, t->reference_decoded, n, t->tolerance,
                      spec.decoder == SP_SPEC_DECODER_NARROW        ? "  same, specialised 32-bit decoder"
                      : spec.decoder == SP_SPEC_DECODER_WIDE_ROWS32 ? "  same, specialised 64-bit layer / 32-bit row decoder"
                                                                    : "  same, specialised 64-bit decoder");
    vkDestroyPipeline(h->ctx.device, specialised_pipeline, NULL);
    check_quantisation_bound(h, t, &skin, gpu, label);
    free(gpu);
}

static void test_mesh(harness* h, const char* path)
{
    static const struct { sp_method method; uint32_t vertex_bits; } configs[] = {
        {SP_METHOD_OSS, 32}, {SP_METHOD_OSS, 48}, {SP_METHOD_OSS, 64}, {SP_METHOD_POT, 32}, {SP_METHOD_CUBE, 48},
        {SP_METHOD_FIXED, 64}, {SP_METHOD_ANY, 32},
    };
    mesh_test t;
    mesh_test_load(h, &t, path);
    check_float32_baseline(h, &t);
    vkx_specialization runtime_spec = sp_gpu_specialization(SP_VERTEX_FORMAT_PACKED, NULL);
    VkPipeline runtime_pipeline = vkx_compute_pipeline(&h->ctx, "skin.comp.spv", &runtime_spec);
    for (size_t c = 0; c < sizeof(configs) / sizeof(configs[0]); ++c)
        check_compressed(h, &t, runtime_pipeline, configs[c].method, configs[c].vertex_bits);
    vkDestroyPipeline(h->ctx.device, runtime_pipeline, NULL);
    mesh_test_free(&t);
}

int main(int argc, char** argv)
{
    int needs_file = argc >= 2 && (strcmp(argv[1], "mesh") == 0 || strcmp(argv[1], "meshlets") == 0 ||
                                   strcmp(argv[1], "meshshader") == 0 || strcmp(argv[1], "conformance") == 0);
    if (argc < 2 || (needs_file && argc < 3)) {
        fprintf(stderr, "usage: %s codes|widths|vertices|mesh FILE|meshlets FILE|meshshader FILE|conformance FILE\n", argv[0]);
        return 2;
    }
    harness h;
    memset(&h, 0, sizeof(h));
    vkx_create(&h.ctx, 0);
    printf("device: %s (Vulkan %u.%u)\n", h.ctx.properties.deviceName, VK_API_VERSION_MAJOR(h.ctx.properties.apiVersion),
           VK_API_VERSION_MINOR(h.ctx.properties.apiVersion));
    h.dummy = vkx_buffer_create(&h.ctx, 256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, 1);
    vkx_specialization none = {0, 0, 0, 0}; /* decode.comp declares no specialisation constants */
    h.decode_pipeline = vkx_compute_pipeline(&h.ctx, "decode.comp.spv", &none);
    double start = sp_seconds();

    if (strcmp(argv[1], "codes") == 0) test_codes(&h);
    else if (strcmp(argv[1], "widths") == 0) test_widths(&h);
    else if (strcmp(argv[1], "vertices") == 0) test_vertices(&h);
    else if (strcmp(argv[1], "mesh") == 0) test_mesh(&h, argv[2]);
    else if (strcmp(argv[1], "meshlets") == 0) test_meshlets(&h, argv[2]);
    else if (strcmp(argv[1], "meshshader") == 0) test_meshshader(&h, argv[2]);
    else if (strcmp(argv[1], "conformance") == 0) test_conformance(&h, argv[2]);
    else {
        fprintf(stderr, "unknown test %s\n", argv[1]);
        return 2;
    }

    printf("%s: %zu decoded codes / skinned vertices checked, %zu mismatches, %.1f s\n", argv[1], h.checked, h.failures, sp_seconds() - start);
    if (h.unsorted_codes)
        printf("note: libskinpack accepted %zu codes whose weights are not descending (decoded identically)\n",
               h.unsorted_codes);
    vkDestroyPipeline(h.ctx.device, h.decode_pipeline, NULL);
    vkx_buffer_destroy(&h.ctx, &h.dummy);
    vkx_destroy(&h.ctx);
    if (h.failures) {
        printf("FAIL\n");
        return 1;
    }
    if (h.checked == 0 && strcmp(argv[1], "mesh") != 0) {
        printf("FAIL: nothing was checked\n");
        return 1;
    }
    printf("PASS\n");
    return 0;
}
