/*
 * meshlets.c - the public meshlet entry points: options, bounds, argument checks, scratch
 * layout, builder dispatch and the aggregate statistics.
 */
#include "meshlets_internal.h"

#include <string.h>

void sp_meshlet_options_default(sp_meshlet_options* options)
{
    memset(options, 0, sizeof(*options));
    options->builder = SP_MESHLETS_SKIN;
    options->max_vertices = 64;
    options->max_triangles = 124;
    options->max_joints = 32;
    options->min_group_triangles = 16;
    options->joint_cost = 0.0f;
    options->tuple_cost = 0.0f;
    options->palette_effort = 0;
}

size_t sp_meshlet_common_scratch_bound(size_t triangle_count, size_t vertex_count, size_t max_triangles)
{
    return sp_meshlet_align8(triangle_count * SP_MESHLET_TRIANGLE_JOINTS * sizeof(uint16_t)) +
           sp_meshlet_align8(triangle_count) + sp_meshlet_align8(vertex_count) + sp_meshlet_align8(SP_JOINT_SLOT_COUNT) +
           sp_meshlet_align8(max_triangles * sizeof(uint32_t));
}

static size_t stats_scratch_bound(size_t vertex_count)
{
    return sp_meshlet_tuple_set_slots(vertex_count) * sizeof(uint64_t);
}

static size_t builder_scratch_bound(const sp_meshlet_options* options, size_t triangle_count, size_t vertex_count)
{
    size_t bytes = stats_scratch_bound(vertex_count);
    uint32_t builder = options->builder;
    size_t own = builder == SP_MESHLETS_COMMON ? sp_meshlet_common_builder_scratch_bound(triangle_count)
               : builder == SP_MESHLETS_SKIN
                   ? sp_meshlet_skin_builder_scratch_bound(triangle_count, vertex_count, options->palette_effort > 0)
                   : 0;
    return own > bytes ? own : bytes;
}

void sp_meshlets_bound(size_t index_count, size_t vertex_count, size_t influences, const sp_meshlet_options* options,
                       sp_meshlet_sizes* sizes)
{
    sp_meshlet_options defaults;
    if (!options) {
        sp_meshlet_options_default(&defaults);
        options = &defaults;
    }
    size_t triangle_count = index_count / 3;
    if (influences < 1 || influences > SP_MAX_INFLUENCES)
        influences = SP_MAX_INFLUENCES;
    uint32_t max_triangles = options->max_triangles <= SP_MESHLET_MAX_TRIANGLES ? options->max_triangles
                                                                                : SP_MESHLET_MAX_TRIANGLES;
    /* Palette closes can end a meshlet after any triangle, so the only general bound is one
     * triangle per meshlet; each meshlet vertex entry comes from a distinct index, each palette
     * entry from a distinct (vertex, slot) pair, each local tuple from a distinct vertex entry. */
    sizes->meshlets = triangle_count;
    sizes->vertices = triangle_count * 3;
    sizes->triangles = triangle_count;
    sizes->joints = triangle_count * 3 * influences;
    sizes->tuples = triangle_count * 3;
    sizes->scratch_bytes = sp_meshlet_common_scratch_bound(triangle_count, vertex_count, max_triangles) +
                           builder_scratch_bound(options, triangle_count, vertex_count);
}

sp_result sp_check_meshlet_options(const sp_meshlet_options* o)
{
    if (!o)
        return SP_ERR_INVALID_ARGUMENT;
    if (o->builder >= SP_MESHLETS_BUILDER_COUNT || o->max_vertices < 3 || o->max_vertices > SP_MESHLET_MAX_VERTICES ||
        o->max_triangles < 1 || o->max_triangles > SP_MESHLET_MAX_TRIANGLES || o->max_joints < 1 ||
        o->max_joints > SP_MESHLET_MAX_JOINTS || !(o->joint_cost >= 0.0f && o->joint_cost <= 1000.0f) ||
        !(o->tuple_cost >= 0.0f && o->tuple_cost <= 1000.0f) || o->palette_effort > SP_MESHLET_MAX_PALETTE_EFFORT)
        return SP_ERR_INVALID_ARGUMENT;
    return SP_OK;
}

static sp_result check_capacity(const sp_meshlet_buffers* out, const sp_meshlet_sizes* need)
{
    if (!out->meshlets || !out->vertices || !out->vertex_tuples || !out->triangles || !out->joints || !out->tuples)
        return SP_ERR_INVALID_ARGUMENT;
    const sp_meshlet_sizes* have = &out->capacity;
    if (have->meshlets < need->meshlets || have->vertices < need->vertices || have->triangles < need->triangles ||
        have->joints < need->joints || have->tuples < need->tuples)
        return SP_ERR_BUFFER_TOO_SMALL;
    return SP_OK;
}

static void setup_scratch(sp_meshlet_context* ctx, void* scratch, size_t scratch_size)
{
    unsigned char* cursor = (unsigned char*)scratch;
    size_t t = ctx->triangle_count;
    ctx->triangle_joints = sp_meshlet_carve(&cursor, t * SP_MESHLET_TRIANGLE_JOINTS * sizeof(uint16_t));
    ctx->triangle_joint_count = sp_meshlet_carve(&cursor, t);
    ctx->vertex_slot = sp_meshlet_carve(&cursor, ctx->vertex_count);
    ctx->joint_slot = sp_meshlet_carve(&cursor, SP_JOINT_SLOT_COUNT);
    ctx->open_triangles = sp_meshlet_carve(&cursor, ctx->options.max_triangles * sizeof(uint32_t));
    memset(ctx->vertex_slot, SP_MESHLET_NO_SLOT, ctx->vertex_count);
    memset(ctx->joint_slot, SP_MESHLET_NO_SLOT, SP_JOINT_SLOT_COUNT);
    ctx->builder_scratch = cursor;
    ctx->builder_scratch_size = scratch_size - (size_t)(cursor - (unsigned char*)scratch);
}

static void fill_stats(const sp_meshlet_context* ctx, sp_meshlet_stats* stats)
{
    const sp_meshlet* meshlets = ctx->out->meshlets;
    size_t count = ctx->used.meshlets;
    double local_bits = 0.0;
    stats->meshlet_count = count;
    stats->vertex_count = ctx->used.vertices;
    stats->triangle_count = ctx->used.triangles;
    stats->joint_count = ctx->used.joints;
    stats->tuple_count = ctx->used.tuples;
    for (size_t i = 0; i < count; ++i) {
        const sp_meshlet* m = &meshlets[i];
        if (m->vertex_count > stats->max_vertices)
            stats->max_vertices = m->vertex_count;
        if (m->triangle_count > stats->max_triangles)
            stats->max_triangles = m->triangle_count;
        if (m->joint_count > stats->max_joints)
            stats->max_joints = m->joint_count;
        if (m->tuple_bits > stats->local_tuple_bits_max)
            stats->local_tuple_bits_max = m->tuple_bits;
        local_bits += (double)m->tuple_bits * m->vertex_count;
    }
    if (count) {
        stats->mean_vertices = (double)ctx->used.vertices / count;
        stats->mean_triangles = (double)ctx->used.triangles / count;
        stats->mean_joints = (double)ctx->used.joints / count;
    }
    if (ctx->used.vertices)
        stats->local_tuple_bits_mean = local_bits / ctx->used.vertices;
    stats->global_tuples = ctx->global_tuples ? ctx->global_tuples
                                              : sp_meshlet_tuple_ids(ctx, (uint64_t*)ctx->builder_scratch, NULL);
    stats->global_tuple_bits = sp_index_bits(stats->global_tuples);
}

static sp_result check_indices(const uint32_t* indices, size_t index_count, size_t vertex_count, size_t* error_triangle)
{
    for (size_t i = 0; i < index_count; ++i)
        if (indices[i] >= vertex_count) {
            *error_triangle = i / 3;
            return SP_ERR_INVALID_ARGUMENT;
        }
    return SP_OK;
}

sp_result sp_build_meshlets(const uint32_t* indices, size_t index_count, const float* vertex_positions,
                            size_t vertex_count, size_t vertex_positions_stride, const uint16_t* joints,
                            const float* weights, size_t influences, const sp_meshlet_options* options,
                            sp_meshlet_buffers* out, void* scratch, size_t scratch_size, sp_meshlet_stats* stats)
{
    sp_meshlet_stats local_stats;
    if (!stats)
        stats = &local_stats;
    memset(stats, 0, sizeof(*stats));

    sp_meshlet_options defaults;
    if (!options) {
        sp_meshlet_options_default(&defaults);
        options = &defaults;
    }
    if (!indices || !vertex_positions || !joints || !weights || !out || !scratch || index_count == 0 ||
        index_count % 3 != 0 || vertex_count == 0 || vertex_positions_stride < 12 || vertex_positions_stride % 4 != 0 ||
        influences < 1 || influences > SP_MAX_INFLUENCES || index_count / 3 > UINT32_MAX)
        return SP_ERR_INVALID_ARGUMENT;
    sp_result result = sp_check_meshlet_options(options);
    if (result != SP_OK)
        return result;

    sp_meshlet_sizes need;
    sp_meshlets_bound(index_count, vertex_count, influences, options, &need);
    if ((result = check_capacity(out, &need)) != SP_OK)
        return result;
    if (scratch_size < need.scratch_bytes)
        return SP_ERR_BUFFER_TOO_SMALL;
    if ((result = check_indices(indices, index_count, vertex_count, &stats->error_triangle)) != SP_OK)
        return result;

    sp_meshlet_context ctx;
    memset(&ctx, 0, sizeof(ctx));
    ctx.indices = indices;
    ctx.triangle_count = index_count / 3;
    ctx.positions = vertex_positions;
    ctx.position_stride = vertex_positions_stride / sizeof(float);
    ctx.vertex_count = vertex_count;
    ctx.joints = joints;
    ctx.weights = weights;
    ctx.influences = influences;
    ctx.options = *options;
    ctx.out = out;
    setup_scratch(&ctx, scratch, scratch_size);

    if ((result = sp_meshlet_collect_triangle_joints(&ctx, &stats->error_triangle)) != SP_OK)
        return result;
    switch (options->builder) {
    case SP_MESHLETS_NAIVE: sp_meshlets_build_naive(&ctx); break;
    case SP_MESHLETS_COMMON: sp_meshlets_build_common(&ctx); break;
    default: sp_meshlets_build_skin(&ctx); break;
    }
    fill_stats(&ctx, stats);
    return SP_OK;
}
