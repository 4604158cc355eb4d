/* Vertex words: value = code | tuple_index << weight_bits, one or two little-endian u32s. */
#include "skinpack.h"

uint32_t sp_words_per_vertex(uint32_t tuple_bits, uint32_t weight_bits)
{
    uint32_t total = tuple_bits + weight_bits;
    if (tuple_bits > 32 || weight_bits > SP_MAX_WEIGHT_BITS || total > SP_MAX_VERTEX_BITS) return 0;
    return total <= 32 ? 1 : 2;
}

static uint64_t low_mask(uint32_t bits)
{
    return bits >= 64 ? UINT64_MAX : (((uint64_t)1 << bits) - 1);
}

sp_result sp_pack_vertices(const uint32_t* tuple_index, const uint64_t* codes, size_t vertex_count,
                           uint32_t tuple_bits, uint32_t weight_bits, uint32_t* words)
{
    uint32_t per_vertex = sp_words_per_vertex(tuple_bits, weight_bits);
    if (per_vertex == 0) return SP_ERR_BITS_OUT_OF_RANGE;
    if (!tuple_index || !codes || !words) return SP_ERR_INVALID_ARGUMENT;
    for (size_t v = 0; v < vertex_count; ++v) {
        if (codes[v] > low_mask(weight_bits)) return SP_ERR_CODE_OUT_OF_RANGE;
        if ((uint64_t)tuple_index[v] > low_mask(tuple_bits)) return SP_ERR_TUPLE_OUT_OF_RANGE;
        uint64_t value = codes[v] | (weight_bits < 64 ? (uint64_t)tuple_index[v] << weight_bits : 0);
        words[v * per_vertex] = (uint32_t)value;
        if (per_vertex == 2) words[v * 2 + 1] = (uint32_t)(value >> 32);
    }
    return SP_OK;
}

sp_result sp_unpack_vertices(const uint32_t* words, size_t vertex_count, uint32_t tuple_bits, uint32_t weight_bits,
                             uint32_t* tuple_index, uint64_t* codes, size_t* error_vertex)
{
    uint32_t per_vertex = sp_words_per_vertex(tuple_bits, weight_bits);
    if (per_vertex == 0) return SP_ERR_BITS_OUT_OF_RANGE;
    if (!words || !tuple_index || !codes) return SP_ERR_INVALID_ARGUMENT;
    uint64_t used = low_mask(tuple_bits + weight_bits);
    for (size_t v = 0; v < vertex_count; ++v) {
        uint64_t value = words[v * per_vertex];
        if (per_vertex == 2) value |= (uint64_t)words[v * 2 + 1] << 32;
        if (value & ~used) {
            if (error_vertex) *error_vertex = v;
            return SP_ERR_CORRUPT_DATA;
        }
        codes[v] = value & low_mask(weight_bits);
        tuple_index[v] = weight_bits < 64 ? (uint32_t)(value >> weight_bits) : 0;
    }
    return SP_OK;
}
