#include "baker/output/gltf_buffers.h"

#include <cstring>
#include <limits>
#include <set>

#include <tiny_gltf.h>

#include "mesh/errors.h"
#include "mesh/gltf_loader.h"

namespace hemibake {

namespace {

// tinygltf image callback: keep the encoded bytes (PNG, JPEG, KTX2, ...) instead of decoding, so the writer can
// store the input's images unchanged in buffer views.
bool keepEncodedImage(tinygltf::Image* image, const int, std::string*, std::string*, int, int, const unsigned char* bytes,
                      int size, void*) {
    image->image.assign(bytes, bytes + std::max(size, 0));
    image->width = image->height = image->component = image->bits = -1;
    return true;
}

// Extensions whose data refers to no accessor or buffer view the writer would have to remap (or that it remaps
// itself), so unused accessors and buffer views can be dropped safely.
bool extensionKnownSafe(const std::string& name) {
    static const std::set<std::string> known = {
        "KHR_lights_punctual", "KHR_texture_transform", "KHR_mesh_quantization", "KHR_texture_basisu",
        "EXT_texture_webp", "KHR_materials_variants", "KHR_xmp_json_ld", "EXT_mesh_gpu_instancing",
        "KHR_animation_pointer", "MOZ_lightmap",
    };
    return known.count(name) > 0 || name.rfind("KHR_materials_", 0) == 0;
}

std::string sniffMimeType(const std::vector<unsigned char>& b) {
    auto starts = [&](std::initializer_list<unsigned char> sig, std::size_t at = 0) {
        if (b.size() < at + sig.size()) return false;
        std::size_t k = at;
        for (unsigned char c : sig)
            if (b[k++] != c) return false;
        return true;
    };
    if (starts({0x89, 'P', 'N', 'G'})) return "image/png";
    if (starts({0xFF, 0xD8, 0xFF})) return "image/jpeg";
    if (starts({'R', 'I', 'F', 'F'}) && starts({'W', 'E', 'B', 'P'}, 8)) return "image/webp";
    if (starts({0xAB, 'K', 'T', 'X', ' ', '2', '0'})) return "image/ktx2";
    return "";
}

std::size_t align4(std::size_t n) { return (n + 3) & ~std::size_t(3); }



double componentAsDouble(const std::uint8_t* p, int componentType) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: { std::int8_t v; std::memcpy(&v, p, 1); return v; }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return *p;
        case TINYGLTF_COMPONENT_TYPE_SHORT: { std::int16_t v; std::memcpy(&v, p, 2); return v; }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { std::uint16_t v; std::memcpy(&v, p, 2); return v; }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { std::uint32_t v; std::memcpy(&v, p, 4); return v; }
        case TINYGLTF_COMPONENT_TYPE_FLOAT: { float v; std::memcpy(&v, p, 4); return v; }
        default: return 0.0;
    }
}
}  // namespace

tinygltf::Model loadModelKeepingImages(const std::string& path) {
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(keepEncodedImage, nullptr);
    tinygltf::Model model;
    readTinyGltf(path, loader, model);
    return model;
}

GltfBufferEditor::GltfBufferEditor(tinygltf::Model& model, std::string path) : m_(model), path_(std::move(path)) {
    stagingBuffer_ = int(m_.buffers.size());
    m_.buffers.emplace_back();
}

void GltfBufferEditor::fail(const std::string& problem) const { throw InputError(path_, problem); }

const std::uint8_t* GltfBufferEditor::viewBytes(int viewIndex, std::size_t offset, std::size_t needed, const std::string& what) const {
    if (viewIndex < 0 || std::size_t(viewIndex) >= m_.bufferViews.size())
        fail(what + " refers to buffer view " + std::to_string(viewIndex) + ", which does not exist");
    const tinygltf::BufferView& view = m_.bufferViews[std::size_t(viewIndex)];
    if (view.buffer < 0 || std::size_t(view.buffer) >= m_.buffers.size()) fail(what + ": buffer view has no buffer");
    const auto& data = m_.buffers[std::size_t(view.buffer)].data;
    if (offset + needed > view.byteLength || view.byteOffset + view.byteLength > data.size())
        fail(what + " reaches past the end of its buffer view or buffer");
    return data.data() + view.byteOffset + offset;
}

RawElements GltfBufferEditor::readRaw(int accessorIndex, const std::string& what) const {
    if (accessorIndex < 0 || std::size_t(accessorIndex) >= m_.accessors.size())
        fail(what + " refers to accessor " + std::to_string(accessorIndex) + ", which does not exist");
    const tinygltf::Accessor& a = m_.accessors[std::size_t(accessorIndex)];
    RawElements r;
    r.componentType = a.componentType;
    r.type = a.type;
    r.normalized = a.normalized;
    r.count = a.count;
    const int componentSize = tinygltf::GetComponentSizeInBytes(std::uint32_t(a.componentType));
    const int components = tinygltf::GetNumComponentsInType(std::uint32_t(a.type));
    if (componentSize <= 0 || components <= 0) fail(what + " has an unknown component type or type");
    if (a.type == TINYGLTF_TYPE_MAT2 || a.type == TINYGLTF_TYPE_MAT3 || a.type == TINYGLTF_TYPE_MAT4)
        fail(what + " is a matrix accessor, which is not a vertex attribute");
    r.elementSize = std::size_t(componentSize) * std::size_t(components);
    r.bytes.assign(r.count * r.elementSize, 0);
    if (a.bufferView >= 0 && r.count > 0) {
        if (std::size_t(a.bufferView) >= m_.bufferViews.size())
            fail(what + " refers to a buffer view that does not exist");
        const tinygltf::BufferView& view = m_.bufferViews[std::size_t(a.bufferView)];
        const std::size_t stride = view.byteStride ? view.byteStride : r.elementSize;
        const std::uint8_t* base =
            viewBytes(a.bufferView, a.byteOffset, stride * (r.count - 1) + r.elementSize, what);
        for (std::size_t e = 0; e < r.count; ++e)
            std::memcpy(r.bytes.data() + e * r.elementSize, base + e * stride, r.elementSize);
    }
    if (a.sparse.isSparse && a.sparse.count > 0) {
        const std::size_t n = std::size_t(a.sparse.count);
        const int indexSize = tinygltf::GetComponentSizeInBytes(std::uint32_t(a.sparse.indices.componentType));
        if (indexSize != 1 && indexSize != 2 && indexSize != 4) fail(what + ": sparse indices have a bad component type");
        const std::uint8_t* idx = viewBytes(a.sparse.indices.bufferView, std::size_t(a.sparse.indices.byteOffset),
                                            n * std::size_t(indexSize), what + " sparse indices");
        const std::uint8_t* val = viewBytes(a.sparse.values.bufferView, std::size_t(a.sparse.values.byteOffset),
                                            n * r.elementSize, what + " sparse values");
        for (std::size_t j = 0; j < n; ++j) {
            const std::size_t target = std::size_t(componentAsDouble(idx + j * std::size_t(indexSize), a.sparse.indices.componentType));
            if (target >= r.count) fail(what + ": sparse index out of range");
            std::memcpy(r.bytes.data() + target * r.elementSize, val + j * r.elementSize, r.elementSize);
        }
    }
    return r;
}

int GltfBufferEditor::addView(const void* data, std::size_t bytes, int target, std::size_t stride) {
    staging_.resize(align4(staging_.size()), 0);
    tinygltf::BufferView view;
    view.buffer = stagingBuffer_;
    view.byteOffset = staging_.size();
    view.byteLength = bytes;
    view.byteStride = stride;
    view.target = target;
    const auto* p = static_cast<const std::uint8_t*>(data);
    staging_.insert(staging_.end(), p, p + bytes);
    m_.bufferViews.push_back(std::move(view));
    return int(m_.bufferViews.size()) - 1;
}

// A vertex attribute accessor holding raw's elements at `order` (glTF vertex indices), in raw's types.
int GltfBufferEditor::addGatheredAttribute(const RawElements& raw, const std::vector<std::uint32_t>& order, bool withMinMax) {
    // Vertex attribute elements must start on 4-byte boundaries.
    const std::size_t stride = align4(raw.elementSize);
    std::vector<std::uint8_t> data(stride * order.size(), 0);
    for (std::size_t v = 0; v < order.size(); ++v)
        std::memcpy(data.data() + v * stride, raw.bytes.data() + std::size_t(order[v]) * raw.elementSize, raw.elementSize);
    const int view = addView(data.data(), data.size(), kArrayBuffer, stride != raw.elementSize ? stride : 0);
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = raw.componentType;
    a.type = raw.type;
    a.normalized = raw.normalized;
    a.count = order.size();
    if (withMinMax) {
        const int components = tinygltf::GetNumComponentsInType(std::uint32_t(raw.type));
        const std::size_t componentSize = raw.elementSize / std::size_t(components);
        a.minValues.assign(std::size_t(components), std::numeric_limits<double>::infinity());
        a.maxValues.assign(std::size_t(components), -std::numeric_limits<double>::infinity());
        for (std::uint32_t g : order)
            for (int c = 0; c < components; ++c) {
                const double x = componentAsDouble(raw.bytes.data() + std::size_t(g) * raw.elementSize +
                                                       std::size_t(c) * componentSize,
                                                   raw.componentType);
                a.minValues[std::size_t(c)] = std::min(a.minValues[std::size_t(c)], x);
                a.maxValues[std::size_t(c)] = std::max(a.maxValues[std::size_t(c)], x);
            }
    }
    m_.accessors.push_back(std::move(a));
    return int(m_.accessors.size()) - 1;
}

void GltfBufferEditor::moveImagesIntoBufferViews() {
    for (std::size_t i = 0; i < m_.images.size(); ++i) {
        tinygltf::Image& image = m_.images[i];
        if (image.bufferView >= 0) {
            if (image.mimeType.empty()) image.mimeType = sniffMimeType(image.image);
        } else if (!image.image.empty()) {
            // External file or data URI: tinygltf read it; store the same bytes in the BIN buffer.
            if (image.mimeType.empty()) image.mimeType = sniffMimeType(image.image);
            if (image.mimeType.empty()) fail("image " + std::to_string(i) + " ('" + image.uri + "') has an unknown format");
            image.bufferView = addView(image.image.data(), image.image.size(), 0);
        } else if (!image.uri.empty()) {
            fail("image " + std::to_string(i) + " ('" + image.uri + "') could not be read");
        }
        image.uri.clear();
        image.image.clear();
    }
}

// One BIN buffer holding exactly the buffer views something refers to.
void GltfBufferEditor::compactBuffers() {
    bool prune = true;
    for (const auto& e : m_.extensionsUsed)
        if (!extensionKnownSafe(e)) prune = false;

    // Accessors.
    std::vector<int> accessorMap(m_.accessors.size(), prune ? -1 : 0);
    auto markAccessor = [&](int a) {
        if (a >= 0 && std::size_t(a) < accessorMap.size()) accessorMap[std::size_t(a)] = 0;
    };
    for (const auto& mesh : m_.meshes)
        for (const auto& prim : mesh.primitives) {
            for (const auto& [name, a] : prim.attributes) markAccessor(a);
            markAccessor(prim.indices);
            for (const auto& target : prim.targets)
                for (const auto& [name, a] : target) markAccessor(a);
        }
    for (const auto& skin : m_.skins) markAccessor(skin.inverseBindMatrices);
    for (const auto& anim : m_.animations)
        for (const auto& s : anim.samplers) {
            markAccessor(s.input);
            markAccessor(s.output);
        }
    for (const auto& node : m_.nodes)
        if (auto it = node.extensions.find("EXT_mesh_gpu_instancing");
            it != node.extensions.end() && it->second.Has("attributes") && it->second.Get("attributes").IsObject())
            for (const auto& key : it->second.Get("attributes").Keys())
                markAccessor(it->second.Get("attributes").Get(key).GetNumberAsInt());
    std::vector<tinygltf::Accessor> accessors;
    for (std::size_t a = 0; a < accessorMap.size(); ++a)
        if (accessorMap[a] == 0) {
            accessorMap[a] = int(accessors.size());
            accessors.push_back(std::move(m_.accessors[a]));
        }
    m_.accessors = std::move(accessors);
    auto remapAccessor = [&](int& a) {
        if (a >= 0 && std::size_t(a) < accessorMap.size()) a = accessorMap[std::size_t(a)];
    };
    for (auto& mesh : m_.meshes)
        for (auto& prim : mesh.primitives) {
            for (auto& [name, a] : prim.attributes) remapAccessor(a);
            remapAccessor(prim.indices);
            for (auto& target : prim.targets)
                for (auto& [name, a] : target) remapAccessor(a);
        }
    for (auto& skin : m_.skins) remapAccessor(skin.inverseBindMatrices);
    for (auto& anim : m_.animations)
        for (auto& s : anim.samplers) {
            remapAccessor(s.input);
            remapAccessor(s.output);
        }
    for (auto& node : m_.nodes)
        if (auto it = node.extensions.find("EXT_mesh_gpu_instancing");
            it != node.extensions.end() && it->second.IsObject() && it->second.Has("attributes") &&
            it->second.Get("attributes").IsObject()) {
            auto& attrs = it->second.Get<tinygltf::Value::Object>()["attributes"].Get<tinygltf::Value::Object>();
            for (auto& [key, value] : attrs) {
                int a = value.GetNumberAsInt();
                remapAccessor(a);
                value = tinygltf::Value(a);
            }
        }

    // Buffer views.
    std::vector<int> viewMap(m_.bufferViews.size(), prune ? -1 : 0);
    auto markView = [&](int v) {
        if (v >= 0 && std::size_t(v) < viewMap.size()) viewMap[std::size_t(v)] = 0;
    };
    for (const auto& a : m_.accessors) {
        markView(a.bufferView);
        if (a.sparse.isSparse) {
            markView(a.sparse.indices.bufferView);
            markView(a.sparse.values.bufferView);
        }
    }
    for (const auto& image : m_.images) markView(image.bufferView);
    std::vector<std::uint8_t> bin;
    std::vector<tinygltf::BufferView> views;
    for (std::size_t v = 0; v < viewMap.size(); ++v) {
        if (viewMap[v] != 0) continue;
        tinygltf::BufferView view = std::move(m_.bufferViews[v]);
        if (view.buffer < 0 || std::size_t(view.buffer) >= m_.buffers.size() ||
            view.byteOffset + view.byteLength > m_.buffers[std::size_t(view.buffer)].data.size())
            fail("buffer view " + std::to_string(v) + " reaches past the end of its buffer");
        const auto& data = m_.buffers[std::size_t(view.buffer)].data;
        bin.resize(align4(bin.size()), 0);
        const std::size_t at = bin.size();
        bin.insert(bin.end(), data.begin() + std::ptrdiff_t(view.byteOffset),
                   data.begin() + std::ptrdiff_t(view.byteOffset + view.byteLength));
        view.buffer = 0;
        view.byteOffset = at;
        viewMap[v] = int(views.size());
        views.push_back(std::move(view));
    }
    m_.bufferViews = std::move(views);
    auto remapView = [&](int& v) {
        if (v >= 0 && std::size_t(v) < viewMap.size()) v = viewMap[std::size_t(v)];
    };
    for (auto& a : m_.accessors) {
        remapView(a.bufferView);
        if (a.sparse.isSparse) {
            remapView(a.sparse.indices.bufferView);
            remapView(a.sparse.values.bufferView);
        }
    }
    for (auto& image : m_.images) remapView(image.bufferView);

    tinygltf::Buffer buffer;
    buffer.data = std::move(bin);
    m_.buffers.clear();
    m_.buffers.push_back(std::move(buffer));
}

void GltfBufferEditor::finish() {
    m_.buffers[std::size_t(stagingBuffer_)].data = std::move(staging_);
    compactBuffers();
}

}  // namespace hemibake
