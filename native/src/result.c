/* Result messages and method names. */
#include <string.h>

#include "skinpack.h"

const char* sp_result_string(sp_result result)
{
    switch (result) {
    case SP_OK: return "ok";
    case SP_ERR_INVALID_ARGUMENT: return "invalid argument";
    case SP_ERR_BUFFER_TOO_SMALL: return "buffer too small";
    case SP_ERR_NONFINITE_WEIGHT: return "weight is NaN or infinite";
    case SP_ERR_NEGATIVE_WEIGHT: return "weight is negative";
    case SP_ERR_NO_INFLUENCE: return "vertex has no influence (all weights are zero)";
    case SP_ERR_JOINT_OUT_OF_RANGE: return "joint index is not below the joint count";
    case SP_ERR_TOO_MANY_JOINTS: return "more than 65535 joints";
    case SP_ERR_UNSUPPORTED_METHOD: return "unsupported method or influence count";
    case SP_ERR_BITS_OUT_OF_RANGE: return "bit budget or spacing out of range";
    case SP_ERR_CODE_OUT_OF_RANGE: return "weight code above the largest code of the codec";
    case SP_ERR_TUPLE_OUT_OF_RANGE: return "tuple index is not below the tuple table size";
    case SP_ERR_CORRUPT_DATA: return "corrupt data";
    case SP_ERR_LIMIT_EXCEEDED: return "a limit cannot be met";
    case SP_ERR_CODE_OUTSIDE_SIMPLEX: return "weight code outside the simplex";
    case SP_ERR_DUPLICATE_JOINT: return "the same joint carries weight in two slots";
    case SP_ERR_VERTEX_COUNT_MISMATCH: return "packed vertex count differs from the primitive's";
    case SP_ERR_PARAMETER_MISMATCH: return "a parameter contradicts another one or the stored data";
    case SP_ERR_ABI_MISMATCH: return "library and caller were built from different skinpack.h";
    case SP_ERR_INDEX_OUT_OF_RANGE: return "an index or offset points past its array";
    default: return "unknown result code";
    }
}

static const char* const method_names[SP_METHOD_COUNT] = {"fixed", "cube", "pot", "any", "oss"};

const char* sp_method_name(sp_method method)
{
    return (unsigned)method < SP_METHOD_COUNT ? method_names[method] : NULL;
}

sp_method sp_method_from_name(const char* name)
{
    if (!name) return SP_METHOD_COUNT;
    for (int m = 0; m < SP_METHOD_COUNT; ++m)
        if (strcmp(name, method_names[m]) == 0) return (sp_method)m;
    return SP_METHOD_COUNT;
}

uint32_t sp_index_bits(uint64_t count)
{
    uint32_t bits = 0;
    while (bits < 64 && (count - 1) >> bits) ++bits;
    return count <= 1 ? 0 : bits;
}
