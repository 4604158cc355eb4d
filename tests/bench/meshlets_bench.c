/*
 * meshlets_bench.c - our meshlet builders vs meshoptimizer 1.3 (npm, from node) and 0.18
 * (Debian libmeshoptimizer), all in one run.
 *
 *   meshlets_bench [--reps N] [--node NODE --mo13 meshlets_mo13.mjs] OUT.md NAME=FILE.spmd...
 *
 * For each mesh and each limit pair (64 vertices with 124 and 126 triangles): meshoptimizer
 * 1.3's MeshoptClusterizer.buildMeshlets (cone weight 0; run by meshlets_mo13.mjs, which hands
 * back its meshlets), meshopt_buildMeshlets 0.18 (cone weight 0), the thesis's two builders at
 * palette cap 32 and our skin builder at palette caps 16 and 32. Every split gets the same
 * analysis (palette = joints with non-zero weight on the meshlet's vertices, local tuple LUT by
 * the library's rule; the bench re-derives ours from our vertex lists and stops if they
 * disagree with the library), and every split is checked against the joint lower bound
 * (joint_bound.h): the bench stops if any split beats it. meshoptimizer has no palette cap, so
 * its meshlets over 16 and over 32 joints are counted. Times are the fastest of N runs (default
 * 5; 5 N on meshes under 20k triangles), process CPU time (node: process.cpuUsage); nothing
 * here is asserted.
 */
#define _POSIX_C_SOURCE 200809L /* clock_gettime, popen */

#include "joint_bound.h"
#include "mesh_data.h"
#include "meshlet_check.h"

#include <meshoptimizer.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { MAX_VERTICES = 64, ROWS = 6, SMALL_MESH_TRIANGLES = 20000, SMALL_MESH_REPS = 5 };
static const uint32_t triangle_limits[] = {124, 126};

typedef struct row {
    char builder[96];
    size_t meshlets, palette_entries;
    uint32_t max_joints;
    size_t over16, over32; /* meshlets whose palette has more than 16 / 32 joints */
    double local_bits;     /* mean over meshlet vertex entries of the meshlet's local tuple bits */
    size_t joint_floor;    /* sum over meshlets of the most joints any one of its vertices has */
    double ms;             /* fastest build, process CPU time */
} row;

typedef struct span {
    uint32_t offset, count; /* into a vertex list */
} span;

/* CPU time of the process (single-threaded here), as the node runner measures meshoptimizer 1.3:
 * on a shared machine a build's wall time depends on how often it is preempted. */
static double cpu_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

/* Palette size and local tuple bits of one vertex list, by the rules of sp_build_meshlets. */
static void analyse_vertices(const mesh_data* mesh, const uint32_t* vertices, size_t count, uint32_t* joints,
                             uint32_t* tuple_bits, uint32_t* floor)
{
    *floor = 0;
    static uint16_t slot[65536]; /* palette index + 1; 0 = absent */
    uint16_t palette[1024];
    uint32_t tuples[256];
    uint32_t palette_size = 0, tuple_count = 0;
    size_t k = mesh->influences;
    for (size_t i = 0; i < count; ++i) {
        uint32_t v = vertices[i], tuple = 0;
        for (size_t s = 0; s < k; ++s) {
            if (!(mesh->weights[v * k + s] > 0.0f))
                continue;
            uint16_t j = mesh->joints[v * k + s];
            *floor = (uint32_t)s + 1 > *floor ? (uint32_t)s + 1 : *floor; /* prepared: distinct, weight-sorted */
            if (!slot[j]) {
                palette[palette_size] = j;
                slot[j] = (uint16_t)++palette_size;
            }
            tuple |= (uint32_t)(uint8_t)(slot[j] - 1) << (8 * s); /* palettes stay below 256 at 64 vertices */
        }
        uint32_t found = 0;
        while (found < tuple_count && tuples[found] != tuple)
            ++found;
        if (found == tuple_count)
            tuples[tuple_count++] = tuple;
    }
    for (uint32_t p = 0; p < palette_size; ++p)
        slot[palette[p]] = 0;
    *joints = palette_size;
    *tuple_bits = sp_index_bits(tuple_count);
}

/* Fills the row's split statistics from its meshlets' vertex lists. */
static void analyse_split(row* r, const mesh_data* mesh, const uint32_t* vertices, const span* meshlets, size_t count)
{
    size_t vertex_entries = 0;
    double bits_total = 0.0;
    r->meshlets = count;
    r->palette_entries = r->over16 = r->over32 = r->joint_floor = 0;
    r->max_joints = 0;
    for (size_t m = 0; m < count; ++m) {
        uint32_t joints, bits, floor;
        analyse_vertices(mesh, vertices + meshlets[m].offset, meshlets[m].count, &joints, &bits, &floor);
        r->palette_entries += joints;
        r->joint_floor += floor;
        r->max_joints = joints > r->max_joints ? joints : r->max_joints;
        r->over16 += joints > 16;
        r->over32 += joints > 32;
        vertex_entries += meshlets[m].count;
        bits_total += (double)bits * meshlets[m].count;
    }
    r->local_bits = vertex_entries ? bits_total / vertex_entries : 0.0;
}

static void die(const char* what, const char* detail)
{
    fprintf(stderr, "Error: meshlets_bench: %s: %s\n", what, detail);
    exit(1);
}

static row bench_meshopt_018(const mesh_data* mesh, uint32_t max_triangles, int reps)
{
    size_t bound = meshopt_buildMeshletsBound(mesh->index_count, MAX_VERTICES, max_triangles);
    struct meshopt_Meshlet* meshlets = malloc(bound * sizeof(*meshlets));
    unsigned int* vertices = malloc(bound * MAX_VERTICES * sizeof(unsigned int));
    unsigned char* triangles = malloc(bound * (max_triangles * 3 + 3)); /* 0.18 pads each meshlet to 4 bytes */
    span* spans = malloc(bound * sizeof(span));
    if (!meshlets || !vertices || !triangles || !spans)
        die("meshopt 0.18", "out of memory");
    row r = {"meshopt_buildMeshlets 0.18 (Debian)", 0, 0, 0, 0, 0, 0, 0, 1e30};
    size_t count = 0;
    for (int i = 0; i < reps; ++i) {
        double start = cpu_ms();
        count = meshopt_buildMeshlets(meshlets, vertices, triangles, mesh->indices, mesh->index_count, mesh->positions,
                                      mesh->vertex_count, 3 * sizeof(float), MAX_VERTICES, max_triangles, 0.0f);
        double ms = cpu_ms() - start;
        r.ms = ms < r.ms ? ms : r.ms;
    }
    for (size_t m = 0; m < count; ++m) {
        spans[m].offset = meshlets[m].vertex_offset;
        spans[m].count = meshlets[m].vertex_count;
    }
    analyse_split(&r, mesh, vertices, spans, count);
    free(meshlets);
    free(vertices);
    free(triangles);
    free(spans);
    return r;
}

/* meshoptimizer 1.3 in node: the script writes the meshlets to a file and prints its version
 * and time as one JSON line. */
static row bench_meshopt_13(const mesh_data* mesh, const char* node, const char* script, const char* path,
                            const char* scratch_file, uint32_t max_triangles, int reps)
{
    char command[16384], line[512], version[32] = "?";
    snprintf(command, sizeof(command), "'%s' '%s' '%s' %d %u %d '%s'", node, script, path, MAX_VERTICES, max_triangles,
             reps, scratch_file);
    FILE* p = popen(command, "r");
    if (!p || !fgets(line, sizeof(line), p))
        die("meshoptimizer 1.3 (node)", command);
    int status = pclose(p);
    row r = {"", 0, 0, 0, 0, 0, 0, 0, 0};
    const char* v = strstr(line, "\"version\":\"");
    const char* ms = strstr(line, "\"ms\":");
    if (status != 0 || !v || !ms || sscanf(v + 11, "%31[^\"]", version) != 1 || sscanf(ms + 5, "%lf", &r.ms) != 1)
        die("meshoptimizer 1.3 (node) printed no result", line);
    snprintf(r.builder, sizeof(r.builder), "meshoptimizer %s buildMeshlets (npm)", version);

    FILE* f = fopen(scratch_file, "rb");
    uint32_t count = 0, vertex_entries = 0;
    if (!f || fread(&count, 4, 1, f) != 1)
        die("cannot read", scratch_file);
    uint32_t* table = malloc((size_t)count * 16 + 4);
    span* spans = malloc((size_t)count * sizeof(span) + 1);
    if (!table || !spans || fread(table, 16, count, f) != count || fread(&vertex_entries, 4, 1, f) != 1)
        die("truncated", scratch_file);
    uint32_t* vertices = malloc((size_t)vertex_entries * 4 + 4);
    if (!vertices || fread(vertices, 4, vertex_entries, f) != vertex_entries)
        die("truncated", scratch_file);
    fclose(f);
    for (uint32_t m = 0; m < count; ++m) {
        spans[m].offset = table[m * 4];
        spans[m].count = table[m * 4 + 2];
        if ((size_t)spans[m].offset + spans[m].count > vertex_entries)
            die("meshlet out of range", scratch_file);
        for (uint32_t i = 0; i < spans[m].count; ++i)
            if (vertices[spans[m].offset + i] >= mesh->vertex_count)
                die("vertex out of range", scratch_file);
    }
    analyse_split(&r, mesh, vertices, spans, count);
    free(table);
    free(spans);
    free(vertices);
    return r;
}

static row bench_ours(const mesh_data* mesh, const char* name, uint32_t builder, uint32_t max_triangles,
                      uint32_t palette, int reps)
{
    meshlet_input in = {mesh->indices, mesh->index_count, mesh->positions, mesh->vertex_count, mesh->joints,
                        mesh->weights, mesh->influences};
    sp_meshlet_options o = meshlet_options(builder, MAX_VERTICES, max_triangles, palette);
    meshlet_run run;
    row r = {"", 0, 0, 0, 0, 0, 0, 0, 1e30};
    snprintf(r.builder, sizeof(r.builder), "%s, palette cap %u", name, palette);
    meshlet_run_build(&run, &in, &o); /* allocates; the timed calls reuse the buffers */
    for (int i = 0; i < reps; ++i) {
        double start = cpu_ms();
        sp_result result = sp_build_meshlets(in.indices, in.index_count, in.positions, in.vertex_count,
                                             3 * sizeof(float), in.joints, in.weights, in.influences, &o, &run.out,
                                             run.scratch, run.scratch_size, &run.stats);
        double ms = cpu_ms() - start;
        if (result != SP_OK)
            die(name, sp_result_string(result));
        r.ms = ms < r.ms ? ms : r.ms;
    }
    const sp_meshlet_stats* s = &run.stats;
    span* spans = malloc(s->meshlet_count * sizeof(span) + 1);
    if (!spans)
        die(name, "out of memory");
    for (size_t m = 0; m < s->meshlet_count; ++m) {
        spans[m].offset = run.out.meshlets[m].vertex_offset;
        spans[m].count = run.out.meshlets[m].vertex_count;
    }
    analyse_split(&r, mesh, run.out.vertices, spans, s->meshlet_count);
    if (r.palette_entries != s->joint_count || r.max_joints != s->max_joints ||
        r.local_bits < s->local_tuple_bits_mean - 1e-9 || r.local_bits > s->local_tuple_bits_mean + 1e-9)
        die(name, "the library's statistics disagree with the bench's analysis of its meshlets");
    if (r.max_joints > palette)
        die(name, "a meshlet exceeds the palette cap");
    free(spans);
    meshlet_run_free(&run);
    return r;
}

static void print_row(FILE* f, const row* r, const row* reference)
{
    fprintf(f, "| %s | %zu | %.3f | %zu | %.3f | %zu | %u | %zu | %zu | %.2f | %.1f | %.2f |\n", r->builder,
            r->meshlets, (double)r->meshlets / reference->meshlets, r->palette_entries,
            (double)r->palette_entries / reference->palette_entries, r->joint_floor, r->max_joints, r->over16,
            r->over32, r->local_bits, r->ms, r->ms / reference->ms);
}

typedef struct bench_args {
    int reps;
    const char* node;
    const char* mo13;
    const char* out;
    int first_mesh;
} bench_args;

static bench_args parse_args(int argc, char** argv)
{
    bench_args args = {5, "node", NULL, NULL, 0};
    int a = 1;
    for (; a + 1 < argc && argv[a][0] == '-'; a += 2) {
        if (strcmp(argv[a], "--reps") == 0)
            args.reps = atoi(argv[a + 1]);
        else if (strcmp(argv[a], "--node") == 0)
            args.node = argv[a + 1];
        else if (strcmp(argv[a], "--mo13") == 0)
            args.mo13 = argv[a + 1];
        else
            die("unknown option", argv[a]);
    }
    if (a + 1 >= argc || args.reps < 1 || !args.mo13) {
        fprintf(stderr, "usage: meshlets_bench [--reps N] [--node NODE] --mo13 meshlets_mo13.mjs OUT.md "
                        "NAME=FILE.spmd...\n");
        exit(2);
    }
    args.out = argv[a];
    args.first_mesh = a + 1;
    return args;
}

/* Sum over triangles of the distinct used joints of its three vertices. A meshlet's palette holds
 * every one of its triangles' joints, so it is at least the mean of that count over its
 * triangles; at F triangles per meshlet the sum over meshlets is then at least this sum / F if
 * every meshlet had the same mean. Divided by meshoptimizer 1.3's mean triangles per meshlet it
 * estimates (it is no bound: fuller or unevenly mixed meshlets could go below it) the fewest
 * palette entries a split with mo 1.3's count could reach even if each meshlet's triangles all
 * used the same joints. */
static size_t triangle_joint_sum(const mesh_data* mesh)
{
    size_t sum = 0, k = mesh->influences;
    for (size_t t = 0; t < mesh->index_count / 3; ++t) {
        uint16_t seen[12];
        size_t count = 0;
        for (int c = 0; c < 3; ++c) {
            uint32_t v = mesh->indices[t * 3 + c];
            for (size_t s = 0; s < k; ++s) {
                uint16_t j = mesh->joints[v * k + s];
                size_t i = 0;
                while (i < count && seen[i] != j)
                    ++i;
                if (mesh->weights[v * k + s] > 0.0f && i == count)
                    seen[count++] = j;
            }
        }
        sum += count;
    }
    return sum;
}

/* One mesh at one limit pair: the detail table into details, one summary line into summary. */
static void bench_mesh(const bench_args* args, const char* name, const char* path, const mesh_data* mesh,
                       uint32_t max_triangles, FILE* summary, FILE* details)
{
    char scratch_file[4096];
    snprintf(scratch_file, sizeof(scratch_file), "%s.mo13.bin", args->out);
    row rows[ROWS];
    int n = 0;
    /* a build of a small mesh takes milliseconds: more runs, so that one undisturbed run is likely */
    int reps = mesh->index_count / 3 < SMALL_MESH_TRIANGLES ? args->reps * SMALL_MESH_REPS : args->reps;
    rows[n++] = bench_meshopt_13(mesh, args->node, args->mo13, path, scratch_file, max_triangles, reps);
    remove(scratch_file);
    if (max_triangles % 4 == 0) /* 0.18 asserts a multiple of 4 */
        rows[n++] = bench_meshopt_018(mesh, max_triangles, reps);
    rows[n++] = bench_ours(mesh, "thesis naive", SP_MESHLETS_NAIVE, max_triangles, 32, reps);
    rows[n++] = bench_ours(mesh, "thesis common influences", SP_MESHLETS_COMMON, max_triangles, 32, reps);
    const row* cap16 = &rows[n];
    rows[n++] = bench_ours(mesh, "skinpack skin (ours)", SP_MESHLETS_SKIN, max_triangles, 16, reps);
    const row* cap32 = &rows[n];
    rows[n++] = bench_ours(mesh, "skinpack skin (ours)", SP_MESHLETS_SKIN, max_triangles, 32, reps);

    meshlet_input in = {mesh->indices, mesh->index_count, mesh->positions, mesh->vertex_count,
                        mesh->joints, mesh->weights, mesh->influences};
    joint_bound bound;
    if (!joint_bound_compute(&in, MAX_VERTICES, max_triangles, &bound))
        die(name, "joint bound: out of memory");
    for (int r = 0; r < n; ++r)
        if (rows[r].palette_entries < bound.palette_sum) {
            fprintf(stderr, "Error: meshlets_bench: %s: %s has %zu palette entries, below the lower bound %zu\n", name,
                    rows[r].builder, rows[r].palette_entries, bound.palette_sum);
            exit(1);
        }
    const row* mo = &rows[0];
    double fill_estimate = (double)triangle_joint_sum(mesh) * (double)mo->meshlets / (double)(mesh->index_count / 3);
    fprintf(summary, "| %s | %u | %zu (%zu, %zu) | %zu (%.4f) | %zu (%.4f) | %zu | %zu (%.3f) | %zu (%.3f) | %zu (%.3f) "
                     "| %.0f (%.3f) | %.2f | %.2f |\n",
            name, max_triangles, mo->meshlets, mo->over16, mo->over32, cap32->meshlets,
            (double)cap32->meshlets / mo->meshlets, cap16->meshlets, (double)cap16->meshlets / mo->meshlets,
            mo->palette_entries, cap32->palette_entries, (double)cap32->palette_entries / mo->palette_entries,
            cap16->palette_entries, (double)cap16->palette_entries / mo->palette_entries, bound.palette_sum,
            (double)bound.palette_sum / mo->palette_entries, fill_estimate, fill_estimate / mo->palette_entries,
            cap32->ms / mo->ms, cap16->ms / mo->ms);
    fprintf(details,
            "\n### %s, %d vertices / %u triangles (%zu triangles, %zu vertices, %zu joints)\n\n"
            "Palette entries summed over meshlets, any split within these limits: at least %zu (by joint %zu + "
            "forced splits %zu; by influence count %zu).\n\n"
            "| builder | meshlets | ÷ mo 1.3 | palette entries | ÷ mo 1.3 | joint floor | max joints | meshlets over 16 "
            "| over 32 | local tuple bits/vertex | ms | time ÷ mo 1.3 |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
            name, MAX_VERTICES, max_triangles, mesh->index_count / 3, mesh->vertex_count, mesh->joint_count,
            bound.palette_sum, bound.by_joint, bound.forced_splits, bound.by_influence_count);
    for (int r = 0; r < n; ++r)
        print_row(details, &rows[r], mo);
    if (max_triangles % 4 != 0)
        fprintf(details, "\nmeshoptimizer 0.18 is not run at %u triangles: it requires a multiple of 4.\n", max_triangles);
}

int main(int argc, char** argv)
{
    bench_args args = parse_args(argc, argv);
    char* summary_text = NULL;
    char* details_text = NULL;
    size_t summary_size = 0, details_size = 0;
    FILE* summary = open_memstream(&summary_text, &summary_size);
    FILE* details = open_memstream(&details_text, &details_size);
    if (!summary || !details)
        die("open_memstream", "out of memory");
    for (int i = args.first_mesh; i < argc; ++i) {
        char name[128];
        const char* eq = strchr(argv[i], '=');
        const char* path = eq ? eq + 1 : argv[i];
        snprintf(name, sizeof(name), "%.*s", eq ? (int)(eq - argv[i]) : (int)strlen(argv[i]), argv[i]);
        mesh_data mesh;
        if (!mesh_data_load(path, 4, &mesh))
            return 1;
        for (size_t l = 0; l < sizeof(triangle_limits) / sizeof(triangle_limits[0]); ++l)
            bench_mesh(&args, name, path, &mesh, triangle_limits[l], summary, details);
        printf("%s: done\n", name);
        mesh_data_free(&mesh);
    }
    fclose(summary);
    fclose(details);
    FILE* f = fopen(args.out, "w");
    if (!f)
        die("cannot write", args.out);
    fprintf(f, "## Results\n\n%d vertices, K = 4 influences after sp_prepare_influences. Time: fastest of %d runs "
               "(%d on meshes under %d triangles), CPU time of the process (node: process.cpuUsage), ratio to "
               "meshoptimizer 1.3 (npm, WebAssembly in node) in the same run.\n\n"
               "| mesh | max triangles | mo 1.3 meshlets (over 16, over 32 joints) | ours cap 32 (÷ mo 1.3, <= 1.00) "
               "| ours cap 16 (÷ mo 1.3, <= 1.03) | mo 1.3 palette entries | ours cap 32 (÷, <= 0.90) "
               "| ours cap 16 (÷) | lower bound, any split (÷) | estimate at mo 1.3's fill (÷) | time cap 32 ÷ mo 1.3 (<= 2) "
               "| time cap 16 ÷ mo 1.3 |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|---|\n%s%s",
            MAX_VERTICES, args.reps, args.reps * SMALL_MESH_REPS, SMALL_MESH_TRIANGLES, summary_text, details_text);
    fclose(f);
    free(summary_text);
    free(details_text);
    return 0;
}
