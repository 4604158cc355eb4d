/*
 * meshlets_bench.c - meshlet builders vs meshoptimizer, all in one run.
 *
 *   meshlets_bench [--reps N] [--palette P] OUT.md NAME=FILE.spmd...
 *
 * For each mesh: meshopt_buildMeshlets (64/124, cone_weight 0) and meshopt_buildMeshletsScan
 * (Debian libmeshoptimizer 0.18) and our three builders at the same limits with palette limit P
 * (default 32). meshoptimizer's meshlets get the same per-meshlet analysis as ours (distinct
 * joints, local tuple LUT bits) so the columns compare like for like. Times are the minimum of
 * N runs (default 5) and are reported as ratios to meshopt_buildMeshlets of the same run;
 * nothing here is asserted.
 */
#define _POSIX_C_SOURCE 200809L /* clock_gettime, fmemopen */

#include "joint_bound.h"
#include "mesh_data.h"
#include "meshlet_check.h"

#include <meshoptimizer.h>
#include <stdio.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>
#include <time.h>

enum { MAX_VERTICES = 64, MAX_TRIANGLES = 124 };

typedef struct row {
    const char* builder;
    size_t meshlets;
    double mean_vertices, mean_triangles, mean_joints;
    uint32_t max_joints;
    double local_bits, global_bits;
    double ms;
    double joint_floor; /* mean over meshlets of the most influences any one of its vertices has */
} row;

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t); /* CPU time: the machine is shared */
    return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

/* Palette and local tuple LUT of one vertex list, by the rules of sp_build_meshlets. */
static void analyse_vertices(const mesh_data* mesh, const uint32_t* vertices, size_t count, uint32_t* joints,
                             uint32_t* tuple_bits, uint32_t* floor)
{
    *floor = 0;
    static uint16_t slot[65536]; /* palette index + 1; 0 = absent */
    uint16_t palette[1024];
    uint8_t tuples[256][4];
    uint32_t palette_size = 0, tuple_count = 0;
    size_t k = mesh->influences < 4 ? mesh->influences : 4;
    for (size_t i = 0; i < count; ++i) {
        uint32_t v = vertices[i];
        uint8_t tuple[4] = {0, 0, 0, 0};
        for (size_t s = 0; s < k; ++s) {
            if (!(mesh->weights[v * mesh->influences + s] > 0.0f))
                continue;
            *floor = (uint32_t)s + 1 > *floor ? (uint32_t)s + 1 : *floor;
            uint16_t j = mesh->joints[v * mesh->influences + s];
            if (!slot[j]) {
                palette[palette_size] = j;
                slot[j] = (uint16_t)++palette_size;
            }
            tuple[s] = (uint8_t)(slot[j] - 1); /* meshopt meshlets stay below 256 joints at 64 vertices */
        }
        uint32_t found = 0;
        while (found < tuple_count && memcmp(tuples[found], tuple, 4) != 0)
            ++found;
        if (found == tuple_count)
            memcpy(tuples[tuple_count++], tuple, 4);
    }
    for (uint32_t p = 0; p < palette_size; ++p)
        slot[palette[p]] = 0;
    *joints = palette_size;
    uint32_t bits = 0;
    while ((1u << bits) < tuple_count)
        ++bits;
    *tuple_bits = bits;
}

typedef size_t (*meshopt_builder)(const mesh_data*, struct meshopt_Meshlet*, unsigned int*, unsigned char*);

static size_t run_meshopt_build(const mesh_data* m, struct meshopt_Meshlet* out, unsigned int* v, unsigned char* t)
{
    return meshopt_buildMeshlets(out, v, t, m->indices, m->index_count, m->positions, m->vertex_count,
                                 3 * sizeof(float), MAX_VERTICES, MAX_TRIANGLES, 0.0f);
}

static size_t run_meshopt_scan(const mesh_data* m, struct meshopt_Meshlet* out, unsigned int* v, unsigned char* t)
{
    return meshopt_buildMeshletsScan(out, v, t, m->indices, m->index_count, m->vertex_count, MAX_VERTICES,
                                     MAX_TRIANGLES);
}

static row bench_meshopt(const mesh_data* mesh, const char* name, meshopt_builder build, int with_bounds, int reps,
                         uint32_t global_bits)
{
    size_t bound = meshopt_buildMeshletsBound(mesh->index_count, MAX_VERTICES, MAX_TRIANGLES);
    struct meshopt_Meshlet* meshlets = malloc(bound * sizeof(*meshlets));
    unsigned int* vertices = malloc(bound * MAX_VERTICES * sizeof(unsigned int));
    unsigned char* triangles = malloc(bound * MAX_TRIANGLES * 3);
    row r = {name, 0, 0, 0, 0, 0, 0, global_bits, 1e30, 0};
    for (int i = 0; i < reps; ++i) {
        double start = now_ms();
        r.meshlets = build(mesh, meshlets, vertices, triangles);
        if (with_bounds)
            for (size_t m = 0; m < r.meshlets; ++m) {
                struct meshopt_Bounds b = meshopt_computeMeshletBounds(
                    vertices + meshlets[m].vertex_offset, triangles + meshlets[m].triangle_offset,
                    meshlets[m].triangle_count, mesh->positions, mesh->vertex_count, 3 * sizeof(float));
                (void)b;
            }
        double ms = now_ms() - start;
        r.ms = ms < r.ms ? ms : r.ms;
    }
    size_t vertex_entries = 0, triangle_total = 0, joint_total = 0, floor_total = 0;
    double bits_total = 0;
    for (size_t m = 0; m < r.meshlets; ++m) {
        uint32_t joints, bits, floor;
        analyse_vertices(mesh, vertices + meshlets[m].vertex_offset, meshlets[m].vertex_count, &joints, &bits, &floor);
        floor_total += floor;
        vertex_entries += meshlets[m].vertex_count;
        triangle_total += meshlets[m].triangle_count;
        joint_total += joints;
        r.max_joints = joints > r.max_joints ? joints : r.max_joints;
        bits_total += (double)bits * meshlets[m].vertex_count;
    }
    r.mean_vertices = (double)vertex_entries / r.meshlets;
    r.mean_triangles = (double)triangle_total / r.meshlets;
    r.mean_joints = (double)joint_total / r.meshlets;
    r.local_bits = bits_total / vertex_entries;
    r.joint_floor = (double)floor_total / r.meshlets;
    free(meshlets);
    free(vertices);
    free(triangles);
    return r;
}

static row bench_ours(const mesh_data* mesh, const char* name, uint32_t builder, uint32_t palette, int reps,
                      sp_meshlet_stats* stats_out)
{
    meshlet_input in = {mesh->indices, mesh->index_count, mesh->positions, mesh->vertex_count, mesh->joints,
                        mesh->weights, mesh->influences};
    sp_meshlet_options o = meshlet_options(builder, MAX_VERTICES, MAX_TRIANGLES, palette);
    meshlet_run run;
    row r = {name, 0, 0, 0, 0, 0, 0, 0, 1e30, 0};
    meshlet_run_build(&run, &in, &o); /* allocates; the timed calls reuse the buffers */
    for (int i = 0; i < reps; ++i) {
        double start = now_ms();
        sp_result result = sp_build_meshlets(in.indices, in.index_count, in.positions, in.vertex_count,
                                             3 * sizeof(float), in.joints, in.weights, in.influences, &o, &run.out,
                                             run.scratch, run.scratch_size, &run.stats);
        double ms = now_ms() - start;
        if (result != SP_OK) {
            fprintf(stderr, "%s: %s\n", name, sp_result_string(result));
            exit(1);
        }
        r.ms = ms < r.ms ? ms : r.ms;
    }
    const sp_meshlet_stats* s = &run.stats;
    r.meshlets = s->meshlet_count;
    r.mean_vertices = s->mean_vertices;
    r.mean_triangles = s->mean_triangles;
    r.mean_joints = s->mean_joints;
    r.max_joints = s->max_joints;
    r.local_bits = s->local_tuple_bits_mean;
    r.global_bits = s->global_tuple_bits;
    *stats_out = *s;
    size_t floor_total = 0;
    for (size_t m = 0; m < s->meshlet_count; ++m) {
        const sp_meshlet* meshlet = &run.out.meshlets[m];
        uint32_t joints, bits, floor;
        analyse_vertices(mesh, run.out.vertices + meshlet->vertex_offset, meshlet->vertex_count, &joints, &bits, &floor);
        floor_total += floor;
        if (joints != meshlet->joint_count || bits != meshlet->tuple_bits) {
            fprintf(stderr, "%s: meshlet %zu disagrees with the bench's analysis: %u/%u joints, %u/%u bits\n", name, m, joints, meshlet->joint_count, bits, meshlet->tuple_bits);
            exit(1);
        }
    }
    r.joint_floor = (double)floor_total / s->meshlet_count;
    meshlet_run_free(&run);
    return r;
}

/* The joint lower bound (joint_bound.h) and a check that no builder's split goes below it: a
 * bound that some real split beats would be wrong, and the bench stops rather than print it. */
static joint_bound bound_of(const mesh_data* mesh, const char* name, const row* rows, int row_count)
{
    meshlet_input in = {mesh->indices, mesh->index_count, mesh->positions, mesh->vertex_count,
                        mesh->joints, mesh->weights, mesh->influences};
    joint_bound bound;
    if (!joint_bound_compute(&in, MAX_VERTICES, MAX_TRIANGLES, &bound))
        exit(1);
    for (int r = 0; r < row_count; ++r) {
        double palette_sum = rows[r].mean_joints * (double)rows[r].meshlets;
        if (palette_sum + 0.5 < (double)bound.palette_sum) {
            fprintf(stderr, "%s: %s has %.0f palette entries, below the lower bound %zu\n", name, rows[r].builder,
                    palette_sum, bound.palette_sum);
            exit(1);
        }
    }
    return bound;
}

static void print_row(FILE* f, const row* r, const row* reference)
{
    fprintf(f, "| %s | %zu | %.2f | %.1f | %.1f | %.2f | %.2f | %u | %.2f | %.0f | %.2f | %.2f |\n", r->builder,
            r->meshlets, (double)r->meshlets / reference->meshlets, r->mean_vertices, r->mean_triangles,
            r->mean_joints, r->joint_floor, r->max_joints, r->local_bits, r->global_bits, r->ms, r->ms / reference->ms);
}

int main(int argc, char** argv)
{
    int reps = 5;
    uint32_t palette = 32;
    int a = 1;
    for (; a + 1 < argc && argv[a][0] == '-'; a += 2) {
        if (strcmp(argv[a], "--reps") == 0)
            reps = atoi(argv[a + 1]);
        else if (strcmp(argv[a], "--palette") == 0)
            palette = (uint32_t)atoi(argv[a + 1]);
    }
    if (a + 1 >= argc || reps < 1) {
        fprintf(stderr, "usage: meshlets_bench [--reps N] [--palette P] OUT.md NAME=FILE.spmd...\n");
        return 2;
    }
    FILE* f = fopen(argv[a], "w");
    if (!f) {
        perror(argv[a]);
        return 1;
    }
    fprintf(f, "## Results\n\nLimits %d vertices / %d triangles, palette limit %u (ours), K = 4 influences after "
               "sp_prepare_influences. Time: minimum of %d runs; ratio to meshopt_buildMeshlets in the same run.\n\n",
            MAX_VERTICES, MAX_TRIANGLES, palette, reps);
    fprintf(f, "| mesh | triangles | vertices | joints | count ours/meshopt (<= 1.10) | joints ours/meshopt (<= 0.5) "
               "| joints: lower bound at 1.10x count / meshopt | local/global tuple bits (<= 0.70) "
               "| time ours/(meshopt+bounds) (<= 2) | time ours/meshopt |\n"
               "|---|---|---|---|---|---|---|---|---|---|\n");
    char details[1 << 16];
    size_t used = 0;
    for (int i = a + 1; i < argc; ++i) {
        char name[128];
        const char* eq = strchr(argv[i], '=');
        const char* path = eq ? eq + 1 : argv[i];
        snprintf(name, sizeof(name), "%.*s", eq ? (int)(eq - argv[i]) : (int)strlen(argv[i]), argv[i]);
        mesh_data mesh;
        if (!mesh_data_load(path, 4, &mesh))
            return 1;
        int n = reps;
        sp_meshlet_stats stats;
        row rows[6];
        rows[5] = bench_ours(&mesh, "skinpack skin (ours)", SP_MESHLETS_SKIN, palette, n, &stats);
        rows[0] = bench_meshopt(&mesh, "meshopt_buildMeshlets", run_meshopt_build, 0, n, stats.global_tuple_bits);
        rows[1] = bench_meshopt(&mesh, "meshopt_buildMeshlets + bounds", run_meshopt_build, 1, n, stats.global_tuple_bits);
        rows[2] = bench_meshopt(&mesh, "meshopt_buildMeshletsScan", run_meshopt_scan, 0, n, stats.global_tuple_bits);
        rows[3] = bench_ours(&mesh, "thesis naive", SP_MESHLETS_NAIVE, palette, n, &stats);
        rows[4] = bench_ours(&mesh, "thesis common influences", SP_MESHLETS_COMMON, palette, n, &stats);
        const row *mo = &rows[0], *mob = &rows[1], *ours = &rows[5];
        joint_bound bound = bound_of(&mesh, name, rows, 6);
        double most_meshlets = floor(1.10 * (double)mo->meshlets); /* a count is whole */
        double mean_bound = (double)bound.palette_sum / most_meshlets;
        mean_bound = mean_bound < 1.0 ? 1.0 : mean_bound; /* every vertex has an influence */
        fprintf(f, "| %s | %zu | %zu | %zu | %.3f | %.3f | %.3f | %.3f | %.2f | %.2f |\n", name,
                mesh.index_count / 3, mesh.vertex_count, mesh.joint_count, (double)ours->meshlets / mo->meshlets,
                ours->mean_joints / mo->mean_joints,
                mean_bound / mo->mean_joints,
                ours->local_bits / ours->global_bits, ours->ms / mob->ms, ours->ms / mo->ms);
        used += (size_t)snprintf(details + used, sizeof(details) - used,
                                 "\n### %s (%zu triangles, %zu vertices, %zu joints, %zu unique tuples)\n\n"
                                 "Palette entries summed over meshlets, any split: at least %zu (by joint %zu + "
                                 "forced splits %zu; by influence count %zu), so a mean of at least %.2f joints "
                                 "with at most %.0f meshlets (1.10x meshopt).\n\n"
                                 "| builder | meshlets | ÷ meshopt | mean vertices | mean triangles | mean joints | "
                                 "joint floor | max joints | local tuple bits/vertex | global tuple bits | ms | "
                                 "time ÷ meshopt |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
                                 name, mesh.index_count / 3, mesh.vertex_count, mesh.joint_count, stats.global_tuples,
                                 bound.palette_sum, bound.by_joint, bound.forced_splits, bound.by_influence_count,
                                 mean_bound, most_meshlets);
        for (int r = 0; r < 6; ++r) {
            char line[512];
            FILE* mem = fmemopen(line, sizeof(line), "w");
            print_row(mem, &rows[r], mo);
            fclose(mem);
            used += (size_t)snprintf(details + used, sizeof(details) - used, "%s", line);
        }
        printf("%s: done\n", name);
        mesh_data_free(&mesh);
    }
    fprintf(f, "%s", details);
    fclose(f);
    return 0;
}
