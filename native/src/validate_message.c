/* Field names and one-line messages for sp_validate_packed reports: what is wrong, where. */
#include <stdio.h>

#include "skinpack.h"

static const char* const field_names[SP_FIELD_COUNT] = {
    "", "method", "influences", "jointCount", "weightBits", "tupleBits", "n", "axisSamples", "maxError",
    "vertices", "tupleTable", "meshlets.offsets", "meshlets.counts", "meshlets.vertices", "meshlets.vertexTuples",
    "meshlets.triangles", "meshlets.joints", "meshlets.tuples", "meshlets limits"};

const char* sp_field_name(sp_field field)
{
    return (unsigned)field < SP_FIELD_COUNT ? field_names[field] : "";
}

/* What the index of a report counts, by field. */
static const char* index_unit(uint32_t field)
{
    if (field == SP_FIELD_VERTICES) return "vertex";
    if (field == SP_FIELD_TUPLE_TABLE) return "tuple";
    if (field == SP_FIELD_AXIS_SAMPLES) return "axis";
    if (field >= SP_FIELD_MESHLET_OFFSETS && field < SP_FIELD_MESHLET_LIMITS) return "meshlet";
    return NULL;
}

size_t sp_format_validation(const sp_validation* report, char* buffer, size_t buffer_size)
{
    char where[64] = "";
    if (!report) return (size_t)snprintf(buffer, buffer_size, "no report");
    if (report->result == SP_OK) return (size_t)snprintf(buffer, buffer_size, "ok");
    const char* name = sp_field_name((sp_field)report->field);
    const char* unit = index_unit(report->field);
    unsigned long long value = report->value, limit = report->limit;
    if (unit) snprintf(where, sizeof(where), " at %s %zu", unit, report->index);
    switch (report->result) {
    case SP_ERR_CODE_OUT_OF_RANGE:
        return (size_t)snprintf(buffer, buffer_size, "%s: weight code %llu above the largest code %llu%s", name, value,
                                limit, where);
    case SP_ERR_CODE_OUTSIDE_SIMPLEX:
        return (size_t)snprintf(buffer, buffer_size, "%s: weight code %llu outside the simplex%s", name, value, where);
    case SP_ERR_DUPLICATE_JOINT:
        return (size_t)snprintf(buffer, buffer_size, "%s: joint %llu carries weight in slots %u and %u (tuple %llu)%s",
                                name, value, report->slot, report->other_slot, limit, where);
    case SP_ERR_TUPLE_OUT_OF_RANGE:
        return (size_t)snprintf(buffer, buffer_size, "%s: tuple index %llu not below the table's %llu tuples%s", name,
                                value, limit, where);
    case SP_ERR_CORRUPT_DATA:
        return (size_t)snprintf(buffer, buffer_size, "%s: bits set above the %llu used bits%s", name, limit, where);
    case SP_ERR_JOINT_OUT_OF_RANGE:
        return (size_t)snprintf(buffer, buffer_size, "%s: joint %llu not below jointCount %llu%s", name, value, limit,
                                where);
    case SP_ERR_VERTEX_COUNT_MISMATCH:
        return (size_t)snprintf(buffer, buffer_size, "%s: %llu packed vertices, the primitive has %llu", name, value,
                                limit);
    case SP_ERR_INDEX_OUT_OF_RANGE:
        return (size_t)snprintf(buffer, buffer_size, "%s: index %llu not below %llu%s", name, value, limit, where);
    case SP_ERR_LIMIT_EXCEEDED:
        return (size_t)snprintf(buffer, buffer_size, "%s: count %llu outside 1..%llu%s", name, value, limit, where);
    case SP_ERR_PARAMETER_MISMATCH:
        if (report->field == SP_FIELD_MESHLET_TUPLES)
            return (size_t)snprintf(buffer, buffer_size, "%s: palette gives joint %llu in slot %u where the vertex "
                                    "decodes to joint %llu%s", name, value, report->slot, limit, where);
        return (size_t)snprintf(buffer, buffer_size, "%s: %llu contradicts the other parameters or the data (expected "
                                "%llu)%s", name, value, limit, where);
    case SP_ERR_UNSUPPORTED_METHOD:
        return (size_t)snprintf(buffer, buffer_size, "%s: unknown method", name);
    case SP_ERR_BITS_OUT_OF_RANGE:
    case SP_ERR_TOO_MANY_JOINTS:
        if (report->field == SP_FIELD_MAX_ERROR)
            return (size_t)snprintf(buffer, buffer_size, "%s: not a number in [0, 1]", name);
        if (value < limit)
            return (size_t)snprintf(buffer, buffer_size, "%s: %llu below the minimum %llu%s", name, value, limit, where);
        if (limit == SP_MAX_WEIGHT_BITS && (report->field == SP_FIELD_N || report->field == SP_FIELD_AXIS_SAMPLES))
            return (size_t)snprintf(buffer, buffer_size, "%s: %llu needs weight codes of more than 64 bits%s", name,
                                    value, where);
        return (size_t)snprintf(buffer, buffer_size, "%s: %llu above the maximum %llu%s", name, value, limit, where);
    default:
        return (size_t)snprintf(buffer, buffer_size, "%s%s%s%s", name, *name ? ": " : "",
                                sp_result_string((sp_result)report->result), where);
    }
}
