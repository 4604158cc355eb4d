/*
 * cli_compress.c - skinpack compress: replaces (compact) or accompanies (fallback) the
 * JOINTS_n/WEIGHTS_n of every skinned primitive with SKINPACK_packed_skin. All compression is
 * sp_compress_skin's; this file only moves arrays between the glTF document and the library.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli_common.h"
#include "commands.h"

typedef struct compress_args {
    const char* input;
    const char* output;
    sp_compress_options options;
    double max_error; /* --max-error, 0 = unused */
    int compact;
    int json;
    int meshlets; /* --meshlets: also write skin-aware meshlets */
    int meshopt;  /* --meshopt: packed words (and tuple table) meshopt-compressed where that is smaller */
    int weight_bits_given; /* --weight-bits (0 in options.weight_bits means "not given") */
    sp_meshlet_options meshlet_options; /* --meshlet-vertices/-triangles/-joints over the library's defaults */
    const char* meshlet_limit;          /* the first of those options given, for the error without --meshlets */
} compress_args;

/* One primitive's outcome. Primitives with the same JOINTS_n/WEIGHTS_n accessors share the
 * first one's result (shared_with >= 0) and are compressed once. */
typedef struct compressed_primitive {
    size_t mesh, primitive;
    long shared_with;
    gltf_skin_attributes attributes;
    gltf_packed_skin packed;
    sp_compressed_skin skin;
    double input_bits_per_vertex;  /* JOINTS_n + WEIGHTS_n as stored in the input */
    double output_bits_per_vertex; /* vertex words + tuple table as stored in the output */
    size_t packed_bytes;           /* bytes of the vertex words + tuple table (as the GPU holds them) */
    size_t stored_packed_bytes;    /* the bytes stored for them (less with --meshopt; base64 in a .gltf adds 1/3) */
    sp_meshlet_stats meshlet_stats; /* --meshlets */
} compressed_primitive;

/*
 * Compact mode: the primitive keeps JOINTS_0/WEIGHTS_0, but their data moves to the fallback
 * buffer (no bytes), as EXT_meshopt_compression does it: a loader without the extension fails
 * to load the buffer instead of reading zeros, one with it fills them from the packed data.
 * JOINTS_1/WEIGHTS_1 go (the packed skin has at most 4 influences). The freed bytes are cut.
 */
static size_t make_compact(gltf_doc* doc, const compressed_primitive* p) {
    const gltf_skin_attributes* at = &p->attributes;
    gltf_set_skin_attributes(doc, p->mesh, p->primitive, at->joints[0], at->weights[0]);
    if (p->shared_with >= 0) return 0; /* the first primitive with these accessors moved them */
    size_t freed = 0;
    for (size_t s = 0; s < at->sets; ++s) {
        freed += gltf_make_fallback(doc, at->joints[s]);
        freed += gltf_make_fallback(doc, at->weights[s]);
    }
    return freed;
}

static void compress_usage(FILE* out) {
    sp_meshlet_options defaults;
    sp_meshlet_options_default(&defaults);
    fprintf(out,
            "usage: skinpack compress IN -o OUT [options]\n"
            "  --method oss|any|pot|cube|fixed   weight codec (default oss)\n"
            "  --vertex-bits B      tuple index + weight code budget a vertex (default 32)\n"
            "  --weight-bits B      weight code budget alone\n"
            "  --max-error D        fewest bits whose proven max weight error is <= D\n"
            "  --max-influences K   influences kept a vertex, 1..4 (default 4)\n"
            "  --fallback           keep JOINTS_0/WEIGHTS_0, extension optional (default)\n"
            "  --compact            remove them, extension required\n"
            "  --meshlets           also store skin-aware meshlets (palettes, local tuple tables)\n"
            "  --meshlet-vertices N   meshlet vertex limit, 3..%d (default %u)\n"
            "  --meshlet-triangles N  meshlet triangle limit, 1..%d (default %u)\n"
            "  --meshlet-joints N     palette cap: joints a meshlet may use, 1..%d (default %u)\n"
            "  --meshlet-effort N     random border moves tried per triangle for smaller palettes,\n"
            "                         0..%d (default %u; the time grows with it: 5k triangles ~0.1 s at 300)\n"
            "  --meshopt            meshopt-compress the packed words and tuple table where that is smaller\n"
            "                       (EXT_meshopt_compression, required; KHR_ if the input uses it)\n"
            "  --exact-tuples       no don't-care sharing: zero-weight slots keep their joints\n"
            "  --json               machine-readable report on stdout\n"
            "IN and OUT are .gltf or .glb; OUT's kind follows its file name.\n",
            SP_MESHLET_MAX_VERTICES, defaults.max_vertices, SP_MESHLET_MAX_TRIANGLES, defaults.max_triangles,
            SP_MESHLET_MAX_JOINTS, defaults.max_joints, SP_MESHLET_MAX_PALETTE_EFFORT, defaults.palette_effort);
}

static int parse_uint(const char* s, unsigned long max, uint32_t* out) {
    char* end = NULL;
    unsigned long v = strtoul(s, &end, 10);
    if (!s[0] || *end || v > max) return -1;
    *out = (uint32_t)v;
    return 0;
}

/* The weight-code widths the library accepts for a method and K (lo > hi: none). */
static void weight_bits_range(sp_method method, uint32_t k, uint32_t* lo, uint32_t* hi) {
    *lo = SP_MAX_WEIGHT_BITS + 1;
    *hi = 0;
    for (uint32_t b = 0; b <= SP_MAX_WEIGHT_BITS; ++b) {
        sp_codec codec;
        if (sp_codec_from_bits(method, k, b, &codec) != SP_OK) continue;
        if (b < *lo) *lo = b;
        *hi = b;
    }
}

/* --weight-bits / --vertex-bits against what the method can do with --max-influences
 * influences (a primitive with fewer influences is checked again when it is compressed). */
static int check_budget(const compress_args* args) {
    const sp_compress_options* o = &args->options;
    uint32_t lo, hi;
    weight_bits_range(o->method, o->max_influences, &lo, &hi);
    const char* name = sp_method_name(o->method);
    if (lo > hi) {
        fprintf(stderr, "Error: --method %s is not defined for %u influences (--max-influences)\n", name,
                o->max_influences);
        return -1;
    }
    if (args->weight_bits_given && (o->weight_bits == 0 || o->weight_bits < lo || o->weight_bits > hi)) {
        fprintf(stderr, "Error: --weight-bits %u: method %s with %u influences takes %u..%u bits\n",
                o->weight_bits, name, o->max_influences, lo ? lo : 1, hi);
        return -1;
    }
    if (o->vertex_bits && o->vertex_bits < lo) {
        fprintf(stderr, "Error: --vertex-bits %u: method %s with %u influences needs at least %u bits for "
                "the weights, plus the tuple index\n", o->vertex_bits, name, o->max_influences, lo);
        return -1;
    }
    return 0;
}

static int is_budget_option(const char* a) {
    return strcmp(a, "--vertex-bits") == 0 || strcmp(a, "--weight-bits") == 0 || strcmp(a, "--max-error") == 0;
}

/* --vertex-bits, --weight-bits or --max-error: the one budget (0 in options means "not this"). */
static int parse_budget(const char* a, const char* value, compress_args* args) {
    sp_compress_options* o = &args->options;
    if (strcmp(a, "--vertex-bits") == 0) {
        o->weight_bits = 0;
        if (parse_uint(value, SP_MAX_VERTEX_BITS, &o->vertex_bits) || !o->vertex_bits) {
            fprintf(stderr, "Error: --vertex-bits must be 1..%d\n", SP_MAX_VERTEX_BITS);
            return -1;
        }
    } else if (strcmp(a, "--weight-bits") == 0) {
        o->vertex_bits = 0;
        args->weight_bits_given = 1;
        if (parse_uint(value, SP_MAX_WEIGHT_BITS, &o->weight_bits)) {
            fprintf(stderr, "Error: --weight-bits must be 0..%d\n", SP_MAX_WEIGHT_BITS);
            return -1;
        }
    } else {
        char* end = NULL;
        args->max_error = strtod(value, &end);
        if (*end || !(args->max_error > 0 && args->max_error < 1)) {
            fprintf(stderr, "Error: --max-error must be a number in (0, 1)\n");
            return -1;
        }
        o->vertex_bits = 0;
    }
    return 0;
}

/* --meshlet-vertices/-triangles/-joints/-effort: 1 if a is one of them (value consumed), 0 if
 * not, -1 on a bad value. The ranges are the library's (sp_check_meshlet_options). */
static int parse_meshlet_limit(const char* a, const char* value, compress_args* args) {
    sp_meshlet_options* o = &args->meshlet_options;
    uint32_t* field = strcmp(a, "--meshlet-vertices") == 0    ? &o->max_vertices
                      : strcmp(a, "--meshlet-triangles") == 0 ? &o->max_triangles
                      : strcmp(a, "--meshlet-joints") == 0    ? &o->max_joints
                      : strcmp(a, "--meshlet-effort") == 0    ? &o->palette_effort
                                                              : NULL;
    if (!field || !value) return 0;
    if (!args->meshlet_limit) args->meshlet_limit = a;
    if (parse_uint(value, UINT32_MAX, field) || sp_check_meshlet_options(o) != SP_OK) {
        fprintf(stderr, "Error: %s %s: vertices must be 3..%d, triangles 1..%d, joints 1..%d, effort 0..%d\n", a,
                value, SP_MESHLET_MAX_VERTICES, SP_MESHLET_MAX_TRIANGLES, SP_MESHLET_MAX_JOINTS,
                SP_MESHLET_MAX_PALETTE_EFFORT);
        return -1;
    }
    return 1;
}

static int parse_args(int argc, char** argv, compress_args* args) {
    memset(args, 0, sizeof(*args));
    sp_compress_options_default(&args->options);
    sp_meshlet_options_default(&args->meshlet_options);
    int budgets = 0;
    for (int i = 1; i < argc; ++i) {
        const char* a = argv[i];
        const char* value = i + 1 < argc ? argv[i + 1] : NULL;
        int limit = parse_meshlet_limit(a, value, args);
        if (limit < 0) return -1;
        if (limit > 0) {
            ++i;
        } else if (strcmp(a, "-o") == 0 && value) {
            args->output = value;
            ++i;
        } else if (strcmp(a, "--method") == 0 && value) {
            args->options.method = sp_method_from_name(value);
            if (args->options.method == SP_METHOD_COUNT) {
                fprintf(stderr, "Error: --method: unknown method '%s' (", value);
                for (int m = 0; m < SP_METHOD_COUNT; ++m) fprintf(stderr, "%s%s", m ? ", " : "", sp_method_name((sp_method)m));
                fprintf(stderr, ")\n");
                return -1;
            }
            ++i;
        } else if (is_budget_option(a) && value) {
            if (parse_budget(a, value, args)) return -1;
            ++budgets;
            ++i;
        } else if (strcmp(a, "--max-influences") == 0 && value) {
            if (parse_uint(value, SP_MAX_INFLUENCES, &args->options.max_influences) ||
                !args->options.max_influences) {
                fprintf(stderr, "Error: --max-influences must be 1..%d\n", SP_MAX_INFLUENCES);
                return -1;
            }
            ++i;
        } else if (strcmp(a, "--fallback") == 0) {
            args->compact = 0;
        } else if (strcmp(a, "--compact") == 0) {
            args->compact = 1;
        } else if (strcmp(a, "--json") == 0) {
            args->json = 1;
        } else if (strcmp(a, "--meshlets") == 0) {
            args->meshlets = 1;
        } else if (strcmp(a, "--meshopt") == 0) {
            args->meshopt = 1;
        } else if (strcmp(a, "--exact-tuples") == 0) {
            args->options.merge_dont_care = 0;
        } else if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            compress_usage(stdout);
            exit(0);
        } else if (a[0] == '-' || args->input) {
            fprintf(stderr, "Error: unexpected argument '%s'\n", a);
            return -1;
        } else {
            args->input = a;
        }
    }
    if (args->meshlet_limit && !args->meshlets) {
        fprintf(stderr, "Error: %s needs --meshlets\n", args->meshlet_limit);
        return -1;
    }
    if (budgets > 1) {
        fprintf(stderr, "Error: give at most one of --vertex-bits, --weight-bits, --max-error\n");
        return -1;
    }
    if (args->meshopt && !gltf_meshopt_supported()) {
        fprintf(stderr, "Error: --meshopt needs libmeshoptimizer writing vertex codec version 0 "
                "(EXT_meshopt_compression); this skinpack was built without it\n");
        return -1;
    }
    if (check_budget(args)) return -1;
    if (!args->input || !args->output) {
        compress_usage(stderr);
        return -1;
    }
    return 0;
}

/* The built meshlets as the extension's "meshlets" accessors: per-meshlet offsets, counts, bounds
 * and cones packed four to an element, then the flat arrays as sp_build_meshlets wrote them. */
static int add_meshlet_accessors(gltf_doc* doc, gltf_packed_meshlets* ml, const sp_meshlet_buffers* out,
                                 const sp_meshlet_stats* stats, const sp_meshlet_options* options, uint32_t k,
                                 char* err, size_t err_size) {
    size_t n = stats->meshlet_count;
    uint32_t* offsets = malloc(n * 4 * sizeof(uint32_t));
    uint16_t* counts = malloc(n * 4 * sizeof(uint16_t));
    float* bounds = malloc(n * 4 * sizeof(float));
    float* cones = malloc(n * 4 * sizeof(float));
    int rc = -1;
    if (!offsets || !counts || !bounds || !cones) {
        snprintf(err, err_size, "out of memory");
        goto done;
    }
    for (size_t m = 0; m < n; ++m) {
        const sp_meshlet* built = &out->meshlets[m];
        uint32_t o[4] = {built->vertex_offset, built->triangle_offset, built->joint_offset, built->tuple_offset};
        uint16_t c[4] = {built->vertex_count, built->triangle_count, built->joint_count, built->tuple_count};
        float b[4] = {built->center[0], built->center[1], built->center[2], built->radius};
        float cone[4] = {built->cone_axis[0], built->cone_axis[1], built->cone_axis[2], built->cone_cutoff};
        memcpy(offsets + 4 * m, o, sizeof(o));
        memcpy(counts + 4 * m, c, sizeof(c));
        memcpy(bounds + 4 * m, b, sizeof(b));
        memcpy(cones + 4 * m, cone, sizeof(cone));
    }
    ml->present = 1;
    ml->offsets = gltf_add_accessor(doc, offsets, n, GLTF_UNSIGNED_INT, 4, 0, GLTF_ACCESSOR_BOUNDS);
    ml->counts = gltf_add_accessor(doc, counts, n, GLTF_UNSIGNED_SHORT, 4, 0, GLTF_ACCESSOR_BOUNDS);
    ml->bounds = gltf_add_accessor(doc, bounds, n, GLTF_FLOAT, 4, 0, 0);
    ml->cones = gltf_add_accessor(doc, cones, n, GLTF_FLOAT, 4, 0, 0);
    ml->vertices = gltf_add_accessor(doc, out->vertices, stats->vertex_count, GLTF_UNSIGNED_INT, 1, 0, GLTF_ACCESSOR_BOUNDS);
    ml->vertex_tuples = gltf_add_accessor(doc, out->vertex_tuples, stats->vertex_count, GLTF_UNSIGNED_BYTE, 1, 0,
                                          GLTF_ACCESSOR_BOUNDS);
    ml->triangles = gltf_add_accessor(doc, out->triangles, stats->triangle_count * 3, GLTF_UNSIGNED_BYTE, 1, 0,
                                      GLTF_ACCESSOR_BOUNDS);
    ml->joints = gltf_add_accessor(doc, out->joints, stats->joint_count, GLTF_UNSIGNED_SHORT, 1, 0, GLTF_ACCESSOR_BOUNDS);
    ml->tuples = gltf_add_accessor(doc, out->tuples, stats->tuple_count, GLTF_UNSIGNED_BYTE, (int)k, 0,
                                   GLTF_ACCESSOR_BOUNDS);
    ml->max_vertices = options->max_vertices;
    ml->max_triangles = options->max_triangles;
    ml->max_joints = options->max_joints;
    rc = 0;
done:
    free(offsets);
    free(counts);
    free(bounds);
    free(cones);
    return rc;
}

/*
 * --meshlets: sp_build_meshlets on the primitive's triangles with the weights and joints a
 * decoder will see (the packed data decoded again), stored as the extension's "meshlets".
 */
static int build_meshlets(gltf_doc* doc, compressed_primitive* p, const uint32_t* words, const uint16_t* lut,
                          const sp_meshlet_options* limits, char* err, size_t err_size) {
    const sp_compressed_skin* s = &p->skin;
    size_t index_count = 0, vertex_count = 0;
    if (gltf_primitive_triangles(doc, p->mesh, p->primitive, &index_count, &vertex_count, err, err_size)) return -1;
    if (vertex_count != s->vertex_count) {
        snprintf(err, err_size, "POSITION has %zu vertices, JOINTS_0 %zu", vertex_count, s->vertex_count);
        return -1;
    }
    cli_decoded_skin decoded;
    if (cli_decode_packed_arrays(&p->packed, words, s->vertex_count, s->words_per_vertex, lut, s->lut_size, 0,
                                 &decoded, err, err_size))
        return -1;
    uint32_t k = s->influences;
    sp_meshlet_options options = *limits;
    sp_meshlet_sizes sizes;
    sp_meshlets_bound(index_count, vertex_count, k, &options, &sizes);
    uint32_t* indices = malloc(index_count * sizeof(uint32_t));
    float* positions = malloc(vertex_count * 3 * sizeof(float));
    sp_meshlet_buffers out;
    memset(&out, 0, sizeof(out));
    out.meshlets = malloc(sizes.meshlets * sizeof(sp_meshlet));
    out.vertices = malloc(sizes.vertices * sizeof(uint32_t));
    out.vertex_tuples = malloc(sizes.vertices);
    out.triangles = malloc(sizes.triangles * 3);
    out.joints = malloc(sizes.joints * sizeof(uint16_t));
    out.tuples = malloc(sizes.tuples * k);
    out.capacity = sizes;
    void* scratch = malloc(sizes.scratch_bytes ? sizes.scratch_bytes : 1);
    int rc = -1;
    sp_meshlet_stats* stats = &p->meshlet_stats;
    if (!indices || !positions || !out.meshlets || !out.vertices || !out.vertex_tuples || !out.triangles ||
        !out.joints || !out.tuples || !scratch) {
        snprintf(err, err_size, "out of memory");
        goto done;
    }
    if (gltf_read_triangles(doc, p->mesh, p->primitive, indices, positions, err, err_size)) goto done;
    sp_result r = sp_build_meshlets(indices, index_count, positions, vertex_count, 3 * sizeof(float), decoded.joints,
                                    decoded.weights, k, &options, &out, scratch, sizes.scratch_bytes, stats);
    if (r != SP_OK) {
        if (r == SP_ERR_LIMIT_EXCEEDED)
            snprintf(err, err_size, "meshlets: triangle %zu uses more joints than the palette cap %u (--meshlet-joints)",
                     stats->error_triangle, options.max_joints);
        else
            snprintf(err, err_size, "meshlets: %s (triangle %zu)", sp_result_string(r), stats->error_triangle);
        goto done;
    }
    if (add_meshlet_accessors(doc, &p->packed.meshlets, &out, stats, &options, k, err, err_size)) goto done;
    rc = 0;
done:
    cli_decoded_skin_free(&decoded);
    free(indices);
    free(positions);
    free(out.meshlets);
    free(out.vertices);
    free(out.vertex_tuples);
    free(out.triangles);
    free(out.joints);
    free(out.tuples);
    free(scratch);
    return rc;
}

/* Why sp_compress_skin refused a primitive, in terms of the file and the options. */
static void describe_failure(sp_result r, const compressed_primitive* p, const sp_compress_options* options,
                             size_t joint_count, char* err, size_t err_size) {
    uint32_t lo, hi, k = p->skin.influences ? p->skin.influences : options->max_influences;
    weight_bits_range(options->method, k, &lo, &hi);
    if (r == SP_ERR_JOINT_OUT_OF_RANGE)
        snprintf(err, err_size, "vertex %zu: joint %u is past the skin's %zu joints", p->skin.prepare.error_vertex,
                 p->skin.prepare.error_joint, joint_count);
    else if (r == SP_ERR_BITS_OUT_OF_RANGE || r == SP_ERR_INVALID_ARGUMENT)
        snprintf(err, err_size, "the bit budget (%s %u) fits no %s configuration for %u influences (the weights "
                 "take %u..%u bits; with the tuple index at most %d bits in all)",
                 options->weight_bits ? "--weight-bits" : "--vertex-bits",
                 options->weight_bits ? options->weight_bits : options->vertex_bits, sp_method_name(options->method),
                 k, lo, hi, SP_MAX_VERTEX_BITS);
    else
        snprintf(err, err_size, "vertex %zu: %s", p->skin.prepare.error_vertex, sp_result_string(r));
}

static int compress_primitive(gltf_doc* doc, const compress_args* args, compressed_primitive* p, char* err,
                              size_t err_size) {
    const gltf_skin_attributes* at = &p->attributes;
    size_t vc = at->vertex_count, stride = 4 * at->sets;
    uint16_t* joints = malloc(vc * stride * sizeof(uint16_t));
    float* weights = malloc(vc * stride * sizeof(float));
    uint32_t* words = malloc(vc * 2 * sizeof(uint32_t));
    uint16_t* lut = malloc(vc * SP_MAX_INFLUENCES * sizeof(uint16_t));
    size_t scratch_size = sp_compress_scratch_bound(vc, stride);
    void* scratch = malloc(scratch_size ? scratch_size : 1);
    int rc = -1;
    if (!joints || !weights || !words || !lut || !scratch) {
        snprintf(err, err_size, "out of memory");
        goto done;
    }
    if (gltf_read_skin(doc, at, joints, weights, err, err_size)) goto done;

    size_t joint_count = at->joint_count;
    if (joint_count == 0) { /* no skinned node uses the mesh: the largest index bounds the joints */
        for (size_t i = 0; i < vc * stride; ++i)
            if (joints[i] >= joint_count) joint_count = (size_t)joints[i] + 1;
        if (joint_count == 0) joint_count = 1;
    }
    sp_compress_options options = args->options;
    if (args->max_error > 0) { /* the library's one search, for the K it will use (also K = 1) */
        options.vertex_bits = options.weight_bits = 0;
        options.max_error = args->max_error;
    }

    sp_result r = sp_compress_skin(joints, weights, vc, stride, joint_count, &options, words, lut, NULL, NULL,
                                   &p->skin, scratch, scratch_size);
    if (r != SP_OK) {
        describe_failure(r, p, &options, joint_count, err, err_size);
        goto done;
    }

    const sp_compressed_skin* s = &p->skin;
    uint32_t k = s->influences;
    memset(&p->packed, 0, sizeof(p->packed));
    p->packed.influences = k;
    p->packed.joint_count = (uint32_t)s->joint_count;
    p->packed.method = s->codec.method;
    p->packed.n = s->codec.n;
    for (uint32_t i = 0; i + 1 < k && i < 3; ++i) p->packed.axis_samples[i] = s->codec.axis_samples[i];
    p->packed.axis_sample_count = s->codec.method == SP_METHOD_ANY && k > 1 ? k - 1 : 0; /* as it is written */
    p->packed.weight_bits = s->weight_bits;
    p->packed.tuple_bits = s->tuple_bits;
    p->packed.max_error = s->codec.max_error;
    if (args->meshlets && build_meshlets(doc, p, words, lut, &args->meshlet_options, err, err_size)) goto done;

    size_t lut_entries = s->lut_size * k;
    int lut_type = GLTF_UNSIGNED_SHORT;
    if (s->joint_bytes == 1) { /* narrow in place: u8 entries fit where the u16 were */
        uint8_t* narrow = (uint8_t*)lut;
        for (size_t i = 0; i < lut_entries; ++i) narrow[i] = (uint8_t)lut[i];
        lut_type = GLTF_UNSIGNED_BYTE;
    }
    int meshopt = args->meshopt ? GLTF_ACCESSOR_MESHOPT : 0;
    p->packed.vertices = gltf_add_accessor(doc, words, vc, GLTF_UNSIGNED_INT, (int)s->words_per_vertex, 0, meshopt);
    /* no min/max on the words: bit fields, and glTF does not ask for them */
    p->packed.tuple_table = gltf_add_accessor(doc, lut, s->lut_size, lut_type, (int)k, 0,
                                              GLTF_ACCESSOR_BOUNDS | meshopt);
    p->packed_bytes = vc * 4 * s->words_per_vertex + lut_entries * (size_t)s->joint_bytes;
    p->stored_packed_bytes = gltf_stored_view_bytes(doc, p->packed.vertices) +
                             gltf_stored_view_bytes(doc, p->packed.tuple_table);
    p->input_bits_per_vertex = at->stored_bits_per_vertex;
    p->output_bits_per_vertex = 32.0 * s->words_per_vertex + s->lut_bits_per_vertex;
    rc = 0;
done:
    free(joints);
    free(weights);
    free(words);
    free(lut);
    free(scratch);
    return rc;
}

static int same_attributes(const gltf_skin_attributes* a, const gltf_skin_attributes* b) {
    return a->sets == b->sets && memcmp(a->joints, b->joints, sizeof(a->joints)) == 0 &&
           memcmp(a->weights, b->weights, sizeof(a->weights)) == 0;
}

static void print_json(const compress_args* args, const compressed_primitive* prims, size_t count,
                       size_t input_bytes, size_t output_bytes) {
    double in_bits = 0, out_bits = 0;
    size_t vertices = 0;
    printf("{\n  \"input\": ");
    cli_json_string(stdout, args->input);
    printf(",\n  \"output\": ");
    cli_json_string(stdout, args->output);
    printf(",\n  \"mode\": \"%s\",\n  \"primitives\": [", args->compact ? "compact" : "fallback");
    for (size_t i = 0; i < count; ++i) {
        const compressed_primitive* p = &prims[i];
        const sp_compressed_skin* s = &p->skin;
        if (p->shared_with < 0) {
            in_bits += p->input_bits_per_vertex * (double)s->vertex_count;
            out_bits += p->output_bits_per_vertex * (double)s->vertex_count;
            vertices += s->vertex_count;
        }
        printf("%s\n    {\"mesh\": %zu, \"primitive\": %zu, \"shared_with\": %ld, \"vertices\": %zu, \"joints\": %zu, "
               "\"influences\": %u, \"method\": \"%s\", \"n\": %llu, \"unique_tuples\": %zu, \"tuple_bits\": %u, "
               "\"weight_bits\": %u, \"words_per_vertex\": %u, \"lut_bits_per_vertex\": ",
               i ? "," : "", p->mesh, p->primitive, p->shared_with, s->vertex_count, s->joint_count, s->influences,
               sp_method_name((sp_method)s->codec.method), (unsigned long long)s->codec.n, s->lut_size,
               s->tuple_bits, s->weight_bits, s->words_per_vertex);
        cli_json_number(stdout, s->lut_bits_per_vertex);
        printf(", \"bits_per_vertex\": ");
        cli_json_number(stdout, s->bits_per_vertex);
        printf(", \"input_bits_per_vertex\": ");
        cli_json_number(stdout, p->input_bits_per_vertex);
        printf(", \"stored_bits_per_vertex\": ");
        cli_json_number(stdout, p->output_bits_per_vertex);
        printf(", \"max_error_bound\": ");
        cli_json_number(stdout, s->codec.max_error);
        printf(", \"max_weight_error\": ");
        cli_json_number(stdout, s->quantization.max_error);
        printf(", \"rms_weight_error\": ");
        cli_json_number(stdout, s->quantization.rms_error);
        printf(", \"max_pruning_error\": ");
        cli_json_number(stdout, s->prepare.max_pruning_error);
        printf(", \"packed_bytes\": %zu, \"stored_packed_bytes\": %zu", p->packed_bytes, p->stored_packed_bytes);
        printf(", \"pruned_vertices\": %zu, \"influence_histogram\": [", s->prepare.pruned_vertices);
        for (int c = 0; c <= SP_MAX_INPUT_INFLUENCES; ++c)
            printf("%s%zu", c ? ", " : "", s->prepare.influence_histogram[c]);
        printf("]");
        if (p->packed.meshlets.present) {
            const sp_meshlet_stats* ms = &p->meshlet_stats;
            printf(", \"meshlets\": {\"count\": %zu, \"max_vertices\": %u, \"max_triangles\": %u, \"mean_joints\": ",
                   ms->meshlet_count, ms->max_vertices, ms->max_triangles);
            cli_json_number(stdout, ms->mean_joints);
            printf(", \"max_joints\": %u, \"palette_entries\": %zu, \"global_tuple_bits\": %u, "
                   "\"local_tuple_bits_mean\": ", ms->max_joints, ms->joint_count, s->tuple_bits);
            cli_json_number(stdout, ms->local_tuple_bits_mean);
            printf("}");
        }
        printf("}");
    }
    printf("\n  ],\n  \"vertices\": %zu,\n  \"input_bits_per_vertex\": ", vertices);
    cli_json_number(stdout, vertices ? in_bits / (double)vertices : 0);
    printf(",\n  \"output_bits_per_vertex\": ");
    cli_json_number(stdout, vertices ? out_bits / (double)vertices : 0);
    printf(",\n  \"meshopt\": %s,\n  \"input_bytes\": %zu,\n  \"output_bytes\": %zu\n}\n",
           args->meshopt ? "true" : "false", input_bytes, output_bytes);
}

static void print_table(const compress_args* args, const compressed_primitive* prims, size_t count,
                        size_t input_bytes, size_t output_bytes) {
    printf("%-5s %-5s %8s %6s %2s %7s %-6s %10s %10s %6s %10s %10s\n", "mesh", "prim", "vertices", "joints", "K",
           "tuples", "codec", "bits/v in", "bits/v out", "ratio", "max error", "bound");
    for (size_t i = 0; i < count; ++i) {
        const compressed_primitive* p = &prims[i];
        const sp_compressed_skin* s = &p->skin;
        if (p->shared_with >= 0) {
            printf("%-5zu %-5zu (same attributes as row %ld)\n", p->mesh, p->primitive, p->shared_with + 1);
            continue;
        }
        char codec[32];
        snprintf(codec, sizeof(codec), "%s%u", sp_method_name((sp_method)s->codec.method), s->weight_bits);
        printf("%-5zu %-5zu %8zu %6zu %2u %7zu %-6s %10.1f %10.1f %5.1fx %10.2e %10.2e\n", p->mesh, p->primitive,
               s->vertex_count, s->joint_count, s->influences, s->lut_size, codec, p->input_bits_per_vertex,
               p->output_bits_per_vertex, p->input_bits_per_vertex / p->output_bits_per_vertex,
               s->quantization.max_error, s->codec.max_error);
        if (p->packed.meshlets.present)
            printf("            meshlets: %zu, up to %u vertices / %u triangles / %u joints, %.1f joints on average, "
                   "tuple index %u -> %.2f bits\n", p->meshlet_stats.meshlet_count, p->meshlet_stats.max_vertices,
                   p->meshlet_stats.max_triangles, p->meshlet_stats.max_joints, p->meshlet_stats.mean_joints,
                   s->tuple_bits, p->meshlet_stats.local_tuple_bits_mean);
        if (args->meshopt)
            printf("            meshopt: words + tuple table %zu -> %zu bytes in the file\n", p->packed_bytes,
                   p->stored_packed_bytes);
    }
    printf("%s mode; bits/v out = packed words + tuple table%s. file: %zu -> %zu bytes\n",
           args->compact ? "compact" : "fallback",
           args->compact ? "" : " (JOINTS_0/WEIGHTS_0 are kept as well)", input_bytes, output_bytes);
}

/* Every skinned primitive, checked; primitives with the same accessors (and, with meshlets, the
 * same geometry) point at the first with shared_with. Returns the count, or -1 after a message. */
static long find_skinned(const gltf_doc* doc, const compress_args* args, compressed_primitive** out) {
    char err[CLI_ERR_SIZE];
    size_t capacity = 0, count = 0;
    compressed_primitive* prims = NULL;
    for (size_t m = 0; m < gltf_mesh_count(doc); ++m) {
        for (size_t pi = 0; pi < gltf_primitive_count(doc, m); ++pi) {
            gltf_packed_skin existing;
            gltf_skin_attributes attributes;
            int has = gltf_get_packed(doc, m, pi, &existing, err, sizeof(err));
            if (has > 0)
                snprintf(err, sizeof(err), "already carries " GLTF_EXTENSION_NAME "; run skinpack decompress first");
            int skinned = has == 0 ? gltf_primitive_skin(doc, m, pi, &attributes, err, sizeof(err)) : -1;
            if (skinned > 0 && attributes.placeholder) {
                snprintf(err, sizeof(err), "JOINTS_0/WEIGHTS_0 have no data (no bufferView, or a buffer without data) "
                         "and there is no " GLTF_EXTENSION_NAME " to supply it");
                skinned = -1;
            }
            if (skinned < 0) {
                fprintf(stderr, "Error: %s: mesh %zu primitive %zu: %s\n", args->input, m, pi, err);
                free(prims);
                return -1;
            }
            if (!skinned) continue;
            compressed_primitive* grown = cli_grow(prims, &capacity, count, sizeof(*prims));
            if (!grown) {
                fprintf(stderr, "Error: out of memory\n");
                free(prims);
                return -1;
            }
            prims = grown;
            compressed_primitive* p = &prims[count];
            memset(p, 0, sizeof(*p));
            p->mesh = m;
            p->primitive = pi;
            p->attributes = attributes;
            p->shared_with = -1;
            for (size_t j = 0; j < count && p->shared_with < 0; ++j)
                if (prims[j].shared_with < 0 && same_attributes(&prims[j].attributes, &attributes) &&
                    (!args->meshlets || gltf_same_geometry(doc, prims[j].mesh, prims[j].primitive, m, pi)))
                    p->shared_with = (long)j;
            ++count;
        }
    }
    *out = prims;
    return (long)count;
}

/* Compresses each primitive once (the shared ones take the first's result). */
static int compress_all(gltf_doc* doc, const compress_args* args, compressed_primitive* prims, size_t count) {
    char err[CLI_ERR_SIZE];
    for (size_t i = 0; i < count; ++i) {
        compressed_primitive* p = &prims[i];
        if (p->shared_with >= 0) {
            const compressed_primitive* first = &prims[p->shared_with];
            p->skin = first->skin;
            p->packed = first->packed;
            p->input_bits_per_vertex = first->input_bits_per_vertex;
            p->output_bits_per_vertex = first->output_bits_per_vertex;
            p->packed_bytes = first->packed_bytes;
            p->stored_packed_bytes = first->stored_packed_bytes;
            p->meshlet_stats = first->meshlet_stats;
        } else if (compress_primitive(doc, args, p, err, sizeof(err))) {
            fprintf(stderr, "Error: %s: mesh %zu primitive %zu: %s\n", args->input, p->mesh, p->primitive,
                    err);
            return -1;
        }
        gltf_set_packed(doc, p->mesh, p->primitive, &p->packed);
    }
    return 0;
}

int skinpack_cmd_compress(int argc, char** argv) {
    compress_args args;
    if (parse_args(argc, argv, &args)) return 2;
    char err[CLI_ERR_SIZE];
    gltf_doc* doc = gltf_load_file(args.input, err, sizeof(err));
    if (!doc) {
        fprintf(stderr, "Error: %s: %s\n", args.input, err);
        return 1;
    }
    compressed_primitive* prims = NULL;
    int rc = 1;
    gltf_plan_output(doc, cli_output_is_binary(args.output, gltf_is_binary(doc)));
    long found = find_skinned(doc, &args, &prims);
    if (found < 0) goto done;
    size_t count = (size_t)found;
    if (count == 0) {
        size_t copied = 0;
        if (gltf_write_unchanged(doc, args.output, cli_output_is_binary(args.output, gltf_is_binary(doc)), &copied,
                                 err, sizeof(err))) {
            fprintf(stderr, "Error: %s\n", err);
            goto done;
        }
        fprintf(stderr, "Warning: %s: no skinned primitives, nothing to compress; written unchanged to %s\n",
                args.input, args.output);
        rc = 0;
        goto done;
    }
    /* Compact mode moves JOINTS_n/WEIGHTS_n out first, so that the packed arrays end the
     * accessor and bufferView lists and decompress can take them away again without a trace. */
    size_t freed = 0;
    for (size_t i = 0; i < count && args.compact; ++i) freed += make_compact(doc, &prims[i]);
    if (args.compact && freed == 0)
        fprintf(stderr, "Warning: %s: the old JOINTS_n/WEIGHTS_n bytes stay in the file (they are "
                "in an external buffer, shared, or the file uses an extension whose references skinpack does not "
                "know); the file is correct but not smaller\n", args.input);
    if (compress_all(doc, &args, prims, count)) goto done;
    gltf_declare_extension(doc, 1, args.compact);
    size_t output_bytes = 0;
    if (gltf_write_file(doc, args.output, cli_output_is_binary(args.output, gltf_is_binary(doc)), &output_bytes, err,
                        sizeof(err))) {
        fprintf(stderr, "Error: %s\n", err);
        goto done;
    }
    if (args.json)
        print_json(&args, prims, count, cli_file_size(args.input), output_bytes);
    else
        print_table(&args, prims, count, cli_file_size(args.input), output_bytes);
    rc = 0;
done:
    free(prims);
    gltf_free(doc);
    return rc;
}
