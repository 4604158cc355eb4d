/* Version, struct sizes and the small format rules callers must not re-implement: the
 * tupleTable component width and the JSON form of integers above 2^53. */
#include <string.h>

#include "skinpack.h"

uint32_t sp_version(void) { return SP_VERSION; }

size_t sp_struct_size(sp_struct_id id)
{
    static const size_t sizes[SP_STRUCT_COUNT] = SP_STRUCT_SIZES_INIT;
    return (unsigned)id < SP_STRUCT_COUNT ? sizes[id] : 0;
}

sp_result sp_check_abi(uint32_t version, const size_t* struct_sizes, size_t count, uint32_t* bad_id)
{
    if (bad_id) *bad_id = SP_STRUCT_COUNT;
    if (version != SP_VERSION) return SP_ERR_ABI_MISMATCH;
    if (count > SP_STRUCT_COUNT || (count && !struct_sizes)) return SP_ERR_INVALID_ARGUMENT;
    for (size_t id = 0; id < count; ++id)
        if (struct_sizes[id] != sp_struct_size((sp_struct_id)id)) {
            if (bad_id) *bad_id = (uint32_t)id;
            return SP_ERR_ABI_MISMATCH;
        }
    return SP_OK;
}

uint32_t sp_joint_bytes(size_t joint_count)
{
    if (joint_count == 0 || joint_count > SP_MAX_JOINTS) return 0;
    return joint_count <= 256 ? 1 : 2;
}

sp_result sp_parse_decimal(const char* text, size_t length, uint64_t* value)
{
    if (!text || !value || length == 0 || length > 20 || text[0] == '0') return SP_ERR_INVALID_ARGUMENT;
    uint64_t v = 0;
    for (size_t i = 0; i < length; ++i) {
        if (text[i] < '0' || text[i] > '9') return SP_ERR_INVALID_ARGUMENT;
        uint64_t digit = (uint64_t)(text[i] - '0');
        if (v > (UINT64_MAX - digit) / 10) return SP_ERR_INVALID_ARGUMENT; /* above 2^64 - 1 */
        v = v * 10 + digit;
    }
    if (v <= SP_JSON_MAX_SAFE_INTEGER) return SP_ERR_INVALID_ARGUMENT; /* must be a JSON number */
    *value = v;
    return SP_OK;
}
