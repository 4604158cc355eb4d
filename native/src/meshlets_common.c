/*
 * meshlets_common.c - baseline 2, the thesis's "common influences" builder (listing A.2).
 * Triangles whose three vertices use the same joint set form groups; each group with at least
 * min_group_triangles triangles is cut into meshlets by the naive greedy walk (groups in
 * ascending key order), everything else (mixed triangles and small groups) goes to a remainder
 * that is cut the same way at the end, in index order. Every group ends its own meshlet, which is why this
 * builder makes more meshlets than the naive one.
 */
#include "meshlets_internal.h"

#include <stdlib.h>

#define REMAINDER_KEY UINT64_MAX

typedef struct triangle_key {
    uint64_t key;      /* the shared joint set, ascending, 16 bits a joint, padded with 0xffff */
    uint32_t triangle;
} triangle_key;

size_t sp_meshlet_common_builder_scratch_bound(size_t triangle_count)
{
    return triangle_count * (sizeof(triangle_key) + sizeof(uint32_t)) + 16;
}

static uint32_t distinct_used_joints(const sp_meshlet_context* ctx, uint32_t v)
{
    size_t k = ctx->influences;
    uint32_t count = 0;
    for (size_t s = 0; s < k; ++s) {
        if (!(ctx->weights[v * k + s] > 0.0f))
            continue;
        int repeated = 0;
        for (size_t r = 0; r < s; ++r)
            repeated |= ctx->weights[v * k + r] > 0.0f && ctx->joints[v * k + r] == ctx->joints[v * k + s];
        count += !repeated;
    }
    return count;
}

/* Each vertex's joint set is a subset of the triangle's union, so the three sets are equal
 * exactly when each one is as large as the union. */
static uint64_t common_key(const sp_meshlet_context* ctx, size_t t)
{
    uint32_t count = ctx->triangle_joint_count[t];
    if (count == 0 || count > SP_MAX_INFLUENCES)
        return REMAINDER_KEY;
    for (int c = 0; c < 3; ++c)
        if (distinct_used_joints(ctx, ctx->indices[t * 3 + c]) != count)
            return REMAINDER_KEY;
    const uint16_t* list = ctx->triangle_joints + t * SP_MESHLET_TRIANGLE_JOINTS;
    uint64_t key = 0;
    for (uint32_t i = 0; i < SP_MAX_INFLUENCES; ++i)
        key = key << 16 | (i < count ? list[i] : 0xffffu);
    return key;
}

static int compare_keys(const void* a, const void* b)
{
    const triangle_key* x = (const triangle_key*)a;
    const triangle_key* y = (const triangle_key*)b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return (x->triangle > y->triangle) - (x->triangle < y->triangle);
}

static int compare_triangles(const void* a, const void* b)
{
    uint32_t x = *(const uint32_t*)a, y = *(const uint32_t*)b;
    return (x > y) - (x < y);
}

void sp_meshlets_build_common(sp_meshlet_context* ctx)
{
    size_t count = ctx->triangle_count;
    triangle_key* keys = (triangle_key*)ctx->builder_scratch;
    uint32_t* order = (uint32_t*)(keys + count);
    for (size_t t = 0; t < count; ++t) {
        keys[t].key = common_key(ctx, t);
        keys[t].triangle = (uint32_t)t;
    }
    qsort(keys, count, sizeof(triangle_key), compare_keys);

    /* order[] gets the large groups from the front and the remainder from the back; the
     * remainder is then walked in index order, like the naive builder (source meshes are
     * usually ordered coherently; key order would scatter it). */
    size_t front = 0, back = count;
    for (size_t start = 0, end; start < count; start = end) {
        for (end = start + 1; end < count && keys[end].key == keys[start].key;)
            ++end;
        int large = keys[start].key != REMAINDER_KEY && end - start >= ctx->options.min_group_triangles;
        if (large) {
            for (size_t i = start; i < end; ++i)
                order[front + i - start] = keys[i].triangle;
            sp_meshlet_greedy(ctx, order + front, end - start);
            front += end - start;
        } else {
            for (size_t i = start; i < end; ++i)
                order[--back] = keys[i].triangle;
        }
    }
    qsort(order + back, count - back, sizeof(uint32_t), compare_triangles);
    sp_meshlet_greedy(ctx, order + back, count - back);
}
