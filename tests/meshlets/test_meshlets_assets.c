/*
 * test_meshlets_assets.c - every builder at several limits on real skinned meshes exported by
 * export_mesh_data.py (label "meshlets"): the full meshlet_check on each output (every meshlet
 * within every limit, the palette cap included), determinism of each builder (at 64/124/32),
 * the skin builder with palette_effort, the palette-limit error on a limit below the mesh's
 * widest triangle, and that no builder's split goes below the joint lower bound (joint_bound.h)
 * that the benchmark uses to judge the joints-per-meshlet target.
 *
 *   test_meshlets_assets FILE.spmd...
 */
#include "joint_bound.h"
#include "mesh_data.h"
#include "meshlet_check.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const char* builder_names[SP_MESHLETS_BUILDER_COUNT] = {"naive", "common", "skin"};

/* One builder at one limit set: the full check, the joint lower bound, determinism if asked;
 * its statistics into *stats if given. Returns the number of failures. */
static int check_split(const char* path, const char* weights, const meshlet_input* in, sp_meshlet_options o,
                       int determinism, sp_meshlet_stats* stats)
{
    meshlet_run run, again;
    meshlet_run_build(&run, in, &o);
    char message[256] = "";
    int ok = meshlet_check(&run, in, &o, message, sizeof(message));
    joint_bound bound;
    double palette_sum = run.stats.mean_joints * (double)run.stats.meshlet_count;
    if (!joint_bound_compute(in, o.max_vertices, o.max_triangles, &bound))
        return 1;
    if (run.result == SP_OK && palette_sum + 0.5 < (double)bound.palette_sum) {
        snprintf(message, sizeof(message), "%.0f palette entries, below the lower bound %zu", palette_sum,
                 bound.palette_sum);
        ok = 0;
    }
    int same = 1;
    if (determinism) {
        meshlet_run_build(&again, in, &o);
        same = meshlet_runs_equal(&run, &again, in->influences, in->index_count / 3);
        meshlet_run_free(&again);
    }
    printf("%s %s%-6s %3u/%3u/%3u: %s%s %zu meshlets, joints mean %.2f max %u, tuple bits %.2f local / %u global\n",
           path, weights, builder_names[o.builder], o.max_vertices, o.max_triangles, o.max_joints, ok ? "ok" : message,
           same ? "" : " NOT DETERMINISTIC", run.stats.meshlet_count, run.stats.mean_joints, run.stats.max_joints,
           run.stats.local_tuple_bits_mean, run.stats.global_tuple_bits);
    if (stats)
        *stats = run.stats;
    meshlet_run_free(&run);
    return !ok + !same;
}

/* The weight of joint j among a vertex's K slots (0 if absent). */
static float weight_of(const uint16_t* joints, const float* weights, size_t k, uint16_t j)
{
    for (size_t s = 0; s < k; ++s)
        if (weights[s] > 0.0f && joints[s] == j)
            return weights[s];
    return 0.0f;
}

/* The weights `skinpack compress --meshlets` builds from (mesh_data_decode_compressed, which
 * the benchmark's "as compressed" rows use): every decoded used joint is a used joint of the
 * prepared vertex and every weight within the codec's bound of the prepared one; and the skin
 * builder's splits of them at the benchmark's limits pass the full check, caps included. */
static int check_as_compressed(const char* path, mesh_data* mesh)
{
    if (!mesh_data_decode_compressed(mesh))
        return 1;
    size_t k = mesh->influences, kd = mesh->decoded_influences, bad = 0;
    for (size_t v = 0; v < mesh->vertex_count; ++v) {
        const uint16_t *pj = mesh->joints + v * k, *dj = mesh->decoded_joints + v * kd;
        const float *pw = mesh->weights + v * k, *dw = mesh->decoded_weights + v * kd;
        for (size_t s = 0; s < kd; ++s)
            bad += dw[s] > 0.0f && !(weight_of(pj, pw, k, dj[s]) > 0.0f);
        for (size_t s = 0; s < k && pw[s] > 0.0f; ++s)
            bad += fabs((double)pw[s] - weight_of(dj, dw, kd, pj[s])) > mesh->decoded_max_error + 1e-6;
    }
    printf("%s as compressed: %zu influences, %u + %u bits, %zu prepared influences decode to 0, %zu wrong\n", path,
           kd, mesh->decoded_weight_bits, mesh->decoded_tuple_bits, mesh->lost_influences, bad);
    meshlet_input in = {mesh->indices, mesh->index_count, mesh->positions, mesh->vertex_count, mesh->decoded_joints,
                        mesh->decoded_weights, kd};
    int failures = bad != 0;
    for (uint32_t triangles = 124; triangles <= 126; triangles += 2)
        for (uint32_t cap = 16; cap <= 32; cap += 16)
            failures += check_split(path, "as compressed ", &in, meshlet_options(SP_MESHLETS_SKIN, 64, triangles, cap), 0,
                                    NULL);
    return failures;
}

/* palette_effort on the skin builder at the benchmark's limits: the full check, the bound and
 * determinism (check_split), and never more meshlets or palette entries than without it. The
 * subdivided copies get a token effort: the walk gains nothing there and its time grows with
 * the triangles (docs/meshlets.md). */
static int check_palette_effort(const char* path, const meshlet_input* in)
{
    int failures = 0;
    for (uint32_t cap = 16; cap <= 32; cap += 16) {
        sp_meshlet_options o = meshlet_options(SP_MESHLETS_SKIN, 64, 124, cap);
        meshlet_run base;
        meshlet_run_build(&base, in, &o);
        o.palette_effort = in->index_count / 3 < 20000 ? 300 : 2;
        sp_meshlet_stats walked;
        failures += check_split(path, "effort ", in, o, 1, &walked);
        int kept = walked.meshlet_count <= base.stats.meshlet_count && walked.joint_count <= base.stats.joint_count;
        printf("%s effort %u, cap %u: %zu meshlets / %zu palette entries (effort 0: %zu / %zu)%s\n", path,
               o.palette_effort, cap, walked.meshlet_count, walked.joint_count, base.stats.meshlet_count,
               base.stats.joint_count, kept ? "" : " MORE THAN WITHOUT");
        failures += !kept;
        meshlet_run_free(&base);
    }
    return failures;
}

static int check_file(const char* path)
{
    mesh_data mesh;
    if (!mesh_data_load(path, 4, &mesh))
        return 1;
    printf("%s: %zu vertices, %zu triangles, %zu joints, %zu vertices without weights bound to joint 0\n", path,
           mesh.vertex_count, mesh.index_count / 3, mesh.joint_count, mesh.unweighted_vertices);
    meshlet_input in = {mesh.indices, mesh.index_count, mesh.positions, mesh.vertex_count, mesh.joints, mesh.weights,
                        mesh.influences};
    /* the benchmark's limits (64 vertices, 124 or 126 triangles, palette cap 32 or 16) and others */
    const uint32_t limits[][3] = {{64, 124, 32}, {64, 124, 16}, {64, 126, 32}, {64, 126, 16},
                                  {32, 64, 12},  {128, 256, 48}, {255, 512, 255}};
    int failures = 0;
    for (uint32_t b = 0; b < SP_MESHLETS_BUILDER_COUNT; ++b)
        for (size_t l = 0; l < sizeof(limits) / sizeof(limits[0]); ++l)
            failures += check_split(path, "", &in, meshlet_options(b, limits[l][0], limits[l][1], limits[l][2]), l == 0,
                                    NULL);
    failures += check_palette_effort(path, &in);
    failures += check_as_compressed(path, &mesh);

    /* the widest triangle: build one meshlet per triangle and take the largest palette */
    sp_meshlet_options single = meshlet_options(SP_MESHLETS_NAIVE, 64, 1, SP_MESHLET_MAX_JOINTS);
    meshlet_run run;
    meshlet_run_build(&run, &in, &single);
    uint32_t widest = run.stats.max_joints;
    meshlet_run_free(&run);
    if (widest > 1) {
        single.max_joints = widest - 1;
        single.builder = SP_MESHLETS_SKIN;
        meshlet_run_build(&run, &in, &single);
        int named = run.result == SP_ERR_LIMIT_EXCEEDED && run.stats.error_triangle < in.index_count / 3;
        printf("%s palette limit %u below the widest triangle (%u joints): %s, triangle %zu\n", path, widest - 1, widest,
               sp_result_string(run.result), run.stats.error_triangle);
        failures += !named;
        meshlet_run_free(&run);
    }
    mesh_data_free(&mesh);
    return failures;
}

int main(int argc, char** argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_meshlets_assets FILE.spmd...\n");
        return 2;
    }
    int failures = 0;
    for (int i = 1; i < argc; ++i)
        failures += check_file(argv[i]);
    return failures ? 1 : 0;
}
