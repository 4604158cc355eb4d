/*
 * The distinct (significant count, joint prefix) keys of a mesh's vertices, found in one pass
 * (internal to the tuple table build). Not part of the public API.
 */
#ifndef SKINPACK_TUPLE_KEYS_H
#define SKINPACK_TUPLE_KEYS_H

#include <stddef.h>
#include <stdint.h>

#include "platform.h"

/*
 * The first `length` of k joints (k <= 4 of 16 bits) as one key, joint s in bits 16 s..16 s + 15
 * and the slots past the length zero. The tuple table's prefix hash uses the same key.
 */
SP_INLINE uint64_t sp_tuple_prefix_key(const uint16_t* joints, size_t k, size_t length)
{
    uint64_t key = joints[0];
    if (k > 1) key |= (uint64_t)joints[1] << 16;
    if (k > 2) key |= (uint64_t)joints[2] << 32;
    if (k > 3) key |= (uint64_t)joints[3] << 48;
    return length >= 4 ? key : key & ((((uint64_t)1) << (16 * length)) - 1);
}

/*
 * Distinct keys in order of first use: key u is sp_tuple_prefix_key(joints + first[u] * k, k,
 * max(count[u], 1)), where count[u] is the vertex's significant count as given (0 and 1 are two
 * keys of one prefix; the table build treats them alike).
 */
typedef struct sp_tuple_keys {
    size_t size;
    uint64_t* keys;
    uint32_t* first;  /* the first vertex with the key */
    uint8_t* counts;  /* its significant count, as given (k without significant counts) */
} sp_tuple_keys;

/* Scratch bytes of sp_collect_tuple_keys: the hash table (reused by the caller afterwards) and
 * the key records (vertex_count of each). */
size_t sp_tuple_keys_table_bytes(size_t vertex_count);
size_t sp_tuple_keys_record_bytes(size_t vertex_count);

/*
 * Finds the distinct keys of vertex_count vertices of k joints (significant may be NULL: every
 * count is k; else every count <= k, checked by the caller) and writes each vertex's key number
 * to ids (vertex_count). table: sp_tuple_keys_table_bytes, records:
 * sp_tuple_keys_record_bytes, both 8-byte aligned.
 */
void sp_collect_tuple_keys(const uint16_t* joints, const uint8_t* significant, size_t vertex_count, size_t k,
                           uint32_t* ids, void* table, void* records, sp_tuple_keys* out);

#endif
