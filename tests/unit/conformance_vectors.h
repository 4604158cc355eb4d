/* Reader of docs/extension/conformance/weights.jsonl (one flat JSON object a line, 64-bit
 * integers as decimal strings, float32 weights as hex bit patterns), shared by the C unit test
 * and the GLSL harness. */
#ifndef SKINPACK_CONFORMANCE_VECTORS_H
#define SKINPACK_CONFORMANCE_VECTORS_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "skinpack.h"

/* The value after "key": in a flat JSON line; strings are returned without their quotes. */
static inline const char* conformance_field(const char* line, const char* key)
{
    char pattern[64];
    snprintf(pattern, sizeof(pattern), "\"%s\": ", key);
    const char* at = strstr(line, pattern);
    return at ? at + strlen(pattern) : NULL;
}

static inline uint64_t conformance_quoted_u64(const char** at)
{
    while (**at && **at != '"') ++*at;
    ++*at;
    uint64_t v = strtoull(*at, (char**)at, 10);
    ++*at; /* closing quote */
    return v;
}

/* Up to max entries of a ["..", ".."] array of quoted integers (hex when base is 16). */
static inline size_t conformance_quoted_array(const char* at, uint64_t* out, size_t max, int base)
{
    size_t count = 0;
    if (!at || *at != '[') return 0;
    ++at;
    while (*at && *at != ']' && count < max) {
        if (*at == '"') {
            ++at;
            out[count++] = strtoull(at, (char**)&at, base);
        }
        ++at;
    }
    return count;
}

typedef struct conformance_vector {
    sp_method method;
    uint32_t k, weight_bits;
    uint64_t n, axes[3], max_code, scale, code, grid[4], weights[4];
    size_t axis_count, grid_count, weight_count;
    int valid;
    char reason[32];
} conformance_vector;

static inline int conformance_parse(const char* line, conformance_vector* v)
{
    const char* at = conformance_field(line, "method");
    char name[16] = {0};
    if (!at || sscanf(at, "\"%15[a-z]\"", name) != 1) return -1;
    v->method = sp_method_from_name(name);
    v->k = (uint32_t)strtoul(conformance_field(line, "influences"), NULL, 10);
    at = conformance_field(line, "n"), v->n = conformance_quoted_u64(&at);
    v->axis_count = conformance_quoted_array(conformance_field(line, "axisSamples"), v->axes, 3, 10);
    v->weight_bits = (uint32_t)strtoul(conformance_field(line, "weightBits"), NULL, 10);
    at = conformance_field(line, "maxCode"), v->max_code = conformance_quoted_u64(&at);
    at = conformance_field(line, "scale"), v->scale = conformance_quoted_u64(&at);
    at = conformance_field(line, "code"), v->code = conformance_quoted_u64(&at);
    v->valid = strncmp(conformance_field(line, "valid"), "true", 4) == 0;
    v->grid_count = conformance_quoted_array(conformance_field(line, "grid"), v->grid, 4, 10);
    v->weight_count = conformance_quoted_array(conformance_field(line, "weights"), v->weights, 4, 16);
    at = conformance_field(line, "reason");
    if (at) sscanf(at, "\"%31[^\"]\"", v->reason);
    return v->method < SP_METHOD_COUNT ? 0 : -1;
}

#endif
