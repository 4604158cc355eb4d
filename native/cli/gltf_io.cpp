// gltf_io.cpp - gltf_io.h on top of tinygltf (Debian's libtinygltf). The only C++ in the CLI:
// it turns tinygltf's model into checked flat arrays and back, and knows nothing about codecs.
#include "gltf_io.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

struct gltf_doc {
    tinygltf::Model model;
    bool binary = false;
};

static int fail(char* err, size_t err_size, const char* format, ...) {
    if (err && err_size) {
        va_list args;
        va_start(args, format);
        vsnprintf(err, err_size, format, args);
        va_end(args);
    }
    return -1;
}

// Images are passed through as stored (bufferView or uri): never decoded, never re-encoded.
static bool keep_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
                       void*) {
    return true;
}
static bool keep_image_uri(const std::string*, const std::string*, const tinygltf::Image*, bool, std::string*, void*) {
    return false; // "not written": the writer keeps the original uri
}

static gltf_doc* load(const unsigned char* bytes, size_t size, const std::string& base_dir, char* err,
                      size_t err_size) {
    if (size < 4) {
        fail(err, err_size, "file is too small to be glTF (%zu bytes)", size);
        return nullptr;
    }
    if (size > 0xffffffffu) {
        fail(err, err_size, "file is larger than 4 GiB");
        return nullptr;
    }
    gltf_doc* doc = new gltf_doc();
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(keep_image, nullptr);
    std::string error, warning;
    bool ok = false;
    doc->binary = memcmp(bytes, "glTF", 4) == 0;
    try {
        if (doc->binary)
            ok = loader.LoadBinaryFromMemory(&doc->model, &error, &warning, bytes, unsigned(size), base_dir);
        else
            ok = loader.LoadASCIIFromString(&doc->model, &error, &warning, reinterpret_cast<const char*>(bytes),
                                            unsigned(size), base_dir);
    } catch (const std::exception& e) {
        error = e.what();
        ok = false;
    }
    if (!ok) {
        while (!error.empty() && (error.back() == '\n' || error.back() == ' ')) error.pop_back();
        fail(err, err_size, "not a readable glTF file: %s", error.empty() ? "parse error" : error.c_str());
        delete doc;
        return nullptr;
    }
    // Geometry-compression extensions keep the real bytes elsewhere; reading the fallback
    // buffers would give garbage or nothing.
    for (const std::string& name : doc->model.extensionsRequired) {
        if (name == "KHR_draco_mesh_compression" || name == "EXT_meshopt_compression" ||
            name == "KHR_meshopt_compression") {
            fail(err, err_size, "the file requires %s, which skinpack cannot decode (write it without compression, "
                 "e.g. gltfpack without -c)", name.c_str());
            delete doc;
            return nullptr;
        }
    }
    // tinygltf does not check every bufferView against the bytes it actually loaded: do it
    // here, so a truncated GLB or .bin is an error and never an out-of-range read later.
    for (size_t i = 0; i < doc->model.bufferViews.size(); ++i) {
        const tinygltf::BufferView& view = doc->model.bufferViews[i];
        if (view.buffer < 0 || size_t(view.buffer) >= doc->model.buffers.size()) {
            fail(err, err_size, "bufferView %zu refers to buffer %d, which does not exist", i, view.buffer);
            delete doc;
            return nullptr;
        }
        size_t have = doc->model.buffers[size_t(view.buffer)].data.size();
        if (view.byteOffset > have || view.byteLength > have - view.byteOffset) {
            fail(err, err_size, "bufferView %zu (bytes %zu..%zu) lies outside buffer %d (%zu bytes): missing or "
                 "truncated buffer", i, view.byteOffset, view.byteOffset + view.byteLength, view.buffer, have);
            delete doc;
            return nullptr;
        }
    }
    return doc;
}

extern "C" gltf_doc* gltf_load_file(const char* path, char* err, size_t err_size) {
    std::ifstream file(path, std::ios::binary);
    if (!file) {
        fail(err, err_size, "cannot open %s: %s", path, strerror(errno));
        return nullptr;
    }
    std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    if (file.bad()) {
        fail(err, err_size, "cannot read %s", path);
        return nullptr;
    }
    std::string dir(path);
    size_t slash = dir.find_last_of('/');
    dir = slash == std::string::npos ? std::string(".") : dir.substr(0, slash);
    return load(bytes.data(), bytes.size(), dir, err, err_size);
}

extern "C" gltf_doc* gltf_load_memory(const void* data, size_t size, char* err, size_t err_size) {
    // An empty base_dir would let tinygltf resolve relative uris against the working folder.
    return load(static_cast<const unsigned char*>(data), size, "/nonexistent-skinpack-memory", err, err_size);
}

extern "C" void gltf_free(gltf_doc* doc) { delete doc; }
extern "C" int gltf_is_binary(const gltf_doc* doc) { return doc->binary; }
extern "C" size_t gltf_mesh_count(const gltf_doc* doc) { return doc->model.meshes.size(); }
extern "C" size_t gltf_primitive_count(const gltf_doc* doc, size_t mesh) {
    return doc->model.meshes[mesh].primitives.size();
}

// ---- accessors ----

static size_t component_size(int component_type) {
    switch (component_type) {
    case GLTF_BYTE: case GLTF_UNSIGNED_BYTE: return 1;
    case GLTF_SHORT: case GLTF_UNSIGNED_SHORT: return 2;
    case GLTF_UNSIGNED_INT: case GLTF_FLOAT: return 4;
    default: return 0;
    }
}

static size_t type_components(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
    }
}

static int type_for_components(int components) {
    static const int types[] = {0, TINYGLTF_TYPE_SCALAR, TINYGLTF_TYPE_VEC2, TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4};
    return types[components];
}

// A checked view of an accessor's elements: element i starts at data + i * stride.
struct element_view {
    const unsigned char* data;
    size_t stride;
    size_t count;
    size_t components;
    int component_type;
    bool normalized;
};

static int view_accessor(const tinygltf::Model& model, int index, const char* what, element_view* view, char* err,
                         size_t err_size) {
    if (index < 0 || size_t(index) >= model.accessors.size())
        return fail(err, err_size, "%s refers to accessor %d, which does not exist", what, index);
    const tinygltf::Accessor& accessor = model.accessors[size_t(index)];
    if (accessor.sparse.isSparse)
        return fail(err, err_size, "%s (accessor %d) is sparse, which is not supported here", what, index);
    size_t csize = component_size(accessor.componentType);
    size_t comps = type_components(accessor.type);
    if (!csize || !comps)
        return fail(err, err_size, "%s (accessor %d) has an invalid componentType or type", what, index);
    if (accessor.count == 0) return fail(err, err_size, "%s (accessor %d) has count 0", what, index);
    if (accessor.bufferView < 0 || size_t(accessor.bufferView) >= model.bufferViews.size())
        return fail(err, err_size, "%s (accessor %d) has no valid bufferView (%d)", what, index, accessor.bufferView);
    const tinygltf::BufferView& bv = model.bufferViews[size_t(accessor.bufferView)];
    size_t element = csize * comps;
    size_t stride = bv.byteStride ? bv.byteStride : element;
    if (stride < element)
        return fail(err, err_size, "%s (accessor %d): byteStride %zu is smaller than an element (%zu bytes)", what,
                    index, stride, element);
    // offset + (count - 1) * stride + element <= byteLength, without overflow.
    if (accessor.byteOffset > bv.byteLength || (accessor.count - 1) > (SIZE_MAX - element) / stride ||
        (accessor.count - 1) * stride + element > bv.byteLength - accessor.byteOffset)
        return fail(err, err_size, "%s (accessor %d, %zu elements) points past the end of bufferView %d (%zu bytes)",
                    what, index, accessor.count, accessor.bufferView, bv.byteLength);
    if ((bv.byteOffset + accessor.byteOffset) % csize != 0)
        return fail(err, err_size, "%s (accessor %d) is not aligned to its component size", what, index);
    view->data = model.buffers[size_t(bv.buffer)].data.data() + bv.byteOffset + accessor.byteOffset;
    view->stride = stride;
    view->count = accessor.count;
    view->components = comps;
    view->component_type = accessor.componentType;
    view->normalized = accessor.normalized;
    return 0;
}

static double read_component(const element_view& view, size_t element, size_t component) {
    const unsigned char* p = view.data + element * view.stride + component * component_size(view.component_type);
    switch (view.component_type) {
    case GLTF_UNSIGNED_BYTE: {
        uint8_t v = *p;
        return view.normalized ? v / 255.0 : v;
    }
    case GLTF_UNSIGNED_SHORT: {
        uint16_t v;
        memcpy(&v, p, 2);
        return view.normalized ? v / 65535.0 : v;
    }
    case GLTF_UNSIGNED_INT: {
        uint32_t v;
        memcpy(&v, p, 4);
        return v;
    }
    case GLTF_FLOAT: {
        float v;
        memcpy(&v, p, 4);
        return v;
    }
    case GLTF_BYTE: {
        int8_t v;
        memcpy(&v, p, 1);
        return view.normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case GLTF_SHORT: {
        int16_t v;
        memcpy(&v, p, 2);
        return view.normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    }
    return 0;
}

// ---- skins ----

static size_t mesh_joint_count(const tinygltf::Model& model, size_t mesh) {
    size_t joints = 0;
    for (const tinygltf::Node& node : model.nodes) {
        if (node.mesh != int(mesh) || node.skin < 0 || size_t(node.skin) >= model.skins.size()) continue;
        size_t n = model.skins[size_t(node.skin)].joints.size();
        joints = joints == 0 ? n : std::min(joints, n); // indices must be valid for every skin using the mesh
    }
    return joints;
}

extern "C" size_t gltf_mesh_joint_count(const gltf_doc* doc, size_t mesh) {
    return mesh_joint_count(doc->model, mesh);
}

static int find_attribute(const tinygltf::Primitive& primitive, const std::string& name) {
    auto it = primitive.attributes.find(name);
    return it == primitive.attributes.end() ? -1 : it->second;
}

extern "C" int gltf_primitive_skin(const gltf_doc* doc, size_t mesh, size_t primitive,
                                   gltf_skin_attributes* attributes, char* err, size_t err_size) {
    const tinygltf::Model& model = doc->model;
    const tinygltf::Primitive& prim = model.meshes[mesh].primitives[primitive];
    memset(attributes, 0, sizeof(*attributes));
    for (size_t s = 0; s < GLTF_MAX_SKIN_SETS; ++s) {
        attributes->joints[s] = find_attribute(prim, "JOINTS_" + std::to_string(s));
        attributes->weights[s] = find_attribute(prim, "WEIGHTS_" + std::to_string(s));
    }
    for (const auto& attribute : prim.attributes) {
        const std::string& name = attribute.first;
        if ((name.rfind("JOINTS_", 0) == 0 || name.rfind("WEIGHTS_", 0) == 0) && name != "JOINTS_0" &&
            name != "JOINTS_1" && name != "WEIGHTS_0" && name != "WEIGHTS_1")
            return fail(err, err_size, "mesh %zu primitive %zu: %s is not supported (at most 8 influences, "
                        "JOINTS_0/1 and WEIGHTS_0/1)", mesh, primitive, name.c_str());
    }
    for (size_t s = 0; s < GLTF_MAX_SKIN_SETS; ++s) {
        bool j = attributes->joints[s] >= 0, w = attributes->weights[s] >= 0;
        if (j != w)
            return fail(err, err_size, "mesh %zu primitive %zu: %s_%zu without %s_%zu", mesh, primitive,
                        j ? "JOINTS" : "WEIGHTS", s, j ? "WEIGHTS" : "JOINTS", s);
        if (j) {
            if (attributes->sets != s)
                return fail(err, err_size, "mesh %zu primitive %zu: JOINTS_%zu without JOINTS_%zu", mesh, primitive,
                            s, s - 1);
            attributes->sets = s + 1;
        }
    }
    if (attributes->sets == 0) return 0;

    // Compact mode keeps the attribute names on accessors without data (see gltf_io.h).
    size_t dataless = 0;
    for (size_t s = 0; s < attributes->sets; ++s)
        for (int index : {attributes->joints[s], attributes->weights[s]}) {
            if (index < 0 || size_t(index) >= model.accessors.size())
                return fail(err, err_size, "mesh %zu primitive %zu: accessor %d does not exist", mesh, primitive, index);
            const tinygltf::Accessor& a = model.accessors[size_t(index)];
            dataless += a.bufferView < 0 && !a.sparse.isSparse;
        }
    if (dataless) {
        if (dataless != 2 * attributes->sets)
            return fail(err, err_size, "mesh %zu primitive %zu: some JOINTS_n/WEIGHTS_n accessors have data and some "
                        "not", mesh, primitive);
        attributes->placeholder = 1;
        attributes->vertex_count = model.accessors[size_t(attributes->joints[0])].count;
        attributes->joint_count = mesh_joint_count(model, mesh);
        return 1;
    }

    double bits = 0;
    for (size_t s = 0; s < attributes->sets; ++s) {
        char what[64];
        element_view jv, wv;
        snprintf(what, sizeof(what), "mesh %zu primitive %zu JOINTS_%zu", mesh, primitive, s);
        if (view_accessor(model, attributes->joints[s], what, &jv, err, err_size)) return -1;
        if (jv.components != 4 || model.accessors[size_t(attributes->joints[s])].type != TINYGLTF_TYPE_VEC4 ||
            (jv.component_type != GLTF_UNSIGNED_BYTE && jv.component_type != GLTF_UNSIGNED_SHORT) || jv.normalized)
            return fail(err, err_size, "%s must be VEC4 of unnormalised UNSIGNED_BYTE or UNSIGNED_SHORT", what);
        snprintf(what, sizeof(what), "mesh %zu primitive %zu WEIGHTS_%zu", mesh, primitive, s);
        if (view_accessor(model, attributes->weights[s], what, &wv, err, err_size)) return -1;
        bool float_ok = wv.component_type == GLTF_FLOAT && !wv.normalized;
        bool int_ok = (wv.component_type == GLTF_UNSIGNED_BYTE || wv.component_type == GLTF_UNSIGNED_SHORT) &&
                      wv.normalized;
        if (wv.components != 4 || model.accessors[size_t(attributes->weights[s])].type != TINYGLTF_TYPE_VEC4 ||
            !(float_ok || int_ok))
            return fail(err, err_size, "%s must be VEC4 of FLOAT or normalised UNSIGNED_BYTE/UNSIGNED_SHORT", what);
        if (jv.count != wv.count || (s > 0 && jv.count != attributes->vertex_count))
            return fail(err, err_size, "mesh %zu primitive %zu: JOINTS_n and WEIGHTS_n counts differ", mesh,
                        primitive);
        attributes->vertex_count = jv.count;
        bits += 32.0 * double(component_size(jv.component_type) + component_size(wv.component_type));
    }
    attributes->stored_bits_per_vertex = bits;
    attributes->joint_count = mesh_joint_count(model, mesh);
    return 1;
}

extern "C" int gltf_read_skin(const gltf_doc* doc, const gltf_skin_attributes* attributes, uint16_t* joints,
                              float* weights, char* err, size_t err_size) {
    const tinygltf::Model& model = doc->model;
    size_t stride = 4 * attributes->sets;
    for (size_t s = 0; s < attributes->sets; ++s) {
        element_view jv, wv;
        if (view_accessor(model, attributes->joints[s], "JOINTS", &jv, err, err_size) ||
            view_accessor(model, attributes->weights[s], "WEIGHTS", &wv, err, err_size))
            return -1;
        for (size_t v = 0; v < attributes->vertex_count; ++v) {
            for (size_t c = 0; c < 4; ++c) {
                double j = read_component(jv, v, c);
                double w = read_component(wv, v, c);
                if (attributes->joint_count && j >= double(attributes->joint_count))
                    return fail(err, err_size, "vertex %zu: JOINTS_%zu joint index %.0f is past the skin's %zu "
                                "joints", v, s, j, attributes->joint_count);
                if (!std::isfinite(w) || w < 0)
                    return fail(err, err_size, "vertex %zu: WEIGHTS_%zu weight %g is %s", v, s, w,
                                std::isfinite(w) ? "negative" : "not a finite number");
                joints[v * stride + s * 4 + c] = uint16_t(j);
                weights[v * stride + s * 4 + c] = float(w);
            }
        }
    }
    return 0;
}

// ---- the extension JSON ----

// A JSON number that must be an integer in [lo, hi] (doubles are exact up to 2^53).
static int json_integer(const tinygltf::Value& object, const char* key, double lo, double hi, bool required,
                        uint64_t* out, char* err, size_t err_size) {
    if (!object.Has(key)) {
        if (required) return fail(err, err_size, GLTF_EXTENSION_NAME ": missing \"%s\"", key);
        return 0;
    }
    const tinygltf::Value& value = object.Get(key);
    double d = value.IsNumber() ? value.GetNumberAsDouble() : NAN;
    if (!value.IsNumber() || !std::isfinite(d) || d != std::floor(d) || d < lo || d > hi)
        return fail(err, err_size, GLTF_EXTENSION_NAME ": \"%s\" must be an integer in [%.0f, %.0f]", key, lo, hi);
    *out = uint64_t(d);
    return 0;
}

static const char* const method_names[] = {"fixed", "cube", "pot", "any", "oss"};

extern "C" int gltf_get_packed(const gltf_doc* doc, size_t mesh, size_t primitive, gltf_packed_skin* packed,
                               char* err, size_t err_size) {
    const tinygltf::Primitive& prim = doc->model.meshes[mesh].primitives[primitive];
    auto it = prim.extensions.find(GLTF_EXTENSION_NAME);
    if (it == prim.extensions.end()) return 0;
    const tinygltf::Value& ext = it->second;
    memset(packed, 0, sizeof(*packed));
    if (!ext.IsObject()) return fail(err, err_size, GLTF_EXTENSION_NAME " must be a JSON object");
    const double max_safe = 9007199254740992.0; // 2^53
    uint64_t v = 0;
    if (json_integer(ext, "vertices", 0, 2147483647.0, true, &v, err, err_size)) return -1;
    packed->vertices = int(v);
    if (json_integer(ext, "tupleTable", 0, 2147483647.0, true, &v, err, err_size)) return -1;
    packed->tuple_table = int(v);
    if (json_integer(ext, "influences", 1, 4, true, &v, err, err_size)) return -1;
    packed->influences = uint32_t(v);
    if (json_integer(ext, "jointCount", 1, 65535, true, &v, err, err_size)) return -1;
    packed->joint_count = uint32_t(v);
    if (json_integer(ext, "weightBits", 0, 64, true, &v, err, err_size)) return -1;
    packed->weight_bits = uint32_t(v);
    if (json_integer(ext, "tupleBits", 0, 32, true, &v, err, err_size)) return -1;
    packed->tuple_bits = uint32_t(v);
    if (json_integer(ext, "n", 0, max_safe, true, &packed->n, err, err_size)) return -1;
    const tinygltf::Value& method = ext.Get("method");
    if (!method.IsString()) return fail(err, err_size, GLTF_EXTENSION_NAME ": \"method\" must be a string");
    packed->method = 5;
    for (uint32_t m = 0; m < 5; ++m)
        if (method.Get<std::string>() == method_names[m]) packed->method = m;
    if (packed->method == 5)
        return fail(err, err_size, GLTF_EXTENSION_NAME ": unknown method \"%s\"", method.Get<std::string>().c_str());
    if (ext.Has("axisSamples")) {
        const tinygltf::Value& axes = ext.Get("axisSamples");
        if (!axes.IsArray() || axes.ArrayLen() + 1 != packed->influences || axes.ArrayLen() > 3)
            return fail(err, err_size, GLTF_EXTENSION_NAME ": \"axisSamples\" must be an array of influences - 1 "
                        "integers");
        for (size_t i = 0; i < axes.ArrayLen(); ++i) {
            const tinygltf::Value& q = axes.Get(int(i));
            double d = q.IsNumber() ? q.GetNumberAsDouble() : NAN;
            if (!std::isfinite(d) || d != std::floor(d) || d < 0 || d > max_safe)
                return fail(err, err_size, GLTF_EXTENSION_NAME ": \"axisSamples\" entries must be integers");
            packed->axis_samples[i] = uint64_t(d);
        }
    } else if (packed->method == 3 && packed->influences > 1) {
        return fail(err, err_size, GLTF_EXTENSION_NAME ": method \"any\" needs \"axisSamples\"");
    }
    if (ext.Has("meshlets")) {
        const tinygltf::Value& m = ext.Get("meshlets");
        if (!m.IsObject()) return fail(err, err_size, GLTF_EXTENSION_NAME ": \"meshlets\" must be an object");
        gltf_packed_meshlets* ml = &packed->meshlets;
        struct { const char* key; int* index; bool required; } refs[] = {
            {"offsets", &ml->offsets, true}, {"counts", &ml->counts, true}, {"bounds", &ml->bounds, true},
            {"cones", &ml->cones, false}, {"vertices", &ml->vertices, true},
            {"vertexTuples", &ml->vertex_tuples, true}, {"triangles", &ml->triangles, true},
            {"joints", &ml->joints, true}, {"tuples", &ml->tuples, true}};
        for (auto& ref : refs) {
            uint64_t index = 0;
            *ref.index = -1;
            if (!m.Has(ref.key) && !ref.required) continue;
            if (json_integer(m, ref.key, 0, 2147483647.0, true, &index, err, err_size)) return -1;
            *ref.index = int(index);
        }
        uint64_t limit = 0;
        if (json_integer(m, "maxVertices", 3, 255, false, &limit, err, err_size)) return -1;
        ml->max_vertices = uint32_t(limit);
        limit = 0;
        if (json_integer(m, "maxTriangles", 1, 512, false, &limit, err, err_size)) return -1;
        ml->max_triangles = uint32_t(limit);
        limit = 0;
        if (json_integer(m, "maxJoints", 1, 255, false, &limit, err, err_size)) return -1;
        ml->max_joints = uint32_t(limit);
        ml->present = 1;
    }
    packed->max_error = NAN;
    if (ext.Has("maxError")) {
        const tinygltf::Value& e = ext.Get("maxError");
        if (!e.IsNumber()) return fail(err, err_size, GLTF_EXTENSION_NAME ": \"maxError\" must be a number");
        packed->max_error = e.GetNumberAsDouble();
    }
    return 1;
}

extern "C" int gltf_packed_sizes(const gltf_doc* doc, const gltf_packed_skin* packed, size_t* vertex_count,
                                 uint32_t* words_per_vertex, size_t* lut_size, char* err, size_t err_size) {
    const tinygltf::Model& model = doc->model;
    element_view words, lut;
    if (view_accessor(model, packed->vertices, GLTF_EXTENSION_NAME " vertices", &words, err, err_size) ||
        view_accessor(model, packed->tuple_table, GLTF_EXTENSION_NAME " tupleTable", &lut, err, err_size))
        return -1;
    int words_type = model.accessors[size_t(packed->vertices)].type;
    if (words.component_type != GLTF_UNSIGNED_INT || words.normalized ||
        (words_type != TINYGLTF_TYPE_SCALAR && words_type != TINYGLTF_TYPE_VEC2))
        return fail(err, err_size, GLTF_EXTENSION_NAME ": the vertices accessor must be UNSIGNED_INT SCALAR or VEC2");
    int lut_type = model.accessors[size_t(packed->tuple_table)].type;
    int want = packed->joint_count <= 256 ? GLTF_UNSIGNED_BYTE : GLTF_UNSIGNED_SHORT;
    if (lut.component_type != want || lut.normalized || lut_type != type_for_components(int(packed->influences)))
        return fail(err, err_size, GLTF_EXTENSION_NAME ": the tupleTable accessor must be %s with %u components",
                    want == GLTF_UNSIGNED_BYTE ? "UNSIGNED_BYTE" : "UNSIGNED_SHORT", packed->influences);
    *vertex_count = words.count;
    *words_per_vertex = uint32_t(words.components);
    *lut_size = lut.count;
    return 0;
}

extern "C" int gltf_read_packed(const gltf_doc* doc, const gltf_packed_skin* packed, uint32_t* words, uint16_t* lut,
                                char* err, size_t err_size) {
    const tinygltf::Model& model = doc->model;
    element_view wv, lv;
    if (view_accessor(model, packed->vertices, GLTF_EXTENSION_NAME " vertices", &wv, err, err_size) ||
        view_accessor(model, packed->tuple_table, GLTF_EXTENSION_NAME " tupleTable", &lv, err, err_size))
        return -1;
    for (size_t v = 0; v < wv.count; ++v)
        for (size_t c = 0; c < wv.components; ++c) words[v * wv.components + c] = uint32_t(read_component(wv, v, c));
    for (size_t e = 0; e < lv.count; ++e)
        for (size_t c = 0; c < lv.components; ++c) lut[e * lv.components + c] = uint16_t(read_component(lv, e, c));
    return 0;
}

// ---- geometry and generic accessors ----

extern "C" int gltf_primitive_triangles(const gltf_doc* doc, size_t mesh, size_t primitive, size_t* index_count,
                                        size_t* vertex_count, char* err, size_t err_size) {
    const tinygltf::Model& model = doc->model;
    const tinygltf::Primitive& prim = model.meshes[mesh].primitives[primitive];
    if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1)
        return fail(err, err_size, "mesh %zu primitive %zu: meshlets need a triangle list (mode %d)", mesh, primitive,
                    prim.mode);
    element_view pv;
    if (view_accessor(model, find_attribute(prim, "POSITION"), "POSITION", &pv, err, err_size)) return -1;
    if (pv.components != 3) return fail(err, err_size, "POSITION must be VEC3");
    *vertex_count = pv.count;
    if (prim.indices < 0) {
        *index_count = pv.count;
    } else {
        element_view iv;
        if (view_accessor(model, prim.indices, "indices", &iv, err, err_size)) return -1;
        if (iv.components != 1 || (iv.component_type != GLTF_UNSIGNED_BYTE && iv.component_type != GLTF_UNSIGNED_SHORT &&
                                   iv.component_type != GLTF_UNSIGNED_INT))
            return fail(err, err_size, "indices must be SCALAR unsigned integers");
        *index_count = iv.count;
    }
    if (*index_count % 3 != 0 || *index_count == 0)
        return fail(err, err_size, "mesh %zu primitive %zu: %zu indices is not a triangle list", mesh, primitive,
                    *index_count);
    return 0;
}

extern "C" int gltf_same_geometry(const gltf_doc* doc, size_t mesh_a, size_t primitive_a, size_t mesh_b,
                                  size_t primitive_b) {
    const tinygltf::Primitive& a = doc->model.meshes[mesh_a].primitives[primitive_a];
    const tinygltf::Primitive& b = doc->model.meshes[mesh_b].primitives[primitive_b];
    return a.indices == b.indices && a.mode == b.mode && find_attribute(a, "POSITION") == find_attribute(b, "POSITION");
}

extern "C" int gltf_read_triangles(const gltf_doc* doc, size_t mesh, size_t primitive, uint32_t* indices,
                                   float* positions, char* err, size_t err_size) {
    const tinygltf::Model& model = doc->model;
    const tinygltf::Primitive& prim = model.meshes[mesh].primitives[primitive];
    element_view pv;
    if (view_accessor(model, find_attribute(prim, "POSITION"), "POSITION", &pv, err, err_size)) return -1;
    for (size_t v = 0; v < pv.count; ++v)
        for (size_t c = 0; c < 3; ++c) positions[v * 3 + c] = float(read_component(pv, v, c));
    if (prim.indices < 0) {
        for (size_t i = 0; i < pv.count; ++i) indices[i] = uint32_t(i);
        return 0;
    }
    element_view iv;
    if (view_accessor(model, prim.indices, "indices", &iv, err, err_size)) return -1;
    for (size_t i = 0; i < iv.count; ++i) {
        double index = read_component(iv, i, 0);
        if (index >= double(pv.count))
            return fail(err, err_size, "index %zu (%.0f) is past the %zu vertices", i, index, pv.count);
        indices[i] = uint32_t(index);
    }
    return 0;
}

extern "C" int gltf_read_accessor_u32(const gltf_doc* doc, int accessor, int component_type, int components,
                                      size_t* count, uint32_t* out, char* err, size_t err_size) {
    element_view view;
    if (view_accessor(doc->model, accessor, "accessor", &view, err, err_size)) return -1;
    if (view.component_type != component_type || view.components != size_t(components) || view.normalized ||
        doc->model.accessors[size_t(accessor)].type != type_for_components(components))
        return fail(err, err_size, "accessor %d must have componentType %d and %d components", accessor,
                    component_type, components);
    *count = view.count;
    if (!out) return 0;
    for (size_t e = 0; e < view.count; ++e)
        for (size_t c = 0; c < size_t(components); ++c) {
            if (component_type == GLTF_FLOAT) {
                float f = float(read_component(view, e, c));
                memcpy(&out[e * size_t(components) + c], &f, 4);
            } else {
                out[e * size_t(components) + c] = uint32_t(read_component(view, e, c));
            }
        }
    return 0;
}
// A dense, non-sparse accessor over a bufferView (-1: no data).
static tinygltf::Accessor plain_accessor(int view, int component_type, int normalized, size_t count, int components) {
    tinygltf::Accessor accessor;
    accessor.bufferView = view;
    accessor.byteOffset = 0;
    accessor.componentType = component_type;
    accessor.normalized = normalized != 0;
    accessor.count = count;
    accessor.type = type_for_components(components);
    accessor.sparse.isSparse = false;
    return accessor;
}


// ---- editing ----

extern "C" int gltf_add_accessor(gltf_doc* doc, const void* data, size_t count, int component_type, int components,
                                 int normalized, int flags) {
    tinygltf::Model& model = doc->model;
    if (!data) { // a data-less placeholder (compact mode's JOINTS_0/WEIGHTS_0)
        model.accessors.push_back(plain_accessor(-1, component_type, normalized, count, components));
        return int(model.accessors.size() - 1);
    }
    size_t csize = component_size(component_type);
    size_t bytes = count * size_t(components) * csize;
    // New data goes into its own buffer; gltf_collect_garbage or the writer merges buffers.
    if (model.buffers.empty() || !model.buffers.back().uri.empty() || model.buffers.back().name != "skinpack") {
        tinygltf::Buffer buffer;
        buffer.name = "skinpack";
        model.buffers.push_back(buffer);
    }
    size_t buffer_index = model.buffers.size() - 1;
    std::vector<unsigned char>& out = model.buffers[buffer_index].data;
    out.resize((out.size() + 3) & ~size_t(3), 0);
    tinygltf::BufferView view;
    view.buffer = int(buffer_index);
    view.byteOffset = out.size();
    view.byteLength = bytes;
    if (flags & GLTF_ACCESSOR_VERTEX_ATTRIBUTE) view.target = TINYGLTF_TARGET_ARRAY_BUFFER;
    out.insert(out.end(), static_cast<const unsigned char*>(data), static_cast<const unsigned char*>(data) + bytes);
    model.bufferViews.push_back(view);

    tinygltf::Accessor accessor =
        plain_accessor(int(model.bufferViews.size() - 1), component_type, normalized, count, components);
    model.accessors.push_back(accessor);
    if (!(flags & GLTF_ACCESSOR_BOUNDS)) return int(model.accessors.size() - 1);
    element_view ev = {static_cast<const unsigned char*>(data), size_t(components) * csize, count, size_t(components),
                       component_type, false};
    accessor.minValues.assign(size_t(components), INFINITY);
    accessor.maxValues.assign(size_t(components), -INFINITY);
    for (size_t e = 0; e < count; ++e)
        for (size_t c = 0; c < size_t(components); ++c) {
            double v = read_component(ev, e, c); // raw integer values: glTF min/max are unnormalised
            accessor.minValues[c] = std::min(accessor.minValues[c], v);
            accessor.maxValues[c] = std::max(accessor.maxValues[c], v);
        }
    model.accessors.back() = accessor;
    return int(model.accessors.size() - 1);
}

static void declare(std::vector<std::string>& list, bool present) {
    auto it = std::find(list.begin(), list.end(), GLTF_EXTENSION_NAME);
    if (present && it == list.end()) list.push_back(GLTF_EXTENSION_NAME);
    if (!present && it != list.end()) list.erase(it);
}

extern "C" void gltf_declare_extension(gltf_doc* doc, int used, int required) {
    declare(doc->model.extensionsUsed, used != 0);
    declare(doc->model.extensionsRequired, required != 0);
}

static tinygltf::Value json_number(uint64_t v) {
    if (v <= 2147483647u) return tinygltf::Value(int(v));
    return tinygltf::Value(double(v));
}

static tinygltf::Value packed_to_json(const gltf_packed_skin* packed) {
    tinygltf::Value::Object o;
    o["vertices"] = tinygltf::Value(packed->vertices);
    o["tupleTable"] = tinygltf::Value(packed->tuple_table);
    o["influences"] = json_number(packed->influences);
    o["jointCount"] = json_number(packed->joint_count);
    o["method"] = tinygltf::Value(std::string(method_names[packed->method]));
    o["n"] = json_number(packed->n);
    if (packed->method == 3 && packed->influences > 1) {
        tinygltf::Value::Array axes;
        for (uint32_t i = 0; i + 1 < packed->influences; ++i) axes.push_back(json_number(packed->axis_samples[i]));
        o["axisSamples"] = tinygltf::Value(std::move(axes));
    }
    o["weightBits"] = json_number(packed->weight_bits);
    o["tupleBits"] = json_number(packed->tuple_bits);
    if (std::isfinite(packed->max_error)) o["maxError"] = tinygltf::Value(packed->max_error);
    const gltf_packed_meshlets* ml = &packed->meshlets;
    if (ml->present) {
        tinygltf::Value::Object m;
        m["offsets"] = tinygltf::Value(ml->offsets);
        m["counts"] = tinygltf::Value(ml->counts);
        m["bounds"] = tinygltf::Value(ml->bounds);
        if (ml->cones >= 0) m["cones"] = tinygltf::Value(ml->cones);
        m["vertices"] = tinygltf::Value(ml->vertices);
        m["vertexTuples"] = tinygltf::Value(ml->vertex_tuples);
        m["triangles"] = tinygltf::Value(ml->triangles);
        m["joints"] = tinygltf::Value(ml->joints);
        m["tuples"] = tinygltf::Value(ml->tuples);
        m["maxVertices"] = json_number(ml->max_vertices);
        m["maxTriangles"] = json_number(ml->max_triangles);
        m["maxJoints"] = json_number(ml->max_joints);
        o["meshlets"] = tinygltf::Value(std::move(m));
    }
    return tinygltf::Value(std::move(o));
}

extern "C" void gltf_set_packed(gltf_doc* doc, size_t mesh, size_t primitive, const gltf_packed_skin* packed) {
    doc->model.meshes[mesh].primitives[primitive].extensions[GLTF_EXTENSION_NAME] = packed_to_json(packed);
    declare(doc->model.extensionsUsed, true);
}

extern "C" void gltf_remove_packed(gltf_doc* doc, size_t mesh, size_t primitive) {
    doc->model.meshes[mesh].primitives[primitive].extensions.erase(GLTF_EXTENSION_NAME);
}

extern "C" void gltf_remove_skin_attributes(gltf_doc* doc, size_t mesh, size_t primitive) {
    std::map<std::string, int>& attributes = doc->model.meshes[mesh].primitives[primitive].attributes;
    for (auto it = attributes.begin(); it != attributes.end();) {
        if (it->first.rfind("JOINTS_", 0) == 0 || it->first.rfind("WEIGHTS_", 0) == 0)
            it = attributes.erase(it);
        else
            ++it;
    }
}

extern "C" void gltf_set_skin_attributes(gltf_doc* doc, size_t mesh, size_t primitive, int joints, int weights) {
    gltf_remove_skin_attributes(doc, mesh, primitive);
    std::map<std::string, int>& attributes = doc->model.meshes[mesh].primitives[primitive].attributes;
    attributes["JOINTS_0"] = joints;
    attributes["WEIGHTS_0"] = weights;
}

// ---- garbage collection ----

// Extensions known not to hold accessor or bufferView indices (or, for EXT_mesh_gpu_instancing
// and ours, whose indices this file remaps). Anything else blocks removing data.
static bool extension_is_safe(const std::string& name) {
    static const char* const prefixes[] = {"KHR_materials_", "KHR_texture_", "KHR_lights_punctual",
                                           "KHR_mesh_quantization", "EXT_texture_webp", "EXT_mesh_gpu_instancing",
                                           "KHR_xmp", "KHR_animation_pointer", GLTF_EXTENSION_NAME};
    for (const char* prefix : prefixes)
        if (name.rfind(prefix, 0) == 0) return true;
    return false;
}

template <typename F>
static void for_each_accessor_ref(tinygltf::Model& model, F&& f) {
    for (tinygltf::Mesh& mesh : model.meshes)
        for (tinygltf::Primitive& prim : mesh.primitives) {
            for (auto& a : prim.attributes) f(a.second);
            if (prim.indices >= 0) f(prim.indices);
            for (auto& target : prim.targets)
                for (auto& a : target) f(a.second);
            auto it = prim.extensions.find(GLTF_EXTENSION_NAME);
            if (it != prim.extensions.end() && it->second.IsObject()) {
                tinygltf::Value::Object& o = it->second.Get<tinygltf::Value::Object>();
                for (const char* key : {"vertices", "tupleTable"}) {
                    auto k = o.find(key);
                    if (k != o.end() && k->second.IsInt()) {
                        int index = k->second.GetNumberAsInt();
                        f(index);
                        k->second = tinygltf::Value(index);
                    }
                }
                auto meshlets = o.find("meshlets");
                if (meshlets != o.end() && meshlets->second.IsObject()) {
                    for (auto& k : meshlets->second.Get<tinygltf::Value::Object>()) {
                        if (k.first.rfind("max", 0) == 0 || !k.second.IsInt()) continue; // limits, not accessors
                        int index = k.second.GetNumberAsInt();
                        f(index);
                        k.second = tinygltf::Value(index);
                    }
                }
            }
        }
    for (tinygltf::Skin& skin : model.skins)
        if (skin.inverseBindMatrices >= 0) f(skin.inverseBindMatrices);
    for (tinygltf::Animation& animation : model.animations)
        for (tinygltf::AnimationSampler& sampler : animation.samplers) {
            if (sampler.input >= 0) f(sampler.input);
            if (sampler.output >= 0) f(sampler.output);
        }
    for (tinygltf::Node& node : model.nodes) {
        auto it = node.extensions.find("EXT_mesh_gpu_instancing");
        if (it == node.extensions.end() || !it->second.IsObject()) continue;
        tinygltf::Value::Object& o = it->second.Get<tinygltf::Value::Object>();
        auto attrs = o.find("attributes");
        if (attrs == o.end() || !attrs->second.IsObject()) continue;
        for (auto& a : attrs->second.Get<tinygltf::Value::Object>()) {
            if (!a.second.IsInt()) continue;
            int index = a.second.GetNumberAsInt();
            f(index);
            a.second = tinygltf::Value(index);
        }
    }
}

extern "C" int gltf_collect_garbage(gltf_doc* doc, char* err, size_t err_size) {
    tinygltf::Model& model = doc->model;
    for (const std::string& name : model.extensionsUsed)
        if (!extension_is_safe(name))
            return fail(err, err_size, "the file uses %s, which may refer to accessors or bufferViews; skinpack "
                        "cannot safely remove data from it", name.c_str());

    // Accessors: keep the referenced ones, in their original order.
    std::vector<int> accessor_map(model.accessors.size(), -1);
    bool bad = false;
    for_each_accessor_ref(model, [&](int& index) {
        if (index < 0 || size_t(index) >= accessor_map.size()) bad = true;
        else accessor_map[size_t(index)] = 0;
    });
    if (bad) return fail(err, err_size, "an accessor index is out of range");
    std::vector<tinygltf::Accessor> accessors;
    for (size_t i = 0; i < model.accessors.size(); ++i)
        if (accessor_map[i] == 0) {
            accessor_map[i] = int(accessors.size());
            accessors.push_back(model.accessors[i]);
        }
    for_each_accessor_ref(model, [&](int& index) { index = accessor_map[size_t(index)]; });
    model.accessors.swap(accessors);

    // BufferViews: those referenced whole (images, sparse parts) are copied whole; a view that
    // only accessors use is cut to the byte ranges they read, so removed attributes that shared
    // a view with kept ones (e.g. TEXCOORD_0 and JOINTS_0 back to back) free their bytes too.
    size_t view_count = model.bufferViews.size();
    std::vector<bool> whole(view_count, false);
    std::vector<std::vector<std::pair<size_t, size_t>>> ranges(view_count); // [begin, end) in the view
    for (tinygltf::Image& image : model.images) {
        if (image.bufferView < 0) continue;
        if (size_t(image.bufferView) >= view_count) return fail(err, err_size, "an image bufferView is out of range");
        whole[size_t(image.bufferView)] = true;
    }
    for (tinygltf::Accessor& a : model.accessors) {
        for (int ref : {a.bufferView, a.sparse.isSparse ? a.sparse.indices.bufferView : -1,
                        a.sparse.isSparse ? a.sparse.values.bufferView : -1})
            if (ref >= int(view_count)) return fail(err, err_size, "an accessor bufferView is out of range");
        if (a.sparse.isSparse) {
            if (a.bufferView >= 0) whole[size_t(a.bufferView)] = true;
            if (a.sparse.indices.bufferView >= 0) whole[size_t(a.sparse.indices.bufferView)] = true;
            if (a.sparse.values.bufferView >= 0) whole[size_t(a.sparse.values.bufferView)] = true;
            continue;
        }
        if (a.bufferView < 0) continue;
        const tinygltf::BufferView& view = model.bufferViews[size_t(a.bufferView)];
        size_t element = component_size(a.componentType) * type_components(a.type);
        size_t stride = view.byteStride ? view.byteStride : element;
        size_t end = a.count ? a.byteOffset + (a.count - 1) * stride + element : a.byteOffset;
        if (!element || end > view.byteLength) {
            whole[size_t(a.bufferView)] = true; // malformed: keep the bytes as they were
            continue;
        }
        // Include the last element's stride padding, so accessors that follow each other in an
        // interleaved or padded view stay one piece (and one bufferView).
        end = std::min(view.byteLength, a.byteOffset + a.count * stride);
        // Start on a 4-byte boundary of the buffer so every accessor keeps its alignment.
        size_t begin = a.byteOffset;
        size_t aligned = ((view.byteOffset + begin) & ~size_t(3));
        if (aligned < view.byteOffset) {
            whole[size_t(a.bufferView)] = true;
            continue;
        }
        ranges[size_t(a.bufferView)].push_back({aligned - view.byteOffset, end});
    }

    // Repack into one buffer, every piece 4-byte aligned (enough for every component type).
    // Buffers with a uri (external .bin) are folded in too: the output is self-contained.
    tinygltf::Buffer packed;
    std::vector<tinygltf::BufferView> views;
    std::vector<int> view_map(view_count, -1); // for whole views
    // per old view: merged ranges and the new view index of each
    std::vector<std::vector<std::pair<std::pair<size_t, size_t>, int>>> pieces(view_count);
    auto append = [&](const tinygltf::BufferView& from, size_t begin, size_t end) {
        const std::vector<unsigned char>& src = model.buffers[size_t(from.buffer)].data;
        packed.data.resize((packed.data.size() + 3) & ~size_t(3), 0);
        tinygltf::BufferView view = from;
        view.buffer = 0;
        view.byteOffset = packed.data.size();
        view.byteLength = end - begin;
        packed.data.insert(packed.data.end(), src.begin() + long(from.byteOffset + begin),
                           src.begin() + long(from.byteOffset + end));
        views.push_back(view);
        return int(views.size() - 1);
    };
    for (size_t i = 0; i < view_count; ++i) {
        const tinygltf::BufferView& view = model.bufferViews[i];
        if (whole[i]) {
            view_map[i] = append(view, 0, view.byteLength);
            continue;
        }
        std::vector<std::pair<size_t, size_t>>& r = ranges[i];
        if (r.empty()) continue; // unused: dropped
        std::sort(r.begin(), r.end());
        std::vector<std::pair<size_t, size_t>> merged;
        for (const auto& range : r) {
            if (!merged.empty() && range.first <= merged.back().second)
                merged.back().second = std::max(merged.back().second, range.second);
            else
                merged.push_back(range);
        }
        for (const auto& range : merged) pieces[i].push_back({range, append(view, range.first, range.second)});
    }
    for (tinygltf::Accessor& a : model.accessors) {
        if (a.sparse.isSparse) {
            if (a.sparse.indices.bufferView >= 0) a.sparse.indices.bufferView = view_map[size_t(a.sparse.indices.bufferView)];
            if (a.sparse.values.bufferView >= 0) a.sparse.values.bufferView = view_map[size_t(a.sparse.values.bufferView)];
        }
        if (a.bufferView < 0) continue;
        size_t old = size_t(a.bufferView);
        if (whole[old]) {
            a.bufferView = view_map[old];
            continue;
        }
        for (const auto& piece : pieces[old])
            if (a.byteOffset >= piece.first.first && a.byteOffset < piece.first.second) {
                a.bufferView = piece.second;
                a.byteOffset -= piece.first.first;
                break;
            }
    }
    for (tinygltf::Image& image : model.images)
        if (image.bufferView >= 0) image.bufferView = view_map[size_t(image.bufferView)];
    model.bufferViews.swap(views);
    packed.data.resize((packed.data.size() + 3) & ~size_t(3), 0);
    if (!model.buffers.empty()) {
        packed.name = model.buffers[0].name == "skinpack" ? std::string() : model.buffers[0].name;
        packed.extras = model.buffers[0].extras;
    }
    model.buffers.clear();
    if (!packed.data.empty()) model.buffers.push_back(packed);
    return 0;
}

// ---- writing ----

// glTF binary needs all data in the first buffer: fold extra buffers into it (without removing
// anything, so this is safe for any extension).
static tinygltf::Model merged_for_glb(const tinygltf::Model& source) {
    tinygltf::Model model = source;
    if (model.buffers.size() <= 1 && (model.buffers.empty() || model.buffers[0].uri.empty())) return model;
    std::vector<size_t> base(model.buffers.size());
    tinygltf::Buffer merged;
    merged.name = model.buffers[0].name;
    for (size_t b = 0; b < model.buffers.size(); ++b) {
        merged.data.resize((merged.data.size() + 3) & ~size_t(3), 0);
        base[b] = merged.data.size();
        merged.data.insert(merged.data.end(), model.buffers[b].data.begin(), model.buffers[b].data.end());
    }
    for (tinygltf::BufferView& view : model.bufferViews) {
        view.byteOffset += base[size_t(view.buffer)];
        view.buffer = 0;
    }
    merged.data.resize((merged.data.size() + 3) & ~size_t(3), 0);
    model.buffers.assign(1, merged);
    return model;
}

extern "C" int gltf_serialize(const gltf_doc* doc, int binary, void** data, size_t* size, char* err,
                              size_t err_size) {
    tinygltf::Model model = binary ? merged_for_glb(doc->model) : doc->model;
    for (tinygltf::Buffer& buffer : model.buffers) {
        buffer.uri.clear(); // written embedded: as the GLB chunk or as a data uri
        buffer.data.resize((buffer.data.size() + 3) & ~size_t(3), 0);
    }
    tinygltf::TinyGLTF writer;
    writer.SetImageWriter(keep_image_uri, nullptr);
    std::ostringstream stream;
    bool ok = false;
    try {
        ok = writer.WriteGltfSceneToStream(&model, stream, !binary, binary != 0);
    } catch (const std::exception& e) {
        return fail(err, err_size, "cannot serialise glTF: %s", e.what());
    }
    if (!ok) return fail(err, err_size, "cannot serialise glTF");
    std::string bytes = stream.str();
    *data = malloc(bytes.size() ? bytes.size() : 1);
    if (!*data) return fail(err, err_size, "out of memory");
    memcpy(*data, bytes.data(), bytes.size());
    *size = bytes.size();
    return 0;
}

extern "C" int gltf_write_file(const gltf_doc* doc, const char* path, int binary, size_t* bytes_written, char* err,
                               size_t err_size) {
    void* data = nullptr;
    size_t size = 0;
    if (gltf_serialize(doc, binary, &data, &size, err, err_size)) return -1;
    std::string temp = std::string(path) + ".tmp-" + std::to_string(getpid());
    FILE* file = fopen(temp.c_str(), "wb");
    if (!file) {
        free(data);
        return fail(err, err_size, "cannot create %s: %s", temp.c_str(), strerror(errno));
    }
    bool ok = fwrite(data, 1, size, file) == size;
    ok = (fflush(file) == 0) && ok;
    ok = (fclose(file) == 0) && ok;
    free(data);
    if (!ok || rename(temp.c_str(), path) != 0) {
        int e = errno;
        remove(temp.c_str());
        return fail(err, err_size, "cannot write %s: %s", path, strerror(e));
    }
    if (bytes_written) *bytes_written = size;
    return 0;
}
