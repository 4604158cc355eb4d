/* joint_bound.c - see joint_bound.h. The three counts, for a split into meshlets of at most
 * max_vertices vertices and max_triangles triangles, each triangle in exactly one meshlet:
 *
 * Only referenced vertices (used by some triangle) count: an unused vertex is in no meshlet.
 *
 * - by joint: every triangle touching one of the vertices joint j weights (T_j triangles) lies in
 *   a meshlet whose palette holds j, and that meshlet holds all three of its vertices; so the
 *   meshlets holding j cover the N_j vertices of those triangles (the weighted vertices and the
 *   ring around them) and are at least need_j = max(ceil(N_j / max_vertices),
 *   ceil(T_j / max_triangles));
 * - forced splits: if need_j = need_k = 1 and one triangle touches both, that triangle's meshlet
 *   is the only one holding j and the only one holding k, so all triangles touching j or k share
 *   it. Joining such joints gives groups whose triangles must fit one meshlet; each group that
 *   does not fit makes at least one of its (disjoint) joints need a second palette entry;
 * - by influence count: a vertex with n distinct used joints puts them all in the meshlet of
 *   every triangle around it, so the meshlets with >= n joints hold the T_n triangles touching a
 *   vertex with >= n influences and their N_n vertices: at least max(ceil(N_n / max_vertices),
 *   ceil(T_n / max_triangles)) of them.
 */
#include "joint_bound.h"

#include <stdlib.h>
#include <string.h>

static size_t ceil_div(size_t a, size_t b)
{
    return (a + b - 1) / b;
}

static size_t max_size(size_t a, size_t b)
{
    return a > b ? a : b;
}

static size_t find_root(size_t* parent, size_t x)
{
    while (parent[x] != x)
        x = parent[x] = parent[parent[x]];
    return x;
}

static int compare_pairs(const void* a, const void* b)
{
    const size_t* p = a;
    const size_t* q = b;
    if (p[0] != q[0])
        return p[0] < q[0] ? -1 : 1;
    return (p[1] > q[1]) - (p[1] < q[1]);
}

/* The distinct joints vertex v uses (weight > 0): a repeated joint is one palette entry. */
static size_t vertex_joints(const meshlet_input* in, size_t v, uint16_t* joints)
{
    size_t count = 0;
    for (size_t s = 0; s < in->influences; ++s) {
        if (!(in->weights[v * in->influences + s] > 0.0f))
            continue;
        uint16_t j = in->joints[v * in->influences + s];
        size_t seen = 0;
        while (seen < count && joints[seen] != j)
            seen++;
        if (seen == count)
            joints[count++] = j;
    }
    return count;
}

/* The distinct joints of triangle t (<= 3 * influences), and the most any one corner uses. */
static size_t triangle_joints(const meshlet_input* in, size_t t, uint16_t* joints, size_t* most_influences)
{
    size_t count = 0;
    *most_influences = 0;
    for (int c = 0; c < 3; ++c) {
        uint16_t corner[8];
        size_t used = vertex_joints(in, in->indices[t * 3 + c], corner);
        for (size_t i = 0; i < used; ++i) {
            size_t seen = 0;
            while (seen < count && joints[seen] != corner[i])
                seen++;
            if (seen == count)
                joints[count++] = corner[i];
        }
        *most_influences = max_size(*most_influences, used);
    }
    return count;
}

/* N_j for every joint (the distinct vertices of the triangles touching joint j) into
 * ring_vertices, and N_n for n = 1..8 into ring_with (vertices of triangles touching a vertex of
 * >= n influences). triangle_list: scratch of sum(joint_triangles) entries; offset: joint_slots + 1;
 * stamp and most: vertex_count entries. */
static void count_rings(const meshlet_input* in, const size_t* joint_triangles, size_t joint_slots, size_t* offset,
                        uint32_t* triangle_list, uint32_t* stamp, unsigned char* most, size_t* ring_vertices,
                        size_t* ring_with)
{
    size_t triangle_count = in->index_count / 3;
    uint16_t joints[3 * 8];
    offset[0] = 0;
    for (size_t j = 0; j < joint_slots; ++j)
        offset[j + 1] = offset[j] + joint_triangles[j];
    memset(most, 0, in->vertex_count);
    for (size_t t = 0; t < triangle_count; ++t) {
        size_t corner_most, n = triangle_joints(in, t, joints, &corner_most);
        for (size_t i = 0; i < n; ++i)
            triangle_list[offset[joints[i]]++] = (uint32_t)t;
        for (int c = 0; c < 3; ++c) {
            uint32_t v = in->indices[t * 3 + c];
            most[v] = (unsigned char)max_size(most[v], corner_most);
        }
    }
    for (size_t j = joint_slots; j > 0; --j) /* offsets back to the starts */
        offset[j] = offset[j - 1];
    offset[0] = 0;
    memset(stamp, 0, in->vertex_count * sizeof(uint32_t));
    for (size_t j = 0; j < joint_slots; ++j) {
        ring_vertices[j] = 0;
        for (size_t i = offset[j]; i < offset[j + 1]; ++i)
            for (int c = 0; c < 3; ++c) {
                uint32_t v = in->indices[(size_t)triangle_list[i] * 3 + c];
                if (stamp[v] != (uint32_t)j + 1) {
                    stamp[v] = (uint32_t)j + 1;
                    ring_vertices[j]++;
                }
            }
    }
    for (size_t v = 0; v < in->vertex_count; ++v)
        for (size_t n = 1; n <= most[v]; ++n)
            ring_with[n]++;
}

/* Groups of single-meshlet joints joined by shared triangles that do not fit one meshlet. */
static size_t count_forced_splits(const meshlet_input* in, const size_t* need, size_t joint_slots, size_t max_vertices,
                                  size_t max_triangles, size_t* parent, size_t* pairs, size_t* group_triangles)
{
    size_t triangle_count = in->index_count / 3, pair_count = 0, forced = 0;
    uint16_t joints[3 * 8];
    for (size_t j = 0; j < joint_slots; ++j)
        parent[j] = j;
    for (size_t t = 0; t < triangle_count; ++t) {
        size_t most, n = triangle_joints(in, t, joints, &most), first = joint_slots;
        for (size_t i = 0; i < n; ++i) {
            if (need[joints[i]] != 1)
                continue;
            if (first == joint_slots)
                first = joints[i];
            else
                parent[find_root(parent, joints[i])] = find_root(parent, first);
        }
    }
    memset(group_triangles, 0, joint_slots * sizeof(size_t));
    for (size_t t = 0; t < triangle_count; ++t) {
        size_t most, n = triangle_joints(in, t, joints, &most);
        for (size_t i = 0; i < n; ++i)
            if (need[joints[i]] == 1) { /* all its single-meshlet joints are in one group */
                size_t group = find_root(parent, joints[i]);
                group_triangles[group]++;
                for (int c = 0; c < 3; ++c) {
                    pairs[pair_count * 2] = group;
                    pairs[pair_count * 2 + 1] = in->indices[t * 3 + c];
                    pair_count++;
                }
                break;
            }
    }
    qsort(pairs, pair_count, 2 * sizeof(size_t), compare_pairs);
    for (size_t i = 0; i < pair_count;) {
        size_t group = pairs[i * 2], vertices = 0;
        for (; i < pair_count && pairs[i * 2] == group; ++i)
            vertices += i == 0 || pairs[i * 2] != pairs[i * 2 - 2] || pairs[i * 2 + 1] != pairs[i * 2 - 1];
        forced += vertices > max_vertices || group_triangles[group] > max_triangles;
    }
    return forced;
}

int joint_bound_compute(const meshlet_input* in, size_t max_vertices, size_t max_triangles, joint_bound* out)
{
    size_t joint_slots = 65536, triangle_count = in->index_count / 3;
    size_t ring_with[9] = {0}, triangles_with[9] = {0};
    size_t* joint_triangles = calloc(joint_slots, sizeof(size_t));
    size_t* ring_vertices = calloc(joint_slots, sizeof(size_t));
    size_t* offset = malloc((joint_slots + 1) * sizeof(size_t));
    size_t* need = calloc(joint_slots, sizeof(size_t));
    size_t* parent = malloc(joint_slots * sizeof(size_t));
    size_t* group_triangles = malloc(joint_slots * sizeof(size_t));
    size_t* pairs = malloc((triangle_count * 6 + 1) * sizeof(size_t));
    uint32_t* triangle_list = NULL;
    uint32_t* stamp = malloc((in->vertex_count + 1) * sizeof(uint32_t));
    unsigned char* most = malloc(in->vertex_count + 1);
    int ok = joint_triangles && ring_vertices && offset && need && parent && group_triangles && pairs &&
             stamp && most && in->influences <= 8;
    if (ok) {
        uint16_t joints[3 * 8];
        size_t listed = 0;
        for (size_t t = 0; t < triangle_count; ++t) {
            size_t corner_most, n = triangle_joints(in, t, joints, &corner_most);
            for (size_t i = 0; i < n; ++i)
                joint_triangles[joints[i]]++;
            for (size_t k = 1; k <= corner_most; ++k)
                triangles_with[k]++;
            listed += n;
        }
        ok = (triangle_list = malloc((listed + 1) * sizeof(uint32_t))) != NULL;
    }
    if (ok) {
        /* only vertices that a triangle uses reach a meshlet: the rings count no other */
        count_rings(in, joint_triangles, joint_slots, offset, triangle_list, stamp, most, ring_vertices, ring_with);
        memset(out, 0, sizeof(*out));
        for (size_t k = 1; k <= in->influences; ++k)
            out->by_influence_count += max_size(ceil_div(ring_with[k], max_vertices),
                                                ceil_div(triangles_with[k], max_triangles));
        for (size_t j = 0; j < joint_slots; ++j) {
            need[j] = max_size(ceil_div(ring_vertices[j], max_vertices), ceil_div(joint_triangles[j], max_triangles));
            out->by_joint += need[j];
        }
        out->forced_splits = count_forced_splits(in, need, joint_slots, max_vertices, max_triangles, parent, pairs,
                                                  group_triangles);
        out->palette_sum = max_size(out->by_influence_count, out->by_joint + out->forced_splits);
    }
    free(joint_triangles);
    free(ring_vertices);
    free(offset);
    free(need);
    free(parent);
    free(group_triangles);
    free(pairs);
    free(triangle_list);
    free(stamp);
    free(most);
    return ok;
}
