/*
 * harness_meshshader.c - "skinpack_shader_harness meshshader FILE": skin.mesh's logic on a
 * device without VK_EXT_mesh_shader (lavapipe in CI).
 *
 * skin_meshlet_test.comp runs shaders/skin_meshlet.glsl - the code skin.mesh is made of - with
 * the mesh outputs written to buffers, one record per meshlet and instance. This file checks
 * them against C: skinned world and clip positions (linear blend skinning with the C-decoded
 * weights), triangle corners, the per-triangle cull flag (clip-space determinant) and the
 * per-meshlet normal-cone decision of rigid meshlets. What it cannot check is the mesh stage
 * itself: output arrays, rasterisation, timing.
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "skinpack.h"
#include "sp_gpu.h"
#include "vk_context.h"

enum { MESHSHADER_INSTANCES = 8, MESHSHADER_COLUMNS = 4 };
#define DET_RELATIVE_EPSILON 1e-5  /* |det| below this times its rounding scale: sign undecidable */
#define CONE_EPSILON 1e-4          /* |dot - cutoff| below this: cone decision undecidable */

/* clip = view_projection (p, 1), in double. */
static void clip_position(const float vp[16], const double p[3], double clip[4])
{
    for (int r = 0; r < 4; ++r) clip[r] = vp[r] * p[0] + vp[4 + r] * p[1] + vp[8 + r] * p[2] + vp[12 + r];
}

/* skin_instance_offset of skin_common.glsl. */
static void instance_offset(const SpSkinParameters* params, uint32_t instance, double offset[3])
{
    uint32_t cell = params->counts.w + instance, columns = params->counts.z ? params->counts.z : 1;
    offset[0] = (double)(cell % columns) * params->camera.w;
    offset[1] = (double)(cell / columns) * params->camera.w;
    offset[2] = 0;
}

/* Joint matrices of every instance: the exported pose, then a turn about z that differs per
 * instance (rotation + translation, so rigid meshlets keep exact normal cones) - each instance
 * shows the camera another side, so culling decisions of both kinds occur. */
static float* instance_matrices(const sp_skin_mesh* mesh, uint32_t instances)
{
    size_t per_instance = (size_t)mesh->joint_count * 12;
    float* rows = malloc(per_instance * instances * sizeof(float));
    for (uint32_t i = 0; i < instances; ++i) {
        double angle = 0.4 + 6.283185307179586 * i / instances, c = cos(angle), s = sin(angle);
        double turn[3][3] = {{c, -s, 0}, {s, c, 0}, {0, 0, 1}};
        for (size_t j = 0; j < mesh->joint_count; ++j) {
            const float* pose = mesh->pose_rows + 12 * j;
            float* out = rows + per_instance * i + 12 * j;
            for (int r = 0; r < 3; ++r)
                for (int col = 0; col < 4; ++col)
                    out[4 * r + col] = (float)(turn[r][0] * pose[col] + turn[r][1] * pose[4 + col] + turn[r][2] * pose[8 + col]);
        }
    }
    return rows;
}

/* meshlet_cone_faces_away of skin_meshlet.glsl in double: 1 culled, 0 kept, -1 too close to
 * the cutoff to tell float from double. */
static int reference_cone_faces_away(const sp_meshlet* m, const uint16_t* palette, const float* instance_rows,
                                     const SpSkinParameters* params, uint32_t instance, int* rigid)
{
    *rigid = m->joint_count == 1 && m->cone_cutoff < 1.0f;
    if (!*rigid) return 0;
    const float* rows = instance_rows + 12 * (size_t)palette[m->joint_offset];
    double offset[3], apex[3], axis[3], view[3], axis_length = 0, view_length = 0, dot = 0;
    instance_offset(params, instance, offset);
    const float* camera = &params->camera.x;
    for (int r = 0; r < 3; ++r) {
        const float* row = rows + 4 * r;
        apex[r] = row[0] * m->cone_apex[0] + row[1] * m->cone_apex[1] + row[2] * m->cone_apex[2] + row[3] + offset[r];
        axis[r] = row[0] * m->cone_axis[0] + row[1] * m->cone_axis[1] + row[2] * m->cone_axis[2];
        view[r] = apex[r] - camera[r];
        axis_length += axis[r] * axis[r];
        view_length += view[r] * view[r];
    }
    for (int r = 0; r < 3; ++r) dot += view[r] * axis[r];
    dot /= sqrt(axis_length * view_length);
    if (fabs(dot - m->cone_cutoff) <= CONE_EPSILON) return -1;
    return dot >= m->cone_cutoff;
}

static double length3(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

/* triangle_faces_away of skin_meshlet.glsl in double, on the clip (x, y, w) rows: culled when
 * all w > 0 and det >= 0. Returns -1 when a w or det is within rounding of 0. det is
 * a . ((b - a) x (c - a)); clip errors of d per component change it by about
 * d (|e1||e2| + 2 |a| (|e1| + |e2|)), so that is the scale the epsilon is relative to. */
static int reference_triangle_culled(const double* clip_a, const double* clip_b, const double* clip_c, int* behind_eye)
{
    const double* corners[3] = {clip_a, clip_b, clip_c};
    double xyw[3][3], largest = 0;
    int in_front = 1;
    for (int k = 0; k < 3; ++k) {
        xyw[k][0] = corners[k][0];
        xyw[k][1] = corners[k][1];
        xyw[k][2] = corners[k][3];
        largest = fmax(largest, length3(xyw[k]));
    }
    for (int k = 0; k < 3; ++k) {
        if (fabs(xyw[k][2]) <= DET_RELATIVE_EPSILON * largest) return -1;
        in_front &= xyw[k][2] > 0;
    }
    *behind_eye = !in_front;
    if (!in_front) return 0;
    double e1[3], e2[3];
    for (int r = 0; r < 3; ++r) {
        e1[r] = xyw[1][r] - xyw[0][r];
        e2[r] = xyw[2][r] - xyw[0][r];
    }
    double cross[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    double det = xyw[0][0] * cross[0] + xyw[0][1] * cross[1] + xyw[0][2] * cross[2];
    double scale = largest * (length3(e1) * length3(e2) + 2 * largest * (length3(e1) + length3(e2)));
    if (fabs(det) <= DET_RELATIVE_EPSILON * scale) return -1;
    return det >= 0;
}

/* One dispatch of skin_meshlet_test.comp: meshlet_count x instances workgroups. Returns the
 * records (malloc'ed), filled with 0xcd first so that anything the shader skips cannot pass. */
static SpMeshletOutputRecord* gpu_meshlet_outputs(harness* h, VkPipeline pipeline, vkx_buffer* const inputs[SP_BINDING_COUNT],
                                                  const SpSkinParameters* params, uint32_t meshlet_count, uint32_t instances)
{
    vkx_context* ctx = &h->ctx;
    size_t record_count = (size_t)meshlet_count * instances;
    vkx_buffer output = vkx_poisoned_buffer(ctx, record_count * sizeof(SpMeshletOutputRecord), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    vkx_buffer* bindings[SP_BINDING_COUNT];
    memcpy(bindings, inputs, sizeof(bindings));
    bindings[SP_BINDING_OUTPUT] = &output;
    VkDescriptorSet set = vkx_descriptor_set(ctx, bindings, &h->dummy);
    vkx_dispatch_and_wait(ctx, pipeline, set, params, (uint32_t)sizeof(*params), meshlet_count, instances);
    SpMeshletOutputRecord* records = malloc(record_count * sizeof(SpMeshletOutputRecord));
    memcpy(records, output.mapped, record_count * sizeof(SpMeshletOutputRecord));
    vkResetDescriptorPool(ctx->device, ctx->descriptor_pool, 0);
    vkx_buffer_destroy(ctx, &output);
    return records;
}

/* What the C reference decided, over all meshlets and instances. */
typedef struct cull_counts {
    size_t rigid, cone_culled, cone_kept, cone_skipped;
    size_t culled, front, behind_eye, skipped;
} cull_counts;

/* The C side of one instance: world (3 per vertex) and clip (4 per vertex) positions. */
typedef struct instance_reference {
    double* world;
    double* clip;
    double world_tolerance;
} instance_reference;

/* C's triangle decision for triangle t of a meshlet (see reference_triangle_culled). */
static int meshlet_triangle_culled(const sp_gpu_meshlets* built, const sp_meshlet* meshlet, uint32_t t,
                                   const instance_reference* ref, int* behind_eye)
{
    const uint8_t* local = built->arrays.triangles + 3 * ((size_t)meshlet->triangle_offset + t);
    const double* clip[3];
    for (int k = 0; k < 3; ++k) clip[k] = ref->clip + 4 * (size_t)built->arrays.vertices[meshlet->vertex_offset + local[k]];
    *behind_eye = 0;
    return reference_triangle_culled(clip[0], clip[1], clip[2], behind_eye);
}

/* The cone is conservative: when it culls a meshlet, none of its triangles may face the camera.
 * This ties the cone's sign convention to the triangles' winding, which mirroring the shader's
 * formula in C could not. */
static void check_cone_is_conservative(harness* h, const sp_gpu_meshlets* built, size_t m, uint32_t instance,
                                       const instance_reference* ref)
{
    const sp_meshlet* meshlet = &built->arrays.meshlets[m];
    for (uint32_t t = 0; t < meshlet->triangle_count; ++t) {
        int behind_eye;
        if (meshlet_triangle_culled(built, meshlet, t, ref, &behind_eye) == 0 && !behind_eye) {
            fail_check(h, "meshlet %zu instance %u: its normal cone culls it, but triangle %u faces the camera", m, instance, t);
            return;
        }
    }
}

/* The record's normal-cone decision against C's, counted. Returns 0 when the record failed
 * or the GPU culled the meshlet (nothing more to check). */
static int check_record_cone(harness* h, const sp_gpu_meshlets* built, size_t m, uint32_t instance,
                             const SpMeshletOutputRecord* r, const instance_reference* ref, const float* instance_rows,
                             const SpSkinParameters* params, cull_counts* counts)
{
    const sp_meshlet* meshlet = &built->arrays.meshlets[m];
    int rigid;
    int cone = reference_cone_faces_away(meshlet, built->arrays.joints, instance_rows, params, instance, &rigid);
    int gpu_culled = r->counts.x == 0 && r->counts.y == 0;
    counts->rigid += (size_t)rigid;
    if (rigid) ++*(cone < 0 ? &counts->cone_skipped : cone ? &counts->cone_culled : &counts->cone_kept);
    ++h->checked;
    if (cone >= 0 && gpu_culled != cone) {
        fail_check(h, "meshlet %zu instance %u: the GPU %s it by its normal cone, C %s", m, instance,
                   gpu_culled ? "culled" : "kept", cone ? "culls" : "keeps");
        return 0;
    }
    if (cone == 1) check_cone_is_conservative(h, built, m, instance, ref);
    if (gpu_culled) return 0;
    if (r->counts.x != meshlet->vertex_count || r->counts.y != meshlet->triangle_count) {
        fail_check(h, "meshlet %zu instance %u: outputs %u vertices, %u triangles; the meshlet has %u, %u", m, instance,
                   r->counts.x, r->counts.y, meshlet->vertex_count, meshlet->triangle_count);
        return 0;
    }
    return 1;
}

/* The record's world and clip positions against C's. The clip tolerance is the world error
 * carried through the matrix, plus a few float roundings of the product. */
static void check_record_vertices(harness* h, const sp_gpu_meshlets* built, size_t m, uint32_t instance,
                                  const SpMeshletOutputRecord* r, const instance_reference* ref, const float* vp)
{
    const sp_meshlet* meshlet = &built->arrays.meshlets[m];
    for (uint32_t i = 0; i < meshlet->vertex_count; ++i) {
        uint32_t v = built->arrays.vertices[meshlet->vertex_offset + i];
        const double* world = ref->world + 3 * (size_t)v;
        const double* clip = ref->clip + 4 * (size_t)v;
        const float* got_world = &r->world[i].x;
        const float* got_clip = &r->clip[i].x;
        double world_error = 0, clip_error = 0, clip_tolerance = 0;
        for (int c = 0; c < 3; ++c) world_error = fmax(world_error, fabs(got_world[c] - world[c]));
        for (int row = 0; row < 4; ++row) {
            double reach = fabs(vp[12 + row]), spread = 0;
            for (int c = 0; c < 3; ++c) {
                reach += fabs(vp[4 * c + row] * world[c]);
                spread += fabs(vp[4 * c + row]);
            }
            clip_tolerance = fmax(clip_tolerance, spread * ref->world_tolerance + 8 * FLT_EPSILON * reach);
            clip_error = fmax(clip_error, fabs(got_clip[row] - clip[row]));
        }
        ++h->checked;
        if (!(world_error <= ref->world_tolerance) || !(clip_error <= clip_tolerance))
            fail_check(h, "meshlet %zu instance %u vertex %u (source %u): world off by %.3g (tolerance %.3g), clip by %.3g (%.3g)",
                       m, instance, i, v, world_error, ref->world_tolerance, clip_error, clip_tolerance);
    }
}

/* The record's triangle corners and cull flags against C's, counted. */
static void check_record_triangles(harness* h, const sp_gpu_meshlets* built, size_t m, uint32_t instance,
                                   const SpMeshletOutputRecord* r, const instance_reference* ref, cull_counts* counts)
{
    const sp_meshlet* meshlet = &built->arrays.meshlets[m];
    for (uint32_t t = 0; t < meshlet->triangle_count; ++t) {
        const uint8_t* local = built->arrays.triangles + 3 * ((size_t)meshlet->triangle_offset + t);
        const uint32_t* got = &r->triangles[t].x;
        ++h->checked;
        if (got[0] != local[0] || got[1] != local[1] || got[2] != local[2] || got[3] > 1) {
            fail_check(h, "meshlet %zu instance %u triangle %u: corners (%u %u %u) flag %u, want (%u %u %u)", m, instance, t,
                       got[0], got[1], got[2], got[3], local[0], local[1], local[2]);
            continue;
        }
        int behind_eye;
        int culled = meshlet_triangle_culled(built, meshlet, t, ref, &behind_eye);
        if (culled < 0) {
            ++counts->skipped;
            continue;
        }
        ++*(culled ? &counts->culled : behind_eye ? &counts->behind_eye : &counts->front);
        if ((uint32_t)culled != got[3])
            fail_check(h, "meshlet %zu instance %u triangle %u: the GPU %s it, C %s it", m, instance, t,
                       got[3] ? "culled" : "kept", culled ? "culls" : "keeps");
    }
}

/* Checks one record (meshlet m, instance i) against the C reference. */
static void check_meshlet_record(harness* h, const sp_gpu_meshlets* built, size_t m, uint32_t instance,
                                 const SpMeshletOutputRecord* r, const instance_reference* ref, const float* instance_rows,
                                 const SpSkinParameters* params, cull_counts* counts)
{
    if (!check_record_cone(h, built, m, instance, r, ref, instance_rows, params, counts)) return;
    check_record_vertices(h, built, m, instance, r, ref, params->view_projection.columns);
    check_record_triangles(h, built, m, instance, r, ref, counts);
}

/* RE_Player has no rigid meshlet (every meshlet has several palette joints), so skin.mesh's
 * normal-cone path never runs on it. A second, synthetic mesh covers it: six spherical caps
 * (half-angle 50 degrees, so their cones can cull) facing +-x, +-y, +-z around the body's
 * bounding box, all bound with weight 1 to the joint the pose moves most - every meshlet the
 * builder makes of them is rigid, however it groups them, and a cap of 64 vertices fills one. */
enum { CAP_RINGS = 7, CAP_SEGMENTS = 9, CAP_COUNT = 6 };

/* The joint whose rest-to-pose matrix is furthest from the identity. */
static uint16_t most_moved_joint(const sp_skin_mesh* mesh)
{
    uint16_t best = 0;
    double best_distance = -1;
    for (uint32_t j = 0; j < mesh->joint_count && mesh->pose_count; ++j) {
        double distance = 0;
        for (int e = 0; e < 12; ++e) distance += fabs(mesh->pose_rows[12 * j + e] - (e % 5 == 0 ? 1.0 : 0.0));
        if (distance > best_distance) {
            best_distance = distance;
            best = (uint16_t)j;
        }
    }
    return best;
}

enum { CAP_VERTICES = 1 + CAP_RINGS * CAP_SEGMENTS, CAP_TRIANGLES = CAP_SEGMENTS + 2 * CAP_SEGMENTS * (CAP_RINGS - 1) };

/* A point of a cap: its apex (i = 0), then ring after ring of CAP_SEGMENTS points. */
static void cap_point(uint32_t i, const float center[3], float radius, const float normal[3], const float u[3],
                      const float w[3], float* out)
{
    const double half_angle = 50.0 * 3.14159265358979 / 180.0;
    uint32_t ring = i == 0 ? 0 : 1 + (i - 1) / CAP_SEGMENTS, segment = i == 0 ? 0 : (i - 1) % CAP_SEGMENTS;
    double polar = half_angle * ring / CAP_RINGS, azimuth = 6.283185307179586 * segment / CAP_SEGMENTS;
    for (int c = 0; c < 3; ++c)
        out[c] = center[c] + radius * (float)(cos(polar) * normal[c] + sin(polar) * (cos(azimuth) * u[c] + sin(azimuth) * w[c]));
}

/* Cap number `cap` (axis +-x, +-y, +-z): its sphere sits one box size outside the box
 * [low, high] on that side. Writes its vertices, bound to joint, and returns index advanced
 * past its triangles. */
static uint32_t* add_cap(sp_skin_mesh* caps, uint32_t cap, const float low[3], const float high[3], uint16_t joint,
                         uint32_t* index)
{
    float size = fmaxf(high[0] - low[0], fmaxf(high[1] - low[1], high[2] - low[2])), radius = 0.1f * size;
    int axis = (int)cap / 2;
    float sign = cap % 2 ? -1.0f : 1.0f, normal[3] = {0, 0, 0}, center[3];
    normal[axis] = sign;
    for (int c = 0; c < 3; ++c) center[c] = 0.5f * (low[c] + high[c]);
    center[axis] = (sign > 0 ? high[axis] : low[axis]) + sign * size;
    /* tangents u, w with u x w = normal, so counter-clockwise triangles face outwards */
    float u[3] = {0, 0, 0}, w[3];
    u[(axis + 1) % 3] = 1;
    w[0] = normal[1] * u[2] - normal[2] * u[1];
    w[1] = normal[2] * u[0] - normal[0] * u[2];
    w[2] = normal[0] * u[1] - normal[1] * u[0];
    uint32_t first = cap * CAP_VERTICES;
    for (uint32_t i = 0; i < CAP_VERTICES; ++i) {
        cap_point(i, center, radius, normal, u, w, caps->positions + 3 * (first + i));
        caps->joints[8 * (size_t)(first + i)] = joint;
        caps->weights[8 * (size_t)(first + i)] = 1.0f;
    }
    for (uint32_t s = 0; s < CAP_SEGMENTS; ++s) {
        uint32_t next = (s + 1) % CAP_SEGMENTS;
        *index++ = first, *index++ = first + 1 + s, *index++ = first + 1 + next;
        for (uint32_t ring = 1; ring < CAP_RINGS; ++ring) {
            uint32_t a = first + 1 + (ring - 1) * CAP_SEGMENTS, b = a + CAP_SEGMENTS;
            *index++ = a + s, *index++ = b + s, *index++ = b + next;
            *index++ = a + s, *index++ = b + next, *index++ = a + next;
        }
    }
    return index;
}

/* Fills caps (same joint count and pose as body) with the cap geometry described above. */
static void rigid_caps_mesh(const sp_skin_mesh* body, sp_skin_mesh* caps)
{
    memset(caps, 0, sizeof(*caps));
    snprintf(caps->name, sizeof(caps->name), "%.40s rigid caps", body->name);
    caps->vertex_count = CAP_COUNT * CAP_VERTICES;
    caps->triangle_count = CAP_COUNT * CAP_TRIANGLES;
    caps->joint_count = body->joint_count;
    caps->influences = 8;
    caps->pose_count = 1;
    caps->positions = malloc((size_t)caps->vertex_count * 3 * sizeof(float));
    caps->indices = malloc((size_t)caps->triangle_count * 3 * sizeof(uint32_t));
    caps->joints = calloc((size_t)caps->vertex_count * 8, sizeof(uint16_t));
    caps->weights = calloc((size_t)caps->vertex_count * 8, sizeof(float));
    caps->pose_rows = malloc((size_t)body->joint_count * 12 * sizeof(float));
    memcpy(caps->pose_rows, body->pose_rows, (size_t)body->joint_count * 12 * sizeof(float));
    uint16_t joint = most_moved_joint(body);

    float low[3] = {INFINITY, INFINITY, INFINITY}, high[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t v = 0; v < body->vertex_count; ++v)
        for (int c = 0; c < 3; ++c) {
            low[c] = fminf(low[c], body->positions[3 * v + c]);
            high[c] = fmaxf(high[c], body->positions[3 * v + c]);
        }
    uint32_t* index = caps->indices;
    for (uint32_t cap = 0; cap < CAP_COUNT; ++cap) index = add_cap(caps, cap, low, high, joint, index);
}

/* The C side of every instance: world = LBS(C-decoded weights) + grid offset, clip = VP world. */
static instance_reference* reference_instances(const sp_skin_mesh* mesh, const uint16_t* joints, const float* weights,
                                               uint32_t k, const float* matrices, const SpSkinParameters* params,
                                               uint32_t instances)
{
    size_t n = mesh->vertex_count;
    instance_reference* refs = calloc(instances, sizeof(*refs));
    float* skinned = malloc(n * 3 * sizeof(float));
    double extent = 1e-6;
    for (uint32_t i = 0; i < instances; ++i) {
        sp_reference_skin(mesh->positions, n, joints, weights, k, matrices + (size_t)i * mesh->joint_count * 12, skinned);
        double offset[3];
        instance_offset(params, i, offset);
        refs[i].world = malloc(n * 3 * sizeof(double));
        refs[i].clip = malloc(n * 4 * sizeof(double));
        for (size_t v = 0; v < n; ++v) {
            for (int c = 0; c < 3; ++c) {
                refs[i].world[3 * v + c] = (double)skinned[3 * v + c] + offset[c];
                extent = fmax(extent, fabs(refs[i].world[3 * v + c]));
            }
            clip_position(params->view_projection.columns, refs[i].world + 3 * v, refs[i].clip + 4 * v);
        }
    }
    /* float accumulation vs the double C reference: a few ulps of the largest coordinate */
    for (uint32_t i = 0; i < instances; ++i) refs[i].world_tolerance = 2e-6 * extent;
    free(skinned);
    return refs;
}

/* The default meshlets of the packed skin; fails when skin.mesh could not hold them. */
static void build_scene_meshlets(const sp_skin_mesh* mesh, const sp_gpu_default_skin* packed, sp_gpu_meshlets* built)
{
    sp_result result = sp_gpu_meshlets_build(mesh->indices, (size_t)mesh->triangle_count * 3, mesh->positions,
                                             mesh->vertex_count, 12, packed->joints, packed->weights,
                                             packed->skin.influences, built);
    if (result != SP_OK) vkx_fail("sp_build_meshlets: %s", sp_result_string(result));
    const sp_meshlet_stats* stats = &built->stats;
    printf("%s: %zu meshlets, up to %u vertices / %u triangles / %u joints\n", mesh->name, stats->meshlet_count,
           stats->max_vertices, stats->max_triangles, stats->max_joints);
    if (stats->max_vertices > SP_MESH_SHADER_MAX_VERTICES || stats->max_triangles > SP_MESH_SHADER_MAX_TRIANGLES)
        vkx_fail("the default meshlets exceed skin.mesh's %u vertices / %u triangles", SP_MESH_SHADER_MAX_VERTICES,
                 SP_MESH_SHADER_MAX_TRIANGLES);
}

/* The scene: instances on a 4 x 2 grid, each turned another way; the camera stands between
 * the rows looking at the second, so the first row is behind the eye (w < 0: kept). */
static SpSkinParameters scene_parameters(const sp_skin_mesh* mesh, const sp_gpu_meshlets* built)
{
    size_t n = mesh->vertex_count;
    double extent = 1e-6;
    for (size_t i = 0; i < n * 3; ++i) extent = fmax(extent, fabs((double)mesh->positions[i]));
    double spacing = 1.25 * extent;
    SpSkinParameters params;
    memset(&params, 0, sizeof(params));
    float eye[3] = {(float)(1.5 * spacing), (float)(0.5 * spacing), (float)(0.5 * extent)};
    float target[3] = {eye[0], eye[1] + (float)spacing, (float)(0.3 * extent)};
    sp_gpu_camera(16.0f / 9.0f, eye, target, params.view_projection.columns);
    params.counts = (sp_gpu_uvec4){(uint32_t)n, mesh->joint_count, MESHSHADER_COLUMNS, 0};
    params.camera = (sp_gpu_vec4){eye[0], eye[1], eye[2], (float)spacing};
    params.meshlet_arrays = (sp_gpu_uvec4){built->offsets[0], built->offsets[1], built->offsets[2], built->offsets[3]};
    params.meshlet_extra = (sp_gpu_uvec4){built->offsets[4], (uint32_t)built->stats.meshlet_count, 0, 0};
    return params;
}

/* The input buffers of skin_meshlet_test.comp, all but its output. */
typedef struct scene_buffers {
    vkx_buffer codec, words, lut, matrices, positions, meshlets, data;
} scene_buffers;

static void upload_scene(vkx_context* ctx, const sp_skin_mesh* mesh, const sp_gpu_default_skin* packed,
                         const sp_gpu_meshlets* built, const SpGpuCodec* gpu_codec, const float* matrices, scene_buffers* b)
{
    const sp_compressed_skin* skin = &packed->skin;
    size_t n = mesh->vertex_count, lut_entries = skin->lut_size * skin->influences;
    VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    b->codec = vkx_host_buffer(ctx, gpu_codec, sizeof(*gpu_codec), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    b->words = vkx_upload(ctx, packed->words, n * skin->words_per_vertex * 4, storage);
    b->lut = vkx_upload(ctx, packed->lut_bytes, lut_entries * skin->joint_bytes, storage);
    b->matrices = vkx_upload(ctx, matrices, (size_t)MESHSHADER_INSTANCES * mesh->joint_count * 12 * sizeof(float), storage);
    b->positions = vkx_upload(ctx, mesh->positions, n * 3 * sizeof(float), storage);
    b->meshlets = vkx_upload(ctx, built->arrays.meshlets, built->stats.meshlet_count * sizeof(sp_meshlet), storage);
    b->data = vkx_upload(ctx, built->data, built->data_words * 4, storage);
}

static void destroy_scene(vkx_context* ctx, scene_buffers* b)
{
    vkx_buffer* all[] = {&b->codec, &b->words, &b->lut, &b->matrices, &b->positions, &b->meshlets, &b->data};
    for (size_t i = 0; i < sizeof(all) / sizeof(all[0]); ++i) vkx_buffer_destroy(ctx, all[i]);
}

/* The meshes, poses and C references one pipeline is checked against. */
typedef struct scene {
    const sp_skin_mesh* mesh;
    sp_gpu_meshlets built;
    SpSkinParameters params;
    float* matrices; /* MESHSHADER_INSTANCES x joint_count rows */
    instance_reference* refs;
    vkx_buffer* inputs[SP_BINDING_COUNT];
} scene;

/* Runs the scene through one pipeline, checks every record and prints what C decided. */
static cull_counts check_scene_pipeline(harness* h, const scene* sc, const vkx_specialization* spec, const char* name)
{
    vkx_context* ctx = &h->ctx;
    size_t meshlet_count = sc->built.stats.meshlet_count;
    VkPipeline pipeline = vkx_compute_pipeline(ctx, "skin_meshlet_test.comp.spv", spec);
    SpMeshletOutputRecord* records = gpu_meshlet_outputs(h, pipeline, sc->inputs, &sc->params, (uint32_t)meshlet_count,
                                                         MESHSHADER_INSTANCES);
    vkDestroyPipeline(ctx->device, pipeline, NULL);
    cull_counts counts = {0};
    size_t failures_before = h->failures;
    for (uint32_t i = 0; i < MESHSHADER_INSTANCES; ++i)
        for (size_t m = 0; m < meshlet_count; ++m)
            check_meshlet_record(h, &sc->built, m, i, &records[i * meshlet_count + m], &sc->refs[i],
                                 sc->matrices + (size_t)i * sc->mesh->joint_count * 12, &sc->params, &counts);
    free(records);
    printf("  %s pipeline: %zu mismatches\n", name, h->failures - failures_before);
    printf("    triangles: %zu culled, %zu kept facing the camera, %zu kept behind the eye, %zu skipped (|det| or |w| ~ 0)\n",
           counts.culled, counts.front, counts.behind_eye, counts.skipped);
    printf("    rigid meshlets with a cone (x instances): %zu - %zu culled, %zu kept, %zu skipped (dot ~ cutoff)\n",
           counts.rigid, counts.cone_culled, counts.cone_kept, counts.cone_skipped);
    return counts;
}

/* Compresses mesh (OSS, 32-bit words), builds its meshlets, poses MESHSHADER_INSTANCES
 * instances in front of and behind a camera, runs skin_meshlet_test.comp and checks every
 * record. Returns what the C reference decided (specialised pipeline). */
static cull_counts meshshader_scene(harness* h, const sp_skin_mesh* mesh)
{
    sp_gpu_default_skin packed;
    sp_gpu_default_skin_build(mesh, &packed);
    scene sc = {.mesh = mesh};
    build_scene_meshlets(mesh, &packed, &sc.built);
    sc.params = scene_parameters(mesh, &sc.built);
    sc.matrices = instance_matrices(mesh, MESHSHADER_INSTANCES);
    sc.refs = reference_instances(mesh, packed.joints, packed.weights, packed.skin.influences, sc.matrices, &sc.params,
                                  MESHSHADER_INSTANCES);

    SpGpuCodec gpu_codec = sp_gpu_skin_codec(&packed.skin, mesh->joint_count);
    scene_buffers buffers;
    upload_scene(&h->ctx, mesh, &packed, &sc.built, &gpu_codec, sc.matrices, &buffers);
    sc.inputs[SP_BINDING_CODEC] = &buffers.codec;
    sc.inputs[SP_BINDING_VERTEX_WORDS] = &buffers.words;
    sc.inputs[SP_BINDING_TUPLE_LUT] = &buffers.lut;
    sc.inputs[SP_BINDING_JOINT_MATRICES] = &buffers.matrices;
    sc.inputs[SP_BINDING_POSITIONS] = &buffers.positions;
    sc.inputs[SP_BINDING_MESHLETS] = &buffers.meshlets;
    sc.inputs[SP_BINDING_MESHLET_DATA] = &buffers.data;

    /* Decoder picked at run time, then specialised to the codec (what an engine ships). */
    vkx_specialization runtime = sp_gpu_specialization(SP_VERTEX_FORMAT_PACKED, NULL);
    vkx_specialization specialised = sp_gpu_specialization(SP_VERTEX_FORMAT_PACKED, &gpu_codec);
    check_scene_pipeline(h, &sc, &runtime, "runtime-decoder");
    cull_counts counts = check_scene_pipeline(h, &sc, &specialised, "specialised");

    destroy_scene(&h->ctx, &buffers);
    for (uint32_t i = 0; i < MESHSHADER_INSTANCES; ++i) {
        free(sc.refs[i].world);
        free(sc.refs[i].clip);
    }
    free(sc.refs);
    free(sc.matrices);
    sp_gpu_meshlets_free(&sc.built);
    sp_gpu_default_skin_free(&packed);
    return counts;
}

void test_meshshader(harness* h, const char* path)
{
    sp_skin_mesh body, caps;
    sp_skin_mesh_load(path, &body);
    rigid_caps_mesh(&body, &caps);
    cull_counts body_counts = meshshader_scene(h, &body);
    cull_counts caps_counts = meshshader_scene(h, &caps);
    /* A scene where one outcome never happens would not test the rule. */
    if (body_counts.culled == 0 || body_counts.front == 0 || body_counts.behind_eye == 0)
        fail_check(h, "%s does not produce culled, front-facing and behind-eye triangles", body.name);
    if (caps_counts.cone_culled == 0 || caps_counts.cone_kept == 0)
        fail_check(h, "%s does not produce normal-cone decisions of both kinds", caps.name);
    sp_skin_mesh_free(&body);
    sp_skin_mesh_free(&caps);
}
