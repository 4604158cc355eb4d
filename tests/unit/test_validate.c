/* Format rules of the library: version/ABI check, joint width rule, large JSON integers, the
 * max-error search (also for K = 1), the Any encoder's w1 >= 0 guarantee, and sp_validate_packed
 * with its messages on valid and corrupted primitives (with and without meshlets). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

#include "packed_fixture.h"

static void abi_and_rules(void)
{
    CHECK(sp_version() == SP_VERSION);
    uint32_t bad = 0;
    CHECK(SP_CHECK_ABI(&bad) == SP_OK && bad == SP_STRUCT_COUNT);
    size_t sizes[SP_STRUCT_COUNT] = SP_STRUCT_SIZES_INIT;
    CHECK(sp_struct_size(SP_STRUCT_COMPRESS_OPTIONS) == sizeof(sp_compress_options));
    CHECK(sp_struct_size(SP_STRUCT_COUNT) == 0);
    sizes[SP_STRUCT_MESHLET] += 4; /* a caller with another layout */
    CHECK(sp_check_abi(SP_VERSION, sizes, SP_STRUCT_COUNT, &bad) == SP_ERR_ABI_MISMATCH && bad == SP_STRUCT_MESHLET);
    CHECK(sp_check_abi(SP_VERSION + 1, sizes, 0, &bad) == SP_ERR_ABI_MISMATCH && bad == SP_STRUCT_COUNT);
    CHECK(sp_check_abi(SP_VERSION, sizes, SP_STRUCT_MESHLET, &bad) == SP_OK); /* an older, shorter list */

    for (int r = 0; r < SP_RESULT_COUNT; ++r) /* every code, the validation ones included, has its message */
        CHECK_MSG(strcmp(sp_result_string((sp_result)r), "unknown result code") != 0, "result %d", r);
    for (int f = 1; f < SP_FIELD_COUNT; ++f) CHECK_MSG(sp_field_name((sp_field)f)[0] != 0, "field %d", f);
    CHECK(sp_field_name(SP_FIELD_COUNT)[0] == 0);

    CHECK(sp_joint_bytes(0) == 0 && sp_joint_bytes(1) == 1 && sp_joint_bytes(256) == 1);
    CHECK(sp_joint_bytes(257) == 2 && sp_joint_bytes(65535) == 2 && sp_joint_bytes(65536) == 0);

    for (int m = 0; m < SP_METHOD_COUNT; ++m) CHECK((int)sp_method_from_name(sp_method_name((sp_method)m)) == m);
    CHECK(sp_method_from_name("OSS") == SP_METHOD_COUNT && sp_method_name(SP_METHOD_COUNT) == NULL);

    uint64_t v = 0;
    CHECK(sp_parse_decimal("18446744073709551615", 20, &v) == SP_OK && v == UINT64_MAX);
    CHECK(sp_parse_decimal("9007199254740993", 16, &v) == SP_OK && v == 9007199254740993ull);
    CHECK(sp_parse_decimal("9007199254740992", 16, &v) == SP_ERR_INVALID_ARGUMENT); /* 2^53: a JSON number */
    CHECK(sp_parse_decimal("18446744073709551616", 20, &v) == SP_ERR_INVALID_ARGUMENT);
    CHECK(sp_parse_decimal("09007199254740993", 17, &v) == SP_ERR_INVALID_ARGUMENT);
    CHECK(sp_parse_decimal("-9007199254740993", 17, &v) == SP_ERR_INVALID_ARGUMENT);
    CHECK(sp_parse_decimal("", 0, &v) == SP_ERR_INVALID_ARGUMENT);
}

/* The search returns the fewest bits: one bit less misses the target. */
static void max_error_search(void)
{
    const double targets[] = {1e-2, 1e-3, 5e-4, 1e-5, 1e-7};
    for (int m = 0; m < SP_METHOD_COUNT; ++m)
        for (uint32_t k = 1; k <= 4; ++k)
            for (size_t t = 0; t < sizeof(targets) / sizeof(targets[0]); ++t) {
                sp_codec codec, fewer;
                sp_result r = sp_codec_from_max_error((sp_method)m, k, targets[t], &codec);
                if (r != SP_OK) {
                    CHECK(r == SP_ERR_BITS_OUT_OF_RANGE && sp_codec_from_bits((sp_method)m, k, 64, &fewer) == SP_OK &&
                          fewer.max_error > targets[t]);
                    continue;
                }
                CHECK(codec.max_error <= targets[t]);
                if (k == 1) CHECK(codec.bits == 0);
                for (uint32_t b = 0; b + 1 <= codec.bits; ++b)
                    CHECK(sp_codec_from_bits((sp_method)m, k, b, &fewer) != SP_OK || fewer.max_error > targets[t]);
            }
    sp_codec codec;
    CHECK(sp_codec_from_max_error(SP_METHOD_OSS, 4, 0, &codec) == SP_ERR_BITS_OUT_OF_RANGE);
    CHECK(sp_codec_from_max_error(SP_METHOD_OSS, 4, NAN, &codec) == SP_ERR_BITS_OUT_OF_RANGE);

    /* Through sp_compress_skin, single-influence meshes included (rigid props). */
    static packed p;
    for (size_t influences = 1; influences <= 4; influences += 3) {
        make_mesh(influences);
        sp_compress_options o;
        sp_compress_options_default(&o);
        o.vertex_bits = 0;
        o.max_error = 1e-3;
        CHECK(compress(&o, &p) == SP_OK);
        CHECK(p.info.influences == influences && p.info.codec.max_error <= 1e-3);
        CHECK(sp_codec_from_max_error(SP_METHOD_OSS, (uint32_t)influences, 1e-3, &codec) == SP_OK &&
              codec.bits == p.info.weight_bits);
        CHECK(p.info.quantization.max_error <= p.info.codec.max_error);
        CHECK(sp_validate_packed(&p.prim, NULL, NULL, NULL) == SP_OK);
        o.weight_bits = 20; /* two budgets */
        CHECK(compress(&o, &p) == SP_ERR_INVALID_ARGUMENT);
        o.weight_bits = 0;
        o.max_error = -1; /* no budget left, and a negative one */
        CHECK(compress(&o, &p) == SP_ERR_INVALID_ARGUMENT);
    }
}

/* Regression: Any at small budgets rounded the stored weights past a sum of 1 (w1 < 0) and wrote
 * codes its own decoder rejects. Every code must decode, within the codec's bound. */
static void any_codes_always_valid(void)
{
    for (uint32_t k = 2; k <= 4; ++k)
        for (uint32_t bits = 1; bits <= 16; ++bits) {
            sp_codec codec;
            if (sp_codec_from_bits(SP_METHOD_ANY, k, bits, &codec) != SP_OK) continue;
            for (int trial = 0; trial < 4000; ++trial) {
                float w[4] = {0}, decoded[4];
                double sum = 0;
                for (uint32_t i = 0; i < k; ++i) sum += (w[i] = (float)rng_unit());
                for (uint32_t i = 0; i < k; ++i) w[i] = (float)(w[i] / sum);
                for (uint32_t i = 0; i < k; ++i) /* sorted, descending */
                    for (uint32_t j = i + 1; j < k; ++j)
                        if (w[j] > w[i]) { float t = w[i]; w[i] = w[j]; w[j] = t; }
                uint64_t code = sp_encode_weights(&codec, w);
                size_t bad = 0;
                CHECK_MSG(sp_decode_weights_batch(&codec, &code, 1, decoded, &bad) == SP_OK, "K %u bits %u", k, bits);
                CHECK(decoded[0] >= 0);
                for (uint32_t i = 0; i < k; ++i)
                    CHECK_MSG(fabs((double)decoded[i] - w[i]) <= codec.max_error, "K %u bits %u slot %u: %g > %g", k,
                              bits, i, fabs((double)decoded[i] - w[i]), codec.max_error);
            }
        }
}

static int message_has(const sp_validation* report, const char* text)
{
    char message[256];
    sp_format_validation(report, message, sizeof(message));
    if (strstr(message, text)) return 1;
    fprintf(stderr, "message \"%s\" lacks \"%s\"\n", message, text);
    return 0;
}

/* Valid primitives of every method and K decode exactly as sp_decompress_skin does. */
static void valid_primitives(void)
{
    static packed p;
    static uint16_t joints[V * 4], ref_joints[V * 4];
    static float weights[V * 4], ref_weights[V * 4];
    for (size_t influences = 1; influences <= 4; ++influences) {
        make_mesh(influences);
        for (int m = 0; m < SP_METHOD_COUNT; ++m)
            for (uint32_t b = 0; b < 5; ++b) { /* 12: the Any w1 < 0 regression at small vertex budgets */
                static const uint32_t budgets[5] = {10, 12, 16, 32, 64};
                uint32_t bits = budgets[b];
                sp_compress_options o;
                sp_compress_options_default(&o);
                o.method = (sp_method)m;
                o.vertex_bits = bits;
                if (compress(&o, &p) != SP_OK) continue;
                sp_validation report;
                CHECK_MSG(sp_validate_packed(&p.prim, joints, weights, &report) == SP_OK, "method %d K %zu bits %u",
                          m, influences, bits);
                CHECK(report.codec.bits == p.info.weight_bits && report.codec.max_code == p.info.codec.max_code);
                uint32_t k = p.info.influences;
                CHECK(sp_decompress_skin(&p.info.codec, p.words, V, p.info.tuple_bits, p.lut, p.info.lut_size, JOINTS,
                                         ref_joints, ref_weights, NULL) == SP_OK);
                CHECK(memcmp(joints, ref_joints, V * k * sizeof(uint16_t)) == 0);
                CHECK(memcmp(weights, ref_weights, V * k * sizeof(float)) == 0);
                CHECK(message_has(&report, "ok"));
            }
    }
}

#define EXPECT(prim_expr, result_code, field_code, text)                                            \
    do {                                                                                            \
        sp_packed_primitive bad = base->prim;                                                      \
        prim_expr;                                                                                  \
        sp_validation report;                                                                       \
        CHECK_MSG(sp_validate_packed(&bad, NULL, NULL, &report) == (result_code), "%s", #prim_expr); \
        CHECK_MSG(report.field == (field_code), "%s: field %u", #prim_expr, report.field);         \
        CHECK_MSG(message_has(&report, text), "%s", #prim_expr);                                    \
    } while (0)

/* Every declared parameter out of range or contradicting the data, each with its message. */
static void bad_parameters(const packed* base)
{
    EXPECT(bad.params.method = SP_METHOD_COUNT, SP_ERR_UNSUPPORTED_METHOD, SP_FIELD_METHOD, "method: unknown");
    EXPECT(bad.params.influences = 5, SP_ERR_BITS_OUT_OF_RANGE, SP_FIELD_INFLUENCES, "influences: 5 above the maximum 4");
    EXPECT(bad.params.influences = (uint64_t)1 << 32 | 4, SP_ERR_BITS_OUT_OF_RANGE, SP_FIELD_INFLUENCES, "influences");
    EXPECT(bad.params.joint_count = 0, SP_ERR_TOO_MANY_JOINTS, SP_FIELD_JOINT_COUNT, "jointCount: 0 below the minimum 1");
    EXPECT(bad.params.joint_count = 70000, SP_ERR_TOO_MANY_JOINTS, SP_FIELD_JOINT_COUNT, "jointCount");
    EXPECT(bad.params.weight_bits = 65, SP_ERR_BITS_OUT_OF_RANGE, SP_FIELD_WEIGHT_BITS, "weightBits: 65 above the maximum 64");
    EXPECT(bad.params.weight_bits -= 1, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_WEIGHT_BITS, "weightBits");
    EXPECT(bad.params.tuple_bits += 1, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_TUPLE_BITS, "tupleBits");
    EXPECT(bad.params.tuple_bits = 33, SP_ERR_BITS_OUT_OF_RANGE, SP_FIELD_TUPLE_BITS, "tupleBits: 33");
    EXPECT(bad.params.n = 1, SP_ERR_BITS_OUT_OF_RANGE, SP_FIELD_N, "n: 1 below the minimum 2");
    EXPECT(bad.params.n = ((uint64_t)1 << 63) + 1, SP_ERR_BITS_OUT_OF_RANGE, SP_FIELD_N, "n:");
    EXPECT(bad.params.n += 1, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_WEIGHT_BITS, "weightBits"); /* n of more bits */
    EXPECT(bad.params.n = 20000000, SP_ERR_BITS_OUT_OF_RANGE, SP_FIELD_N, "n: 20000000 needs weight codes of more than 64 bits"); /* K = 4: > 64 bits */
    EXPECT(bad.params.axis_sample_count = 3, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_AXIS_SAMPLES, "axisSamples");
    EXPECT((bad.params.has_max_error = 1, bad.params.max_error = NAN), SP_ERR_BITS_OUT_OF_RANGE, SP_FIELD_MAX_ERROR,
           "maxError: not a number");
    EXPECT(bad.words_per_vertex = 2, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_VERTICES, "vertices: 2 contradicts");
    EXPECT(bad.lut_components = 3, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_TUPLE_TABLE, "tupleTable: 3");
    EXPECT(bad.lut_component_bytes = 2, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_TUPLE_TABLE, "tupleTable: 2");
    EXPECT(bad.skin_joint_count = JOINTS - 1, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_JOINT_COUNT, "jointCount: 40");
    EXPECT(bad.primitive_vertex_count = V + 1, SP_ERR_VERTEX_COUNT_MISMATCH, SP_FIELD_VERTICES,
           "vertices: 1024 packed vertices, the primitive has 1025");
    EXPECT(bad.lut_size = 0, SP_ERR_INDEX_OUT_OF_RANGE, SP_FIELD_TUPLE_TABLE, "tupleTable");
    EXPECT(bad.params.joint_count = 2, SP_ERR_JOINT_OUT_OF_RANGE, SP_FIELD_TUPLE_TABLE, "not below jointCount 2 at tuple");
}

/* Primitives sharing accessors must declare the same; unused axis entries do not count. */
static void shared_parameters(const packed* base)
{
    sp_packed_params a = base->prim.params, b = a;
    CHECK(sp_packed_params_equal(&a, &b) == 1);
    b.axis_samples[2] = 77; /* not declared: OSS has no axisSamples */
    CHECK(sp_packed_params_equal(&a, &b) == 1);
    b = a, b.joint_count += 1;
    CHECK(sp_packed_params_equal(&a, &b) == 0);
    b = a, b.n += 1;
    CHECK(sp_packed_params_equal(&a, &b) == 0);
    b = a, b.max_error *= 2;
    CHECK(sp_packed_params_equal(&a, &b) == 0);
    b = a, b.has_max_error = 0;
    CHECK(sp_packed_params_equal(&a, &b) == 0);
    b = a, b.method = SP_METHOD_ANY, b.axis_sample_count = 3;
    CHECK(sp_packed_params_equal(&a, &b) == 0 && sp_packed_params_equal(&a, NULL) == 0);
}

/* Corrupt words and tables, each named by vertex. */
static void bad_data(packed* base)
{
    static uint32_t words[2 * V];
    static uint16_t lut[4 * V];
    const sp_packed_primitive* prim = &base->prim;
    uint32_t wpv = prim->words_per_vertex, tb = (uint32_t)prim->params.tuple_bits;
    uint32_t wb = (uint32_t)prim->params.weight_bits, k = (uint32_t)prim->params.influences;
    CHECK(wpv == 1 && tb + wb < 32); /* the mutations below assume spare high bits */
    memcpy(words, prim->words, sizeof(words));
    words[812] |= 1u << 31;
    EXPECT(bad.words = words, SP_ERR_CORRUPT_DATA, SP_FIELD_VERTICES, "used bits at vertex 812");
    memcpy(words, prim->words, sizeof(words));
    words[100] = (words[100] & ((1u << wb) - 1)) | ((uint32_t)prim->lut_size << wb);
    EXPECT(bad.words = words, SP_ERR_TUPLE_OUT_OF_RANGE, SP_FIELD_VERTICES, "at vertex 100");
    /* a code of the OSS codec at max_code + 1, when the code width leaves room */
    memcpy(words, prim->words, sizeof(words));
    sp_codec codec;
    CHECK(sp_codec_from_params(SP_METHOD_OSS, k, prim->params.n, NULL, &codec) == SP_OK);
    if (codec.max_code + 1 < ((uint64_t)1 << wb)) {
        words[7] = (words[7] & ~((1u << wb) - 1)) | (uint32_t)(codec.max_code + 1);
        EXPECT(bad.words = words, SP_ERR_CODE_OUT_OF_RANGE, SP_FIELD_VERTICES, "above the largest code");
    }
    /* a vertex whose tuple repeats a joint in two weighted slots */
    memcpy(lut, prim->lut, sizeof(lut));
    size_t v = 0;
    for (; v < V; ++v) if ((base->words[v] & ((1u << wb) - 1)) != 0) break; /* more than one weight */
    CHECK(v < V);
    uint32_t tuple = base->words[v] >> wb;
    lut[tuple * k + 1] = lut[tuple * k];
    char text[64];
    snprintf(text, sizeof(text), "carries weight in slots 0 and 1 (tuple %u) at vertex", tuple);
    EXPECT(bad.lut = lut, SP_ERR_DUPLICATE_JOINT, SP_FIELD_VERTICES, text);
    /* the older decoder applies the same rule */
    static uint16_t joints[4 * V];
    static float weights[4 * V];
    size_t bad_vertex = V;
    CHECK(sp_decompress_skin(&base->info.codec, base->words, V, tb, lut, prim->lut_size, JOINTS, joints, weights,
                             &bad_vertex) == SP_ERR_DUPLICATE_JOINT);
    CHECK(bad_vertex <= v);
}

/* Grid methods: an unsorted grid point; Any: a point past the simplex (w1 < 0). */
static void codes_outside_simplex(void)
{
    static packed p;
    make_mesh(4);
    for (int m = 0; m < SP_METHOD_COUNT; ++m) {
        sp_compress_options o;
        sp_compress_options_default(&o);
        o.method = (sp_method)m;
        o.vertex_bits = 0;
        o.weight_bits = 20;
        CHECK(compress(&o, &p) == SP_OK);
        const sp_codec* codec = &p.info.codec;
        float w[4] = {0.1f, 0.2f, 0.3f, 0.4f}; /* ascending: never written */
        uint64_t code = codec->max_code; /* Any: every axis at its top, sum 13/12 > 1 */
        uint64_t q[4];
        if (m != SP_METHOD_ANY && m != SP_METHOD_OSS) { /* grid: pack q2 > q1 by hand */
            code = 0;
            for (int i = 0; i < 4; ++i) q[i] = (uint64_t)(w[i] * (float)codec->scale);
            uint32_t shift = 0;
            for (int i = m == SP_METHOD_FIXED ? 0 : 1, c = 0; i < 4; ++i, ++c) {
                code |= q[i] << shift;
                shift += codec->component_bits[c];
            }
        }
        if (m == SP_METHOD_OSS) continue; /* every OSS code below max_code is a valid sample */
        uint32_t tb = p.info.tuple_bits, wb = p.info.weight_bits;
        static uint32_t words[2 * V];
        memcpy(words, p.words, sizeof(words));
        words[812] = (uint32_t)code | ((words[812] >> wb) << wb);
        (void)tb;
        sp_packed_primitive bad = p.prim;
        bad.words = words;
        sp_validation report;
        CHECK_MSG(sp_validate_packed(&bad, NULL, NULL, &report) == SP_ERR_CODE_OUTSIDE_SIMPLEX, "method %d", m);
        CHECK(message_has(&report, "outside the simplex at vertex 812"));
    }
}

static void meshlets(packed* base)
{
    static meshlet_arrays a, b;
    CHECK(build_meshlets(base, &a) == 0);
    base->prim.meshlets = &a.view;
    sp_validation report;
    CHECK(sp_validate_packed(&base->prim, NULL, NULL, &report) == SP_OK);
    b = a;
    b.view.offsets = b.offsets, b.view.counts = b.counts, b.view.vertices = b.vertices;
    b.view.vertex_tuples = b.vertex_tuples, b.view.triangles = b.triangles, b.view.joints = b.joints;
    b.view.tuples = b.tuples;
    b.counts[4 * 2] = 0;
    EXPECT(bad.meshlets = &b.view, SP_ERR_LIMIT_EXCEEDED, SP_FIELD_MESHLET_COUNTS, "meshlets.counts: count 0 outside 1..1 at meshlet 2");
    b = a, b.view.offsets = b.offsets, b.view.counts = b.counts;
    b.counts[4 * 1] = 65; /* over maxVertices 64 */
    EXPECT(bad.meshlets = &b.view, SP_ERR_LIMIT_EXCEEDED, SP_FIELD_MESHLET_VERTICES, "at meshlet 1");
    b = a, b.view.offsets = b.offsets, b.view.counts = b.counts;
    b.offsets[4 * 3] = (uint32_t)a.view.vertex_entries;
    EXPECT(bad.meshlets = &b.view, SP_ERR_INDEX_OUT_OF_RANGE, SP_FIELD_MESHLET_OFFSETS, "at meshlet 3");
    b = a, b.view.triangles = b.triangles;
    b.triangles[3 * a.meshlets[4].triangle_offset + 1] = (uint8_t)a.meshlets[4].vertex_count;
    EXPECT(bad.meshlets = &b.view, SP_ERR_INDEX_OUT_OF_RANGE, SP_FIELD_MESHLET_TRIANGLES, "meshlets.triangles: index");
    b = a, b.view.vertices = b.vertices;
    b.vertices[a.meshlets[0].vertex_offset] = V;
    EXPECT(bad.meshlets = &b.view, SP_ERR_INDEX_OUT_OF_RANGE, SP_FIELD_MESHLET_VERTICES, "index 1024 not below 1024");
    b = a, b.view.joints = b.joints;
    b.joints[a.meshlets[0].joint_offset] = JOINTS;
    EXPECT(bad.meshlets = &b.view, SP_ERR_JOINT_OUT_OF_RANGE, SP_FIELD_MESHLET_JOINTS, "meshlets.joints: joint 40");
    b = a, b.view.tuples = b.tuples;
    b.tuples[a.meshlets[0].tuple_offset * base->info.influences] = (uint8_t)a.meshlets[0].joint_count;
    EXPECT(bad.meshlets = &b.view, SP_ERR_INDEX_OUT_OF_RANGE, SP_FIELD_MESHLET_TUPLES, "meshlets.tuples");
    /* a palette that points the vertex at another joint: valid indices, wrong skin */
    b = a, b.view.joints = b.joints;
    size_t m = 0;
    while (m < TRIS && a.meshlets[m].joint_count < 2) ++m;
    CHECK(m < TRIS);
    uint16_t first = b.joints[a.meshlets[m].joint_offset];
    b.joints[a.meshlets[m].joint_offset] = b.joints[a.meshlets[m].joint_offset + 1];
    b.joints[a.meshlets[m].joint_offset + 1] = first;
    EXPECT(bad.meshlets = &b.view, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_MESHLET_TUPLES, "where the vertex decodes to");
    b = a;
    b.view.max_joints = 300;
    EXPECT(bad.meshlets = &b.view, SP_ERR_BITS_OUT_OF_RANGE, SP_FIELD_MESHLET_LIMITS, "meshlets limits: 300 above the maximum 255");
    base->prim.meshlets = NULL;
}

int main(void)
{
    abi_and_rules();
    max_error_search();
    any_codes_always_valid();
    valid_primitives();
    codes_outside_simplex();
    static packed base;
    make_mesh(4);
    sp_compress_options o;
    sp_compress_options_default(&o);
    o.vertex_bits = 0;
    o.weight_bits = 20; /* spare high bits for the corruptions */
    CHECK(compress(&o, &base) == SP_OK);
    bad_parameters(&base);
    shared_parameters(&base);
    bad_data(&base);
    meshlets(&base);
    return check_report("test_validate");
}
