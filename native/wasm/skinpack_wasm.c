/*
 * skinpack_wasm.c - the WebAssembly interface of libskinpack's decode side (web/src/wasm.js).
 *
 * JavaScript cannot fill C structs without copying their layout, so it hands the library one
 * primitive through a call object: set the declared parameters and the arrays (in this
 * module's memory, allocated with the exported malloc), validate (and decode), then read the
 * result, the message and the codec back through the functions here. Every format rule stays
 * in the library (sp_validate_packed, sp_codec_from_params, sp_format_validation); this file
 * only moves values across the boundary and lays out the decoded skin as three.js wants it.
 */
#include <stdlib.h>
#include <string.h>

#include "skinpack.h"

#define SPW_EXPORT(name) __attribute__((export_name(#name)))

/* One validation or decode: what the caller declared, what the library reported. */
typedef struct spw_call {
    sp_packed_primitive primitive;
    sp_validation report;
    char message[256];
} spw_call;

SPW_EXPORT(spw_call_create) spw_call* spw_call_create(void)
{
    return (spw_call*)calloc(1, sizeof(spw_call));
}

SPW_EXPORT(spw_call_destroy) void spw_call_destroy(spw_call* call)
{
    free(call);
}

/* The declared parameters, as the extension's JSON gives them (method as sp_method_from_name
 * returns it; axis_count: entries of "axisSamples", the first three passed in a0..a2). */
SPW_EXPORT(spw_set_params)
void spw_set_params(spw_call* call, uint32_t method, uint64_t influences, uint64_t joint_count, uint64_t weight_bits,
                    uint64_t tuple_bits, uint64_t n, uint32_t axis_count, uint64_t a0, uint64_t a1, uint64_t a2,
                    uint32_t has_max_error, double max_error)
{
    sp_packed_params* p = &call->primitive.params;
    p->method = method;
    p->influences = influences;
    p->joint_count = joint_count;
    p->weight_bits = weight_bits;
    p->tuple_bits = tuple_bits;
    p->n = n;
    p->axis_sample_count = axis_count;
    p->axis_samples[0] = a0;
    p->axis_samples[1] = a1;
    p->axis_samples[2] = a2;
    p->has_max_error = has_max_error;
    p->max_error = max_error;
}

/* The "vertices" accessor: vertex_count elements of words_per_vertex u32 (its component
 * count); primitive_vertex_count: the primitive's POSITION count. */
SPW_EXPORT(spw_set_words)
void spw_set_words(spw_call* call, const uint32_t* words, size_t vertex_count, uint32_t words_per_vertex,
                   size_t primitive_vertex_count)
{
    call->primitive.words = words;
    call->primitive.vertex_count = vertex_count;
    call->primitive.words_per_vertex = words_per_vertex;
    call->primitive.primitive_vertex_count = primitive_vertex_count;
}

/* The "tupleTable" accessor widened to u16: lut_size elements of components joints, stored in
 * component_bytes each; skin_joint_count: joints of the smallest skin using the mesh (0: none). */
SPW_EXPORT(spw_set_table)
void spw_set_table(spw_call* call, const uint16_t* lut, size_t lut_size, uint32_t components, uint32_t component_bytes,
                   size_t skin_joint_count)
{
    call->primitive.lut = lut;
    call->primitive.lut_size = lut_size;
    call->primitive.lut_components = components;
    call->primitive.lut_component_bytes = component_bytes;
    call->primitive.skin_joint_count = skin_joint_count;
}

/* sp_validate_packed on the call's primitive; joints/weights (vertex_count * K each, weight
 * order) may be NULL to validate only. Returns the sp_result. */
SPW_EXPORT(spw_validate) uint32_t spw_validate(spw_call* call, uint16_t* joints, float* weights)
{
    return (uint32_t)sp_validate_packed(&call->primitive, joints, weights, &call->report);
}

/*
 * Checks the declared parameters alone, for callers that have no arrays yet: sp_validate_packed
 * on a primitive without arrays. It checks, in its documented order, every parameter's range,
 * the method's rules for n and axisSamples and weightBits against the codec before anything
 * about the arrays, whose first check (a tuple table of at least one entry) an empty primitive
 * fails: that failure means the parameters passed, and the report then holds their codec.
 * Returns the sp_result; spw_validate checks the rest.
 */
SPW_EXPORT(spw_check_params) uint32_t spw_check_params(spw_call* call)
{
    sp_packed_primitive params_only;
    memset(&params_only, 0, sizeof(params_only));
    params_only.params = call->primitive.params;
    sp_result r = sp_validate_packed(&params_only, NULL, NULL, &call->report);
    if (r == SP_ERR_INDEX_OUT_OF_RANGE && call->report.field == SP_FIELD_TUPLE_TABLE) {
        sp_codec codec = call->report.codec;
        memset(&call->report, 0, sizeof(call->report));
        call->report.codec = codec;
        r = SP_OK;
    }
    return (uint32_t)r;
}

/* The message of the last report (sp_format_validation), NUL-terminated in the call object. */
SPW_EXPORT(spw_message) const char* spw_message(spw_call* call)
{
    sp_format_validation(&call->report, call->message, sizeof(call->message));
    return call->message;
}

/* sp_packed_params_equal of two calls' declared parameters: 1 if primitives that share a
 * "vertices" accessor may declare both, else 0. */
SPW_EXPORT(spw_params_equal) uint32_t spw_params_equal(const spw_call* a, const spw_call* b)
{
    return (uint32_t)sp_packed_params_equal(&a->primitive.params, &b->primitive.params);
}

/* Where the last report stopped: its sp_field and index (vertex, table entry, meshlet, axis). */
SPW_EXPORT(spw_report_field) uint32_t spw_report_field(const spw_call* call)
{
    return call->report.field;
}

SPW_EXPORT(spw_report_index) size_t spw_report_index(const spw_call* call)
{
    return call->report.index;
}

/* The codec of a successful report, as integers in this order (SPW_CODEC_VALUES entries):
 * method, influences, bits, component_bits[0..3], n, axis_samples[0..2], scale, max_code. */
#define SPW_CODEC_VALUES 14
SPW_EXPORT(spw_codec_values) void spw_codec_values(const spw_call* call, uint64_t* out)
{
    const sp_codec* c = &call->report.codec;
    out[0] = c->method;
    out[1] = c->influences;
    out[2] = c->bits;
    for (int i = 0; i < SP_MAX_INFLUENCES; ++i) out[3 + i] = c->component_bits[i];
    out[7] = c->n;
    for (int i = 0; i < SP_MAX_INFLUENCES - 1; ++i) out[8 + i] = c->axis_samples[i];
    out[11] = c->scale;
    out[12] = c->max_code;
    out[13] = SPW_CODEC_VALUES;
}

/* The proven error bound of the reported codec (sp_codec.max_error). */
SPW_EXPORT(spw_codec_max_error) double spw_codec_max_error(const spw_call* call)
{
    return call->report.codec.max_error;
}

/*
 * Lays out a decoded skin in place as `skinpack decompress` writes JOINTS_0/WEIGHTS_0 and
 * three.js reads skinIndex/skinWeight: spw_validate wrote count vertices of K joints (u16) and
 * weights (weight order) at the start of joints and weights, which hold count * 4 entries;
 * afterwards every vertex has 4 slots, a slot without weight (or past K) joint 0 and weight 0,
 * and with joint_bytes 1 the joints are u8 (count * 4 bytes at the start of joints).
 * Backwards, so no K-wide entry is overwritten before it is read; the u8 narrowing forwards.
 */
SPW_EXPORT(spw_expand) void spw_expand(uint16_t* joints, float* weights, size_t count, uint32_t k, uint32_t joint_bytes)
{
    for (size_t v = count; v-- > 0;)
        for (uint32_t s = 4; s-- > 0;) {
            float w = s < k ? weights[v * k + s] : 0.0f;
            joints[v * 4 + s] = s < k && w > 0 ? joints[v * k + s] : 0;
            weights[v * 4 + s] = w;
        }
    if (joint_bytes == 1) {
        uint8_t* narrow = (uint8_t*)joints;
        /* the caller asks for u8 only when jointCount <= 256, so every joint fits */
        for (size_t i = 0; i < count * 4; ++i) narrow[i] = (uint8_t)joints[i];
    }
}
