/* FNV-1a over bytes: the golden tests' fingerprint of an output buffer (chain calls to hash
 * several buffers; start from FNV1A_OFFSET). */
#ifndef SKINPACK_TEST_FNV1A_H
#define SKINPACK_TEST_FNV1A_H

#include <stddef.h>
#include <stdint.h>

#define FNV1A_OFFSET 14695981039346656037ull

static inline uint64_t fnv1a(uint64_t hash, const void* data, size_t size)
{
    const unsigned char* bytes = data;
    for (size_t i = 0; i < size; ++i) hash = (hash ^ bytes[i]) * 0x100000001b3ull;
    return hash;
}

#endif
