// gltf_doc.hpp - what the three parts of the glTF layer share (not for the C commands):
//   gltf_read.cpp       loading (.glb/.gltf, fallback buffers), checked accessor views, skins
//   gltf_extension.cpp  the SKINPACK_packed_skin JSON, read and written
//   gltf_edit.cpp       surgical edits of the input's JSON, new binary data, writing
//
// A document is kept twice: tinygltf's model of the input (read-only; every read goes through
// it and its bounds checks) and the input's own JSON (nlohmann::ordered_json, member order
// kept), which the edits change in place and which is what gets written. So a member skinpack
// does not own is written back as it was read, whatever tinygltf makes of it.
#ifndef SKINPACK_GLTF_DOC_HPP
#define SKINPACK_GLTF_DOC_HPP

#include "gltf_io.h"

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include <map>
#include <string>
#include <vector>

using ordered_json = nlohmann::ordered_json;

// A new bufferView's "buffer" before writing decides where its bytes go (see gltf_edit.cpp).
#define GLTF_PENDING_DATA_BUFFER (-1)     // offset into gltf_doc::added
#define GLTF_PENDING_FALLBACK_BUFFER (-2) // offset into the fallback buffer (no data)
#define GLTF_PENDING_MESHOPT_FALLBACK_BUFFER (-3) // offset into the meshopt fallback buffer (no data)

struct gltf_doc {
    tinygltf::Model model;              // the input as tinygltf reads it: never edited
    bool binary = false;                // the input is .glb
    std::string path;                   // the input file ("" from memory)
    std::string dir;                    // its folder: relative uris resolve against it
    ordered_json json;                  // the input's JSON, edited in place, written out
    std::vector<unsigned char> bin;     // the input's GLB BIN chunk (buffer 0 without uri)
    std::vector<bool> fallback_buffer;  // per input buffer: a data-less fallback buffer
    std::map<size_t, std::vector<unsigned char>> cut_data; // data: uri buffers with bytes cut: their new bytes
    std::vector<unsigned char> added;   // new binary data (views with GLTF_PENDING_DATA_BUFFER)
    size_t fallback_bytes = 0;          // size of the fallback buffer written for compact mode
    size_t meshopt_fallback_bytes = 0;  // size of the meshopt fallback buffer (compress --meshopt)
    bool output_binary = false;         // the kind it will be written as (gltf_plan_output)
    std::vector<size_t> released_buffers; // input buffers that held views skinpack removed: dropped if unused
    bool edited = false;                // anything changed since loading
};

int gltf_fail(char* err, size_t err_size, const char* format, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 3, 4)))
#endif
    ;

size_t gltf_component_size(int component_type);
size_t gltf_type_components(int type);
int gltf_type_for_components(int components);
const char* gltf_type_name(int components); // "SCALAR".."VEC4"

// A checked view of an accessor's elements: element i starts at data + i * stride.
struct gltf_element_view {
    const unsigned char* data;
    size_t stride;
    size_t count;
    size_t components;
    int component_type;
    bool normalized;
};

// Checks that accessor `index` has data inside its bufferView and buffer; `what` names it in
// messages ("mesh 0 primitive 1 JOINTS_0").
int gltf_view_accessor(const gltf_doc* doc, int index, const char* what, gltf_element_view* view, char* err,
                       size_t err_size);
double gltf_read_component(const gltf_element_view& view, size_t element, size_t component);

// Decodes every EXT_/KHR_meshopt_compression bufferView into tinygltf's model (gltf_meshopt.cpp).
int gltf_decode_meshopt(gltf_doc* doc, char* err, size_t err_size);
// The EXT_/KHR_meshopt_compression object of a bufferView (its name in *name), or nullptr.
const ordered_json* gltf_meshopt_of(const ordered_json& view, const char** name);
// The meshopt extension skinpack writes into doc: KHR_meshopt_compression when the input uses it,
// else EXT_meshopt_compression.
const char* gltf_meshopt_extension_for(const gltf_doc* doc);
// ATTRIBUTES-mode encoding (vertex codec version 0) of count elements of stride bytes into *out.
// false when stride does not allow the mode (a multiple of 4, at most 256) or the library
// cannot write version 0.
bool gltf_meshopt_encode_attributes(const void* data, size_t count, size_t stride, std::vector<unsigned char>* out);

// The JSON array doc->json[key], created empty when missing.
ordered_json& gltf_json_array(gltf_doc* doc, const char* key);

#endif // SKINPACK_GLTF_DOC_HPP
