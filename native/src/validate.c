/*
 * Validation of a stored SKINPACK_packed_skin primitive: the one implementation of every rule
 * of docs/extension/README.md that a reader checks. Order: declared parameters, then how they
 * fit each other and the stored arrays, then the tuple table, every vertex, the meshlets. The
 * first failure stops and is reported with its field, index and values (sp_format_validation
 * turns that into the message).
 */
#include <string.h>

#include "codec_internal.h"

static sp_result fail(sp_validation* report, sp_result result, sp_field field, size_t index, uint64_t value,
                      uint64_t limit)
{
    report->result = result;
    report->field = (uint32_t)field;
    report->index = index;
    report->value = value;
    report->limit = limit;
    return result;
}

int sp_find_duplicate_joint(const uint16_t* joints, const float* weights, uint32_t k, uint32_t* slot,
                            uint32_t* other_slot)
{
    for (uint32_t a = 0; a < k; ++a)
        for (uint32_t b = a + 1; b < k; ++b)
            if (joints[a] == joints[b] && weights[a] > 0 && weights[b] > 0) {
                *slot = a;
                *other_slot = b;
                return 1;
            }
    return 0;
}

/* Ranges of the declared integers and the method's own rules for n and axisSamples. */
static sp_result check_params(const sp_packed_params* p, sp_validation* report)
{
    if (p->method >= SP_METHOD_COUNT) return fail(report, SP_ERR_UNSUPPORTED_METHOD, SP_FIELD_METHOD, 0, p->method, 0);
    if (p->influences < 1 || p->influences > SP_MAX_INFLUENCES)
        return fail(report, SP_ERR_BITS_OUT_OF_RANGE, SP_FIELD_INFLUENCES, 0, p->influences,
                    p->influences < 1 ? 1 : SP_MAX_INFLUENCES);
    if (p->joint_count < 1 || p->joint_count > SP_MAX_JOINTS)
        return fail(report, SP_ERR_TOO_MANY_JOINTS, SP_FIELD_JOINT_COUNT, 0, p->joint_count,
                    p->joint_count < 1 ? 1 : SP_MAX_JOINTS);
    if (p->weight_bits > SP_MAX_WEIGHT_BITS)
        return fail(report, SP_ERR_BITS_OUT_OF_RANGE, SP_FIELD_WEIGHT_BITS, 0, p->weight_bits, SP_MAX_WEIGHT_BITS);
    if (p->tuple_bits > 32)
        return fail(report, SP_ERR_BITS_OUT_OF_RANGE, SP_FIELD_TUPLE_BITS, 0, p->tuple_bits, 32);
    uint32_t k = (uint32_t)p->influences;
    uint32_t want_axes = p->method == SP_METHOD_ANY ? k - 1 : 0;
    if (p->axis_sample_count != want_axes)
        return fail(report, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_AXIS_SAMPLES, 0, p->axis_sample_count, want_axes);
    if (p->has_max_error && !(p->max_error >= 0 && p->max_error <= 1))
        return fail(report, SP_ERR_BITS_OUT_OF_RANGE, SP_FIELD_MAX_ERROR, 0, 0, 1);
    if (k == 1 || p->method == SP_METHOD_ANY) {
        if (p->n != 0) return fail(report, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_N, 0, p->n, 0);
    } else {
        uint64_t lo = p->method == SP_METHOD_OSS || p->method == SP_METHOD_POT ? 2 : 1;
        uint64_t hi = p->method == SP_METHOD_OSS ? ((uint64_t)1 << 63) : 64;
        if (p->n < lo || p->n > hi)
            return fail(report, SP_ERR_BITS_OUT_OF_RANGE, SP_FIELD_N, 0, p->n, p->n < lo ? lo : hi);
    }
    for (uint32_t a = 0; a < want_axes; ++a)
        if (p->axis_samples[a] < 2)
            return fail(report, SP_ERR_BITS_OUT_OF_RANGE, SP_FIELD_AXIS_SAMPLES, a, p->axis_samples[a], 2);
    sp_result r = sp_codec_from_params((sp_method)p->method, k, p->n, p->axis_samples, &report->codec);
    if (r != SP_OK) /* in range one by one, but the codes need more than 64 bits */
        return fail(report, SP_ERR_BITS_OUT_OF_RANGE, p->method == SP_METHOD_ANY ? SP_FIELD_AXIS_SAMPLES : SP_FIELD_N,
                    0, p->method == SP_METHOD_ANY ? p->axis_samples[0] : p->n, SP_MAX_WEIGHT_BITS);
    return SP_OK;
}

/* The declared widths against the codec and the arrays; the counts against the primitive. */
static sp_result check_layout(const sp_packed_primitive* prim, sp_validation* report)
{
    const sp_packed_params* p = &prim->params;
    const sp_codec* codec = &report->codec;
    if (p->weight_bits != codec->bits)
        return fail(report, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_WEIGHT_BITS, 0, p->weight_bits, codec->bits);
    if (prim->lut_size == 0) return fail(report, SP_ERR_INDEX_OUT_OF_RANGE, SP_FIELD_TUPLE_TABLE, 0, 0, 1);
    uint32_t tuple_bits = sp_index_bits(prim->lut_size);
    if (p->tuple_bits != tuple_bits)
        return fail(report, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_TUPLE_BITS, 0, p->tuple_bits, tuple_bits);
    uint32_t words = sp_words_per_vertex((uint32_t)p->tuple_bits, (uint32_t)p->weight_bits);
    if (words == 0)
        return fail(report, SP_ERR_BITS_OUT_OF_RANGE, SP_FIELD_TUPLE_BITS, 0, p->tuple_bits + p->weight_bits, 64);
    if (prim->words_per_vertex != words)
        return fail(report, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_VERTICES, 0, prim->words_per_vertex, words);
    if (prim->lut_components != p->influences)
        return fail(report, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_TUPLE_TABLE, 0, prim->lut_components, p->influences);
    uint32_t joint_bytes = sp_joint_bytes((size_t)p->joint_count);
    if (prim->lut_component_bytes != joint_bytes)
        return fail(report, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_TUPLE_TABLE, 0, prim->lut_component_bytes,
                    joint_bytes);
    if (prim->skin_joint_count && p->joint_count > prim->skin_joint_count)
        return fail(report, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_JOINT_COUNT, 0, p->joint_count,
                    prim->skin_joint_count);
    if (prim->vertex_count != prim->primitive_vertex_count || prim->vertex_count == 0)
        return fail(report, SP_ERR_VERTEX_COUNT_MISMATCH, SP_FIELD_VERTICES, 0, prim->vertex_count,
                    prim->primitive_vertex_count);
    for (size_t i = 0; i < prim->lut_size * p->influences; ++i)
        if (prim->lut[i] >= p->joint_count)
            return fail(report, SP_ERR_JOINT_OUT_OF_RANGE, SP_FIELD_TUPLE_TABLE, i / p->influences, prim->lut[i],
                        p->joint_count);
    return SP_OK;
}

/* Decodes vertex v of a primitive whose layout passed, checking the vertex's own rules. */
static sp_result decode_vertex(const sp_packed_primitive* prim, size_t v, uint16_t* joints, float* weights,
                               sp_validation* report)
{
    const sp_codec* codec = &report->codec;
    uint32_t k = codec->influences, tuple_bits = (uint32_t)prim->params.tuple_bits;
    const uint32_t* words = prim->words + v * prim->words_per_vertex;
    uint32_t tuple = 0;
    uint64_t code = 0;
    if (sp_unpack_vertices(words, 1, tuple_bits, codec->bits, &tuple, &code, NULL) != SP_OK)
        return fail(report, SP_ERR_CORRUPT_DATA, SP_FIELD_VERTICES, v, prim->words_per_vertex == 2 ? words[1] : words[0],
                    tuple_bits + codec->bits);
    if (tuple >= prim->lut_size) return fail(report, SP_ERR_TUPLE_OUT_OF_RANGE, SP_FIELD_VERTICES, v, tuple, prim->lut_size);
    if (code > codec->max_code) return fail(report, SP_ERR_CODE_OUT_OF_RANGE, SP_FIELD_VERTICES, v, code, codec->max_code);
    if (sp_decode_weights_batch(codec, &code, 1, weights, NULL) != SP_OK)
        return fail(report, SP_ERR_CODE_OUTSIDE_SIMPLEX, SP_FIELD_VERTICES, v, code, codec->max_code);
    memcpy(joints, prim->lut + (size_t)tuple * k, k * sizeof(uint16_t));
    if (sp_find_duplicate_joint(joints, weights, k, &report->slot, &report->other_slot))
        return fail(report, SP_ERR_DUPLICATE_JOINT, SP_FIELD_VERTICES, v, joints[report->slot], tuple);
    return SP_OK;
}

static sp_result check_vertices(const sp_packed_primitive* prim, uint16_t* out_joints, float* out_weights,
                                sp_validation* report)
{
    uint32_t k = report->codec.influences;
    for (size_t v = 0; v < prim->vertex_count; ++v) {
        uint16_t joints[SP_MAX_INFLUENCES];
        float weights[SP_MAX_INFLUENCES];
        sp_result r = decode_vertex(prim, v, joints, weights, report);
        if (r != SP_OK) return r;
        if (out_joints) memcpy(out_joints + v * k, joints, k * sizeof(uint16_t));
        if (out_weights) memcpy(out_weights + v * k, weights, k * sizeof(float));
    }
    return SP_OK;
}

/* Declared limits: in their ranges (docs/extension), and absolute caps when absent. */
static sp_result check_meshlet_limits(const sp_packed_meshlets* ml, uint32_t limits[4], sp_validation* report)
{
    static const uint32_t lowest[3] = {3, 1, 1};
    static const uint32_t highest[3] = {SP_MESHLET_MAX_VERTICES, SP_MESHLET_MAX_TRIANGLES, SP_MESHLET_MAX_JOINTS};
    const uint32_t declared[3] = {ml->max_vertices, ml->max_triangles, ml->max_joints};
    for (uint32_t i = 0; i < 3; ++i) {
        if (declared[i] && (declared[i] < lowest[i] || declared[i] > highest[i]))
            return fail(report, SP_ERR_BITS_OUT_OF_RANGE, SP_FIELD_MESHLET_LIMITS, i, declared[i],
                        declared[i] < lowest[i] ? lowest[i] : highest[i]);
        limits[i] = declared[i] ? declared[i] : highest[i];
    }
    limits[3] = 255; /* local tuple indices are u8 */
    return SP_OK;
}

/* Offsets + counts of meshlet m inside the arrays, counts non-zero and within the limits. */
static sp_result check_meshlet_ranges(const sp_packed_meshlets* ml, size_t m, const uint32_t limits[4],
                                      sp_validation* report)
{
    static const sp_field fields[4] = {SP_FIELD_MESHLET_VERTICES, SP_FIELD_MESHLET_TRIANGLES, SP_FIELD_MESHLET_JOINTS,
                                       SP_FIELD_MESHLET_TUPLES};
    const uint64_t sizes[4] = {ml->vertex_entries, ml->triangle_bytes / 3, ml->joint_entries, ml->tuple_count};
    for (uint32_t i = 0; i < 4; ++i) {
        uint64_t offset = ml->offsets[4 * m + i], count = ml->counts[4 * m + i];
        if (count == 0 || count > 0xFFFF)
            return fail(report, SP_ERR_LIMIT_EXCEEDED, SP_FIELD_MESHLET_COUNTS, m, count, count ? 0xFFFF : 1);
        if (count > limits[i]) return fail(report, SP_ERR_LIMIT_EXCEEDED, fields[i], m, count, limits[i]);
        if (offset + count > sizes[i])
            return fail(report, SP_ERR_INDEX_OUT_OF_RANGE, SP_FIELD_MESHLET_OFFSETS, m, offset + count, sizes[i]);
    }
    return SP_OK;
}

/* Every local index of meshlet m in range; palette joints agree with the decoded vertices. */
static sp_result check_meshlet_indices(const sp_packed_primitive* prim, size_t m, sp_validation* report)
{
    const sp_packed_meshlets* ml = prim->meshlets;
    uint32_t k = report->codec.influences;
    size_t vo = ml->offsets[4 * m], to = ml->offsets[4 * m + 1], jo = ml->offsets[4 * m + 2], uo = ml->offsets[4 * m + 3];
    uint32_t vc = ml->counts[4 * m], tc = ml->counts[4 * m + 1], jc = ml->counts[4 * m + 2], uc = ml->counts[4 * m + 3];
    for (uint32_t i = 0; i < 3 * tc; ++i)
        if (ml->triangles[3 * to + i] >= vc)
            return fail(report, SP_ERR_INDEX_OUT_OF_RANGE, SP_FIELD_MESHLET_TRIANGLES, m, ml->triangles[3 * to + i], vc);
    for (uint32_t i = 0; i < jc; ++i)
        if (ml->joints[jo + i] >= prim->params.joint_count)
            return fail(report, SP_ERR_JOINT_OUT_OF_RANGE, SP_FIELD_MESHLET_JOINTS, m, ml->joints[jo + i],
                        prim->params.joint_count);
    for (uint32_t i = 0; i < uc * k; ++i)
        if (ml->tuples[uo * k + i] >= jc)
            return fail(report, SP_ERR_INDEX_OUT_OF_RANGE, SP_FIELD_MESHLET_TUPLES, m, ml->tuples[uo * k + i], jc);
    for (uint32_t i = 0; i < vc; ++i) {
        uint32_t source = ml->vertices[vo + i], local = ml->vertex_tuples[vo + i];
        if (source >= prim->vertex_count)
            return fail(report, SP_ERR_INDEX_OUT_OF_RANGE, SP_FIELD_MESHLET_VERTICES, m, source, prim->vertex_count);
        if (local >= uc) return fail(report, SP_ERR_INDEX_OUT_OF_RANGE, SP_FIELD_MESHLET_VERTEX_TUPLES, m, local, uc);
        uint16_t joints[SP_MAX_INFLUENCES];
        float weights[SP_MAX_INFLUENCES];
        sp_result r = decode_vertex(prim, source, joints, weights, report);
        if (r != SP_OK) return r;
        for (uint32_t s = 0; s < k; ++s) {
            uint16_t palette_joint = ml->joints[jo + ml->tuples[(uo + local) * k + s]];
            if (weights[s] > 0 && palette_joint != joints[s]) {
                report->slot = s;
                return fail(report, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_MESHLET_TUPLES, m, palette_joint, joints[s]);
            }
        }
    }
    return SP_OK;
}

static sp_result check_meshlets(const sp_packed_primitive* prim, sp_validation* report)
{
    const sp_packed_meshlets* ml = prim->meshlets;
    uint32_t limits[4];
    sp_result r = check_meshlet_limits(ml, limits, report);
    if (r != SP_OK) return r;
    if (ml->meshlet_count == 0) return fail(report, SP_ERR_LIMIT_EXCEEDED, SP_FIELD_MESHLET_OFFSETS, 0, 0, 1);
    if (!ml->offsets || !ml->counts || !ml->vertices || !ml->vertex_tuples || !ml->triangles || !ml->joints ||
        !ml->tuples)
        return fail(report, SP_ERR_INVALID_ARGUMENT, SP_FIELD_MESHLET_OFFSETS, 0, 0, 0);
    if (ml->triangle_bytes % 3)
        return fail(report, SP_ERR_PARAMETER_MISMATCH, SP_FIELD_MESHLET_TRIANGLES, 0, ml->triangle_bytes, 3);
    for (size_t m = 0; m < ml->meshlet_count; ++m) {
        if ((r = check_meshlet_ranges(ml, m, limits, report)) != SP_OK) return r;
        if ((r = check_meshlet_indices(prim, m, report)) != SP_OK) return r;
    }
    return SP_OK;
}

sp_result sp_validate_packed(const sp_packed_primitive* primitive, uint16_t* out_joints, float* out_weights,
                             sp_validation* report)
{
    sp_validation local;
    if (!report) report = &local;
    memset(report, 0, sizeof(*report));
    if (!primitive || (primitive->vertex_count && !primitive->words) || (primitive->lut_size && !primitive->lut))
        return fail(report, SP_ERR_INVALID_ARGUMENT, SP_FIELD_NONE, 0, 0, 0);
    sp_result r = check_params(&primitive->params, report);
    if (r == SP_OK) r = check_layout(primitive, report);
    if (r == SP_OK) r = check_vertices(primitive, out_joints, out_weights, report);
    if (r == SP_OK && primitive->meshlets) r = check_meshlets(primitive, report);
    if (r == SP_OK) {
        sp_codec codec = report->codec;
        memset(report, 0, sizeof(*report));
        report->codec = codec;
    }
    return r;
}

int sp_packed_params_equal(const sp_packed_params* a, const sp_packed_params* b)
{
    if (!a || !b) return 0;
    int same = a->method == b->method && a->influences == b->influences && a->joint_count == b->joint_count &&
               a->weight_bits == b->weight_bits && a->tuple_bits == b->tuple_bits && a->n == b->n &&
               a->axis_sample_count == b->axis_sample_count && a->has_max_error == b->has_max_error &&
               (!a->has_max_error || a->max_error == b->max_error);
    for (uint32_t i = 0; same && i < a->axis_sample_count && i < SP_MAX_INFLUENCES - 1; ++i)
        same = a->axis_samples[i] == b->axis_samples[i];
    return same;
}
