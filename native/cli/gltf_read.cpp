// gltf_read.cpp - loading a glTF document (gltf_doc.hpp) and checked reads of its accessors:
// skin attributes, geometry, generic arrays. Nothing here changes the document.
#include "gltf_doc.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <sys/stat.h>

int gltf_fail(char* err, size_t err_size, const char* format, ...) {
    if (err && err_size) {
        va_list args;
        va_start(args, format);
        vsnprintf(err, err_size, format, args);
        va_end(args);
    }
    return -1;
}
#define fail gltf_fail

// Images are never decoded: skinpack only passes them through (in the JSON it writes).
static bool keep_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
                       void*) {
    return true;
}


// ---- loading ----

static const uint32_t GLB_MAGIC = 0x46546C67u, GLB_CHUNK_JSON = 0x4E4F534Au, GLB_CHUNK_BIN = 0x004E4942u;

// Splits a GLB into its JSON text and BIN chunk, each checked against the header.
static int split_glb(const unsigned char* bytes, size_t size, std::string* json_text, std::vector<unsigned char>* bin,
                     char* err, size_t err_size) {
    uint32_t header[5];
    if (size < sizeof(header)) return fail(err, err_size, "not a readable glTF file: GLB is shorter than its 20-byte header (%zu bytes)", size);
    memcpy(header, bytes, sizeof(header));
    if (header[1] != 2) return fail(err, err_size, "not a readable glTF file: GLB version %u is not 2", header[1]);
    if (header[2] > size)
        return fail(err, err_size, "not a readable glTF file: GLB header says %u bytes but the file has %zu (truncated)", header[2], size);
    size_t length = header[2];
    if (length < sizeof(header))
        return fail(err, err_size, "not a readable glTF file: the GLB header's length %zu is shorter than the header", length);
    if (header[4] != GLB_CHUNK_JSON) return fail(err, err_size, "not a readable glTF file: the first GLB chunk is not JSON");
    if (header[3] > length - 20) return fail(err, err_size, "not a readable glTF file: the GLB JSON chunk runs past the end of the file");
    json_text->assign(reinterpret_cast<const char*>(bytes) + 20, header[3]);
    size_t offset = 20 + size_t(header[3]);
    bin->clear();
    if (offset + 8 > length) return 0;
    uint32_t chunk[2];
    memcpy(chunk, bytes + offset, 8);
    if (chunk[1] != GLB_CHUNK_BIN) return 0; // unknown chunks are skipped, as the spec says
    if (chunk[0] > length - offset - 8) return fail(err, err_size, "not a readable glTF file: the GLB BIN chunk runs past the end of the file");
    bin->assign(bytes + offset + 8, bytes + offset + 8 + chunk[0]);
    return 0;
}

// A buffer without data: no uri (and not a GLB's buffer 0, the BIN chunk). EXT_meshopt_compression's
// fallback buffer and our compact mode's (marked {"fallback": true}) are such buffers; reading an
// accessor from one is refused.
static bool is_dataless_buffer(const ordered_json& buffer) {
    return buffer.is_object() && !buffer.contains("uri");
}

// The bytes tinygltf gets: the input, except that fallback buffers get a 4-byte data uri
// (tinygltf refuses a buffer without uri outside a GLB, and would give a GLB's BIN chunk to
// every one).
static std::string tinygltf_input(const gltf_doc* doc, const unsigned char* bytes, size_t size) {
    if (std::find(doc->fallback_buffer.begin(), doc->fallback_buffer.end(), true) == doc->fallback_buffer.end())
        return std::string(reinterpret_cast<const char*>(bytes), size);
    ordered_json patched = doc->json;
    for (size_t i = 0; i < doc->fallback_buffer.size(); ++i)
        if (doc->fallback_buffer[i]) {
            patched["buffers"][i]["uri"] = "data:application/octet-stream;base64,AAAAAA==";
            patched["buffers"][i]["byteLength"] = 4;
        }
    std::string text = patched.dump();
    if (!doc->binary) return text;
    while (text.size() % 4) text.push_back(' ');
    size_t bin_padded = (doc->bin.size() + 3) & ~size_t(3);
    uint32_t header[5] = {GLB_MAGIC, 2, uint32_t(20 + text.size() + (doc->bin.empty() ? 0 : 8 + bin_padded)),
                          uint32_t(text.size()), GLB_CHUNK_JSON};
    std::string glb(reinterpret_cast<const char*>(header), sizeof(header));
    glb += text;
    if (!doc->bin.empty()) {
        uint32_t chunk[2] = {uint32_t(bin_padded), GLB_CHUNK_BIN};
        glb.append(reinterpret_cast<const char*>(chunk), sizeof(chunk));
        glb.append(reinterpret_cast<const char*>(doc->bin.data()), doc->bin.size());
        glb.append(bin_padded - doc->bin.size(), '\0');
    }
    return glb;
}

// Parses the JSON (ours) and finds the fallback buffers.
static int parse_json(gltf_doc* doc, const unsigned char* bytes, size_t size, char* err, size_t err_size) {
    std::string text;
    if (doc->binary) {
        if (split_glb(bytes, size, &text, &doc->bin, err, err_size)) return -1;
    } else {
        text.assign(reinterpret_cast<const char*>(bytes), size);
    }
    doc->json = ordered_json::parse(text, nullptr, false);
    if (doc->json.is_discarded()) return fail(err, err_size, "not a readable glTF file: the JSON does not parse");
    if (!doc->json.is_object()) return fail(err, err_size, "not a readable glTF file: the JSON is not an object");
    auto buffers = doc->json.find("buffers");
    if (buffers != doc->json.end() && buffers->is_array())
        for (size_t i = 0; i < buffers->size(); ++i)
            doc->fallback_buffer.push_back(!(doc->binary && i == 0) && is_dataless_buffer((*buffers)[i]));
    return 0;
}

static int load_model(gltf_doc* doc, const std::string& input, char* err, size_t err_size) {
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(keep_image, nullptr);
    std::string error, warning;
    bool ok = false;
    try {
        const unsigned char* data = reinterpret_cast<const unsigned char*>(input.data());
        if (doc->binary)
            ok = loader.LoadBinaryFromMemory(&doc->model, &error, &warning, data, unsigned(input.size()), doc->dir);
        else
            ok = loader.LoadASCIIFromString(&doc->model, &error, &warning, input.data(), unsigned(input.size()),
                                            doc->dir);
    } catch (const std::exception& e) {
        error = e.what();
        ok = false;
    }
    if (ok) return 0;
    // tinygltf's errors are lines, some of them "File not found : " without a name: one line.
    std::string message;
    size_t start = 0;
    while (start < error.size()) {
        size_t end = error.find('\n', start);
        if (end == std::string::npos) end = error.size();
        std::string line = error.substr(start, end - start);
        while (!line.empty() && line.back() == ' ') line.pop_back();
        if (line == "File not found :") line = "a file it refers to was not found";
        if (!line.empty() && message.find(line) == std::string::npos) message += (message.empty() ? "" : "; ") + line;
        start = end + 1;
    }
    error = message;
    return fail(err, err_size, "not a readable glTF file: %s", error.empty() ? "parse error" : error.c_str());
}

// Draco keeps the real bytes elsewhere, in a form skinpack does not decode (meshopt it does).
// Checked on the JSON, before tinygltf, which would only say "invalid bufferView".
static int check_required_extensions(const gltf_doc* doc, char* err, size_t err_size) {
    auto required = doc->json.find("extensionsRequired");
    if (required == doc->json.end() || !required->is_array()) return 0;
    for (const ordered_json& name : *required)
        if (name == "KHR_draco_mesh_compression")
            return fail(err, err_size, "the file requires KHR_draco_mesh_compression (Draco), which skinpack cannot "
                        "decode: compress the skin first, or use meshopt (gltfpack -cc) instead of Draco");
    return 0;
}

// tinygltf does not check every bufferView against the bytes it actually loaded: do it here, so
// a truncated GLB or .bin is an error and never an out-of-range read later.
static int check_buffer_views(const gltf_doc* doc, char* err, size_t err_size) {
    const tinygltf::Model& model = doc->model;
    for (size_t i = 0; i < model.bufferViews.size(); ++i) {
        const tinygltf::BufferView& view = model.bufferViews[i];
        if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size())
            return fail(err, err_size, "bufferView %zu refers to buffer %d, which does not exist", i, view.buffer);
        if (size_t(view.buffer) < doc->fallback_buffer.size() && doc->fallback_buffer[size_t(view.buffer)])
            continue; // no data by design; reading it is refused in gltf_view_accessor
        size_t have = model.buffers[size_t(view.buffer)].data.size();
        if (view.byteOffset > have || view.byteLength > have - view.byteOffset)
            return fail(err, err_size, "bufferView %zu (bytes %zu..%zu) lies outside buffer %d (%zu bytes): missing "
                        "or truncated buffer", i, view.byteOffset, view.byteOffset + view.byteLength, view.buffer,
                        have);
    }
    return 0;
}

static gltf_doc* load(const unsigned char* bytes, size_t size, const std::string& path, const std::string& base_dir,
                      char* err, size_t err_size) {
    if (size < 4) {
        fail(err, err_size, "file is too small to be glTF (%zu bytes)", size);
        return nullptr;
    }
    if (size > 0xffffffffu) {
        fail(err, err_size, "file is larger than 4 GiB");
        return nullptr;
    }
    gltf_doc* doc = new gltf_doc();
    doc->binary = memcmp(bytes, "glTF", 4) == 0;
    doc->output_binary = doc->binary;
    doc->path = path;
    doc->dir = base_dir;
    if (parse_json(doc, bytes, size, err, err_size) || check_required_extensions(doc, err, err_size) ||
        load_model(doc, tinygltf_input(doc, bytes, size), err, err_size)) {
        delete doc;
        return nullptr;
    }
    doc->fallback_buffer.resize(doc->model.buffers.size(), false);
    for (size_t i = 0; i < doc->fallback_buffer.size(); ++i)
        if (doc->fallback_buffer[i]) doc->model.buffers[i].data.clear();
    if (gltf_decode_meshopt(doc, err, err_size) || check_buffer_views(doc, err, err_size)) {
        delete doc;
        return nullptr;
    }
    return doc;
}

extern "C" gltf_doc* gltf_load_file(const char* path, char* err, size_t err_size) {
    struct stat st;
    if (stat(path, &st) != 0) {
        fail(err, err_size, "cannot open: %s", strerror(errno));
        return nullptr;
    }
    if (!S_ISREG(st.st_mode)) {
        fail(err, err_size, "%s", S_ISDIR(st.st_mode) ? "is a folder, not a .gltf or .glb file" : "is not a regular file");
        return nullptr;
    }
    std::ifstream file(path, std::ios::binary);
    if (!file) {
        fail(err, err_size, "cannot open: %s", strerror(errno));
        return nullptr;
    }
    std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    if (file.bad()) {
        fail(err, err_size, "cannot read the file");
        return nullptr;
    }
    std::string dir(path);
    size_t slash = dir.find_last_of('/');
    dir = slash == std::string::npos ? std::string(".") : dir.substr(0, slash);
    return load(bytes.data(), bytes.size(), path, dir, err, err_size);
}

extern "C" gltf_doc* gltf_load_memory(const void* data, size_t size, char* err, size_t err_size) {
    // An empty base_dir would let tinygltf resolve relative uris against the working folder.
    return load(static_cast<const unsigned char*>(data), size, "", "/nonexistent-skinpack-memory", err, err_size);
}

extern "C" void gltf_free(gltf_doc* doc) { delete doc; }
extern "C" int gltf_is_binary(const gltf_doc* doc) { return doc->binary; }
extern "C" size_t gltf_mesh_count(const gltf_doc* doc) { return doc->model.meshes.size(); }
extern "C" size_t gltf_primitive_count(const gltf_doc* doc, size_t mesh) {
    return doc->model.meshes[mesh].primitives.size();
}

ordered_json& gltf_json_array(gltf_doc* doc, const char* key) {
    ordered_json& array = doc->json[key];
    if (!array.is_array()) array = ordered_json::array();
    return array;
}

// ---- accessors ----

size_t gltf_component_size(int component_type) {
    switch (component_type) {
    case GLTF_BYTE: case GLTF_UNSIGNED_BYTE: return 1;
    case GLTF_SHORT: case GLTF_UNSIGNED_SHORT: return 2;
    case GLTF_UNSIGNED_INT: case GLTF_FLOAT: return 4;
    default: return 0;
    }
}

size_t gltf_type_components(int type) {
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

int gltf_type_for_components(int components) {
    static const int types[] = {0, TINYGLTF_TYPE_SCALAR, TINYGLTF_TYPE_VEC2, TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4};
    return components >= 1 && components <= 4 ? types[components] : 0;
}

const char* gltf_type_name(int components) {
    static const char* const names[] = {"", "SCALAR", "VEC2", "VEC3", "VEC4"};
    return components >= 1 && components <= 4 ? names[components] : "";
}

// A bufferView of a fallback buffer: accessors on it have no data (compact mode, meshopt).
static bool in_fallback_buffer(const gltf_doc* doc, int buffer_view) {
    if (buffer_view < 0 || size_t(buffer_view) >= doc->model.bufferViews.size()) return false;
    size_t buffer = size_t(doc->model.bufferViews[size_t(buffer_view)].buffer);
    return buffer < doc->fallback_buffer.size() && doc->fallback_buffer[buffer];
}

int gltf_view_accessor(const gltf_doc* doc, int index, const char* what, gltf_element_view* view, char* err,
                       size_t err_size) {
    const tinygltf::Model& model = doc->model;
    if (index < 0 || size_t(index) >= model.accessors.size())
        return fail(err, err_size, "%s refers to accessor %d, which does not exist", what, index);
    const tinygltf::Accessor& accessor = model.accessors[size_t(index)];
    if (accessor.sparse.isSparse)
        return fail(err, err_size, "%s (accessor %d) is sparse, which is not supported here", what, index);
    size_t csize = gltf_component_size(accessor.componentType);
    size_t comps = gltf_type_components(accessor.type);
    if (!csize || !comps)
        return fail(err, err_size, "%s (accessor %d) has an invalid componentType or type", what, index);
    if (accessor.count == 0) return fail(err, err_size, "%s (accessor %d) has count 0", what, index);
    if (accessor.bufferView < 0 || size_t(accessor.bufferView) >= model.bufferViews.size())
        return fail(err, err_size, "%s (accessor %d) has no valid bufferView (%d)", what, index, accessor.bufferView);
    if (in_fallback_buffer(doc, accessor.bufferView))
        return fail(err, err_size, "%s (accessor %d) lies in a fallback buffer, which has no data (buffer %d)", what,
                    index, model.bufferViews[size_t(accessor.bufferView)].buffer);
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

double gltf_read_component(const gltf_element_view& view, size_t element, size_t component) {
    const unsigned char* p = view.data + element * view.stride + component * gltf_component_size(view.component_type);
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
            return fail(err, err_size, "%s is not supported (at most 8 influences, "
                        "JOINTS_0/1 and WEIGHTS_0/1)", name.c_str());
    }
    for (size_t s = 0; s < GLTF_MAX_SKIN_SETS; ++s) {
        bool j = attributes->joints[s] >= 0, w = attributes->weights[s] >= 0;
        if (j != w)
            return fail(err, err_size, "%s_%zu without %s_%zu",
                        j ? "JOINTS" : "WEIGHTS", s, j ? "WEIGHTS" : "JOINTS", s);
        if (j) {
            if (attributes->sets != s)
                return fail(err, err_size, "JOINTS_%zu without JOINTS_%zu", s, s - 1);
            attributes->sets = s + 1;
        }
    }
    if (attributes->sets == 0) return 0;

    // Compact mode keeps the attribute names on accessors without data: in a fallback buffer
    // (or, in files of skinpack before 1.0, without bufferView).
    size_t dataless = 0;
    for (size_t s = 0; s < attributes->sets; ++s)
        for (int index : {attributes->joints[s], attributes->weights[s]}) {
            if (index < 0 || size_t(index) >= model.accessors.size())
                return fail(err, err_size, "accessor %d does not exist", index);
            const tinygltf::Accessor& a = model.accessors[size_t(index)];
            dataless += (a.bufferView < 0 && !a.sparse.isSparse) || in_fallback_buffer(doc, a.bufferView);
        }
    if (dataless) {
        if (dataless != 2 * attributes->sets)
            return fail(err, err_size, "some JOINTS_n/WEIGHTS_n accessors have data and some "
                        "not");
        attributes->placeholder = 1;
        attributes->vertex_count = model.accessors[size_t(attributes->joints[0])].count;
        attributes->joint_count = mesh_joint_count(model, mesh);
        return 1;
    }

    double bits = 0;
    for (size_t s = 0; s < attributes->sets; ++s) {
        char what[64];
        gltf_element_view jv, wv;
        snprintf(what, sizeof(what), "JOINTS_%zu", s);
        if (gltf_view_accessor(doc, attributes->joints[s], what, &jv, err, err_size)) return -1;
        if (jv.components != 4 || model.accessors[size_t(attributes->joints[s])].type != TINYGLTF_TYPE_VEC4 ||
            (jv.component_type != GLTF_UNSIGNED_BYTE && jv.component_type != GLTF_UNSIGNED_SHORT) || jv.normalized)
            return fail(err, err_size, "%s must be VEC4 of unnormalised UNSIGNED_BYTE or UNSIGNED_SHORT", what);
        snprintf(what, sizeof(what), "WEIGHTS_%zu", s);
        if (gltf_view_accessor(doc, attributes->weights[s], what, &wv, err, err_size)) return -1;
        bool float_ok = wv.component_type == GLTF_FLOAT && !wv.normalized;
        bool int_ok = (wv.component_type == GLTF_UNSIGNED_BYTE || wv.component_type == GLTF_UNSIGNED_SHORT) &&
                      wv.normalized;
        if (wv.components != 4 || model.accessors[size_t(attributes->weights[s])].type != TINYGLTF_TYPE_VEC4 ||
            !(float_ok || int_ok))
            return fail(err, err_size, "%s must be VEC4 of FLOAT or normalised UNSIGNED_BYTE/UNSIGNED_SHORT", what);
        if (jv.count != wv.count || (s > 0 && jv.count != attributes->vertex_count))
            return fail(err, err_size, "JOINTS_n and WEIGHTS_n counts differ");
        attributes->vertex_count = jv.count;
        bits += 32.0 * double(gltf_component_size(jv.component_type) + gltf_component_size(wv.component_type));
    }
    attributes->stored_bits_per_vertex = bits;
    attributes->joint_count = mesh_joint_count(model, mesh);
    return 1;
}

extern "C" int gltf_read_skin(const gltf_doc* doc, const gltf_skin_attributes* attributes, uint16_t* joints,
                              float* weights, char* err, size_t err_size) {
    size_t stride = 4 * attributes->sets;
    for (size_t s = 0; s < attributes->sets; ++s) {
        gltf_element_view jv, wv;
        if (gltf_view_accessor(doc, attributes->joints[s], "JOINTS", &jv, err, err_size) ||
            gltf_view_accessor(doc, attributes->weights[s], "WEIGHTS", &wv, err, err_size))
            return -1;
        for (size_t v = 0; v < attributes->vertex_count; ++v) {
            for (size_t c = 0; c < 4; ++c) {
                double j = gltf_read_component(jv, v, c);
                double w = gltf_read_component(wv, v, c);
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

// ---- geometry and generic accessors ----

extern "C" size_t gltf_primitive_vertex_count(const gltf_doc* doc, size_t mesh, size_t primitive) {
    int position = find_attribute(doc->model.meshes[mesh].primitives[primitive], "POSITION");
    if (position < 0 || size_t(position) >= doc->model.accessors.size()) return 0;
    return doc->model.accessors[size_t(position)].count;
}

extern "C" int gltf_primitive_triangles(const gltf_doc* doc, size_t mesh, size_t primitive, size_t* index_count,
                                        size_t* vertex_count, char* err, size_t err_size) {
    const tinygltf::Model& model = doc->model;
    const tinygltf::Primitive& prim = model.meshes[mesh].primitives[primitive];
    if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1)
        return fail(err, err_size, "mesh %zu primitive %zu: meshlets need a triangle list (mode %d)", mesh, primitive,
                    prim.mode);
    gltf_element_view pv;
    if (gltf_view_accessor(doc, find_attribute(prim, "POSITION"), "POSITION", &pv, err, err_size)) return -1;
    if (pv.components != 3) return fail(err, err_size, "POSITION must be VEC3");
    *vertex_count = pv.count;
    if (prim.indices < 0) {
        *index_count = pv.count;
    } else {
        gltf_element_view iv;
        if (gltf_view_accessor(doc, prim.indices, "indices", &iv, err, err_size)) return -1;
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
    gltf_element_view pv;
    if (gltf_view_accessor(doc, find_attribute(prim, "POSITION"), "POSITION", &pv, err, err_size)) return -1;
    for (size_t v = 0; v < pv.count; ++v)
        for (size_t c = 0; c < 3; ++c) positions[v * 3 + c] = float(gltf_read_component(pv, v, c));
    if (prim.indices < 0) {
        for (size_t i = 0; i < pv.count; ++i) indices[i] = uint32_t(i);
        return 0;
    }
    gltf_element_view iv;
    if (gltf_view_accessor(doc, prim.indices, "indices", &iv, err, err_size)) return -1;
    for (size_t i = 0; i < iv.count; ++i) {
        double index = gltf_read_component(iv, i, 0);
        if (index >= double(pv.count))
            return fail(err, err_size, "index %zu (%.0f) is past the %zu vertices", i, index, pv.count);
        indices[i] = uint32_t(index);
    }
    return 0;
}

extern "C" int gltf_read_accessor_u32(const gltf_doc* doc, int accessor, int component_type, int components,
                                      size_t* count, uint32_t* out, char* err, size_t err_size) {
    gltf_element_view view;
    if (gltf_view_accessor(doc, accessor, "accessor", &view, err, err_size)) return -1;
    if (view.component_type != component_type || view.components != size_t(components) || view.normalized ||
        doc->model.accessors[size_t(accessor)].type != gltf_type_for_components(components))
        return fail(err, err_size, "accessor %d must have componentType %d and %d components", accessor,
                    component_type, components);
    *count = view.count;
    if (!out) return 0;
    for (size_t e = 0; e < view.count; ++e)
        for (size_t c = 0; c < size_t(components); ++c) {
            if (component_type == GLTF_FLOAT) {
                float f = float(gltf_read_component(view, e, c));
                memcpy(&out[e * size_t(components) + c], &f, 4);
            } else {
                out[e * size_t(components) + c] = uint32_t(gltf_read_component(view, e, c));
            }
        }
    return 0;
}
// A dense, non-sparse accessor over a bufferView (-1: no data).
