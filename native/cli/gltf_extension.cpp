// gltf_extension.cpp - the SKINPACK_packed_skin JSON of a primitive (docs/extension/README.md):
// read from the input with its types checked, written into the output document.
#include "gltf_doc.hpp"

#include <cmath>
#include <cstring>

#include "skinpack.h"

#define fail gltf_fail

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

// n and axisSamples entries reach 2^63: a JSON integer up to 2^53, a string of decimal digits
// above (docs/extension: "Large integers").
static int json_large_integer(const tinygltf::Value& value, uint64_t* out) {
    if (value.IsNumber()) {
        double d = value.GetNumberAsDouble();
        if (!std::isfinite(d) || d != std::floor(d) || d < 0 || d > double(SP_JSON_MAX_SAFE_INTEGER)) return -1;
        *out = uint64_t(d);
        return 0;
    }
    if (!value.IsString()) return -1;
    const std::string& text = value.Get<std::string>();
    return sp_parse_decimal(text.data(), text.size(), out) == SP_OK ? 0 : -1; // the library's rule
}

extern "C" int gltf_get_packed(const gltf_doc* doc, size_t mesh, size_t primitive, gltf_packed_skin* packed,
                               char* err, size_t err_size) {
    const tinygltf::Primitive& prim = doc->model.meshes[mesh].primitives[primitive];
    auto it = prim.extensions.find(GLTF_EXTENSION_NAME);
    if (it == prim.extensions.end()) return 0;
    const tinygltf::Value& ext = it->second;
    memset(packed, 0, sizeof(*packed));
    if (!ext.IsObject()) return fail(err, err_size, GLTF_EXTENSION_NAME " must be a JSON object");
    uint64_t v = 0;
    if (json_integer(ext, "vertices", 0, 2147483647.0, true, &v, err, err_size)) return -1;
    packed->vertices = int(v);
    if (json_integer(ext, "tupleTable", 0, 2147483647.0, true, &v, err, err_size)) return -1;
    packed->tuple_table = int(v);
    if (json_integer(ext, "influences", 1, SP_MAX_INFLUENCES, true, &v, err, err_size)) return -1;
    packed->influences = uint32_t(v);
    if (json_integer(ext, "jointCount", 1, SP_MAX_JOINTS, true, &v, err, err_size)) return -1;
    packed->joint_count = uint32_t(v);
    if (json_integer(ext, "weightBits", 0, SP_MAX_WEIGHT_BITS, true, &v, err, err_size)) return -1;
    packed->weight_bits = uint32_t(v);
    if (json_integer(ext, "tupleBits", 0, 32, true, &v, err, err_size)) return -1;
    packed->tuple_bits = uint32_t(v);
    if (!ext.Has("n")) return fail(err, err_size, GLTF_EXTENSION_NAME ": missing \"n\"");
    if (json_large_integer(ext.Get("n"), &packed->n))
        return fail(err, err_size, GLTF_EXTENSION_NAME ": \"n\" must be an integer (a JSON number up to 2^53, a string "
                    "of digits above)");
    const tinygltf::Value& method = ext.Get("method");
    if (!method.IsString()) return fail(err, err_size, GLTF_EXTENSION_NAME ": \"method\" must be a string");
    packed->method = sp_method_from_name(method.Get<std::string>().c_str());
    if (packed->method == SP_METHOD_COUNT)
        return fail(err, err_size, GLTF_EXTENSION_NAME ": unknown method \"%s\"", method.Get<std::string>().c_str());
    if (ext.Has("axisSamples")) {
        const tinygltf::Value& axes = ext.Get("axisSamples");
        if (!axes.IsArray() || axes.ArrayLen() > SP_MAX_INFLUENCES - 1)
            return fail(err, err_size, GLTF_EXTENSION_NAME ": \"axisSamples\" must be an array of at most %d integers",
                        SP_MAX_INFLUENCES - 1);
        packed->axis_sample_count = uint32_t(axes.ArrayLen()); // how many the method needs: sp_validate_packed
        for (size_t i = 0; i < axes.ArrayLen(); ++i)
            if (json_large_integer(axes.Get(int(i)), &packed->axis_samples[i]))
                return fail(err, err_size, GLTF_EXTENSION_NAME ": \"axisSamples\" entries must be integers (JSON "
                            "numbers up to 2^53, strings of digits above)");
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
    gltf_element_view words, lut;
    if (gltf_view_accessor(doc, packed->vertices, GLTF_EXTENSION_NAME " vertices", &words, err, err_size) ||
        gltf_view_accessor(doc, packed->tuple_table, GLTF_EXTENSION_NAME " tupleTable", &lut, err, err_size))
        return -1;
    int words_type = model.accessors[size_t(packed->vertices)].type;
    if (words.component_type != GLTF_UNSIGNED_INT || words.normalized ||
        (words_type != TINYGLTF_TYPE_SCALAR && words_type != TINYGLTF_TYPE_VEC2))
        return fail(err, err_size, GLTF_EXTENSION_NAME ": the vertices accessor must be UNSIGNED_INT SCALAR or VEC2");
    int lut_type = model.accessors[size_t(packed->tuple_table)].type;
    int want = sp_joint_bytes(packed->joint_count) == 1 ? GLTF_UNSIGNED_BYTE : GLTF_UNSIGNED_SHORT;
    if (lut.component_type != want || lut.normalized || lut_type != gltf_type_for_components(int(packed->influences)))
        return fail(err, err_size, GLTF_EXTENSION_NAME ": the tupleTable accessor must be %s with %u components",
                    want == GLTF_UNSIGNED_BYTE ? "UNSIGNED_BYTE" : "UNSIGNED_SHORT", packed->influences);
    *vertex_count = words.count;
    *words_per_vertex = uint32_t(words.components);
    *lut_size = lut.count;
    return 0;
}

extern "C" int gltf_read_packed(const gltf_doc* doc, const gltf_packed_skin* packed, uint32_t* words, uint16_t* lut,
                                char* err, size_t err_size) {
    gltf_element_view wv, lv;
    if (gltf_view_accessor(doc, packed->vertices, GLTF_EXTENSION_NAME " vertices", &wv, err, err_size) ||
        gltf_view_accessor(doc, packed->tuple_table, GLTF_EXTENSION_NAME " tupleTable", &lv, err, err_size))
        return -1;
    for (size_t v = 0; v < wv.count; ++v)
        for (size_t c = 0; c < wv.components; ++c) words[v * wv.components + c] = uint32_t(gltf_read_component(wv, v, c));
    for (size_t e = 0; e < lv.count; ++e)
        for (size_t c = 0; c < lv.components; ++c) lut[e * lv.components + c] = uint16_t(gltf_read_component(lv, e, c));
    return 0;
}


// ---- writing ----

// A JSON integer up to 2^53, else a string of its digits (docs/extension: "Large integers").
static ordered_json large_integer(uint64_t v) {
    if (v <= SP_JSON_MAX_SAFE_INTEGER) return v;
    return std::to_string(v);
}

static ordered_json packed_to_json(const gltf_packed_skin* packed) {
    ordered_json o = ordered_json::object();
    o["vertices"] = packed->vertices;
    o["tupleTable"] = packed->tuple_table;
    o["influences"] = packed->influences;
    o["jointCount"] = packed->joint_count;
    o["method"] = sp_method_name(sp_method(packed->method));
    o["n"] = large_integer(packed->n);
    if (packed->method == SP_METHOD_ANY && packed->influences > 1) {
        ordered_json axes = ordered_json::array();
        for (uint32_t i = 0; i + 1 < packed->influences; ++i) axes.push_back(large_integer(packed->axis_samples[i]));
        o["axisSamples"] = axes;
    }
    o["weightBits"] = packed->weight_bits;
    o["tupleBits"] = packed->tuple_bits;
    if (std::isfinite(packed->max_error)) o["maxError"] = packed->max_error;
    const gltf_packed_meshlets* ml = &packed->meshlets;
    if (ml->present) {
        ordered_json m = ordered_json::object();
        m["offsets"] = ml->offsets;
        m["counts"] = ml->counts;
        m["bounds"] = ml->bounds;
        if (ml->cones >= 0) m["cones"] = ml->cones;
        m["vertices"] = ml->vertices;
        m["vertexTuples"] = ml->vertex_tuples;
        m["triangles"] = ml->triangles;
        m["joints"] = ml->joints;
        m["tuples"] = ml->tuples;
        m["maxVertices"] = ml->max_vertices;
        m["maxTriangles"] = ml->max_triangles;
        m["maxJoints"] = ml->max_joints;
        o["meshlets"] = m;
    }
    return o;
}

static ordered_json& primitive_json(gltf_doc* doc, size_t mesh, size_t primitive) {
    return doc->json["meshes"][mesh]["primitives"][primitive];
}

extern "C" void gltf_set_packed(gltf_doc* doc, size_t mesh, size_t primitive, const gltf_packed_skin* packed) {
    ordered_json& prim = primitive_json(doc, mesh, primitive);
    if (!prim["extensions"].is_object()) prim["extensions"] = ordered_json::object();
    prim["extensions"][GLTF_EXTENSION_NAME] = packed_to_json(packed);
    doc->edited = true;
}

extern "C" void gltf_remove_packed(gltf_doc* doc, size_t mesh, size_t primitive) {
    ordered_json& prim = primitive_json(doc, mesh, primitive);
    auto extensions = prim.find("extensions");
    if (extensions == prim.end() || !extensions->is_object()) return;
    extensions->erase(GLTF_EXTENSION_NAME);
    if (extensions->empty()) prim.erase("extensions");
    doc->edited = true;
}
