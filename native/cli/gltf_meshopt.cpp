// gltf_meshopt.cpp - EXT_meshopt_compression / KHR_meshopt_compression with libmeshoptimizer:
// decoding every compressed bufferView of an input (gltfpack -c/-cc, glTF-Transform meshopt), so
// that skinpack can read the attributes of an optimised file (only tinygltf's model is filled;
// the file keeps its compressed bytes as they are), and encoding the views skinpack writes with
// compress --meshopt (gltf_edit.cpp places them).
#include "gltf_doc.hpp"

#include <cstring>

#ifdef SKINPACK_HAVE_MESHOPT
#include <meshoptimizer.h>
#endif

#define fail gltf_fail

static const char* const MESHOPT_NAMES[] = {"EXT_meshopt_compression", "KHR_meshopt_compression"};

const char* gltf_meshopt_extension_for(const gltf_doc* doc) {
    auto used = doc->json.find("extensionsUsed");
    if (used != doc->json.end() && used->is_array())
        for (const ordered_json& name : *used)
            if (name == MESHOPT_NAMES[1]) return MESHOPT_NAMES[1]; // the input's gltfpack -ce khr convention
    return MESHOPT_NAMES[0];
}

bool gltf_meshopt_encode_attributes(const void* data, size_t count, size_t stride, std::vector<unsigned char>* out) {
#ifdef SKINPACK_HAVE_MESHOPT
    // The header byte of the vertex codec's version 0, the only one EXT_meshopt_compression allows
    // (KHR_meshopt_compression also allows 0xa1, but version 0 is valid for both).
    const unsigned char VERTEX_CODEC_V0 = 0xa0;
    // ATTRIBUTES mode: byteStride a multiple of 4, at most 256 (EXT_meshopt_compression).
    if (!data || count == 0 || stride == 0 || stride % 4 || stride > 256) return false;
    out->resize(meshopt_encodeVertexBufferBound(count, stride));
    size_t size = meshopt_encodeVertexBuffer(out->data(), out->size(), data, count, stride);
    out->resize(size);
    return size > 0 && (*out)[0] == VERTEX_CODEC_V0; // a newer library's default version: not written
#else
    (void)data, (void)count, (void)stride, (void)out;
    return false;
#endif
}

extern "C" int gltf_meshopt_supported(void) {
    static const uint32_t probe[4] = {1, 2, 3, 4};
    std::vector<unsigned char> encoded;
    return gltf_meshopt_encode_attributes(probe, 4, 4, &encoded);
}

const ordered_json* gltf_meshopt_of(const ordered_json& view, const char** name) {
    auto extensions = view.find("extensions");
    if (extensions == view.end() || !extensions->is_object()) return nullptr;
    for (const char* candidate : MESHOPT_NAMES) {
        auto ext = extensions->find(candidate);
        if (ext != extensions->end() && ext->is_object()) {
            *name = candidate;
            return &*ext;
        }
    }
    return nullptr;
}

#ifdef SKINPACK_HAVE_MESHOPT
static size_t unsigned_member(const ordered_json& object, const char* key, bool* ok) {
    auto it = object.find(key);
    if (it == object.end()) return 0;
    if (!it->is_number_unsigned()) *ok = false;
    return it->is_number_unsigned() ? it->get<size_t>() : 0;
}

// Decodes one view's compressed bytes into dest (count * stride bytes).
static int decode_view(const ordered_json& ext, const unsigned char* source, size_t source_size, unsigned char* dest,
                       size_t count, size_t stride, const char* name, size_t view, char* err, size_t err_size) {
    std::string mode = ext.value("mode", std::string());
    std::string filter = ext.contains("filter") && ext["filter"].is_string() ? ext["filter"].get<std::string>() : "NONE";
    int rc = -1;
    if (mode == "ATTRIBUTES") rc = meshopt_decodeVertexBuffer(dest, count, stride, source, source_size);
    else if (mode == "TRIANGLES") rc = meshopt_decodeIndexBuffer(dest, count, stride, source, source_size);
    else if (mode == "INDICES") rc = meshopt_decodeIndexSequence(dest, count, stride, source, source_size);
    else return fail(err, err_size, "bufferView %zu: %s mode \"%s\" is not known", view, name, mode.c_str());
    if (rc == -1) // the header byte: not this mode's data, or a codec version newer than the library
        return fail(err, err_size, "bufferView %zu: %s data does not decode (meshoptimizer error -1: not %s data, "
                    "or a newer encoding than libmeshoptimizer %d supports)", view, name, mode.c_str(),
                    MESHOPTIMIZER_VERSION);
    if (rc != 0)
        return fail(err, err_size, "bufferView %zu: %s data does not decode (meshoptimizer error %d: truncated or "
                    "corrupt)", view, name, rc);
    if (filter == "OCTAHEDRAL") meshopt_decodeFilterOct(dest, count, stride);
    else if (filter == "QUATERNION") meshopt_decodeFilterQuat(dest, count, stride);
    else if (filter == "EXPONENTIAL") meshopt_decodeFilterExp(dest, count, stride);
    else if (filter != "NONE")
        return fail(err, err_size, "bufferView %zu: %s filter \"%s\" is not supported by libmeshoptimizer %d", view,
                    name, filter.c_str(), MESHOPTIMIZER_VERSION);
    return 0;
}
#endif

int gltf_decode_meshopt(gltf_doc* doc, char* err, size_t err_size) {
    auto views = doc->json.find("bufferViews");
    if (views == doc->json.end() || !views->is_array()) return 0;
    for (size_t v = 0; v < views->size() && v < doc->model.bufferViews.size(); ++v) {
        const char* name = nullptr;
        const ordered_json* ext = gltf_meshopt_of((*views)[v], &name);
        if (!ext) continue;
#ifndef SKINPACK_HAVE_MESHOPT
        (void)doc;
        return fail(err, err_size, "bufferView %zu uses %s, and this skinpack was built without libmeshoptimizer", v,
                    name);
#else
        bool ok = true;
        size_t source_buffer = unsigned_member(*ext, "buffer", &ok), offset = unsigned_member(*ext, "byteOffset", &ok);
        size_t length = unsigned_member(*ext, "byteLength", &ok), stride = unsigned_member(*ext, "byteStride", &ok);
        size_t count = unsigned_member(*ext, "count", &ok);
        if (!ok || source_buffer >= doc->model.buffers.size() || stride == 0 || count == 0)
            return fail(err, err_size, "bufferView %zu: %s has an invalid buffer, byteStride or count", v, name);
        const std::vector<unsigned char>& source = doc->model.buffers[source_buffer].data;
        if (offset > source.size() || length > source.size() - offset)
            return fail(err, err_size, "bufferView %zu: %s bytes %zu..%zu lie outside buffer %zu (%zu bytes)", v, name,
                        offset, offset + length, source_buffer, source.size());
        const tinygltf::BufferView& view = doc->model.bufferViews[v];
        size_t target = size_t(view.buffer);
        if (count > SIZE_MAX / stride || count * stride > view.byteLength)
            return fail(err, err_size, "bufferView %zu: %s count * byteStride exceeds byteLength", v, name);
        const ordered_json& target_json = doc->json["buffers"][target];
        size_t target_size = target_json.value("byteLength", size_t(0));
        if (view.byteOffset > target_size || view.byteLength > target_size - view.byteOffset)
            return fail(err, err_size, "bufferView %zu lies outside its fallback buffer %zu", v, target);
        std::vector<unsigned char>& dest = doc->model.buffers[target].data;
        if (dest.size() < target_size) dest.resize(target_size, 0); // a fallback buffer: filled here
        std::vector<unsigned char> decoded(count * stride);
        if (decode_view(*ext, source.data() + offset, length, decoded.data(), count, stride, name, v, err, err_size))
            return -1;
        memcpy(dest.data() + view.byteOffset, decoded.data(), decoded.size());
        if (target < doc->fallback_buffer.size()) doc->fallback_buffer[target] = false; // readable now
#endif
    }
    return 0;
}
