/*
 * meshlets_bench.c - our meshlet builders vs meshoptimizer 1.3 (npm, from node) and 0.18
 * (Debian libmeshoptimizer), all in one run.
 *
 *   meshlets_bench [--reps N] [--node NODE --mo13 meshlets_mo13.mjs] OUT.md NAME=FILE.spmd...
 *
 * For each mesh and each limit pair (64 vertices with 124 and 126 triangles): meshoptimizer
 * 1.3's MeshoptClusterizer.buildMeshlets (cone weight 0; run by meshlets_mo13.mjs, which hands
 * back its meshlets), meshopt_buildMeshlets 0.18 (cone weight 0), the thesis's two builders at
 * palette cap 32 and our skin builder at palette caps 16 and 32 (and at cap 32 with palette_effort,
 * SMALL_MESH_EFFORT / LARGE_MESH_EFFORT), each with two weight sets: the
 * prepared weights and the weights as compressed (mesh_data_decode_compressed: what
 * `skinpack compress --meshlets` builds from). meshoptimizer ignores weights: its splits are
 * built once and analysed with both. Every split gets the same analysis (palette = joints with
 * non-zero weight on the meshlet's vertices, local tuple LUT by the library's rule; the bench
 * re-derives ours from our vertex lists and stops if they disagree with the library), and every
 * split is checked against the joint lower bound (joint_bound.h) of its weight set: the bench
 * stops if any split beats it. meshoptimizer has no palette cap, so
 * its meshlets over 16 and over 32 joints are counted. Times are the fastest of N runs (default
 * 5; 20 N on meshes under 20k triangles: a few-millisecond build is often disturbed on a shared machine), process CPU time (node: process.cpuUsage); nothing
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

enum { MAX_VERTICES = 64, ROWS = 7, SMALL_MESH_TRIANGLES = 20000, SMALL_MESH_REPS = 20 };
/* The palette_effort row (cap 32): on the small meshes 300, where the walk gains; on the
 * subdivided ones 10, to show its time where it gains nothing (docs/meshlets.md). Its builds
 * take 0.1-1 s, so a few runs time them. */
enum { SMALL_MESH_EFFORT = 300, LARGE_MESH_EFFORT = 10, EFFORT_REPS = 3 };
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
static void analyse_vertices(const meshlet_input* in, const uint32_t* vertices, size_t count, uint32_t* joints,
                             uint32_t* tuple_bits, uint32_t* floor)
{
    *floor = 0;
    static uint16_t slot[65536]; /* palette index + 1; 0 = absent */
    uint16_t palette[1024];
    uint32_t tuples[256];
    uint32_t palette_size = 0, tuple_count = 0;
    size_t k = in->influences;
    for (size_t i = 0; i < count; ++i) {
        uint32_t v = vertices[i], tuple = 0, used = 0;
        for (size_t s = 0; s < k; ++s) {
            if (!(in->weights[v * k + s] > 0.0f))
                continue;
            uint16_t j = in->joints[v * k + s];
            *floor = ++used > *floor ? used : *floor; /* the used joints of a vertex are distinct */
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

/* Fills the row's split statistics from its meshlets' vertex lists, with the joints and weights of in. */
static void analyse_split(row* r, const meshlet_input* in, const uint32_t* vertices, const span* meshlets, size_t count)
{
    size_t vertex_entries = 0;
    double bits_total = 0.0;
    r->meshlets = count;
    r->palette_entries = r->over16 = r->over32 = r->joint_floor = 0;
    r->max_joints = 0;
    for (size_t m = 0; m < count; ++m) {
        uint32_t joints, bits, floor;
        analyse_vertices(in, vertices + meshlets[m].offset, meshlets[m].count, &joints, &bits, &floor);
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

/* A split by a builder that ignores the weights (meshoptimizer): its vertex lists, analysed
 * once per weight set. */
typedef struct split {
    char builder[96];
    uint32_t* vertices;
    span* meshlets;
    size_t count;
    double ms; /* fastest build, process CPU time */
} split;

static row analyse_foreign_split(const split* s, const meshlet_input* in)
{
    row r = {"", 0, 0, 0, 0, 0, 0, 0, s->ms};
    snprintf(r.builder, sizeof(r.builder), "%s", s->builder);
    analyse_split(&r, in, s->vertices, s->meshlets, s->count);
    return r;
}

static void split_free(split* s)
{
    free(s->vertices);
    free(s->meshlets);
}

static split bench_meshopt_018(const mesh_data* mesh, uint32_t max_triangles, int reps)
{
    size_t bound = meshopt_buildMeshletsBound(mesh->index_count, MAX_VERTICES, max_triangles);
    struct meshopt_Meshlet* meshlets = malloc(bound * sizeof(*meshlets));
    unsigned char* triangles = malloc(bound * (max_triangles * 3 + 3)); /* 0.18 pads each meshlet to 4 bytes */
    split s = {"meshopt_buildMeshlets 0.18 (Debian)", malloc(bound * MAX_VERTICES * sizeof(uint32_t)),
               malloc(bound * sizeof(span)), 0, 1e30};
    if (!meshlets || !s.vertices || !triangles || !s.meshlets)
        die("meshopt 0.18", "out of memory");
    for (int i = 0; i < reps; ++i) {
        double start = cpu_ms();
        s.count = meshopt_buildMeshlets(meshlets, s.vertices, triangles, mesh->indices, mesh->index_count,
                                        mesh->positions, mesh->vertex_count, 3 * sizeof(float), MAX_VERTICES,
                                        max_triangles, 0.0f);
        double ms = cpu_ms() - start;
        s.ms = ms < s.ms ? ms : s.ms;
    }
    for (size_t m = 0; m < s.count; ++m) {
        s.meshlets[m].offset = meshlets[m].vertex_offset;
        s.meshlets[m].count = meshlets[m].vertex_count;
    }
    free(meshlets);
    free(triangles);
    return s;
}

/* meshoptimizer 1.3 in node: the script writes the meshlets to a file and prints its version
 * and time as one JSON line. */
static split bench_meshopt_13(const mesh_data* mesh, const char* node, const char* script, const char* path,
                              const char* scratch_file, uint32_t max_triangles, int reps)
{
    char command[16384], line[512], version[32] = "?";
    snprintf(command, sizeof(command), "'%s' '%s' '%s' %d %u %d '%s'", node, script, path, MAX_VERTICES, max_triangles,
             reps, scratch_file);
    FILE* p = popen(command, "r");
    if (!p || !fgets(line, sizeof(line), p))
        die("meshoptimizer 1.3 (node)", command);
    int status = pclose(p);
    split s = {"", NULL, NULL, 0, 0};
    const char* v = strstr(line, "\"version\":\"");
    const char* ms = strstr(line, "\"ms\":");
    if (status != 0 || !v || !ms || sscanf(v + 11, "%31[^\"]", version) != 1 || sscanf(ms + 5, "%lf", &s.ms) != 1)
        die("meshoptimizer 1.3 (node) printed no result", line);
    snprintf(s.builder, sizeof(s.builder), "meshoptimizer %s buildMeshlets (npm)", version);

    FILE* f = fopen(scratch_file, "rb");
    uint32_t count = 0, vertex_entries = 0;
    if (!f || fread(&count, 4, 1, f) != 1)
        die("cannot read", scratch_file);
    uint32_t* table = malloc((size_t)count * 16 + 4);
    s.meshlets = malloc((size_t)count * sizeof(span) + 1);
    if (!table || !s.meshlets || fread(table, 16, count, f) != count || fread(&vertex_entries, 4, 1, f) != 1)
        die("truncated", scratch_file);
    s.vertices = malloc((size_t)vertex_entries * 4 + 4);
    if (!s.vertices || fread(s.vertices, 4, vertex_entries, f) != vertex_entries)
        die("truncated", scratch_file);
    fclose(f);
    s.count = count;
    for (uint32_t m = 0; m < count; ++m) {
        s.meshlets[m].offset = table[m * 4];
        s.meshlets[m].count = table[m * 4 + 2];
        if ((size_t)s.meshlets[m].offset + s.meshlets[m].count > vertex_entries)
            die("meshlet out of range", scratch_file);
        for (uint32_t i = 0; i < s.meshlets[m].count; ++i)
            if (s.vertices[s.meshlets[m].offset + i] >= mesh->vertex_count)
                die("vertex out of range", scratch_file);
    }
    free(table);
    return s;
}

static row bench_ours(const meshlet_input* in, const char* name, uint32_t builder, uint32_t max_triangles,
                      uint32_t palette, uint32_t effort, int reps)
{
    sp_meshlet_options o = meshlet_options(builder, MAX_VERTICES, max_triangles, palette);
    o.palette_effort = effort;
    meshlet_run run;
    row r = {"", 0, 0, 0, 0, 0, 0, 0, 1e30};
    if (effort)
        snprintf(r.builder, sizeof(r.builder), "%s, palette cap %u, palette effort %u", name, palette, effort);
    else
        snprintf(r.builder, sizeof(r.builder), "%s, palette cap %u", name, palette);
    meshlet_run_build(&run, in, &o); /* allocates; the timed calls reuse the buffers */
    for (int i = 0; i < reps; ++i) {
        double start = cpu_ms();
        sp_result result = sp_build_meshlets(in->indices, in->index_count, in->positions, in->vertex_count,
                                             3 * sizeof(float), in->joints, in->weights, in->influences, &o, &run.out,
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
    analyse_split(&r, in, run.out.vertices, spans, s->meshlet_count);
    if (r.palette_entries != s->joint_count || r.max_joints != s->max_joints ||
        r.local_bits < s->local_tuple_bits_mean - 1e-9 || r.local_bits > s->local_tuple_bits_mean + 1e-9)
        die(name, "the library's statistics disagree with the bench's analysis of its meshlets");
    if (r.max_joints > palette)
        die(name, "a meshlet exceeds the palette cap");
    free(spans);
    meshlet_run_free(&run);
    return r;
}

static void print_row(FILE* f, const char* weights, const row* r, const row* reference)
{
    fprintf(f, "| %s | %s | %zu | %.3f | %zu | %.3f | %zu | %u | %zu | %zu | %.2f | %.1f | %.2f |\n", weights, r->builder,
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
static size_t triangle_joint_sum(const meshlet_input* in)
{
    size_t sum = 0, k = in->influences;
    for (size_t t = 0; t < in->index_count / 3; ++t) {
        uint16_t seen[12];
        size_t count = 0;
        for (int c = 0; c < 3; ++c) {
            uint32_t v = in->indices[t * 3 + c];
            for (size_t s = 0; s < k; ++s) {
                uint16_t j = in->joints[v * k + s];
                size_t i = 0;
                while (i < count && seen[i] != j)
                    ++i;
                if (in->weights[v * k + s] > 0.0f && i == count)
                    seen[count++] = j;
            }
        }
        sum += count;
    }
    return sum;
}

/* The two weight sets every split is analysed with and ours are built from: the prepared weights
 * (sp_prepare_influences) and the weights a decoder of the default compress sees
 * (mesh_data_decode_compressed), which `skinpack compress --meshlets` builds its meshlets from. */
enum { WEIGHT_SETS = 2 };
static const char* weight_set_names[WEIGHT_SETS] = {"prepared", "as compressed"};

/* The splits of one mesh at one limit pair that do not depend on the weights. */
typedef struct foreign_splits {
    split mo13, mo018;
    int has_018;
} foreign_splits;

/* Every builder on one weight set: rows[0] is meshoptimizer 1.3; stops if a split beats the bound.
 * Writes the summary line (the default build's); returns the row count, *ours the default
 * build's row at cap 32. */
static int bench_weight_set(const char* name, const meshlet_input* in, const foreign_splits* foreign,
                            uint32_t max_triangles, int reps, row rows[ROWS], int* ours, joint_bound* bound,
                            FILE* summary)
{
    int n = 0;
    rows[n++] = analyse_foreign_split(&foreign->mo13, in);
    if (foreign->has_018)
        rows[n++] = analyse_foreign_split(&foreign->mo018, in);
    rows[n++] = bench_ours(in, "thesis naive", SP_MESHLETS_NAIVE, max_triangles, 32, 0, reps);
    rows[n++] = bench_ours(in, "thesis common influences", SP_MESHLETS_COMMON, max_triangles, 32, 0, reps);
    const row* cap16 = &rows[n];
    rows[n++] = bench_ours(in, "skinpack skin (ours)", SP_MESHLETS_SKIN, max_triangles, 16, 0, reps);
    const row* cap32 = &rows[n];
    *ours = n;
    rows[n++] = bench_ours(in, "skinpack skin (ours)", SP_MESHLETS_SKIN, max_triangles, 32, 0, reps);
    uint32_t effort = in->index_count / 3 < SMALL_MESH_TRIANGLES ? SMALL_MESH_EFFORT : LARGE_MESH_EFFORT;
    rows[n++] = bench_ours(in, "skinpack skin (ours)", SP_MESHLETS_SKIN, max_triangles, 32, effort,
                           reps < EFFORT_REPS ? reps : EFFORT_REPS);

    if (!joint_bound_compute(in, MAX_VERTICES, max_triangles, bound))
        die(name, "joint bound: out of memory");
    for (int r = 0; r < n; ++r)
        if (rows[r].palette_entries < bound->palette_sum) {
            fprintf(stderr, "Error: meshlets_bench: %s: %s has %zu palette entries, below the lower bound %zu\n", name,
                    rows[r].builder, rows[r].palette_entries, bound->palette_sum);
            exit(1);
        }
    const row* mo = &rows[0];
    double fill_estimate = (double)triangle_joint_sum(in) * (double)mo->meshlets / (double)(in->index_count / 3);
    fprintf(summary, "| %s | %u | %zu (%zu, %zu) | %zu (%.4f) | %zu (%.4f) | %zu | %zu (%.3f) | %zu (%.3f) | %zu (%.3f) "
                     "| %.0f (%.3f) | %.2f | %.2f |\n",
            name, max_triangles, mo->meshlets, mo->over16, mo->over32, cap32->meshlets,
            (double)cap32->meshlets / mo->meshlets, cap16->meshlets, (double)cap16->meshlets / mo->meshlets,
            mo->palette_entries, cap32->palette_entries, (double)cap32->palette_entries / mo->palette_entries,
            cap16->palette_entries, (double)cap16->palette_entries / mo->palette_entries, bound->palette_sum,
            (double)bound->palette_sum / mo->palette_entries, fill_estimate, fill_estimate / mo->palette_entries,
            cap32->ms / mo->ms, cap16->ms / mo->ms);
    return n;
}

/* The most triangles per meshlet at which the lower bound (64 vertices, at most that many
 * triangles in every meshlet) still exceeds target, or 0 if none does (the bound is
 * non-increasing in the triangle limit: each joint's ceil(T_j / limit) is, and so are the
 * forced splits and the influence-count terms, so a binary search finds it). A split reaches
 * target only with a meshlet of more triangles than this. */
static uint32_t fill_needed(const char* name, const meshlet_input* in, uint32_t max_triangles, size_t target,
                            size_t* bound_there)
{
    uint32_t lo = 0, hi = max_triangles; /* the answer lies in [lo, hi] */
    *bound_there = 0;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo + 1) / 2;
        joint_bound b;
        if (!joint_bound_compute(in, MAX_VERTICES, mid, &b))
            die(name, "joint bound: out of memory");
        if (b.palette_sum > target) {
            lo = mid;
            *bound_there = b.palette_sum;
        } else {
            hi = mid - 1;
        }
    }
    return lo;
}

/* Per weight set: how full meshlets must be for 0.90x of mo 1.3's palette entries (issue 15). */
static void print_fill_needed(FILE* details, const char* name, const meshlet_input* in, uint32_t max_triangles,
                              const row* mo, const row* ours, const char* weights)
{
    size_t target = mo->palette_entries * 9 / 10, bound = 0;
    uint32_t fill = fill_needed(name, in, max_triangles, target, &bound);
    if (fill == max_triangles) {
        fprintf(details, "0.90x of mo 1.3's palette entries (%zu), %s weights: out of reach, below the bound above.\n\n",
                target, weights);
        return;
    }
    fprintf(details, "0.90x of mo 1.3's palette entries (%zu), %s weights: ", target, weights);
    if (fill == 0)
        fprintf(details, "the bound allows it at any fill");
    else
        fprintf(details, "needs a meshlet of more than %u triangles (if every meshlet holds at most %u, the bound "
                         "is %zu)", fill, fill, bound);
    fprintf(details, "; mo 1.3 holds %.1f triangles per meshlet, ours (cap 32) %.1f.\n\n",
            (double)(in->index_count / 3) / mo->meshlets, (double)(in->index_count / 3) / ours->meshlets);
}

/* One mesh at one limit pair: the detail table into details, one summary line per weight set. */
static void bench_mesh(const bench_args* args, const char* name, const char* path, const mesh_data* mesh,
                       uint32_t max_triangles, FILE* summary[WEIGHT_SETS], FILE* details)
{
    char scratch_file[4096];
    snprintf(scratch_file, sizeof(scratch_file), "%s.mo13.bin", args->out);
    /* a build of a small mesh takes milliseconds: more runs, so that one undisturbed run is likely */
    int reps = mesh->index_count / 3 < SMALL_MESH_TRIANGLES ? args->reps * SMALL_MESH_REPS : args->reps;
    foreign_splits foreign = {bench_meshopt_13(mesh, args->node, args->mo13, path, scratch_file, max_triangles, reps),
                              {"", NULL, NULL, 0, 0}, max_triangles % 4 == 0}; /* 0.18 asserts a multiple of 4 */
    remove(scratch_file);
    if (foreign.has_018)
        foreign.mo018 = bench_meshopt_018(mesh, max_triangles, reps);
    const meshlet_input sets[WEIGHT_SETS] = {
        {mesh->indices, mesh->index_count, mesh->positions, mesh->vertex_count, mesh->joints, mesh->weights,
         mesh->influences},
        {mesh->indices, mesh->index_count, mesh->positions, mesh->vertex_count, mesh->decoded_joints,
         mesh->decoded_weights, mesh->decoded_influences}};
    row rows[WEIGHT_SETS][ROWS];
    joint_bound bounds[WEIGHT_SETS];
    int n[WEIGHT_SETS], ours[WEIGHT_SETS];
    for (int w = 0; w < WEIGHT_SETS; ++w)
        n[w] = bench_weight_set(name, &sets[w], &foreign, max_triangles, reps, rows[w], &ours[w], &bounds[w],
                                summary[w]);
    split_free(&foreign.mo13);
    split_free(&foreign.mo018);

    fprintf(details, "\n### %s, %d vertices / %u triangles (%zu triangles, %zu vertices, %zu joints)\n\n", name,
            MAX_VERTICES, max_triangles, mesh->index_count / 3, mesh->vertex_count, mesh->joint_count);
    fprintf(details, "As compressed: %zu influences, %u weight bits + %u tuple bits (%zu tuples); %zu of the prepared "
                     "influences decode to weight 0.\n\n",
            mesh->decoded_influences, mesh->decoded_weight_bits, mesh->decoded_tuple_bits, mesh->decoded_lut_size,
            mesh->lost_influences);
    for (int w = 0; w < WEIGHT_SETS; ++w)
        fprintf(details, "Palette entries summed over meshlets, any split within these limits, %s weights: at least %zu "
                         "(by joint %zu + forced splits %zu; by influence count %zu).\n\n",
                weight_set_names[w], bounds[w].palette_sum, bounds[w].by_joint, bounds[w].forced_splits,
                bounds[w].by_influence_count);
    for (int w = 0; w < WEIGHT_SETS; ++w)
        print_fill_needed(details, name, &sets[w], max_triangles, &rows[w][0], &rows[w][ours[w]],
                          weight_set_names[w]);
    fprintf(details, "| weights | builder | meshlets | ÷ mo 1.3 | palette entries | ÷ mo 1.3 | joint floor | max joints "
                     "| meshlets over 16 | over 32 | local tuple bits/vertex | ms | time ÷ mo 1.3 |\n"
                     "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (int w = 0; w < WEIGHT_SETS; ++w)
        for (int r = 0; r < n[w]; ++r)
            print_row(details, weight_set_names[w], &rows[w][r], &rows[w][0]);
    if (max_triangles % 4 != 0)
        fprintf(details, "\nmeshoptimizer 0.18 is not run at %u triangles: it requires a multiple of 4.\n", max_triangles);
}

/* The summary table of one weight set. */
static void print_summary(FILE* f, const char* heading, const char* rows)
{
    fprintf(f, "%s\n\n| mesh | max triangles | mo 1.3 meshlets (over 16, over 32 joints) | ours cap 32 (÷ mo 1.3, <= 1.00) "
               "| ours cap 16 (÷ mo 1.3, <= 1.03) | mo 1.3 palette entries | ours cap 32 (÷, <= 0.90) "
               "| ours cap 16 (÷) | lower bound, any split (÷) | estimate at mo 1.3's fill (÷) | time cap 32 ÷ mo 1.3 (<= 2) "
               "| time cap 16 ÷ mo 1.3 |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|---|\n%s\n",
            heading, rows);
}

int main(int argc, char** argv)
{
    bench_args args = parse_args(argc, argv);
    char* summary_text[WEIGHT_SETS] = {NULL, NULL};
    char* details_text = NULL;
    size_t summary_size[WEIGHT_SETS] = {0, 0}, details_size = 0;
    FILE* summary[WEIGHT_SETS];
    for (int w = 0; w < WEIGHT_SETS; ++w)
        if (!(summary[w] = open_memstream(&summary_text[w], &summary_size[w])))
            die("open_memstream", "out of memory");
    FILE* details = open_memstream(&details_text, &details_size);
    if (!details)
        die("open_memstream", "out of memory");
    for (int i = args.first_mesh; i < argc; ++i) {
        char name[128];
        const char* eq = strchr(argv[i], '=');
        const char* path = eq ? eq + 1 : argv[i];
        snprintf(name, sizeof(name), "%.*s", eq ? (int)(eq - argv[i]) : (int)strlen(argv[i]), argv[i]);
        mesh_data mesh;
        if (!mesh_data_load(path, 4, &mesh) || !mesh_data_decode_compressed(&mesh))
            return 1;
        for (size_t l = 0; l < sizeof(triangle_limits) / sizeof(triangle_limits[0]); ++l)
            bench_mesh(&args, name, path, &mesh, triangle_limits[l], summary, details);
        printf("%s: done\n", name);
        mesh_data_free(&mesh);
    }
    for (int w = 0; w < WEIGHT_SETS; ++w)
        fclose(summary[w]);
    fclose(details);
    FILE* f = fopen(args.out, "w");
    if (!f)
        die("cannot write", args.out);
    fprintf(f, "## Results\n\n%d vertices. Time: fastest of %d runs (%d on meshes under %d triangles), CPU time of the "
               "process (node: process.cpuUsage), ratio to meshoptimizer 1.3 (npm, WebAssembly in node) in the same "
               "run. Each weight set is analysed by the same rule for every builder (a joint is in a meshlet's palette "
               "when its weight on one of the meshlet's vertices is > 0); meshoptimizer ignores the weights, so its "
               "split is the same for both.\n\n",
            MAX_VERTICES, args.reps, args.reps * SMALL_MESH_REPS, SMALL_MESH_TRIANGLES);
    print_summary(f, "### Prepared weights (K = 4 after sp_prepare_influences)", summary_text[0]);
    print_summary(f, "### As compressed (decoded from the default `skinpack compress`: OSS, 32-bit vertex budget; "
                     "what `compress --meshlets` builds from and a mesh shader loads)", summary_text[1]);
    fputs(details_text, f);
    fclose(f);
    for (int w = 0; w < WEIGHT_SETS; ++w)
        free(summary_text[w]);
    free(details_text);
    return 0;
}
