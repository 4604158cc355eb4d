/*
 * skinpack.h - compression of skinning (vertex-blend) attributes.
 *
 * Implements Kuth & Meyer, "Vertex-Blend Attribute Compression": weights are sorted in
 * descending order, the largest is dropped (recomputed as 1 - sum of the others) and the rest
 * is quantised by one of five codecs (Fixed, Unit Cube, POT AABB, Any AABB, Optimal Simplex
 * Sampling); joint tuples are replaced by an index into a per-mesh table of unique tuples.
 * Skin-aware meshlets (per-meshlet joint palettes and tuple tables) build on the same data.
 *
 * Conventions (as in meshoptimizer): every buffer is owned by the caller and sized with the
 * matching *_bound() function; nothing allocates; there is no global state, so every function
 * is thread-safe on distinct outputs. Functions that can fail return an sp_result;
 * sp_result_string() turns it into a message. "K" is the number of influences kept per vertex
 * (1..4); per-vertex arrays of influences are dense, K (or the input stride) entries a vertex.
 *
 * The format is specified in docs/extension/README.md (1.0; conformance vectors in
 * docs/extension/conformance/) and explained in docs/format.md.
 */
#ifndef SKINPACK_H
#define SKINPACK_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(_WIN32) && defined(SKINPACK_BUILD_SHARED)
#define SP_API __declspec(dllexport)
#elif defined(__GNUC__)
#define SP_API __attribute__((visibility("default")))
#else
#define SP_API
#endif

#define SP_VERSION 100 /* 1.0.0 */

#define SP_MAX_INPUT_INFLUENCES 8   /* bins of influence_histogram; the last counts 8 or more influences */
#define SP_MAX_INFLUENCES 4         /* influences kept per vertex (K) */
#define SP_MAX_JOINTS 65535         /* joint indices are stored as u16 */
#define SP_MAX_WEIGHT_BITS 64       /* largest weight code */
#define SP_MAX_VERTEX_BITS 64       /* tuple index + weight code, one or two 32-bit words */
/* Compact mode: the views of the data-less fallback buffer start this far in (2^24). A loader
 * without the extension that fetches the missing uri as "" gets the page it runs in (three.js
 * does); no page is this large, so its range check fails instead of reading the page as weights. */
#define SP_FALLBACK_VIEW_OFFSET 16777216
#define SP_ERROR_HISTOGRAM_BINS 16

typedef enum sp_result {
    SP_OK = 0,
    SP_ERR_INVALID_ARGUMENT,    /* null pointer, zero count or a parameter out of its range */
    SP_ERR_BUFFER_TOO_SMALL,    /* an output or scratch buffer is smaller than its *_bound() */
    SP_ERR_NONFINITE_WEIGHT,    /* a weight is NaN or infinite */
    SP_ERR_NEGATIVE_WEIGHT,     /* a weight is below zero */
    SP_ERR_NO_INFLUENCE,        /* a vertex has no non-zero weight */
    SP_ERR_JOINT_OUT_OF_RANGE,  /* a joint index >= joint_count */
    SP_ERR_TOO_MANY_JOINTS,     /* joint_count > SP_MAX_JOINTS */
    SP_ERR_UNSUPPORTED_METHOD,  /* unknown method, or a method/influence combination not defined */
    SP_ERR_BITS_OUT_OF_RANGE,   /* a bit budget or spacing that no configuration reaches */
    SP_ERR_CODE_OUT_OF_RANGE,   /* a weight code above the codec's max_code, or one no encoder writes (an invalid tuple) */
    SP_ERR_TUPLE_OUT_OF_RANGE,  /* a tuple index >= the tuple table size */
    SP_ERR_CORRUPT_DATA,        /* stored data violates the format (e.g. non-zero padding bits) */
    SP_ERR_LIMIT_EXCEEDED,      /* a meshlet limit that cannot be met (e.g. one triangle needs more joints than the palette) */
    /* format validation (sp_validate_packed); appended so earlier values keep their numbers */
    SP_ERR_CODE_OUTSIDE_SIMPLEX, /* a weight code <= max_code that no encoder writes (unsorted, or w1 < 0) */
    SP_ERR_DUPLICATE_JOINT,      /* a vertex decodes to the same joint twice with weight on both */
    SP_ERR_VERTEX_COUNT_MISMATCH, /* the packed vertex count differs from the primitive's */
    SP_ERR_PARAMETER_MISMATCH,   /* a declared parameter contradicts another one or the stored data */
    SP_ERR_ABI_MISMATCH,         /* the caller was built against another header (sp_check_abi) */
    SP_ERR_INDEX_OUT_OF_RANGE,   /* a stored index or offset points past the array it indexes */
    SP_RESULT_COUNT
} sp_result;

/* A static, human-readable message for a result code. Never returns NULL. */
SP_API const char* sp_result_string(sp_result result);

/* ------------------------------------------------------------------------------------------ */
/* Weight preparation                                                                          */
/* ------------------------------------------------------------------------------------------ */

typedef struct sp_prepare_stats {
    size_t vertex_count;
    size_t pruned_vertices;       /* vertices that had more than K non-zero influences */
    size_t renormalized_vertices; /* vertices whose weight sum was off by more than the tolerance */
    size_t merged_duplicates;     /* joint entries merged because a vertex listed a joint twice */
    size_t influence_histogram[SP_MAX_INPUT_INFLUENCES + 1]; /* vertices by non-zero influence count, before pruning
                                                               (the last bin: SP_MAX_INPUT_INFLUENCES or more) */
    float max_pruning_error;      /* max over vertices of the L-inf weight change caused by pruning */
    double rms_pruning_error;     /* RMS over vertices of the per-vertex pruning error */
    size_t error_vertex;          /* when the result is an error: the first offending vertex */
    uint32_t error_joint;         /* when the result is SP_ERR_JOINT_OUT_OF_RANGE: the joint index */
} sp_prepare_stats;

/*
 * Sorts each vertex's influences by descending weight (ties: lower joint index first), merges
 * duplicate joints (weights added), drops zero weights, keeps the K largest and renormalises
 * them to sum 1. Unused trailing slots get joint 0 and weight 0.
 *
 * joints, weights: vertex_count * input_stride entries (any input_stride >= 1, e.g. all of
 *   JOINTS_0..n of a glTF file side by side; the cost per vertex grows with input_stride^2).
 * joint_count: number of joints of the skin (1..SP_MAX_JOINTS); every joint index must be below it.
 * sum_tolerance: |sum - 1| above this counts the vertex in renormalized_vertices (all vertices
 *   are renormalised regardless; typical 1e-3).
 * out_joints, out_weights: vertex_count * K entries. out_pruning_error: vertex_count entries or
 *   NULL; the L-inf difference (over all input joints) between the normalised input weights and
 *   the kept, renormalised weights.
 * Errors name the first bad vertex in stats->error_vertex (stats may be NULL).
 */
SP_API sp_result sp_prepare_influences(const uint16_t* joints, const float* weights, size_t vertex_count,
                                       size_t input_stride, size_t joint_count, size_t max_influences,
                                       float sum_tolerance, uint16_t* out_joints, float* out_weights,
                                       float* out_pruning_error, sp_prepare_stats* stats);

/* ------------------------------------------------------------------------------------------ */
/* Weight codecs                                                                               */
/* ------------------------------------------------------------------------------------------ */

typedef enum sp_method {
    SP_METHOD_FIXED = 0, /* K fixed-point numbers of m bits, grid 1/(2^m-1), sum kept exactly 1 */
    SP_METHOD_CUBE = 1,  /* K-1 fixed-point numbers of m bits (unit cube sampling) */
    SP_METHOD_POT = 2,   /* the Fixed grid of m bits, w_i stored in m - floor(log2 i) bits */
    SP_METHOD_ANY = 3,   /* isotropic grid of q_i samples over [0, 1/i], mixed-radix index */
    SP_METHOD_OSS = 4,   /* optimal simplex sampling: N samples along w2, valid tuples only */
    SP_METHOD_COUNT
} sp_method;

/* A configured codec. Fill it with one of the sp_codec_from_* functions, never by hand. */
typedef struct sp_codec {
    uint32_t method;          /* sp_method */
    uint32_t influences;      /* K, 1..4: weights per vertex, including the dropped largest */
    uint32_t bits;            /* width of one weight code: ceil(log2(max_code + 1)) (0 if K = 1) */
    uint32_t component_bits[SP_MAX_INFLUENCES]; /* Fixed/Cube/POT: bits per stored weight, in code order */
    uint64_t n;               /* Fixed/Cube/POT: m (grid 1/(2^m-1)); OSS: N; Any: 0 */
    uint64_t axis_samples[SP_MAX_INFLUENCES - 1]; /* Any: q_2..q_K; else 0 */
    uint64_t scale;           /* integer grid denominator s (weights are q/s): Fixed/Cube/POT 2^m-1, OSS 2(N-1); Any 0 */
    uint64_t max_code;        /* largest valid code: codes are 0..max_code (max_code + 1 may be 2^64) */
    double code_bits;         /* log2(max_code + 1): the information content of a code */
    double max_spacing;       /* largest sample spacing along any stored weight axis (the paper's Delta) */
    double max_error;         /* proven bound of the L-inf error over all K weights for valid input */
} sp_codec;

/* The finest configuration whose codes fit in 'bits' bits (0..64). */
SP_API sp_result sp_codec_from_bits(sp_method method, uint32_t influences, uint32_t bits, sp_codec* codec);
/* The configuration with the fewest bits whose max_spacing <= max_spacing (> 0). */
SP_API sp_result sp_codec_from_spacing(sp_method method, uint32_t influences, double max_spacing, sp_codec* codec);
/* The configuration from stored parameters (n; axis_samples for Any, else NULL), validated:
 * this is how a decoder rebuilds the codec from a file. */
SP_API sp_result sp_codec_from_params(sp_method method, uint32_t influences, uint64_t n,
                                      const uint64_t* axis_samples, sp_codec* codec);
/* Bits a method needs to reach a sample spacing, without the 64-bit limit of a code (for
 * comparisons such as the paper's Table 2): *bits is the integer code width, *code_bits
 * log2 of the code count. */
SP_API sp_result sp_required_bits(sp_method method, uint32_t influences, double max_spacing, uint32_t* bits,
                                  double* code_bits);
/* Short lower-case method name ("fixed", "cube", "pot", "any", "oss"); NULL if unknown. */
SP_API const char* sp_method_name(sp_method method);
/* Parses a method name; returns SP_METHOD_COUNT if unknown. */
SP_API sp_method sp_method_from_name(const char* name);

/* OSS closed forms (exposed for tests and decoders): base index of row j of a triangle with
 * N bottom samples, samples per triangle S(N), base index u(k) of the k-th stacked triangle,
 * samples per tetrahedron T(N). Exact for every N whose T(N) fits in 64 bits. */
SP_API uint64_t sp_oss_row_base(uint64_t n, uint64_t j);
SP_API uint64_t sp_oss_triangle_count(uint64_t n);
SP_API uint64_t sp_oss_layer_base(uint64_t n, uint64_t k);
SP_API uint64_t sp_oss_tetrahedron_count(uint64_t n);

/*
 * Encodes K weights sorted in descending order and summing to 1 (as written by
 * sp_prepare_influences) into one code. Quantisation rounds to the nearest valid grid point in
 * L-inf over all K weights (largest-remainder rounding on the Fixed/Cube/POT/OSS grids), so the
 * decoded tuple is sorted, non-negative and sums to 1.
 */
SP_API uint64_t sp_encode_weights(const sp_codec* codec, const float* weights);
/* Decodes one code into K weights (descending, non-negative, summing to 1 within float
 * rounding). The code must be <= codec->max_code; sp_decode_weights_batch checks that. */
SP_API void sp_decode_weights(const sp_codec* codec, uint64_t code, float* weights);

/* Batch forms over vertex_count vertices of K weights. significant (vertex_count entries, may be
 * NULL) receives one past the last slot whose weight is non-zero after quantisation (Any can
 * leave a zero slot before a non-zero one): the remaining slots are "don't care" for the tuple
 * table. */
SP_API sp_result sp_encode_weights_batch(const sp_codec* codec, const float* weights, size_t vertex_count,
                                         uint64_t* codes, uint8_t* significant);
SP_API sp_result sp_decode_weights_batch(const sp_codec* codec, const uint64_t* codes, size_t vertex_count,
                                         float* weights, size_t* error_vertex);

/* ------------------------------------------------------------------------------------------ */
/* Joint-tuple lookup table                                                                    */
/* ------------------------------------------------------------------------------------------ */

/* Bytes of scratch memory sp_build_tuple_lut needs. */
SP_API size_t sp_tuple_lut_scratch_bound(size_t vertex_count, size_t influences);

/*
 * Builds the table of unique joint tuples (K joints each, in weight order) and the per-vertex
 * tuple index. With significant != NULL, slots at or after significant[v] are don't-care:
 * a vertex reuses any tuple whose leading joints match its significant ones. Entries are in
 * order of first use, so the output is deterministic.
 * lut: room for vertex_count * K joints (the worst case); *lut_size receives the entry count.
 */
SP_API sp_result sp_build_tuple_lut(const uint16_t* joints, const uint8_t* significant, size_t vertex_count,
                                    size_t influences, uint16_t* lut, size_t* lut_size, uint32_t* tuple_index,
                                    void* scratch, size_t scratch_size);

/* ceil(log2(count)), 0 for count <= 1: the width of an index into count entries. */
SP_API uint32_t sp_index_bits(uint64_t count);

/* ------------------------------------------------------------------------------------------ */
/* Bit packing (docs/format.md, "Vertex words")                                               */
/* ------------------------------------------------------------------------------------------ */

/* 32-bit words per vertex for a tuple index of tuple_bits and a weight code of weight_bits:
 * 1 if the sum is <= 32, 2 if <= 64, 0 if it does not fit. */
SP_API uint32_t sp_words_per_vertex(uint32_t tuple_bits, uint32_t weight_bits);
/* value = code | tuple_index << weight_bits, stored little-endian as words_per_vertex u32s. */
SP_API sp_result sp_pack_vertices(const uint32_t* tuple_index, const uint64_t* codes, size_t vertex_count,
                                  uint32_t tuple_bits, uint32_t weight_bits, uint32_t* words);
/* Inverse of sp_pack_vertices. Fails with SP_ERR_CORRUPT_DATA on set bits above
 * tuple_bits + weight_bits (error_vertex names the vertex; may be NULL). */
SP_API sp_result sp_unpack_vertices(const uint32_t* words, size_t vertex_count, uint32_t tuple_bits,
                                    uint32_t weight_bits, uint32_t* tuple_index, uint64_t* codes,
                                    size_t* error_vertex);

/* ------------------------------------------------------------------------------------------ */
/* Error metrics                                                                               */
/* ------------------------------------------------------------------------------------------ */

typedef struct sp_error_stats {
    double max_error;          /* max over vertices of the L-inf weight error */
    double rms_error;          /* RMS over vertices of the per-vertex L-inf error */
    double mean_error;
    size_t worst_vertex;
    double histogram_max;      /* upper edge of the histogram: the codec's max_error bound (or the max seen, if larger) */
    size_t histogram[SP_ERROR_HISTOGRAM_BINS]; /* vertices per bin of width histogram_max / bins */
    size_t vertices_over_bound; /* vertices whose error exceeds codec->max_error (0 for correct code) */
} sp_error_stats;

/*
 * Per-vertex L-inf error between reference weights (vertex_count * K, e.g. the prepared
 * weights) and the decoded codes, including the recomputed largest weight.
 * per_vertex (vertex_count entries) may be NULL.
 */
SP_API sp_result sp_measure_weight_errors(const sp_codec* codec, const float* reference, const uint64_t* codes,
                                          size_t vertex_count, float* per_vertex, sp_error_stats* stats);

/* Fills stats (max, RMS, mean, histogram over [0, histogram_max]) from per-vertex errors. */
SP_API void sp_summarize_errors(const float* per_vertex, size_t vertex_count, double histogram_max,
                                sp_error_stats* stats);

/* ------------------------------------------------------------------------------------------ */
/* Whole skins (container)                                                                     */
/* ------------------------------------------------------------------------------------------ */

typedef struct sp_compress_options {
    sp_method method;           /* default SP_METHOD_OSS */
    uint32_t max_influences;    /* K, 1..4; default 4 */
    uint32_t vertex_bits;       /* budget for tuple index + weight code (e.g. 32, 48, 64); 0 = unused */
    uint32_t weight_bits;       /* budget for the weight code alone; 0 = unused */
    double max_spacing;         /* target sample spacing (Delta); 0 = unused */
    int merge_dont_care;        /* share tuples that differ only in zero-weight slots (default 1) */
    float sum_tolerance;        /* see sp_prepare_influences; default 1e-3 */
    double max_error;           /* fewest weight bits whose proven bound (sp_codec.max_error) is <= this, for
                                   the K actually used (sp_codec_from_max_error); 0 = unused.
                                   Exactly one of vertex_bits, weight_bits, max_spacing, max_error is set. */
} sp_compress_options;

/* Fills the defaults: OSS, K = 4, vertex_bits = 32, merge_dont_care = 1, sum_tolerance = 1e-3. */
SP_API void sp_compress_options_default(sp_compress_options* options);

typedef struct sp_compressed_skin {
    sp_codec codec;
    uint32_t influences;        /* K actually used: min(max_influences, largest influence count) */
    uint32_t tuple_bits;
    uint32_t weight_bits;       /* == codec.bits */
    uint32_t words_per_vertex;  /* 1 or 2 */
    uint32_t joint_bytes;       /* bytes per LUT joint: 1 if joint_count <= 256, else 2 */
    size_t vertex_count;
    size_t joint_count;
    size_t lut_size;            /* unique tuples */
    double lut_bits_per_vertex; /* lut_size * K * 8 * joint_bytes / vertex_count */
    double bits_per_vertex;     /* tuple_bits + weight_bits + lut_bits_per_vertex */
    sp_prepare_stats prepare;
    sp_error_stats quantization; /* error of decoded vs prepared weights */
} sp_compressed_skin;

/* Bytes of scratch memory sp_compress_skin needs. */
SP_API size_t sp_compress_scratch_bound(size_t vertex_count, size_t input_stride);

/*
 * Prepares, quantises and packs a whole skin in one call.
 * words: vertex_count * 2 u32 (the worst case; words_per_vertex says how many are used).
 * lut: vertex_count * SP_MAX_INFLUENCES u16 (worst case; lut_size * K are used).
 * per_vertex_error: vertex_count floats (quantisation error, L-inf) or NULL.
 * per_vertex_pruning: vertex_count floats or NULL.
 */
SP_API sp_result sp_compress_skin(const uint16_t* joints, const float* weights, size_t vertex_count,
                                  size_t input_stride, size_t joint_count, const sp_compress_options* options,
                                  uint32_t* words, uint16_t* lut, float* per_vertex_error,
                                  float* per_vertex_pruning, sp_compressed_skin* result, void* scratch,
                                  size_t scratch_size);

/*
 * Decodes packed words back to K joints and K weights per vertex, validating what the words and
 * table may get wrong: codes above max_code or of invalid tuples, tuple indices >= lut_size, LUT
 * joints >= joint_count, non-zero padding bits, a joint in two weighted slots
 * (SP_ERR_DUPLICATE_JOINT). error_vertex (may be NULL) names the first bad vertex.
 * sp_validate_packed checks everything else a file may get wrong, too.
 */
SP_API sp_result sp_decompress_skin(const sp_codec* codec, const uint32_t* words, size_t vertex_count,
                                    uint32_t tuple_bits, const uint16_t* lut, size_t lut_size,
                                    size_t joint_count, uint16_t* out_joints, float* out_weights,
                                    size_t* error_vertex);

/* ---- Format rules (begin) ---- */
/* ------------------------------------------------------------------------------------------ */
/* Format rules and validation of a stored SKINPACK_packed_skin primitive                      */
/* (docs/extension/README.md is the normative text; this is its one implementation)            */
/* ------------------------------------------------------------------------------------------ */

/* SP_VERSION of the built library. A caller compares it with the SP_VERSION it was built with. */
SP_API uint32_t sp_version(void);

/* The public structs, for sp_struct_size / sp_check_abi. Appended to, never renumbered. */
typedef enum sp_struct_id {
    SP_STRUCT_CODEC = 0,
    SP_STRUCT_PREPARE_STATS,
    SP_STRUCT_ERROR_STATS,
    SP_STRUCT_COMPRESS_OPTIONS,
    SP_STRUCT_COMPRESSED_SKIN,
    SP_STRUCT_MESHLET_OPTIONS,
    SP_STRUCT_MESHLET,
    SP_STRUCT_MESHLET_SIZES,
    SP_STRUCT_MESHLET_BUFFERS,
    SP_STRUCT_MESHLET_STATS,
    SP_STRUCT_PACKED_PARAMS,
    SP_STRUCT_PACKED_MESHLETS,
    SP_STRUCT_PACKED_PRIMITIVE,
    SP_STRUCT_VALIDATION,
    SP_STRUCT_COUNT
} sp_struct_id;

/* sizeof the struct as the library was compiled; 0 for an unknown id. */
SP_API size_t sp_struct_size(sp_struct_id id);

/*
 * Checks that a caller and the library agree: version == sp_version() and, for each of the
 * first count ids, struct_sizes[id] == sp_struct_size(id) (count <= SP_STRUCT_COUNT).
 * Returns SP_OK or SP_ERR_ABI_MISMATCH; *bad_id (may be NULL) receives the first struct that
 * differs, or SP_STRUCT_COUNT when the version differs. C callers use SP_CHECK_ABI(&bad_id).
 */
SP_API sp_result sp_check_abi(uint32_t version, const size_t* struct_sizes, size_t count, uint32_t* bad_id);

/* Bytes of one tupleTable component: 1 (UNSIGNED_BYTE) if joint_count <= 256, 2 (UNSIGNED_SHORT)
 * if <= SP_MAX_JOINTS, 0 if joint_count is 0 or larger. Writers and readers both use this. */
SP_API uint32_t sp_joint_bytes(size_t joint_count);

/* The largest integer a glTF JSON number may hold exactly (2^53). Larger values of "n" and
 * "axisSamples" are written as decimal strings (sp_parse_decimal). */
#define SP_JSON_MAX_SAFE_INTEGER ((uint64_t)1 << 53)

/* Parses a JSON string value that holds a large integer: 1..20 decimal digits, no sign, no
 * leading zero, value > SP_JSON_MAX_SAFE_INTEGER and <= UINT64_MAX (smaller values must be JSON
 * numbers). length: characters of text (no NUL needed). SP_ERR_INVALID_ARGUMENT otherwise. */
SP_API sp_result sp_parse_decimal(const char* text, size_t length, uint64_t* value);

/* The fewest weight bits (0..64) of this method and K whose proven bound codec->max_error is
 * <= max_error (> 0); the one search the CLI and the add-on share. K = 1 needs 0 bits. */
SP_API sp_result sp_codec_from_max_error(sp_method method, uint32_t influences, double max_error, sp_codec* codec);

/* Which declared property or stored array a validation failure is about. */
typedef enum sp_field {
    SP_FIELD_NONE = 0,
    SP_FIELD_METHOD,
    SP_FIELD_INFLUENCES,
    SP_FIELD_JOINT_COUNT,
    SP_FIELD_WEIGHT_BITS,
    SP_FIELD_TUPLE_BITS,
    SP_FIELD_N,
    SP_FIELD_AXIS_SAMPLES,
    SP_FIELD_MAX_ERROR,
    SP_FIELD_VERTICES,          /* the "vertices" accessor (packed words) */
    SP_FIELD_TUPLE_TABLE,       /* the "tupleTable" accessor */
    SP_FIELD_MESHLET_OFFSETS,
    SP_FIELD_MESHLET_COUNTS,
    SP_FIELD_MESHLET_VERTICES,
    SP_FIELD_MESHLET_VERTEX_TUPLES,
    SP_FIELD_MESHLET_TRIANGLES,
    SP_FIELD_MESHLET_JOINTS,
    SP_FIELD_MESHLET_TUPLES,
    SP_FIELD_MESHLET_LIMITS,    /* maxVertices / maxTriangles / maxJoints */
    SP_FIELD_COUNT
} sp_field;

/* The extension property name of a field ("weightBits", "meshlets.counts"); "" for NONE. */
SP_API const char* sp_field_name(sp_field field);

/* The declared parameters of one primitive, as read from JSON. Integers are 64-bit so that a
 * reader can pass what the file says without truncating it. */
typedef struct sp_packed_params {
    uint32_t method;            /* sp_method (sp_method_from_name of "method"); SP_METHOD_COUNT if unknown */
    uint64_t influences;        /* K */
    uint64_t joint_count;       /* "jointCount" */
    uint64_t weight_bits;
    uint64_t tuple_bits;
    uint64_t n;
    uint64_t axis_samples[SP_MAX_INFLUENCES - 1];
    uint32_t axis_sample_count; /* entries of "axisSamples" (0 when absent; K - 1 for Any, else 0) */
    uint32_t has_max_error;
    double max_error;           /* "maxError" when has_max_error */
} sp_packed_params;

/* 1 if two primitives declare the same parameters (every field; axis_samples only up to
 * axis_sample_count), else 0. Primitives that share a "vertices" accessor must (docs/extension). */
SP_API int sp_packed_params_equal(const sp_packed_params* a, const sp_packed_params* b);

/* The optional meshlet arrays (docs/extension: "meshlets"), each widened to the type here. */
typedef struct sp_packed_meshlets {
    size_t meshlet_count;
    const uint32_t* offsets;       /* 4 a meshlet: vertex, triangle, joint, tuple offset */
    const uint32_t* counts;        /* 4 a meshlet (UNSIGNED_SHORT in the file): vertex, triangle, joint, tuple count */
    size_t vertex_entries;
    const uint32_t* vertices;      /* vertex_entries source vertex indices */
    const uint8_t* vertex_tuples;  /* vertex_entries local tuple indices */
    size_t triangle_bytes;         /* bytes of triangles[], 3 a triangle */
    const uint8_t* triangles;
    size_t joint_entries;
    const uint16_t* joints;        /* palettes */
    size_t tuple_count;
    const uint8_t* tuples;         /* tuple_count * K palette indices */
    uint32_t max_vertices, max_triangles, max_joints; /* declared limits; 0 when absent */
} sp_packed_meshlets;

/* Everything a reader has of one packed primitive. */
typedef struct sp_packed_primitive {
    sp_packed_params params;
    const uint32_t* words;           /* vertex_count * words_per_vertex little-endian words */
    size_t vertex_count;             /* elements of the "vertices" accessor */
    uint32_t words_per_vertex;       /* components of the "vertices" accessor (1 or 2) */
    size_t primitive_vertex_count;   /* vertices of the primitive (POSITION count) */
    const uint16_t* lut;             /* lut_size * lut_components joints (widened to u16) */
    size_t lut_size;                 /* elements of the "tupleTable" accessor */
    uint32_t lut_components;         /* its component count (must be K) */
    uint32_t lut_component_bytes;    /* 1 for UNSIGNED_BYTE, 2 for UNSIGNED_SHORT (must be sp_joint_bytes) */
    size_t skin_joint_count;         /* joints of the smallest skin of the nodes that use the mesh; 0 = none */
    const sp_packed_meshlets* meshlets; /* NULL when the primitive has none */
} sp_packed_primitive;

/* Where validation stopped. index is the vertex (VERTICES), table entry (TUPLE_TABLE), meshlet
 * (MESHLET_*) or axis (AXIS_SAMPLES); value and limit are the offending value and the bound or
 * expected value it broke (e.g. code and max_code, count and expected count). */
typedef struct sp_validation {
    sp_result result;
    uint32_t field;            /* sp_field */
    size_t index;
    uint64_t value;
    uint64_t limit;
    uint32_t slot, other_slot; /* SP_ERR_DUPLICATE_JOINT: the two weight slots */
    sp_codec codec;            /* on SP_OK: the codec the parameters describe */
} sp_validation;

/*
 * Validates one stored primitive completely and, if out_joints/out_weights are not NULL, decodes
 * it (vertex_count * K each, weight order, as sp_decompress_skin). Checks, in order: every
 * declared parameter's range and the method's rules for n/axisSamples (K = 1: n = 0, no
 * axisSamples, weightBits 0); weightBits against the codec; tupleBits against the table size;
 * words a vertex and the table's component type and count; jointCount against the skin and the
 * vertex count against the primitive; then every table joint < jointCount, and every vertex:
 * zero padding bits, tuple index < table size, code <= max_code, code inside the simplex, no
 * joint twice with weight on both; then the meshlets (offsets + counts inside the arrays, no
 * empty meshlet, declared limits, every index in range, and each meshlet vertex's palette joints
 * equal to its decoded joints wherever its weight is non-zero).
 * Returns the result also stored in report->result (report may be NULL). On failure outputs are
 * partially written and must be discarded.
 */
SP_API sp_result sp_validate_packed(const sp_packed_primitive* primitive, uint16_t* out_joints, float* out_weights,
                                    sp_validation* report);

/*
 * Writes a one-line message for a validation report into buffer (buffer_size bytes, always
 * NUL-terminated when buffer_size > 0), e.g. "vertices: weight code outside the simplex at
 * vertex 812". Returns the length the full message needs (as snprintf).
 */
SP_API size_t sp_format_validation(const sp_validation* report, char* buffer, size_t buffer_size);

/* The sizes a C caller was compiled with, for sp_check_abi. */
#define SP_STRUCT_SIZES_INIT                                                                           \
    {sizeof(sp_codec), sizeof(sp_prepare_stats), sizeof(sp_error_stats), sizeof(sp_compress_options),  \
     sizeof(sp_compressed_skin), sizeof(sp_meshlet_options), sizeof(sp_meshlet), sizeof(sp_meshlet_sizes), \
     sizeof(sp_meshlet_buffers), sizeof(sp_meshlet_stats), sizeof(sp_packed_params),                    \
     sizeof(sp_packed_meshlets), sizeof(sp_packed_primitive), sizeof(sp_validation)}
/* C only (a compound literal): sp_check_abi with the caller's own version and sizes. */
#define SP_CHECK_ABI(bad_id) \
    sp_check_abi(SP_VERSION, (const size_t[SP_STRUCT_COUNT])SP_STRUCT_SIZES_INIT, SP_STRUCT_COUNT, (bad_id))
/* ---- Format rules (end) ---- */

/* ---- Meshlets (begin) ---- */
/* ------------------------------------------------------------------------------------------ */
/* Skin-aware meshlets (docs/meshlets.md has the algorithms and the exact output layout)       */
/* ------------------------------------------------------------------------------------------ */

#define SP_MESHLET_MAX_VERTICES 255   /* local vertex indices are u8 */
#define SP_MESHLET_MAX_TRIANGLES 512
#define SP_MESHLET_MAX_JOINTS 255     /* palette indices are u8 */
#define SP_MESHLET_TRIANGLE_JOINTS 12 /* a triangle carries at most 3 vertices x 4 joints */
#define SP_MESHLET_MAX_PALETTE_EFFORT 10000 /* sp_meshlet_options.palette_effort */

typedef enum sp_meshlet_builder {
    SP_MESHLETS_NAIVE = 0,  /* thesis listing A.1: greedy in index order */
    SP_MESHLETS_COMMON = 1, /* thesis listing A.2: triangles grouped by identical joint sets */
    SP_MESHLETS_SKIN = 2,   /* ours: adjacency + proximity growth that also minimises joints */
    SP_MESHLETS_BUILDER_COUNT
} sp_meshlet_builder;

typedef struct sp_meshlet_options {
    uint32_t builder;             /* sp_meshlet_builder; default SP_MESHLETS_SKIN */
    uint32_t max_vertices;        /* 3..255, default 64 */
    uint32_t max_triangles;       /* 1..512, default 124 */
    uint32_t max_joints;          /* palette limit 1..255, default 32; every builder respects it */
    uint32_t min_group_triangles; /* SP_MESHLETS_COMMON: smaller groups go to the remainder; default 16 */
    float joint_cost;             /* SP_MESHLETS_SKIN: cost of one new palette joint in new vertices, 0..1000; default 0 */
    float tuple_cost;             /* SP_MESHLETS_SKIN: cost of one new local LUT tuple in new vertices, 0..1000; default 0 */
    /* SP_MESHLETS_SKIN: extra work for smaller palettes, 0..SP_MESHLET_MAX_PALETTE_EFFORT; default 0
     * (none). After the build, palette_effort x triangles random moves of a border triangle to a
     * neighbouring meshlet are tried; one is kept when it passes no limit and adds no joint to
     * that meshlet's palette. The palette sum and the meshlet count never rise; the time grows
     * with the effort (docs/meshlets.md). The same input gives the same meshlets. */
    uint32_t palette_effort;
} sp_meshlet_options;

/* Fills the defaults listed above. */
SP_API void sp_meshlet_options_default(sp_meshlet_options* options);

/* SP_OK if every field is in the range listed above (what sp_build_meshlets accepts), else
 * SP_ERR_INVALID_ARGUMENT. Front ends call it to refuse bad limits before any work. */
SP_API sp_result sp_check_meshlet_options(const sp_meshlet_options* options);

/*
 * One meshlet. Its data lies in the shared arrays of sp_meshlet_buffers:
 *   vertices[vertex_offset + i], vertex_tuples[vertex_offset + i]  (i < vertex_count)
 *   triangles[3 * triangle_offset + 3 * t + c]                      (t < triangle_count, c < 3)
 *   joints[joint_offset + p]                                        (p < joint_count)
 *   tuples[K * tuple_offset + K * u + s]                            (u < tuple_count, s < K)
 * Vertex i's joint in weight slot s is joints[joint_offset + tuples[K * (tuple_offset +
 * vertex_tuples[vertex_offset + i]) + s]]; slots whose weight is zero hold palette index 0.
 * Palettes and LUTs list entries in order of first use along the vertex list. Arrays are packed
 * in meshlet order. Meshlet of source triangle t: see sp_meshlet_buffers.triangle_meshlet.
 */
typedef struct sp_meshlet {
    uint32_t vertex_offset;   /* first entry in vertices[] and vertex_tuples[] */
    uint32_t triangle_offset; /* first triangle (3 bytes each) in triangles[] */
    uint32_t joint_offset;    /* first entry in joints[] (the palette) */
    uint32_t tuple_offset;    /* first tuple (K bytes each) in tuples[] (the local tuple LUT) */
    uint16_t vertex_count;
    uint16_t triangle_count;
    uint16_t joint_count;     /* distinct joints with non-zero weight on the meshlet's vertices */
    uint16_t tuple_count;     /* distinct local tuples */
    uint32_t tuple_bits;      /* sp_index_bits(tuple_count): bits of a vertex's local tuple index */
    float center[3];          /* bounding sphere of the bind-pose vertices */
    float radius;
    float cone_apex[3];       /* normal cone as meshopt_Bounds: back-facing from camera c if */
    float cone_axis[3];       /* dot(normalize(cone_apex - c), cone_axis) >= cone_cutoff */
    float cone_cutoff;        /* 1 when the cone is too wide to cull */
} sp_meshlet;

/* Capacities (in elements) of the output arrays, and the scratch size in bytes. */
typedef struct sp_meshlet_sizes {
    size_t meshlets;
    size_t vertices;    /* entries of vertices[] and of vertex_tuples[] */
    size_t triangles;   /* triangles; triangles[] holds 3 bytes each */
    size_t joints;      /* entries of joints[] */
    size_t tuples;      /* tuples; tuples[] holds K bytes each */
    size_t scratch_bytes;
} sp_meshlet_sizes;

/* Caller-owned output arrays; capacity says how many elements each one holds. */
typedef struct sp_meshlet_buffers {
    sp_meshlet* meshlets;
    uint32_t* vertices;         /* source vertex indices */
    uint8_t* vertex_tuples;     /* local tuple index of each meshlet vertex */
    uint8_t* triangles;         /* local vertex indices, 3 per triangle */
    uint16_t* joints;           /* palettes: joint indices */
    uint8_t* tuples;            /* local tuple LUTs: K palette indices per tuple */
    uint32_t* triangle_meshlet; /* optional (NULL): meshlet of each source triangle */
    sp_meshlet_sizes capacity;  /* scratch_bytes is ignored here */
} sp_meshlet_buffers;

typedef struct sp_meshlet_stats {
    size_t meshlet_count;
    size_t vertex_count, triangle_count, joint_count, tuple_count; /* elements written per array */
    uint32_t max_vertices, max_triangles, max_joints;              /* largest meshlet values */
    double mean_vertices, mean_triangles, mean_joints;
    size_t global_tuples;         /* unique K-joint tuples over the whole mesh (zero-weight slots as joint 0) */
    uint32_t global_tuple_bits;   /* sp_index_bits(global_tuples) */
    double local_tuple_bits_mean; /* mean over meshlet vertex entries of their meshlet's tuple_bits */
    uint32_t local_tuple_bits_max;
    size_t error_triangle;        /* SP_ERR_LIMIT_EXCEEDED / SP_ERR_INVALID_ARGUMENT: the offending triangle */
} sp_meshlet_stats;

/* Worst-case capacities and scratch bytes for sp_build_meshlets with these options (NULL:
 * defaults). The bound holds for every builder: a meshlet has at least one triangle. */
SP_API void sp_meshlets_bound(size_t index_count, size_t vertex_count, size_t influences,
                              const sp_meshlet_options* options, sp_meshlet_sizes* sizes);

/*
 * Splits a triangle list into meshlets with per-meshlet joint palettes and local tuple LUTs.
 * indices: index_count entries (a multiple of 3), each < vertex_count.
 * vertex_positions: float3 at the start of each vertex_positions_stride bytes (>= 12, multiple of 4).
 * joints, weights: K = influences (1..4) entries per vertex, as written by sp_prepare_influences
 *   (weight order; a slot counts as used when its weight is > 0).
 * Every triangle lands in exactly one meshlet; every meshlet respects max_vertices,
 * max_triangles and max_joints. Output is deterministic. A triangle whose vertices use more
 * joints than max_joints fails with SP_ERR_LIMIT_EXCEEDED, stats->error_triangle naming it
 * (stats may be NULL). Output buffers smaller than sp_meshlets_bound: SP_ERR_BUFFER_TOO_SMALL.
 */
SP_API sp_result sp_build_meshlets(const uint32_t* indices, size_t index_count, const float* vertex_positions,
                                   size_t vertex_count, size_t vertex_positions_stride, const uint16_t* joints,
                                   const float* weights, size_t influences, const sp_meshlet_options* options,
                                   sp_meshlet_buffers* out, void* scratch, size_t scratch_size,
                                   sp_meshlet_stats* stats);
/* ---- Meshlets (end) ---- */

#ifdef __cplusplus
}
#endif

#endif /* SKINPACK_H */
