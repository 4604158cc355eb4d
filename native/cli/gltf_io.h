/*
 * gltf_io.h - the small C view of a glTF document that the CLI commands work on.
 *
 * gltf_read.cpp, gltf_extension.cpp and gltf_edit.cpp implement it (the only C++ in the CLI;
 * gltf_doc.hpp). Reads go through tinygltf's model of the input; edits change the input's own
 * JSON in place, so everything skinpack does not own is written back as it was read, and new
 * binary data is appended. The commands never see tinygltf or JSON types: they read skin
 * attributes into flat arrays, hand flat arrays back as accessors and set or read the
 * SKINPACK_packed_skin extension as a plain struct. Everything read from a file is
 * bounds-checked here, so a command can trust what it gets.
 *
 * Functions that can fail return 0 on success and -1 on failure, with a message in err
 * (err_size bytes, always NUL-terminated).
 */
#ifndef SKINPACK_GLTF_IO_H
#define SKINPACK_GLTF_IO_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define GLTF_EXTENSION_NAME "SKINPACK_packed_skin"
#define GLTF_MAX_SKIN_SETS 2 /* JOINTS_0/WEIGHTS_0 and JOINTS_1/WEIGHTS_1: up to 8 influences */

/* glTF componentType values. */
#define GLTF_BYTE 5120
#define GLTF_UNSIGNED_BYTE 5121
#define GLTF_SHORT 5122
#define GLTF_UNSIGNED_SHORT 5123
#define GLTF_UNSIGNED_INT 5125
#define GLTF_FLOAT 5126

typedef struct gltf_doc gltf_doc;

/* Loads .gltf (external or data-URI buffers) or .glb, decided by the file's magic bytes. */
gltf_doc* gltf_load_file(const char* path, char* err, size_t err_size);
/* Same from memory (no external files can be resolved). Used by the fuzzers. */
gltf_doc* gltf_load_memory(const void* data, size_t size, char* err, size_t err_size);
void gltf_free(gltf_doc* doc);

int gltf_is_binary(const gltf_doc* doc);
/* Joints of the skin(s) of the nodes that use the mesh (the smallest, if several); 0 if none. */
size_t gltf_mesh_joint_count(const gltf_doc* doc, size_t mesh);
size_t gltf_mesh_count(const gltf_doc* doc);
size_t gltf_primitive_count(const gltf_doc* doc, size_t mesh);

/* The standard skinning attributes of one primitive. */
typedef struct gltf_skin_attributes {
    int joints[GLTF_MAX_SKIN_SETS];  /* accessor indices, -1 when absent */
    int weights[GLTF_MAX_SKIN_SETS];
    size_t sets;                     /* JOINTS_n/WEIGHTS_n pairs present (0, 1 or 2) */
    size_t vertex_count;
    size_t joint_count;              /* joints of the skin(s) whose nodes use this mesh; 0 if none */
    double stored_bits_per_vertex;   /* bits of all JOINTS_n + WEIGHTS_n elements, as stored */
    int placeholder;                 /* 1: the accessors have no data (compact mode: they lie in a fallback
                                        buffer, the data is in SKINPACK_packed_skin) */
} gltf_skin_attributes;

/*
 * Finds JOINTS_n/WEIGHTS_n of a primitive and checks their accessors (types, ranges, that each
 * JOINTS_n has its WEIGHTS_n, equal counts). Returns 1 if the primitive has them, 0 if not,
 * -1 on a malformed primitive.
 */
int gltf_primitive_skin(const gltf_doc* doc, size_t mesh, size_t primitive, gltf_skin_attributes* attributes,
                        char* err, size_t err_size);

/*
 * Reads the attributes as vertex_count * 4 * sets joints and weights (normalised integer
 * weights become floats in [0, 1]). Checks joints < joint_count (when joint_count > 0).
 */
int gltf_read_skin(const gltf_doc* doc, const gltf_skin_attributes* attributes, uint16_t* joints, float* weights,
                   char* err, size_t err_size);

/* The optional "meshlets" object of the extension: accessor indices and the builder's limits. */
typedef struct gltf_packed_meshlets {
    int present;
    int offsets, counts, bounds, cones; /* one element a meshlet; cones may be -1 */
    int vertices, vertex_tuples, triangles, joints, tuples;
    uint32_t max_vertices, max_triangles, max_joints;
} gltf_packed_meshlets;

/* The JSON of the extension on one primitive (docs/extension/README.md). */
typedef struct gltf_packed_skin {
    int vertices;             /* accessor: UNSIGNED_INT SCALAR (1 word a vertex) or VEC2 (2 words) */
    int tuple_table;          /* accessor: UNSIGNED_BYTE/UNSIGNED_SHORT, SCALAR..VEC4 for K = 1..4 */
    uint32_t influences;      /* K */
    uint32_t joint_count;
    uint32_t method;          /* sp_method */
    uint64_t n;
    uint64_t axis_samples[3]; /* only for any: q2..qK */
    uint32_t axis_sample_count; /* entries of "axisSamples" (0 when absent) */
    uint32_t weight_bits;
    uint32_t tuple_bits;
    double max_error;         /* informative */
    gltf_packed_meshlets meshlets;
} gltf_packed_skin;

/* Returns 1 and fills packed if the primitive has the extension (JSON types checked), 0 if not,
 * -1 if it is malformed. */
int gltf_get_packed(const gltf_doc* doc, size_t mesh, size_t primitive, gltf_packed_skin* packed, char* err,
                    size_t err_size);

/* Checks the extension's accessors against its JSON and reports their sizes. */
int gltf_packed_sizes(const gltf_doc* doc, const gltf_packed_skin* packed, size_t* vertex_count,
                      uint32_t* words_per_vertex, size_t* lut_size, char* err, size_t err_size);
/* Reads vertex_count * words_per_vertex words and lut_size * K joints (as u16). */
int gltf_read_packed(const gltf_doc* doc, const gltf_packed_skin* packed, uint32_t* words, uint16_t* lut,
                     char* err, size_t err_size);

/* The primitive's POSITION count (0 when it has no valid POSITION accessor). */
size_t gltf_primitive_vertex_count(const gltf_doc* doc, size_t mesh, size_t primitive);

/* Triangle-list geometry of a primitive: index count (vertex count when not indexed) and the
 * POSITION accessor. Fails for modes other than TRIANGLES. */
int gltf_primitive_triangles(const gltf_doc* doc, size_t mesh, size_t primitive, size_t* index_count,
                             size_t* vertex_count, char* err, size_t err_size);
/* 1 if two primitives use the same indices, POSITION accessor and mode. */
int gltf_same_geometry(const gltf_doc* doc, size_t mesh_a, size_t primitive_a, size_t mesh_b, size_t primitive_b);
/* Reads index_count indices (each checked < vertex_count) and vertex_count float3 positions. */
int gltf_read_triangles(const gltf_doc* doc, size_t mesh, size_t primitive, uint32_t* indices, float* positions,
                        char* err, size_t err_size);

/* Checks that an accessor has this componentType and component count and returns its element
 * count; with out != NULL also reads count * components values (as integers, or as the float
 * bits when component_type is FLOAT). */
int gltf_read_accessor_u32(const gltf_doc* doc, int accessor, int component_type, int components, size_t* count,
                           uint32_t* out, char* err, size_t err_size);

/* ---- editing (the input's JSON, changed in place; nothing is renumbered) ---- */

#define GLTF_ACCESSOR_VERTEX_ATTRIBUTE 1 /* bufferView target ARRAY_BUFFER */
#define GLTF_ACCESSOR_BOUNDS 2           /* write min/max computed from the data */
#define GLTF_ACCESSOR_MESHOPT 4          /* gltf_add_accessor only: meshopt-compress the view if smaller */

/*
 * Appends an accessor over a new, 4-byte-aligned bufferView holding count elements of
 * components components each (tightly packed, little-endian), appended to the file's binary
 * data. flags: GLTF_ACCESSOR_*. data NULL puts the view in the fallback buffer (a buffer with
 * no data, marked {"fallback": true} in the extension). Returns the accessor index.
 *
 * GLTF_ACCESSOR_MESHOPT: when an element is a multiple of 4 bytes and meshoptimizer's vertex
 * codec makes the bytes smaller, only the encoded bytes are appended; the view itself lies in a
 * data-less meshopt fallback buffer and carries EXT_meshopt_compression (ATTRIBUTES mode;
 * KHR_meshopt_compression when the input uses that), which becomes used and required.
 */
int gltf_add_accessor(gltf_doc* doc, const void* data, size_t count, int component_type, int components,
                      int normalized, int flags);
/* The kind of file doc will be written as (1: .glb); GLTF_ACCESSOR_MESHOPT weighs the JSON and
 * base64 sizes of that kind. Default: the input's kind. */
void gltf_plan_output(gltf_doc* doc, int binary);
/* 1 if this build can write meshopt-compressed views (libmeshoptimizer, vertex codec version 0). */
int gltf_meshopt_supported(void);
/* Bytes an accessor's view occupies in the file: its meshopt-compressed length, or byteLength. */
size_t gltf_stored_view_bytes(const gltf_doc* doc, int accessor);

/*
 * Gives an existing accessor new data (its index, name, extras and extensions stay). When only
 * this accessor uses its bufferView, the view is reused and its old bytes are cut from the
 * buffer if skinpack writes that buffer (GLB BIN chunk, data: uri). Returns the bytes freed.
 */
size_t gltf_replace_accessor_data(gltf_doc* doc, int accessor, const void* data, size_t count, int component_type,
                                  int components, int normalized, int flags);
/* The same with data NULL: the accessor keeps its description, its data moves to the fallback
 * buffer (compact mode). Returns the bytes freed. */
size_t gltf_make_fallback(gltf_doc* doc, int accessor);

/* Writes the extension object on the primitive / removes it. */
void gltf_set_packed(gltf_doc* doc, size_t mesh, size_t primitive, const gltf_packed_skin* packed);
void gltf_remove_packed(gltf_doc* doc, size_t mesh, size_t primitive);
/* Removes JOINTS_n/WEIGHTS_n from the primitive. */
void gltf_remove_skin_attributes(gltf_doc* doc, size_t mesh, size_t primitive);
/* Sets JOINTS_0/WEIGHTS_0 (removing any JOINTS_n/WEIGHTS_n with n > 0 first). */
void gltf_set_skin_attributes(gltf_doc* doc, size_t mesh, size_t primitive, int joints, int weights);
/* Adds or removes the extension name in extensionsUsed / extensionsRequired. */
void gltf_declare_extension(gltf_doc* doc, int used, int required);

/*
 * Removes accessors at the end of the array that nothing refers to and that are listed in
 * removable (the extension's, when decompress drops it), then their bufferViews and bytes.
 * Does nothing when the file uses an extension whose references are unknown. Returns the
 * bytes freed.
 */
size_t gltf_remove_unused_tail(gltf_doc* doc, const int* removable, size_t removable_count);

/* After decompress: accessors nothing uses that still lie in the input's fallback buffer lose
 * their bufferView, and unused views there point at 4 new bytes, so the buffer can go. */
void gltf_release_fallback(gltf_doc* doc);

/* Serialises the document (.glb if binary, else .gltf with new data in data: uris). The caller
 * frees *data with free(). */
int gltf_serialize(const gltf_doc* doc, int binary, void** data, size_t* size, char* err, size_t err_size);

/*
 * Writes to path via a temporary file in the same folder, renamed only on success; no partial
 * file is left behind on failure. Relative uris are rewritten to stay valid from path's folder.
 */
int gltf_write_file(const gltf_doc* doc, const char* path, int binary, size_t* bytes_written, char* err,
                    size_t err_size);
/* For a document with nothing to change: copies the input's bytes exactly when path is of the
 * same kind (and, for .gltf, in the same folder), else writes it as gltf_write_file does. */
int gltf_write_unchanged(const gltf_doc* doc, const char* path, int binary, size_t* bytes_written, char* err,
                         size_t err_size);

#ifdef __cplusplus
}
#endif

#endif /* SKINPACK_GLTF_IO_H */
