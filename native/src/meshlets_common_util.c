/*
 * meshlets_common_util.c - the open meshlet shared by all builders: limit checks, adding
 * triangles, and writing a finished meshlet (vertex list, u8 triangles, joint palette, local
 * tuple LUT, bounding sphere, normal cone) into the caller's buffers.
 */
#include "meshlets_internal.h"

#include <math.h>
#include <string.h>

sp_result sp_meshlet_collect_triangle_joints(sp_meshlet_context* ctx, size_t* error_triangle)
{
    size_t k = ctx->influences;
    for (size_t t = 0; t < ctx->triangle_count; ++t) {
        uint16_t* list = ctx->triangle_joints + t * SP_MESHLET_TRIANGLE_JOINTS;
        uint32_t count = 0;
        for (int c = 0; c < 3; ++c) {
            size_t base = (size_t)ctx->indices[t * 3 + c] * k;
            for (size_t s = 0; s < k; ++s) {
                if (!(ctx->weights[base + s] > 0.0f))
                    continue;
                uint16_t joint = ctx->joints[base + s];
                uint32_t at = count; /* insertion sort step, dropping duplicates */
                while (at > 0 && list[at - 1] > joint)
                    --at;
                if (at > 0 && list[at - 1] == joint)
                    continue;
                for (uint32_t i = count; i > at; --i)
                    list[i] = list[i - 1];
                list[at] = joint;
                ++count;
            }
        }
        if (count > ctx->options.max_joints) {
            *error_triangle = t;
            return SP_ERR_LIMIT_EXCEEDED;
        }
        ctx->triangle_joint_count[t] = (uint8_t)count;
        if (count > 0 && list[count - 1] >= ctx->joint_end) /* the list is ascending */
            ctx->joint_end = list[count - 1] + 1u;
    }
    return SP_OK;
}

int sp_meshlet_fits(const sp_meshlet_context* ctx, size_t t)
{
    return ctx->open_triangle_count < ctx->options.max_triangles &&
           ctx->open_vertex_count + sp_meshlet_new_vertices(ctx, t) <= ctx->options.max_vertices &&
           ctx->open_joint_count + sp_meshlet_new_joints(ctx, t) <= ctx->options.max_joints;
}

void sp_meshlet_add_joints(sp_meshlet_context* ctx, size_t t)
{
    const uint16_t* list = ctx->triangle_joints + t * SP_MESHLET_TRIANGLE_JOINTS;
    for (uint32_t i = 0; i < ctx->triangle_joint_count[t]; ++i) {
        if (ctx->joint_slot[list[i]] != SP_MESHLET_NO_SLOT)
            continue;
        ctx->joint_slot[list[i]] = (uint8_t)ctx->open_joint_count;
        ctx->open_joints[ctx->open_joint_count++] = list[i];
    }
}

void sp_meshlet_add(sp_meshlet_context* ctx, size_t t)
{
    for (int c = 0; c < 3; ++c) {
        uint32_t v = ctx->indices[t * 3 + c];
        if (ctx->vertex_slot[v] != SP_MESHLET_NO_SLOT)
            continue;
        ctx->vertex_slot[v] = (uint8_t)ctx->open_vertex_count;
        ctx->open_vertices[ctx->open_vertex_count++] = v;
    }
    sp_meshlet_add_joints(ctx, t);
    ctx->open_triangles[ctx->open_triangle_count++] = (uint32_t)t;
}

int sp_meshlet_add_triangles(sp_meshlet_context* ctx, const uint32_t* triangles, uint32_t count, int check)
{
    for (uint32_t i = 0; i < count; ++i) {
        if (check && !sp_meshlet_fits(ctx, triangles[i]))
            return 0;
        sp_meshlet_add(ctx, triangles[i]);
    }
    return 1;
}

/* ---- bounds ---------------------------------------------------------------------------- */

static float distance3(const float* a, const float* b)
{
    float d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    return sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

/* Ritter's sphere: start from the widest pair of axis extremes, grow over outliers, then
 * make the radius exact for the final centre so that every vertex is inside. */
static void compute_sphere(const sp_meshlet_context* ctx, sp_meshlet* m)
{
    uint32_t count = ctx->open_vertex_count;
    const float* lo[3];
    const float* hi[3];
    for (int a = 0; a < 3; ++a)
        lo[a] = hi[a] = sp_meshlet_position(ctx, ctx->open_vertices[0]);
    for (uint32_t i = 1; i < count; ++i) {
        const float* p = sp_meshlet_position(ctx, ctx->open_vertices[i]);
        for (int a = 0; a < 3; ++a) {
            if (p[a] < lo[a][a])
                lo[a] = p;
            if (p[a] > hi[a][a])
                hi[a] = p;
        }
    }
    int axis = 0;
    for (int a = 1; a < 3; ++a)
        if (distance3(lo[a], hi[a]) > distance3(lo[axis], hi[axis]))
            axis = a;
    float center[3], radius = distance3(lo[axis], hi[axis]) * 0.5f;
    for (int i = 0; i < 3; ++i)
        center[i] = (lo[axis][i] + hi[axis][i]) * 0.5f;
    for (uint32_t i = 0; i < count; ++i) {
        const float* p = sp_meshlet_position(ctx, ctx->open_vertices[i]);
        float d = distance3(p, center);
        if (d > radius) {
            float grown = (radius + d) * 0.5f, shift = (grown - radius) / d;
            for (int k = 0; k < 3; ++k)
                center[k] += (p[k] - center[k]) * shift;
            radius = grown;
        }
    }
    float exact = 0.0f;
    for (uint32_t i = 0; i < count; ++i) {
        float d = distance3(sp_meshlet_position(ctx, ctx->open_vertices[i]), center);
        exact = d > exact ? d : exact;
    }
    memcpy(m->center, center, sizeof(center));
    m->radius = exact;
}

static int triangle_normal(const sp_meshlet_context* ctx, uint32_t t, float* n)
{
    const float* p0 = sp_meshlet_position(ctx, ctx->indices[t * 3 + 0]);
    const float* p1 = sp_meshlet_position(ctx, ctx->indices[t * 3 + 1]);
    const float* p2 = sp_meshlet_position(ctx, ctx->indices[t * 3 + 2]);
    float e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
    float e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    float length = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(length > 0.0f))
        return 0; /* degenerate triangles do not constrain the cone */
    for (int i = 0; i < 3; ++i)
        n[i] /= length;
    return 1;
}

/* Normal cone with meshopt_Bounds semantics (see sp_meshlet). */
static void compute_cone(const sp_meshlet_context* ctx, sp_meshlet* m)
{
    float normals[SP_MESHLET_MAX_TRIANGLES][3], axis[3] = {0, 0, 0};
    uint32_t count = 0, first_corner[SP_MESHLET_MAX_TRIANGLES];
    for (uint32_t i = 0; i < ctx->open_triangle_count; ++i) {
        uint32_t t = ctx->open_triangles[i];
        if (!triangle_normal(ctx, t, normals[count]))
            continue;
        first_corner[count] = ctx->indices[t * 3];
        for (int k = 0; k < 3; ++k)
            axis[k] += normals[count][k];
        ++count;
    }
    float length = sqrtf(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    memcpy(m->cone_apex, m->center, sizeof(m->center));
    m->cone_cutoff = 1.0f;
    memset(m->cone_axis, 0, sizeof(m->cone_axis));
    if (!(length > 0.0f))
        return;
    for (int k = 0; k < 3; ++k)
        axis[k] /= length;
    memcpy(m->cone_axis, axis, sizeof(axis));

    float min_dot = 1.0f;
    for (uint32_t i = 0; i < count; ++i) {
        float d = normals[i][0] * axis[0] + normals[i][1] * axis[1] + normals[i][2] * axis[2];
        min_dot = d < min_dot ? d : min_dot;
    }
    if (min_dot <= 0.1f)
        return; /* wider than ~84 degrees: back-face culling would almost never hit */

    /* apex: far enough behind the centre along -axis to lie behind every triangle's plane */
    float max_t = 0.0f;
    for (uint32_t i = 0; i < count; ++i) {
        const float* n = normals[i];
        const float* p0 = sp_meshlet_position(ctx, first_corner[i]);
        float dc = (m->center[0] - p0[0]) * n[0] + (m->center[1] - p0[1]) * n[1] + (m->center[2] - p0[2]) * n[2];
        float dn = axis[0] * n[0] + axis[1] * n[1] + axis[2] * n[2];
        float step = dc / dn;
        max_t = step > max_t ? step : max_t;
    }
    for (int k = 0; k < 3; ++k)
        m->cone_apex[k] = m->center[k] - axis[k] * max_t;
    m->cone_cutoff = sqrtf(1.0f - min_dot * min_dot);
}

/* ---- writing a meshlet ----------------------------------------------------------------- */

/* Local tuple LUT: each vertex's joints as palette indices (zero-weight slots: 0), unique
 * entries in order of first use. A meshlet has at most 255 vertices, so a linear search over
 * its own tuples (packed into one u32 each, K <= 4) is cheap and needs no scratch. */
static void write_local_tuples(sp_meshlet_context* ctx, sp_meshlet* m)
{
    size_t k = ctx->influences;
    uint8_t* base = ctx->out->tuples + ctx->used.tuples * k;
    uint8_t* vertex_tuples = ctx->out->vertex_tuples + ctx->used.vertices;
    uint32_t packed[SP_MESHLET_MAX_VERTICES];
    uint32_t count = 0;
    for (uint32_t i = 0; i < ctx->open_vertex_count; ++i) {
        size_t v = ctx->open_vertices[i];
        uint8_t tuple[SP_MAX_INFLUENCES] = {0, 0, 0, 0};
        for (size_t s = 0; s < k; ++s)
            if (ctx->weights[v * k + s] > 0.0f)
                tuple[s] = ctx->joint_slot[ctx->joints[v * k + s]];
        uint32_t key = (uint32_t)tuple[0] | (uint32_t)tuple[1] << 8 | (uint32_t)tuple[2] << 16 | (uint32_t)tuple[3] << 24;
        uint32_t found = 0;
        while (found < count && packed[found] != key)
            ++found;
        if (found == count) {
            packed[count] = key;
            memcpy(base + count++ * k, tuple, k);
        }
        vertex_tuples[i] = (uint8_t)found;
    }
    m->tuple_offset = (uint32_t)ctx->used.tuples;
    m->tuple_count = (uint16_t)count;
    m->tuple_bits = sp_index_bits(count);
    ctx->used.tuples += count;
}

/* The palette in order of first use by the meshlet's vertex list (joint_slot is renumbered to
 * match), so it depends only on the vertex list: a consumer that rebuilds palettes from the
 * vertices (the benchmark does, for meshoptimizer's meshlets) gets the same LUT sizes. */
static void write_palette(sp_meshlet_context* ctx, uint16_t* palette)
{
    size_t k = ctx->influences;
    uint32_t count = 0;
    for (uint32_t i = 0; i < ctx->open_joint_count; ++i)
        ctx->joint_slot[ctx->open_joints[i]] = SP_MESHLET_NO_SLOT;
    for (uint32_t i = 0; i < ctx->open_vertex_count; ++i) {
        size_t v = ctx->open_vertices[i];
        for (size_t s = 0; s < k; ++s) {
            uint16_t joint = ctx->joints[v * k + s];
            if (ctx->weights[v * k + s] > 0.0f && ctx->joint_slot[joint] == SP_MESHLET_NO_SLOT) {
                ctx->joint_slot[joint] = (uint8_t)count;
                palette[count++] = joint;
            }
        }
    }
}

void sp_meshlet_flush(sp_meshlet_context* ctx)
{
    if (ctx->open_triangle_count == 0)
        return;
    sp_meshlet_buffers* out = ctx->out;
    size_t id = ctx->used.meshlets;
    sp_meshlet* m = &out->meshlets[id];
    memset(m, 0, sizeof(*m));

    m->vertex_offset = (uint32_t)ctx->used.vertices;
    m->vertex_count = (uint16_t)ctx->open_vertex_count;
    memcpy(out->vertices + ctx->used.vertices, ctx->open_vertices, ctx->open_vertex_count * sizeof(uint32_t));

    m->triangle_offset = (uint32_t)ctx->used.triangles;
    m->triangle_count = (uint16_t)ctx->open_triangle_count;
    uint8_t* local = out->triangles + ctx->used.triangles * 3;
    for (uint32_t i = 0; i < ctx->open_triangle_count; ++i) {
        uint32_t t = ctx->open_triangles[i];
        for (int c = 0; c < 3; ++c)
            local[i * 3 + c] = ctx->vertex_slot[ctx->indices[t * 3 + c]];
        if (out->triangle_meshlet)
            out->triangle_meshlet[t] = (uint32_t)id;
    }

    m->joint_offset = (uint32_t)ctx->used.joints;
    m->joint_count = (uint16_t)ctx->open_joint_count;
    write_palette(ctx, out->joints + ctx->used.joints);

    write_local_tuples(ctx, m);
    compute_sphere(ctx, m);
    compute_cone(ctx, m);

    ctx->used.meshlets += 1;
    ctx->used.vertices += ctx->open_vertex_count;
    ctx->used.triangles += ctx->open_triangle_count;
    ctx->used.joints += ctx->open_joint_count;

    sp_meshlet_reset_open(ctx);
}

void sp_meshlet_reset_open(sp_meshlet_context* ctx)
{
    /* only the touched slots are reset, so emptying costs O(meshlet) */
    for (uint32_t i = 0; i < ctx->open_vertex_count; ++i)
        ctx->vertex_slot[ctx->open_vertices[i]] = SP_MESHLET_NO_SLOT;
    for (uint32_t i = 0; i < ctx->open_joint_count; ++i)
        ctx->joint_slot[ctx->open_joints[i]] = SP_MESHLET_NO_SLOT;
    ctx->open_vertex_count = ctx->open_triangle_count = ctx->open_joint_count = 0;
}

void sp_meshlet_greedy(sp_meshlet_context* ctx, const uint32_t* order, size_t count)
{
    for (size_t i = 0; i < count; ++i) {
        size_t t = order ? order[i] : i;
        if (!sp_meshlet_fits(ctx, t))
            sp_meshlet_flush(ctx);
        sp_meshlet_add(ctx, t);
    }
    sp_meshlet_flush(ctx);
}
