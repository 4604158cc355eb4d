/* meshlet_check.c - see meshlet_check.h. */
#include "meshlet_check.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

sp_meshlet_options meshlet_options(uint32_t builder, uint32_t max_vertices, uint32_t max_triangles, uint32_t max_joints)
{
    sp_meshlet_options o;
    sp_meshlet_options_default(&o);
    o.builder = builder;
    o.max_vertices = max_vertices;
    o.max_triangles = max_triangles;
    o.max_joints = max_joints;
    return o;
}

sp_result meshlet_run_build(meshlet_run* run, const meshlet_input* in, const sp_meshlet_options* options)
{
    memset(run, 0, sizeof(*run));
    sp_meshlet_sizes s;
    sp_meshlets_bound(in->index_count, in->vertex_count, in->influences, options, &s);
    sp_meshlet_buffers* o = &run->out;
    /* +1 keeps malloc(0) out of the picture for empty inputs */
    o->meshlets = malloc((s.meshlets + 1) * sizeof(sp_meshlet));
    o->vertices = malloc((s.vertices + 1) * sizeof(uint32_t));
    o->vertex_tuples = malloc(s.vertices + 1);
    o->triangles = malloc(s.triangles * 3 + 1);
    o->joints = malloc((s.joints + 1) * sizeof(uint16_t));
    o->tuples = malloc(s.tuples * in->influences + 1);
    o->triangle_meshlet = malloc((in->index_count / 3 + 1) * sizeof(uint32_t));
    o->capacity = s;
    run->scratch_size = s.scratch_bytes;
    run->scratch = malloc(s.scratch_bytes + 1);
    if (!o->meshlets || !o->vertices || !o->vertex_tuples || !o->triangles || !o->joints || !o->tuples ||
        !o->triangle_meshlet || !run->scratch) {
        fprintf(stderr, "meshlet_run_build: out of memory\n");
        exit(2);
    }
    run->result = sp_build_meshlets(in->indices, in->index_count, in->positions, in->vertex_count, 3 * sizeof(float),
                                    in->joints, in->weights, in->influences, options, o, run->scratch,
                                    run->scratch_size, &run->stats);
    return run->result;
}

void meshlet_run_free(meshlet_run* run)
{
    sp_meshlet_buffers* o = &run->out;
    free(o->meshlets);
    free(o->vertices);
    free(o->vertex_tuples);
    free(o->triangles);
    free(o->joints);
    free(o->tuples);
    free(o->triangle_meshlet);
    free(run->scratch);
    memset(run, 0, sizeof(*run));
}

int meshlet_runs_equal(const meshlet_run* a, const meshlet_run* b, size_t influences, size_t triangle_count)
{
    const sp_meshlet_stats *x = &a->stats, *y = &b->stats;
    if (a->result != b->result || x->meshlet_count != y->meshlet_count || x->vertex_count != y->vertex_count ||
        x->triangle_count != y->triangle_count || x->joint_count != y->joint_count || x->tuple_count != y->tuple_count)
        return 0;
    const sp_meshlet_buffers *p = &a->out, *q = &b->out;
    return memcmp(p->meshlets, q->meshlets, x->meshlet_count * sizeof(sp_meshlet)) == 0 &&
           memcmp(p->vertices, q->vertices, x->vertex_count * sizeof(uint32_t)) == 0 &&
           memcmp(p->vertex_tuples, q->vertex_tuples, x->vertex_count) == 0 &&
           memcmp(p->triangles, q->triangles, x->triangle_count * 3) == 0 &&
           memcmp(p->joints, q->joints, x->joint_count * sizeof(uint16_t)) == 0 &&
           memcmp(p->tuples, q->tuples, x->tuple_count * influences) == 0 &&
           memcmp(p->triangle_meshlet, q->triangle_meshlet, triangle_count * sizeof(uint32_t)) == 0;
}

/* ---- checks ------------------------------------------------------------------------------ */

typedef struct report {
    char* message;
    size_t size;
    int failed;
} report;

static int failf(report* r, const char* format, ...)
{
    if (!r->failed) {
        va_list args;
        va_start(args, format);
        vsnprintf(r->message, r->size, format, args);
        va_end(args);
    }
    r->failed = 1;
    return 0;
}

typedef struct triple {
    uint32_t v[3];
} triple;

/* Rotates the smallest index to the front: same triangle, same winding, one spelling. */
static triple canonical(uint32_t a, uint32_t b, uint32_t c)
{
    triple t;
    if (a <= b && a <= c)
        t = (triple){{a, b, c}};
    else if (b <= a && b <= c)
        t = (triple){{b, c, a}};
    else
        t = (triple){{c, a, b}};
    return t;
}

static int compare_triples(const void* x, const void* y)
{
    return memcmp(x, y, sizeof(triple)); /* any total order will do for a multiset compare */
}

static int check_triangles_once(const meshlet_run* run, const meshlet_input* in, report* r)
{
    size_t count = in->index_count / 3;
    if (run->stats.triangle_count != count)
        return failf(r, "%zu triangles written, %zu in the mesh", run->stats.triangle_count, count);
    triple* source = malloc((count + 1) * sizeof(triple));
    triple* built = malloc((count + 1) * sizeof(triple));
    for (size_t t = 0; t < count; ++t)
        source[t] = canonical(in->indices[t * 3], in->indices[t * 3 + 1], in->indices[t * 3 + 2]);
    size_t n = 0;
    for (size_t i = 0; i < run->stats.meshlet_count; ++i) {
        const sp_meshlet* m = &run->out.meshlets[i];
        const uint32_t* verts = run->out.vertices + m->vertex_offset;
        const uint8_t* local = run->out.triangles + (size_t)m->triangle_offset * 3;
        for (uint32_t t = 0; t < m->triangle_count; ++t)
            built[n++] = canonical(verts[local[t * 3]], verts[local[t * 3 + 1]], verts[local[t * 3 + 2]]);
    }
    qsort(source, count, sizeof(triple), compare_triples);
    qsort(built, count, sizeof(triple), compare_triples);
    int same = memcmp(source, built, count * sizeof(triple)) == 0;
    free(source);
    free(built);
    return same ? 1 : failf(r, "the meshlets' triangles are not the mesh's triangle multiset");
}

static int check_triangle_meshlet(const meshlet_run* run, const meshlet_input* in, report* r)
{
    /* each source triangle's meshlet must contain that triangle */
    for (size_t t = 0; t < in->index_count / 3; ++t) {
        uint32_t id = run->out.triangle_meshlet[t];
        if (id >= run->stats.meshlet_count)
            return failf(r, "triangle %zu: meshlet id %u out of range", t, id);
        const sp_meshlet* m = &run->out.meshlets[id];
        const uint32_t* verts = run->out.vertices + m->vertex_offset;
        const uint8_t* local = run->out.triangles + (size_t)m->triangle_offset * 3;
        triple want = canonical(in->indices[t * 3], in->indices[t * 3 + 1], in->indices[t * 3 + 2]);
        int found = 0;
        for (uint32_t i = 0; i < m->triangle_count && !found; ++i) {
            triple have = canonical(verts[local[i * 3]], verts[local[i * 3 + 1]], verts[local[i * 3 + 2]]);
            found = memcmp(&have, &want, sizeof(triple)) == 0;
        }
        if (!found)
            return failf(r, "triangle %zu is not in its meshlet %u", t, id);
    }
    return 1;
}

static int used(const meshlet_input* in, uint32_t v, size_t s)
{
    return in->weights[v * in->influences + s] > 0.0f;
}

static int check_palette(const meshlet_run* run, const meshlet_input* in, size_t id, report* r)
{
    const sp_meshlet* m = &run->out.meshlets[id];
    const uint16_t* palette = run->out.joints + m->joint_offset;
    static unsigned char seen[65536]; /* test code: single-threaded */
    for (uint32_t p = 0; p < m->joint_count; ++p) {
        if (seen[palette[p]]) {
            memset(seen, 0, sizeof(seen));
            return failf(r, "meshlet %zu: joint %u twice in the palette", id, palette[p]);
        }
        seen[palette[p]] = 1;
    }
    /* every used joint is in the palette (mark 2), and every palette joint is used */
    for (uint32_t i = 0; i < m->vertex_count; ++i) {
        uint32_t v = run->out.vertices[m->vertex_offset + i];
        for (size_t s = 0; s < in->influences; ++s) {
            if (!used(in, v, s))
                continue;
            uint16_t j = in->joints[v * in->influences + s];
            if (!seen[j]) {
                memset(seen, 0, sizeof(seen));
                return failf(r, "meshlet %zu: vertex %u uses joint %u missing from the palette", id, v, j);
            }
            seen[j] = 2;
        }
    }
    int exact = 1;
    for (uint32_t p = 0; p < m->joint_count; ++p) {
        exact &= seen[palette[p]] == 2;
        seen[palette[p]] = 0;
    }
    if (!exact)
        return failf(r, "meshlet %zu: palette holds a joint no vertex uses", id);
    /* documented order: first use along the vertex list, vertex by vertex, slot by slot */
    uint32_t next = 0;
    for (uint32_t i = 0; i < m->vertex_count; ++i) {
        uint32_t v = run->out.vertices[m->vertex_offset + i];
        for (size_t s = 0; s < in->influences; ++s) {
            uint16_t j = in->joints[v * in->influences + s];
            if (!used(in, v, s) || seen[j])
                continue;
            seen[j] = 1;
            exact &= next < m->joint_count && palette[next++] == j;
        }
    }
    for (uint32_t p = 0; p < m->joint_count; ++p)
        seen[palette[p]] = 0;
    return exact ? 1 : failf(r, "meshlet %zu: palette is not in order of first use", id);
}

static int check_tuples(const meshlet_run* run, const meshlet_input* in, size_t id, report* r)
{
    const sp_meshlet* m = &run->out.meshlets[id];
    size_t k = in->influences;
    const uint16_t* palette = run->out.joints + m->joint_offset;
    const uint8_t* lut = run->out.tuples + (size_t)m->tuple_offset * k;
    uint32_t bits = 0;
    while ((1u << bits) < m->tuple_count)
        ++bits;
    if (m->tuple_bits != bits)
        return failf(r, "meshlet %zu: tuple_bits %u for %u tuples", id, m->tuple_bits, m->tuple_count);
    for (uint32_t a = 0; a < m->tuple_count; ++a) {
        for (size_t s = 0; s < k; ++s)
            if (lut[a * k + s] >= m->joint_count)
                return failf(r, "meshlet %zu: tuple %u slot %zu beyond the palette", id, a, s);
        for (uint32_t b = 0; b < a; ++b)
            if (memcmp(lut + a * k, lut + b * k, k) == 0)
                return failf(r, "meshlet %zu: tuples %u and %u are equal", id, b, a);
    }
    uint32_t tuples_seen = 0;
    for (uint32_t i = 0; i < m->vertex_count; ++i) {
        uint32_t v = run->out.vertices[m->vertex_offset + i];
        uint8_t index = run->out.vertex_tuples[m->vertex_offset + i];
        if (index >= m->tuple_count || index > tuples_seen)
            return failf(r, "meshlet %zu: vertex %u has tuple %u of %u (not in first-use order)", id, v, index,
                         m->tuple_count);
        tuples_seen += index == tuples_seen;
        for (size_t s = 0; s < k; ++s) {
            uint8_t slot = lut[index * k + s];
            if (used(in, v, s) ? palette[slot] != in->joints[v * k + s] : slot != 0)
                return failf(r, "meshlet %zu: vertex %u slot %zu does not decode to its joint", id, v, s);
        }
    }
    if (tuples_seen != m->tuple_count)
        return failf(r, "meshlet %zu: %u of %u tuples used", id, tuples_seen, m->tuple_count);
    return 1;
}

static int check_bounds(const meshlet_run* run, const meshlet_input* in, size_t id, report* r)
{
    const sp_meshlet* m = &run->out.meshlets[id];
    for (uint32_t i = 0; i < m->vertex_count; ++i) {
        const float* p = in->positions + (size_t)run->out.vertices[m->vertex_offset + i] * 3;
        double d = sqrt(pow(p[0] - m->center[0], 2) + pow(p[1] - m->center[1], 2) + pow(p[2] - m->center[2], 2));
        if (d > m->radius * (1.0 + 1e-5) + 1e-6)
            return failf(r, "meshlet %zu: vertex %u at distance %g outside radius %g", id, i, d, m->radius);
    }
    if (m->cone_cutoff >= 1.0f)
        return 1;
    /* a cone that culls must hold every triangle normal, with the apex behind every plane */
    double min_dot = sqrt(1.0 - (double)m->cone_cutoff * m->cone_cutoff);
    const uint32_t* verts = run->out.vertices + m->vertex_offset;
    const uint8_t* local = run->out.triangles + (size_t)m->triangle_offset * 3;
    for (uint32_t t = 0; t < m->triangle_count; ++t) {
        const float* p0 = in->positions + (size_t)verts[local[t * 3]] * 3;
        const float* p1 = in->positions + (size_t)verts[local[t * 3 + 1]] * 3;
        const float* p2 = in->positions + (size_t)verts[local[t * 3 + 2]] * 3;
        double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]}, e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        double length = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (length == 0.0)
            continue;
        double dot = (n[0] * m->cone_axis[0] + n[1] * m->cone_axis[1] + n[2] * m->cone_axis[2]) / length;
        double behind = ((m->cone_apex[0] - p0[0]) * n[0] + (m->cone_apex[1] - p0[1]) * n[1] +
                         (m->cone_apex[2] - p0[2]) * n[2]) / length;
        if (dot < min_dot - 1e-3 || behind > 1e-4 * (m->radius + 1.0))
            return failf(r, "meshlet %zu: triangle %u outside its normal cone", id, t);
    }
    return 1;
}

static int check_meshlet(const meshlet_run* run, const meshlet_input* in, const sp_meshlet_options* o, size_t id,
                         report* r)
{
    const sp_meshlet* m = &run->out.meshlets[id];
    if (m->triangle_count == 0 || m->vertex_count < 1 || m->vertex_count > o->max_vertices ||
        m->triangle_count > o->max_triangles || m->joint_count > o->max_joints)
        return failf(r, "meshlet %zu breaks a limit: %u vertices, %u triangles, %u joints", id, m->vertex_count,
                     m->triangle_count, m->joint_count);
    for (uint32_t i = 0; i < m->triangle_count * 3u; ++i)
        if (run->out.triangles[(size_t)m->triangle_offset * 3 + i] >= m->vertex_count)
            return failf(r, "meshlet %zu: local index out of range", id);
    for (uint32_t i = 0; i < m->vertex_count; ++i)
        for (uint32_t j = 0; j < i; ++j)
            if (run->out.vertices[m->vertex_offset + i] == run->out.vertices[m->vertex_offset + j])
                return failf(r, "meshlet %zu: vertex listed twice", id);
    return check_palette(run, in, id, r) && check_tuples(run, in, id, r) && check_bounds(run, in, id, r);
}

static int check_stats(const meshlet_run* run, report* r)
{
    const sp_meshlet_stats* s = &run->stats;
    size_t vertices = 0, triangles = 0, joints = 0, tuples = 0;
    uint32_t max_joints = 0;
    for (size_t i = 0; i < s->meshlet_count; ++i) {
        const sp_meshlet* m = &run->out.meshlets[i];
        /* the arrays are packed in meshlet order */
        if (m->vertex_offset != vertices || m->triangle_offset != triangles || m->joint_offset != joints ||
            m->tuple_offset != tuples)
            return failf(r, "meshlet %zu: offsets are not packed", i);
        vertices += m->vertex_count;
        triangles += m->triangle_count;
        joints += m->joint_count;
        tuples += m->tuple_count;
        max_joints = m->joint_count > max_joints ? m->joint_count : max_joints;
    }
    if (vertices != s->vertex_count || triangles != s->triangle_count || joints != s->joint_count ||
        tuples != s->tuple_count || max_joints != s->max_joints ||
        (s->meshlet_count && fabs(s->mean_joints - (double)joints / s->meshlet_count) > 1e-9))
        return failf(r, "stats disagree with the meshlets");
    return 1;
}

int meshlet_check(const meshlet_run* run, const meshlet_input* in, const sp_meshlet_options* options, char* message,
                  size_t message_size)
{
    report r = {message, message_size, 0};
    if (run->result != SP_OK)
        return failf(&r, "build failed: %s", sp_result_string(run->result));
    if (!check_stats(run, &r) || !check_triangles_once(run, in, &r) || !check_triangle_meshlet(run, in, &r))
        return 0;
    for (size_t i = 0; i < run->stats.meshlet_count; ++i)
        if (!check_meshlet(run, in, options, i, &r))
            return 0;
    return 1;
}
