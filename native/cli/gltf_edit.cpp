// gltf_edit.cpp - surgical edits of the input's JSON (gltf_doc.hpp) and writing it out.
//
// Nothing is renumbered: new accessors and bufferViews are appended; the data of an accessor
// skinpack replaces goes into its own bufferView when no one else uses that view, and the old
// bytes are cut from the buffer when it is one skinpack writes anyway (a GLB's BIN chunk, a
// data: uri). Only objects at the end of their arrays are ever removed (what compress added,
// when decompress takes it away again). Every other member and every other byte is written as
// it was read.
#include "gltf_doc.hpp"
#include "skinpack.h"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include <unistd.h>

#define fail gltf_fail

// ---- who refers to what ----

// Extensions whose references to accessors, bufferViews and buffers are all known here (or
// that have none). A file using any other extension keeps every byte where it was.
static bool extension_is_known(const std::string& name) {
    static const char* const prefixes[] = {"KHR_materials_", "KHR_texture_", "KHR_lights_punctual",
                                           "KHR_mesh_quantization", "EXT_texture_webp", "EXT_texture_avif",
                                           "EXT_mesh_gpu_instancing", "KHR_xmp", "KHR_animation_pointer",
                                           "EXT_meshopt_compression", "KHR_meshopt_compression",
                                           "EXT_lights_image_based", GLTF_EXTENSION_NAME};
    for (const char* prefix : prefixes)
        if (name.rfind(prefix, 0) == 0) return true;
    return false;
}

static bool references_known(const gltf_doc* doc) {
    auto used = doc->json.find("extensionsUsed");
    if (used == doc->json.end() || !used->is_array()) return true;
    for (const ordered_json& name : *used)
        if (!name.is_string() || !extension_is_known(name.get<std::string>())) return false;
    return true;
}

struct references {
    std::vector<int> accessors, views; // reference counts
};

static void count(std::vector<int>& counts, const ordered_json& index) {
    if (index.is_number_integer() && index.get<long long>() >= 0 && size_t(index.get<long long>()) < counts.size())
        ++counts[size_t(index.get<long long>())];
}

static const ordered_json* member(const ordered_json& object, const char* key) {
    if (!object.is_object()) return nullptr;
    auto it = object.find(key);
    return it == object.end() ? nullptr : &*it;
}

static void count_values(std::vector<int>& counts, const ordered_json* object) {
    if (!object || !object->is_object()) return;
    for (const auto& item : object->items()) count(counts, item.value());
}

// The extension's own accessors, meshlet limits ("max...") excepted.
static void count_packed_skin(std::vector<int>& counts, const ordered_json& primitive) {
    const ordered_json* extensions = member(primitive, "extensions");
    const ordered_json* packed = extensions ? member(*extensions, GLTF_EXTENSION_NAME) : nullptr;
    if (!packed) return;
    for (const char* key : {"vertices", "tupleTable"})
        if (const ordered_json* v = member(*packed, key)) count(counts, *v);
    if (const ordered_json* meshlets = member(*packed, "meshlets"))
        if (meshlets->is_object())
            for (const auto& item : meshlets->items())
                if (item.key().rfind("max", 0) != 0) count(counts, item.value());
}

static void count_accessor_refs(const ordered_json& json, std::vector<int>& counts) {
    if (const ordered_json* meshes = member(json, "meshes"))
        for (const ordered_json& mesh : *meshes)
            if (const ordered_json* primitives = member(mesh, "primitives"))
                for (const ordered_json& primitive : *primitives) {
                    count_values(counts, member(primitive, "attributes"));
                    if (const ordered_json* indices = member(primitive, "indices")) count(counts, *indices);
                    if (const ordered_json* targets = member(primitive, "targets"))
                        for (const ordered_json& target : *targets) count_values(counts, &target);
                    count_packed_skin(counts, primitive);
                }
    if (const ordered_json* skins = member(json, "skins"))
        for (const ordered_json& skin : *skins)
            if (const ordered_json* ibm = member(skin, "inverseBindMatrices")) count(counts, *ibm);
    if (const ordered_json* animations = member(json, "animations"))
        for (const ordered_json& animation : *animations)
            if (const ordered_json* samplers = member(animation, "samplers"))
                for (const ordered_json& sampler : *samplers)
                    for (const char* key : {"input", "output"})
                        if (const ordered_json* v = member(sampler, key)) count(counts, *v);
    if (const ordered_json* nodes = member(json, "nodes"))
        for (const ordered_json& node : *nodes) {
            const ordered_json* extensions = member(node, "extensions");
            const ordered_json* instancing = extensions ? member(*extensions, "EXT_mesh_gpu_instancing") : nullptr;
            if (instancing) count_values(counts, member(*instancing, "attributes"));
        }
}

static void count_view_refs(const ordered_json& json, std::vector<int>& counts) {
    if (const ordered_json* accessors = member(json, "accessors"))
        for (const ordered_json& accessor : *accessors) {
            if (const ordered_json* v = member(accessor, "bufferView")) count(counts, *v);
            if (const ordered_json* sparse = member(accessor, "sparse"))
                for (const char* part : {"indices", "values"})
                    if (const ordered_json* p = member(*sparse, part))
                        if (const ordered_json* v = member(*p, "bufferView")) count(counts, *v);
        }
    if (const ordered_json* images = member(json, "images"))
        for (const ordered_json& image : *images)
            if (const ordered_json* v = member(image, "bufferView")) count(counts, *v);
}

static size_t array_size(const ordered_json& json, const char* key) {
    const ordered_json* array = member(json, key);
    return array && array->is_array() ? array->size() : 0;
}

static references find_references(const gltf_doc* doc) {
    references refs;
    refs.accessors.assign(array_size(doc->json, "accessors"), 0);
    refs.views.assign(array_size(doc->json, "bufferViews"), 0);
    count_accessor_refs(doc->json, refs.accessors);
    count_view_refs(doc->json, refs.views);
    return refs;
}

// ---- buffer bytes ----

static bool is_data_uri(const ordered_json& buffer) {
    const ordered_json* uri = member(buffer, "uri");
    return uri && uri->is_string() && uri->get<std::string>().rfind("data:", 0) == 0;
}

// The bytes of an input buffer that skinpack writes out itself (GLB BIN chunk, data: uri), or
// nullptr for external files and fallback buffers, whose bytes stay where they are.
static std::vector<unsigned char>* rewritable_bytes(gltf_doc* doc, int buffer) {
    if (buffer < 0 || size_t(buffer) >= doc->model.buffers.size() || doc->fallback_buffer[size_t(buffer)])
        return nullptr;
    const ordered_json& json = doc->json["buffers"][size_t(buffer)];
    if (doc->binary && buffer == 0 && !json.contains("uri")) return &doc->bin;
    if (!is_data_uri(json)) return nullptr;
    auto cut = doc->cut_data.find(size_t(buffer));
    if (cut != doc->cut_data.end()) return &cut->second;
    return &(doc->cut_data[size_t(buffer)] = doc->model.buffers[size_t(buffer)].data); // the model stays as read
}

static size_t json_size(const ordered_json& object, const char* key) {
    const ordered_json* v = member(object, key);
    return v && v->is_number_unsigned() ? v->get<size_t>() : 0;
}

// Byte ranges of buffer b that something uses: bufferViews, and meshopt's compressed ranges.
static void used_ranges(const gltf_doc* doc, int b, size_t skip_view, std::vector<std::pair<size_t, size_t>>* out) {
    const ordered_json* views = member(doc->json, "bufferViews");
    if (!views) return;
    for (size_t i = 0; i < views->size(); ++i) {
        const ordered_json& view = (*views)[i];
        const ordered_json* buffer = member(view, "buffer");
        if (i != skip_view && buffer && buffer->is_number_integer() && buffer->get<int>() == b) {
            size_t offset = json_size(view, "byteOffset");
            out->push_back({offset, offset + json_size(view, "byteLength")});
        }
        const char* name = nullptr;
        const ordered_json* meshopt = gltf_meshopt_of(view, &name);
        const ordered_json* source = meshopt ? member(*meshopt, "buffer") : nullptr;
        if (i != skip_view && source && source->is_number_integer() && source->get<int>() == b) {
            size_t offset = json_size(*meshopt, "byteOffset");
            out->push_back({offset, offset + json_size(*meshopt, "byteLength")});
        }
    }
}

static void shift_offset(ordered_json& object, size_t from, size_t by) {
    size_t offset = json_size(object, "byteOffset");
    if (offset >= from && object.contains("byteOffset")) object["byteOffset"] = offset - by;
}

// The range a view's bytes occupy: its own, or for a meshopt view the compressed range.
static ordered_json* byte_range_of(ordered_json& view) {
    const char* name = nullptr;
    const ordered_json* meshopt = gltf_meshopt_of(view, &name);
    return meshopt ? const_cast<ordered_json*>(meshopt) : &view;
}

// Cuts bytes [begin, begin + length) of buffer b when skinpack writes that buffer and no range
// but view `skip_view`'s overlaps them; later views (and meshopt ranges) move down. Whole 4-byte
// words only, so every alignment is kept: a range's padding up to the next word (or the buffer's
// end) goes with it when nothing else uses those bytes, else its last partial word stays. Returns
// the bytes freed.
static size_t cut_bytes(gltf_doc* doc, int b, size_t begin, size_t length, size_t skip_view) {
    ordered_json& views = doc->json["bufferViews"];
    std::vector<unsigned char>* bytes = rewritable_bytes(doc, b);
    if (!bytes || begin % 4 || begin + length > bytes->size()) return 0;
    std::vector<std::pair<size_t, size_t>> used;
    used_ranges(doc, b, skip_view, &used);
    auto overlaps = [&](size_t end) {
        for (const auto& range : used)
            if (range.first < end && range.second > begin) return true;
        return false;
    };
    // With the padding after it (a meshopt range's length is any), or up to the buffer's end.
    size_t end = std::min(begin + ((length + 3) & ~size_t(3)), bytes->size());
    length = !overlaps(end) ? end - begin : length & ~size_t(3);
    if (length == 0 || overlaps(begin + length)) return 0; // shared bytes
    bytes->erase(bytes->begin() + long(begin), bytes->begin() + long(begin + length));
    for (size_t i = 0; i < views.size(); ++i) {
        ordered_json& other = views[i];
        const ordered_json* ob = member(other, "buffer");
        if (i != skip_view && ob && ob->is_number_integer() && ob->get<int>() == b) shift_offset(other, begin + length, length);
        ordered_json* meshopt = byte_range_of(other);
        const ordered_json* source = meshopt != &other ? member(*meshopt, "buffer") : nullptr;
        if (source && source->is_number_integer() && source->get<int>() == b) shift_offset(*meshopt, begin + length, length);
    }
    return length;
}

// Cuts all bytes of bufferView `view_index` (see cut_bytes).
static size_t cut_view_bytes(gltf_doc* doc, size_t view_index) {
    ordered_json& range = *byte_range_of(doc->json["bufferViews"][view_index]);
    const ordered_json* buffer = member(range, "buffer");
    if (!buffer || !buffer->is_number_integer()) return 0;
    return cut_bytes(doc, buffer->get<int>(), json_size(range, "byteOffset"), json_size(range, "byteLength"),
                     view_index);
}

// An accessor that shares a tightly packed view with others (TEXCOORD_0 and JOINTS_0 back to
// back): its own bytes are cut from inside the view, which shrinks, and the accessors after it
// in the view move down. Only when nothing else reads those bytes. Returns the bytes freed.
static size_t cut_accessor_bytes(gltf_doc* doc, size_t accessor_index, size_t view_index) {
    ordered_json& accessors = doc->json["accessors"];
    ordered_json& view = doc->json["bufferViews"][view_index];
    const ordered_json* buffer = member(view, "buffer");
    const tinygltf::Accessor& a = doc->model.accessors[accessor_index];
    size_t element = gltf_component_size(a.componentType) * gltf_type_components(a.type);
    size_t stride = json_size(view, "byteStride");
    if (!buffer || !buffer->is_number_integer() || (stride && stride != element) || view.contains("extensions") ||
        !element)
        return 0; // interleaved: the bytes are not one range
    size_t begin = json_size(accessors[accessor_index], "byteOffset"), length = a.count * element;
    if (length % 4 || begin % 4 || begin + length > json_size(view, "byteLength")) return 0;
    for (size_t i = 0; i < accessors.size(); ++i) { // every other reader of the view must lie outside the range
        const ordered_json* v = member(accessors[i], "bufferView");
        if (i == accessor_index || !v || !v->is_number_unsigned() || v->get<size_t>() != view_index) continue;
        if (i >= doc->model.accessors.size()) return 0;
        const tinygltf::Accessor& o = doc->model.accessors[i];
        size_t o_begin = json_size(accessors[i], "byteOffset");
        size_t o_element = gltf_component_size(o.componentType) * gltf_type_components(o.type);
        size_t o_end = o_begin + (o.count ? (o.count - 1) * (stride ? stride : o_element) + o_element : 0);
        if (o.sparse.isSparse || (o_begin < begin + length && o_end > begin)) return 0;
    }
    if (const ordered_json* images = member(doc->json, "images"))
        for (const ordered_json& image : *images)
            if (const ordered_json* v = member(image, "bufferView"))
                if (v->is_number_unsigned() && v->get<size_t>() == view_index) return 0;
    size_t freed = cut_bytes(doc, buffer->get<int>(), json_size(view, "byteOffset") + begin, length, view_index);
    if (!freed) return 0;
    view["byteLength"] = json_size(view, "byteLength") - freed;
    for (size_t i = 0; i < accessors.size(); ++i) {
        const ordered_json* v = member(accessors[i], "bufferView");
        if (i != accessor_index && v && v->is_number_unsigned() && v->get<size_t>() == view_index)
            shift_offset(accessors[i], begin + freed, freed);
    }
    return freed;
}

// ---- new data ----

static void declare(gltf_doc* doc, const char* list_name, const char* name, bool present);

// Reserves size bytes, 4-aligned, in the new data (or the fallback buffer); returns the offset.
static size_t reserve(gltf_doc* doc, const void* data, size_t size) {
    if (!data) {
        if (doc->fallback_bytes == 0) doc->fallback_bytes = SP_FALLBACK_VIEW_OFFSET; /* see skinpack.h */
        size_t offset = doc->fallback_bytes;
        doc->fallback_bytes = (offset + size + 3) & ~size_t(3);
        return offset;
    }
    doc->added.resize((doc->added.size() + 3) & ~size_t(3), 0);
    size_t offset = doc->added.size();
    doc->added.insert(doc->added.end(), static_cast<const unsigned char*>(data),
                      static_cast<const unsigned char*>(data) + size);
    return offset;
}

// Points bufferView JSON `view` at new bytes (data NULL: the fallback buffer).
static void place_view(gltf_doc* doc, ordered_json& view, const void* data, size_t size, int flags) {
    view["buffer"] = data ? GLTF_PENDING_DATA_BUFFER : GLTF_PENDING_FALLBACK_BUFFER;
    view["byteOffset"] = reserve(doc, data, size);
    view["byteLength"] = size;
    view.erase("byteStride");
    if (flags & GLTF_ACCESSOR_VERTEX_ATTRIBUTE) view["target"] = 34962; // ARRAY_BUFFER
    else view.erase("target");
    const char* meshopt = nullptr;
    if (gltf_meshopt_of(view, &meshopt)) { // its meshopt data went with the old bytes
        view["extensions"].erase(meshopt);
        if (view["extensions"].empty()) view.erase("extensions");
    }
}

// Reserves size bytes in the meshopt fallback buffer (no data; its views start at 0, as
// gltfpack's do: only a meshopt decoder reads them); returns the offset.
static size_t reserve_meshopt_fallback(gltf_doc* doc, size_t size) {
    size_t offset = doc->meshopt_fallback_bytes;
    doc->meshopt_fallback_bytes = (offset + size + 3) & ~size_t(3);
    return offset;
}

extern "C" void gltf_plan_output(gltf_doc* doc, int binary) { doc->output_binary = binary != 0; }

// The bytes `item` adds to the JSON when it joins the array `key` of the root object, written as
// gltf_write_file writes it (compact in a GLB, indented in a .gltf).
static size_t json_growth(const gltf_doc* doc, const char* key, const ordered_json& item) {
    ordered_json before = ordered_json::object(), after;
    before[key] = ordered_json::array({ordered_json::object({{"byteLength", 1}})});
    after = before;
    after[key].push_back(item);
    int indent = doc->output_binary ? -1 : 2;
    return after.dump(indent).size() - before.dump(indent).size();
}

// The JSON bytes that compressing one more view adds: its extension object, and with the first
// one the fallback buffer and the extension's names in the lists.
static size_t meshopt_json_bytes(const gltf_doc* doc, const char* name, const ordered_json& meshopt) {
    ordered_json view = ordered_json::object({{"byteLength", 1}}), compressed = view;
    compressed["extensions"][name] = meshopt;
    size_t bytes = json_growth(doc, "bufferViews", compressed) - json_growth(doc, "bufferViews", view);
    if (doc->meshopt_fallback_bytes) return bytes;
    ordered_json buffer = ordered_json::object({{"byteLength", 1}});
    buffer["extensions"][name]["fallback"] = true;
    bytes += json_growth(doc, "buffers", buffer);
    for (const char* list : {"extensionsUsed", "extensionsRequired"}) {
        const ordered_json* names = member(doc->json, list);
        if (!names || !names->is_array() || std::find(names->begin(), names->end(), ordered_json(name)) == names->end())
            bytes += json_growth(doc, list, name);
    }
    return bytes;
}

// The bytes `size` bytes of binary data take in the output: as they are in a GLB, base64 in a .gltf.
static size_t stored_size(const gltf_doc* doc, size_t size) { return doc->output_binary ? size : (size + 2) / 3 * 4; }

// Points bufferView JSON `view` at count elements of stride bytes stored meshopt-compressed: the
// encoded bytes in the new data, the view in the meshopt fallback buffer. false (nothing placed)
// when the codec does not apply, or when the encoded bytes plus the JSON they need are not
// smaller than the bytes themselves.
static bool place_meshopt_view(gltf_doc* doc, ordered_json& view, const void* data, size_t count, size_t stride,
                               int flags) {
    std::vector<unsigned char> encoded;
    if (!gltf_meshopt_encode_attributes(data, count, stride, &encoded)) return false;
    const char* name = gltf_meshopt_extension_for(doc);
    ordered_json meshopt = ordered_json::object(); // gltfpack's member order
    meshopt["buffer"] = GLTF_PENDING_DATA_BUFFER;
    meshopt["byteOffset"] = doc->added.size();
    meshopt["byteLength"] = encoded.size();
    meshopt["byteStride"] = stride;
    meshopt["mode"] = "ATTRIBUTES";
    meshopt["count"] = count;
    if (stored_size(doc, encoded.size()) + meshopt_json_bytes(doc, name, meshopt) >= stored_size(doc, count * stride))
        return false;
    meshopt["byteOffset"] = reserve(doc, encoded.data(), encoded.size());
    view["buffer"] = GLTF_PENDING_MESHOPT_FALLBACK_BUFFER;
    view["byteOffset"] = reserve_meshopt_fallback(doc, count * stride);
    view["byteLength"] = count * stride;
    if (flags & GLTF_ACCESSOR_VERTEX_ATTRIBUTE) view["target"] = 34962; // ARRAY_BUFFER
    view["extensions"][name] = meshopt;
    // The fallback buffer has no data: a reader must decode, never read the placeholder.
    declare(doc, "extensionsUsed", name, true);
    declare(doc, "extensionsRequired", name, true);
    return true;
}

static void set_bounds(ordered_json& accessor, const void* data, size_t count, int component_type, int components) {
    gltf_element_view ev = {static_cast<const unsigned char*>(data), size_t(components) * gltf_component_size(component_type),
                            count, size_t(components), component_type, false};
    ordered_json min = ordered_json::array(), max = ordered_json::array();
    for (size_t c = 0; c < size_t(components); ++c) {
        double lo = INFINITY, hi = -INFINITY;
        for (size_t e = 0; e < count; ++e) {
            double v = gltf_read_component(ev, e, c); // raw integer values: glTF min/max are unnormalised
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
        if (component_type == GLTF_FLOAT) {
            min.push_back(lo);
            max.push_back(hi);
        } else {
            min.push_back((long long)lo);
            max.push_back((long long)hi);
        }
    }
    accessor["min"] = min;
    accessor["max"] = max;
}

static void describe_accessor(ordered_json& accessor, size_t count, int component_type, int components, int normalized) {
    accessor.erase("byteOffset");
    accessor.erase("sparse");
    accessor["componentType"] = component_type;
    if (normalized) accessor["normalized"] = true;
    else accessor.erase("normalized");
    accessor["count"] = count;
    accessor["type"] = gltf_type_name(components);
}

extern "C" int gltf_add_accessor(gltf_doc* doc, const void* data, size_t count, int component_type, int components,
                                 int normalized, int flags) {
    ordered_json& views = gltf_json_array(doc, "bufferViews");
    ordered_json& accessors = gltf_json_array(doc, "accessors");
    ordered_json view = ordered_json::object();
    size_t element = size_t(components) * gltf_component_size(component_type);
    if (!(flags & GLTF_ACCESSOR_MESHOPT) || !place_meshopt_view(doc, view, data, count, element, flags))
        place_view(doc, view, data, count * element, flags);
    views.push_back(view);
    ordered_json accessor = ordered_json::object();
    accessor["bufferView"] = views.size() - 1;
    describe_accessor(accessor, count, component_type, components, normalized);
    if (data && (flags & GLTF_ACCESSOR_BOUNDS)) set_bounds(accessor, data, count, component_type, components);
    accessors.push_back(accessor);
    doc->edited = true;
    return int(accessors.size() - 1);
}

extern "C" size_t gltf_stored_view_bytes(const gltf_doc* doc, int accessor) {
    const ordered_json* accessors = member(doc->json, "accessors");
    const ordered_json* views = member(doc->json, "bufferViews");
    if (!accessors || !views || accessor < 0 || size_t(accessor) >= accessors->size()) return 0;
    const ordered_json* index = member((*accessors)[size_t(accessor)], "bufferView");
    if (!index || !index->is_number_unsigned() || index->get<size_t>() >= views->size()) return 0;
    ordered_json view = (*views)[index->get<size_t>()]; // byte_range_of needs a mutable view
    return json_size(*byte_range_of(view), "byteLength");
}

// The bufferView that only accessor `accessor_index` uses (so its bytes may go), or -1.
static long own_view(const gltf_doc* doc, const ordered_json& accessor) {
    const ordered_json* view = member(accessor, "bufferView");
    if (!view || !view->is_number_integer() || !references_known(doc)) return -1;
    references refs = find_references(doc);
    size_t v = view->get<size_t>();
    return v < refs.views.size() && refs.views[v] == 1 ? long(v) : -1;
}

extern "C" size_t gltf_replace_accessor_data(gltf_doc* doc, int accessor_index, const void* data, size_t count,
                                             int component_type, int components, int normalized, int flags) {
    ordered_json& accessor = doc->json["accessors"][size_t(accessor_index)];
    size_t bytes = count * size_t(components) * gltf_component_size(component_type);
    size_t freed = 0;
    long view = own_view(doc, accessor);
    if (view >= 0) { // the accessor's own view moves to the new bytes; the old ones go
        freed = cut_view_bytes(doc, size_t(view));
        place_view(doc, doc->json["bufferViews"][size_t(view)], data, bytes, flags);
    } else {
        const ordered_json* shared = member(accessor, "bufferView");
        if (shared && shared->is_number_unsigned() && references_known(doc) &&
            size_t(accessor_index) < doc->model.accessors.size())
            freed = cut_accessor_bytes(doc, size_t(accessor_index), shared->get<size_t>());
        ordered_json fresh = ordered_json::object();
        place_view(doc, fresh, data, bytes, flags);
        ordered_json& views = gltf_json_array(doc, "bufferViews");
        views.push_back(fresh);
        accessor["bufferView"] = views.size() - 1;
    }
    if (data) {
        describe_accessor(accessor, count, component_type, components, normalized);
        accessor.erase("min");
        accessor.erase("max");
        if (flags & GLTF_ACCESSOR_BOUNDS) set_bounds(accessor, data, count, component_type, components);
    } else {
        accessor.erase("byteOffset"); // a data-less fallback keeps what it says about its values
    }
    doc->edited = true;
    return freed;
}

extern "C" size_t gltf_make_fallback(gltf_doc* doc, int accessor_index) {
    const tinygltf::Accessor& a = doc->model.accessors[size_t(accessor_index)];
    int components = int(gltf_type_components(a.type));
    return gltf_replace_accessor_data(doc, accessor_index, nullptr, a.count, a.componentType, components,
                                      a.normalized, 0);
}

// ---- primitives and the extension lists ----

static ordered_json& attributes_json(gltf_doc* doc, size_t mesh, size_t primitive) {
    return doc->json["meshes"][mesh]["primitives"][primitive]["attributes"];
}

static bool is_skin_set(const std::string& name, bool include_first) {
    for (const char* prefix : {"JOINTS_", "WEIGHTS_"})
        if (name.rfind(prefix, 0) == 0) return include_first || name.substr(strlen(prefix)) != "0";
    return false;
}

extern "C" void gltf_set_skin_attributes(gltf_doc* doc, size_t mesh, size_t primitive, int joints, int weights) {
    ordered_json& attributes = attributes_json(doc, mesh, primitive);
    std::vector<std::string> drop;
    for (const auto& item : attributes.items())
        if (is_skin_set(item.key(), false)) drop.push_back(item.key());
    for (const std::string& key : drop) attributes.erase(key);
    attributes["JOINTS_0"] = joints; // an existing member keeps its place
    attributes["WEIGHTS_0"] = weights;
    doc->edited = true;
}

extern "C" void gltf_remove_skin_attributes(gltf_doc* doc, size_t mesh, size_t primitive) {
    ordered_json& attributes = attributes_json(doc, mesh, primitive);
    std::vector<std::string> drop;
    for (const auto& item : attributes.items())
        if (is_skin_set(item.key(), true)) drop.push_back(item.key());
    for (const std::string& key : drop) attributes.erase(key);
    doc->edited = true;
}

// Adds or removes extension `name` in doc->json[list_name] ("extensionsUsed", "extensionsRequired").
static void declare(gltf_doc* doc, const char* list_name, const char* name, bool present) {
    auto list = doc->json.find(list_name);
    bool listed = false;
    if (list != doc->json.end() && list->is_array())
        listed = std::find(list->begin(), list->end(), ordered_json(name)) != list->end();
    if (present == listed) return;
    doc->edited = true;
    if (present) {
        gltf_json_array(doc, list_name).push_back(name);
        return;
    }
    list->erase(std::find(list->begin(), list->end(), ordered_json(name)));
    if (list->empty()) doc->json.erase(list_name);
}

extern "C" void gltf_declare_extension(gltf_doc* doc, int used, int required) {
    declare(doc, "extensionsUsed", GLTF_EXTENSION_NAME, used != 0);
    declare(doc, "extensionsRequired", GLTF_EXTENSION_NAME, required != 0);
}

// ---- removing what nothing uses ----

// A meshopt extension whose last compressed view skinpack removed leaves the extension lists.
static void undeclare_if_unused(gltf_doc* doc, const char* name) {
    if (const ordered_json* views = member(doc->json, "bufferViews"))
        for (const ordered_json& view : *views) {
            const char* used = nullptr;
            if (gltf_meshopt_of(view, &used) && strcmp(used, name) == 0) return;
        }
    declare(doc, "extensionsUsed", name, false);
    declare(doc, "extensionsRequired", name, false);
}

// Removes accessors from the end of the array while nothing refers to them and `removable`
// says they are skinpack's, then their bufferViews the same way (cutting their bytes).
extern "C" size_t gltf_remove_unused_tail(gltf_doc* doc, const int* removable, size_t removable_count) {
    if (!references_known(doc) || !doc->json.contains("accessors")) return 0;
    std::vector<int> ours(removable, removable + removable_count);
    size_t freed = 0;
    ordered_json& accessors = gltf_json_array(doc, "accessors");
    std::vector<size_t> candidate_views;
    std::vector<std::string> meshopt_names; // of the removed views (compress --meshopt)
    bool removed_accessors = false, removed_views = false;
    while (!accessors.empty()) {
        int last = int(accessors.size() - 1);
        references refs = find_references(doc);
        if (refs.accessors[size_t(last)] || std::find(ours.begin(), ours.end(), last) == ours.end()) break;
        if (const ordered_json* v = member(accessors.back(), "bufferView"))
            if (v->is_number_unsigned()) candidate_views.push_back(v->get<size_t>());
        accessors.erase(accessors.end() - 1);
        removed_accessors = doc->edited = true;
    }
    ordered_json& views = gltf_json_array(doc, "bufferViews");
    while (!views.empty()) {
        size_t last = views.size() - 1;
        references refs = find_references(doc);
        if (refs.views[last] || std::find(candidate_views.begin(), candidate_views.end(), last) == candidate_views.end())
            break;
        const ordered_json* buffer = member(views.back(), "buffer");
        if (buffer && buffer->is_number_integer() && buffer->get<int>() == GLTF_PENDING_FALLBACK_BUFFER) break;
        const char* meshopt = nullptr;
        if (gltf_meshopt_of(views.back(), &meshopt) && std::find(meshopt_names.begin(), meshopt_names.end(),
                                                                  std::string(meshopt)) == meshopt_names.end())
            meshopt_names.push_back(meshopt);
        if (buffer && buffer->is_number_unsigned()) doc->released_buffers.push_back(buffer->get<size_t>());
        freed += cut_view_bytes(doc, last);
        views.erase(views.end() - 1);
        removed_views = true;
    }
    if (removed_accessors && accessors.empty()) doc->json.erase("accessors");
    if (removed_views && views.empty()) doc->json.erase("bufferViews");
    for (const std::string& name : meshopt_names) undeclare_if_unused(doc, name.c_str());
    return freed;
}

// A data-less buffer of the input that skinpack's compact mode made (marked with our extension).
static bool is_our_fallback(const gltf_doc* doc, size_t buffer) {
    if (buffer >= doc->fallback_buffer.size() || !doc->fallback_buffer[buffer]) return false;
    const ordered_json* extensions = member(doc->json["buffers"][buffer], "extensions");
    return extensions && member(*extensions, GLTF_EXTENSION_NAME);
}

static bool in_input_fallback(const gltf_doc* doc, const ordered_json& view) {
    const ordered_json* buffer = member(view, "buffer");
    return buffer && buffer->is_number_unsigned() && is_our_fallback(doc, buffer->get<size_t>());
}

extern "C" void gltf_release_fallback(gltf_doc* doc) {
    if (!doc->json.contains("bufferViews") || !doc->json.contains("accessors")) return;
    ordered_json& views = doc->json["bufferViews"];
    references refs = find_references(doc);
    for (size_t i = 0; i < refs.accessors.size(); ++i) {
        ordered_json& accessor = doc->json["accessors"][i];
        const ordered_json* view = member(accessor, "bufferView");
        if (refs.accessors[i] || !view || !view->is_number_unsigned() || view->get<size_t>() >= views.size() ||
            !in_input_fallback(doc, views[view->get<size_t>()]))
            continue;
        for (const char* key : {"bufferView", "byteOffset", "min", "max"}) accessor.erase(key); // zeros, no data
        doc->edited = true;
    }
    refs = find_references(doc);
    static const unsigned char zeros[4] = {0, 0, 0, 0};
    for (size_t v = 0; v < views.size(); ++v)
        if (!refs.views[v] && in_input_fallback(doc, views[v])) {
            place_view(doc, views[v], zeros, sizeof(zeros), 0); // valid, unused, 4 bytes
            doc->edited = true;
        }
}

// ---- writing ----

static std::string base64(const std::vector<unsigned char>& bytes) {
    static const char* const table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    for (size_t i = 0; i < bytes.size(); i += 3) {
        uint32_t v = uint32_t(bytes[i]) << 16;
        if (i + 1 < bytes.size()) v |= uint32_t(bytes[i + 1]) << 8;
        if (i + 2 < bytes.size()) v |= bytes[i + 2];
        out += table[(v >> 18) & 63];
        out += table[(v >> 12) & 63];
        out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? table[v & 63] : '=';
    }
    return out;
}

static std::string data_uri(const std::vector<unsigned char>& bytes, const std::string& like) {
    size_t comma = like.find(',');
    std::string prefix = like.rfind("data:", 0) == 0 && comma != std::string::npos && like.find(";base64") < comma
                             ? like.substr(0, comma + 1)
                             : std::string("data:application/octet-stream;base64,");
    return prefix + base64(bytes);
}

static void pad4(std::vector<unsigned char>& bytes) { bytes.resize((bytes.size() + 3) & ~size_t(3), 0); }

// The output's buffers: where the new data goes, which buffers are written from memory.
struct output_buffers {
    std::vector<unsigned char> bin; // the GLB BIN chunk (binary output)
    bool has_bin = false;
};

// Buffer 0 becomes (binary output) or stops being (text output) the BIN chunk; buffers whose
// bytes were cut get them back as a data: uri.
static void convert_buffers(const gltf_doc* doc, ordered_json& json, bool binary, output_buffers* out) {
    ordered_json* buffers = json.contains("buffers") && json["buffers"].is_array() ? &json["buffers"] : nullptr;
    size_t count = buffers ? buffers->size() : 0;
    for (size_t b = 0; b < count; ++b) {
        ordered_json& buffer = (*buffers)[b];
        bool glb_chunk = doc->binary && b == 0 && !buffer.contains("uri");
        const std::vector<unsigned char>* bytes = glb_chunk ? &doc->bin : nullptr;
        auto cut = doc->cut_data.find(b);
        if (cut != doc->cut_data.end()) bytes = &cut->second;
        if (binary && b == 0 && (glb_chunk || is_data_uri(buffer))) {
            out->bin = bytes ? *bytes : doc->model.buffers[0].data;
            out->has_bin = true;
            buffer.erase("uri");
            buffer["byteLength"] = out->bin.size();
        } else if (bytes) {
            std::string like = buffer.contains("uri") && buffer["uri"].is_string() ? buffer["uri"].get<std::string>() : "";
            buffer["uri"] = data_uri(*bytes, like);
            buffer["byteLength"] = bytes->size();
            // keep the member order: uri before byteLength as most writers do is not required
        }
    }
}

// A data-less buffer of `bytes` bytes marked {"fallback": true} in extension `name`, appended to
// the output's buffers; returns its index (-1 when bytes is 0: none needed).
static long add_fallback_buffer(ordered_json& json, size_t bytes, const char* name) {
    if (!bytes) return -1;
    ordered_json buffer = ordered_json::object();
    buffer["byteLength"] = bytes;
    buffer["extensions"][name]["fallback"] = true;
    json["buffers"].push_back(buffer);
    return long(json["buffers"].size() - 1);
}

// A new view (or meshopt range) with a GLTF_PENDING_* buffer gets its real buffer and offset.
static void resolve_pending(ordered_json& range, long data_buffer, size_t base, long fallback, long meshopt_fallback) {
    const ordered_json* buffer = member(range, "buffer");
    if (!buffer || !buffer->is_number_integer()) return;
    if (buffer->get<int>() == GLTF_PENDING_DATA_BUFFER) {
        range["buffer"] = data_buffer;
        range["byteOffset"] = range["byteOffset"].get<size_t>() + base;
    } else if (buffer->get<int>() == GLTF_PENDING_FALLBACK_BUFFER) {
        range["buffer"] = fallback;
    } else if (buffer->get<int>() == GLTF_PENDING_MESHOPT_FALLBACK_BUFFER) {
        range["buffer"] = meshopt_fallback;
    }
}

// Appends the new data and the fallback buffers, and points the new bufferViews at them.
static void place_new_data(const gltf_doc* doc, ordered_json& json, bool binary, output_buffers* out) {
    long data_buffer = -1;
    size_t base = 0;
    if (!doc->added.empty()) {
        ordered_json& buffers = json["buffers"];
        if (!buffers.is_array()) buffers = ordered_json::array();
        if (binary && (out->has_bin || buffers.empty())) {
            if (buffers.empty()) buffers.push_back(ordered_json::object());
            pad4(out->bin);
            base = out->bin.size();
            out->bin.insert(out->bin.end(), doc->added.begin(), doc->added.end());
            out->has_bin = true;
            buffers[0]["byteLength"] = out->bin.size();
            data_buffer = 0;
        } else {
            ordered_json buffer = ordered_json::object();
            buffer["byteLength"] = doc->added.size();
            buffer["uri"] = data_uri(doc->added, "");
            buffers.push_back(buffer);
            data_buffer = long(buffers.size() - 1);
        }
    }
    // Ours last: when decompress cannot remove the packed views (a file with extensions whose
    // references are unknown), the meshopt views stay valid and our fallback buffer can still go.
    long meshopt_fallback = add_fallback_buffer(json, doc->meshopt_fallback_bytes, gltf_meshopt_extension_for(doc));
    long fallback = add_fallback_buffer(json, doc->fallback_bytes, GLTF_EXTENSION_NAME);
    if (!json.contains("bufferViews")) return;
    for (ordered_json& view : json["bufferViews"]) {
        resolve_pending(view, data_buffer, base, fallback, meshopt_fallback);
        ordered_json* compressed = byte_range_of(view); // the view itself unless meshopt-compressed
        if (compressed != &view) resolve_pending(*compressed, data_buffer, base, fallback, meshopt_fallback);
    }
}

// Drops buffers at the end of the list that nothing refers to any more and that skinpack made
// empty (an input fallback buffer after decompress, a data: buffer whose bytes were all cut).
static void drop_unused_buffers(const gltf_doc* doc, ordered_json& json) {
    if (!json.contains("buffers") || !json["buffers"].is_array()) return;
    ordered_json& buffers = json["buffers"];
    bool dropped = false;
    while (!buffers.empty()) {
        size_t last = buffers.size() - 1;
        auto cut = doc->cut_data.find(last);
        bool emptied = cut != doc->cut_data.end() && cut->second.empty();
        bool released = std::find(doc->released_buffers.begin(), doc->released_buffers.end(), last) !=
                            doc->released_buffers.end() && !buffers[last].contains("uri") && !(doc->binary && last == 0);
        if (!emptied && !released && !is_our_fallback(doc, last)) break;
        std::vector<std::pair<size_t, size_t>> used;
        used_ranges(doc, int(last), SIZE_MAX, &used);
        if (!used.empty()) break;
        buffers.erase(buffers.end() - 1);
        dropped = true;
    }
    if (dropped && buffers.empty()) json.erase("buffers");
}

static std::string folder_of(const char* path) {
    std::string dir(path);
    size_t slash = dir.find_last_of('/');
    return slash == std::string::npos ? std::string(".") : dir.substr(0, slash);
}

static std::string absolute_dir(const std::string& dir) {
    char* real = realpath(dir.c_str(), nullptr);
    std::string out = real ? real : dir;
    free(real);
    return out;
}

// The path from folder `from` to folder `to` (both absolute), ending in '/' unless empty.
static std::string relative_dir(const std::string& from, const std::string& to) {
    auto split = [](const std::string& path) {
        std::vector<std::string> parts;
        size_t start = 0;
        while (start <= path.size()) {
            size_t end = path.find('/', start);
            if (end == std::string::npos) end = path.size();
            if (end > start) parts.push_back(path.substr(start, end - start));
            start = end + 1;
        }
        return parts;
    };
    std::vector<std::string> a = split(from), b = split(to);
    size_t common = 0;
    while (common < a.size() && common < b.size() && a[common] == b[common]) ++common;
    std::string out;
    for (size_t i = common; i < a.size(); ++i) out += "../";
    for (size_t i = common; i < b.size(); ++i) {
        for (char c : b[i]) out += c == ' ' ? std::string("%20") : std::string(1, c);
        out += '/';
    }
    return out;
}

// A relative uri (no scheme, not absolute) as seen from the output's folder.
static void rebase_uri(ordered_json& object, const std::string& prefix) {
    const ordered_json* uri = member(object, "uri");
    if (prefix.empty() || !uri || !uri->is_string()) return;
    std::string value = uri->get<std::string>();
    size_t colon = value.find(':'), slash = value.find('/');
    if (value.empty() || value[0] == '/' || (colon != std::string::npos && (slash == std::string::npos || colon < slash)))
        return;
    object["uri"] = prefix + value;
}

static void rebase_uris(const gltf_doc* doc, ordered_json& json, const char* output_path) {
    if (doc->path.empty()) return;
    std::string prefix = relative_dir(absolute_dir(folder_of(output_path)), absolute_dir(doc->dir));
    for (const char* key : {"buffers", "images"})
        if (json.contains(key) && json[key].is_array())
            for (ordered_json& object : json[key]) rebase_uri(object, prefix);
}

static std::string glb_bytes(const std::string& json_text, const output_buffers& buffers) {
    std::string text = json_text;
    while (text.size() % 4) text.push_back(' ');
    std::vector<unsigned char> bin = buffers.bin;
    pad4(bin);
    uint32_t header[5] = {0x46546C67u, 2, uint32_t(20 + text.size() + (buffers.has_bin ? 8 + bin.size() : 0)),
                          uint32_t(text.size()), 0x4E4F534Au};
    std::string out(reinterpret_cast<const char*>(header), sizeof(header));
    out += text;
    if (buffers.has_bin) {
        uint32_t chunk[2] = {uint32_t(bin.size()), 0x004E4942u};
        out.append(reinterpret_cast<const char*>(chunk), sizeof(chunk));
        out.append(reinterpret_cast<const char*>(bin.data()), bin.size());
    }
    return out;
}

// The bytes of the output file: the edited JSON with its buffers placed.
static int output_bytes(const gltf_doc* doc, const char* path, bool binary, std::string* out, char* err, size_t err_size) {
    ordered_json json = doc->json;
    output_buffers buffers;
    drop_unused_buffers(doc, json);
    convert_buffers(doc, json, binary, &buffers);
    place_new_data(doc, json, binary, &buffers);
    if (path) rebase_uris(doc, json, path);
    std::string text;
    try {
        text = binary ? json.dump() : json.dump(2);
    } catch (const std::exception&) {
        return fail(err, err_size, "cannot write the JSON: a string in the file is not valid UTF-8");
    }
    if (binary && (text.size() > 0xfffffff0u || buffers.bin.size() > 0xfffffff0u - text.size()))
        return fail(err, err_size, "the output would be larger than a GLB can be (4 GiB)");
    *out = binary ? glb_bytes(text, buffers) : text + "\n";
    return 0;
}

extern "C" int gltf_serialize(const gltf_doc* doc, int binary, void** data, size_t* size, char* err, size_t err_size) {
    std::string bytes;
    if (output_bytes(doc, nullptr, binary != 0, &bytes, err, err_size)) return -1;
    *data = malloc(bytes.size() ? bytes.size() : 1);
    if (!*data) return fail(err, err_size, "out of memory");
    memcpy(*data, bytes.data(), bytes.size());
    *size = bytes.size();
    return 0;
}

static int write_bytes(const char* path, const std::string& bytes, char* err, size_t err_size) {
    std::string temp = std::string(path) + ".tmp-" + std::to_string(getpid());
    FILE* file = fopen(temp.c_str(), "wb");
    if (!file) return fail(err, err_size, "cannot create %s: %s", temp.c_str(), strerror(errno));
    bool ok = fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
    ok = (fflush(file) == 0) && ok;
    ok = (fclose(file) == 0) && ok;
    if (!ok || rename(temp.c_str(), path) != 0) {
        int e = errno;
        remove(temp.c_str());
        return fail(err, err_size, "cannot write %s: %s", path, strerror(e));
    }
    return 0;
}

extern "C" int gltf_write_file(const gltf_doc* doc, const char* path, int binary, size_t* bytes_written, char* err,
                               size_t err_size) {
    std::string bytes;
    if (output_bytes(doc, path, binary != 0, &bytes, err, err_size) || write_bytes(path, bytes, err, err_size)) return -1;
    if (bytes_written) *bytes_written = bytes.size();
    return 0;
}

static int copy_file(const gltf_doc* doc, const char* path, size_t* bytes_written, char* err, size_t err_size) {
    FILE* file = fopen(doc->path.c_str(), "rb");
    if (!file) return fail(err, err_size, "cannot open %s: %s", doc->path.c_str(), strerror(errno));
    std::string bytes;
    char chunk[65536];
    size_t n;
    while ((n = fread(chunk, 1, sizeof(chunk), file)) > 0) bytes.append(chunk, n);
    bool ok = !ferror(file);
    fclose(file);
    if (!ok) return fail(err, err_size, "cannot read %s", doc->path.c_str());
    if (write_bytes(path, bytes, err, err_size)) return -1;
    if (bytes_written) *bytes_written = bytes.size();
    return 0;
}

extern "C" int gltf_write_unchanged(const gltf_doc* doc, const char* path, int binary, size_t* bytes_written, char* err,
                                    size_t err_size) {
    bool same_kind = (binary != 0) == doc->binary && !doc->path.empty();
    if (same_kind && (doc->binary || absolute_dir(folder_of(path)) == absolute_dir(doc->dir)))
        return copy_file(doc, path, bytes_written, err, err_size);
    return gltf_write_file(doc, path, binary, bytes_written, err, err_size); // converted, uris rebased
}
