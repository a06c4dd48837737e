#include "baker/output/gltf_writer.h"
#include "mesh/gltf_loader.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <utility>

#include <tiny_gltf.h>

#include "baker/util/atomic_output.h"
#include "baker/output/exitant_radiance_atlas.h"
#include "baker/output/png_preview.h"
#include "mesh/errors.h"
#include "mesh/gltf_accessor.h"

namespace hemibake {

namespace {

namespace fs = std::filesystem;

constexpr const char* kLightmapExtension = "MOZ_lightmap";
constexpr const char* kEmissiveStrengthExtension = "KHR_materials_emissive_strength";
constexpr int kArrayBuffer = 34962;
constexpr int kElementArrayBuffer = 34963;

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

// tinygltf image callback: keep the encoded bytes (PNG, JPEG, KTX2, ...) instead of decoding, so the writer can
// store the input's images unchanged in buffer views.
bool keepEncodedImage(tinygltf::Image* image, const int, std::string*, std::string*, int, int, const unsigned char* bytes,
                      int size, void*) {
    image->image.assign(bytes, bytes + std::max(size, 0));
    image->width = image->height = image->component = image->bits = -1;
    return true;
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

tinygltf::Model loadModel(const std::string& path) {
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(keepEncodedImage, nullptr);
    tinygltf::Model model;
    readTinyGltf(path, loader, model);
    return model;
}

std::size_t align4(std::size_t n) { return (n + 3) & ~std::size_t(3); }

using Triangle = std::array<std::uint32_t, 3>;

// The loader's triangle list for a primitive (mesh/gltf_loader.cpp assembleTriangles): SurfaceMesh::sourceFace
// indexes it.
std::vector<Triangle> assembleTriangles(int mode, const std::vector<std::uint32_t>& idx) {
    std::vector<Triangle> tris;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        for (std::size_t i = 0; i + 2 < idx.size(); i += 3) tris.push_back({idx[i], idx[i + 1], idx[i + 2]});
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        for (std::size_t i = 0; i + 2 < idx.size(); ++i)
            tris.push_back(i % 2 == 0 ? Triangle{idx[i], idx[i + 1], idx[i + 2]} : Triangle{idx[i + 1], idx[i], idx[i + 2]});
    } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
        for (std::size_t i = 1; i + 1 < idx.size(); ++i) tris.push_back({idx[0], idx[i], idx[i + 1]});
    }
    return tris;
}

// An accessor's elements, densely packed (sparse substitutions applied).
struct RawElements {
    int componentType = 0;
    int type = 0;
    bool normalized = false;
    std::size_t elementSize = 0;
    std::size_t count = 0;
    std::vector<std::uint8_t> bytes;
};

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

class GlbBuilder {
public:
    GlbBuilder(tinygltf::Model& model, const std::string& path, const Scene& scene, const UvAtlas& atlas,
               const std::vector<LightmapImage>& lightmaps, const GltfWriteOptions& options)
        : m_(model), path_(path), scene_(scene), atlas_(atlas), lightmaps_(lightmaps), options_(options) {}

    std::vector<BakedPrimitive> build() {
        for (const char* unsupported : {"EXT_meshopt_compression", "KHR_draco_mesh_compression"})
            if (std::find(m_.extensionsUsed.begin(), m_.extensionsUsed.end(), unsupported) != m_.extensionsUsed.end())
                throw InputError(path_, std::string("uses ") + unsupported + ", which the glTF writer cannot carry over");
        originalMeshes_ = m_.meshes;
        originalMaterials_ = m_.materials;
        stagingBuffer_ = int(m_.buffers.size());
        m_.buffers.emplace_back();

        selectBakedInstances();
        assignMeshes();
        for (const Baked& b : baked_) rewritePrimitive(b);
        assignMaterials();
        moveImagesIntoBufferViews();
        m_.buffers[std::size_t(stagingBuffer_)].data = std::move(staging_);
        compactBuffers();
        finishExtensionsAndAsset();

        std::vector<BakedPrimitive> entries;
        for (const Baked& b : baked_) {
            BakedPrimitive e;
            e.node = m_.nodes[std::size_t(b.node)].name;
            e.mesh = b.outMesh;
            e.primitive = b.primitive;
            e.lightmap = lightmapRelativePath(options_, atlas_.instances[std::size_t(b.instance)].atlas);
            const auto& r = atlas_.instances[std::size_t(b.instance)].rect;
            for (int k = 0; k < 4; ++k) e.rect[k] = r[std::size_t(k)];
            entries.push_back(e);
        }
        return entries;
    }

private:
    struct Baked {
        int instance = -1;
        int node = -1;
        int mesh = -1;  // input mesh
        int primitive = -1;
        int outMesh = -1;
    };

    [[noreturn]] void fail(const std::string& problem) const { throw InputError(path_, problem); }

    void selectBakedInstances() {
        std::set<std::pair<int, int>> seen;  // (node, primitive)
        for (std::size_t i = 0; i < scene_.instances.size(); ++i) {
            const UnwrappedInstance& ui = atlas_.instances[i];
            if (ui.atlas < 0 || ui.triangles.empty()) continue;
            const SourcePrimitive& s = scene_.instances[i].source;
            const std::string where = "instance " + std::to_string(i) + " ('" + s.nodeName + "')";
            if (s.node < 0 || std::size_t(s.node) >= m_.nodes.size() || m_.nodes[std::size_t(s.node)].mesh != s.mesh ||
                s.mesh < 0 || std::size_t(s.mesh) >= m_.meshes.size() || s.primitive < 0 ||
                std::size_t(s.primitive) >= m_.meshes[std::size_t(s.mesh)].primitives.size())
                fail(where + " does not match the file (was the scene loaded from it?)");
            if (std::size_t(ui.atlas) >= lightmaps_.size())
                throw std::invalid_argument(where + " is on atlas " + std::to_string(ui.atlas) + " but only " +
                                            std::to_string(lightmaps_.size()) + " lightmaps were given");
            // A node reached twice (an invalid hierarchy the loader tolerates) is written once.
            if (!seen.insert({s.node, s.primitive}).second) continue;
            baked_.push_back({int(i), s.node, s.mesh, s.primitive, -1});
        }
    }

    void assignMeshes() {
        std::map<int, int> meshOwner;  // input mesh → the node that keeps it
        std::map<int, int> nodeMesh;   // node → output mesh
        for (Baked& b : baked_) {
            auto it = nodeMesh.find(b.node);
            if (it == nodeMesh.end()) {
                int out = b.mesh;
                if (!meshOwner.emplace(b.mesh, b.node).second) {
                    tinygltf::Mesh copy = originalMeshes_[std::size_t(b.mesh)];
                    tinygltf::Node& node = m_.nodes[std::size_t(b.node)];
                    copy.name = (copy.name.empty() ? "mesh" + std::to_string(b.mesh) : copy.name) + " (" +
                                (node.name.empty() ? "node" + std::to_string(b.node) : node.name) + ")";
                    m_.meshes.push_back(std::move(copy));
                    out = int(m_.meshes.size()) - 1;
                    node.mesh = out;
                }
                it = nodeMesh.emplace(b.node, out).first;
            }
            b.outMesh = it->second;
            tinygltf::Node& node = m_.nodes[std::size_t(b.node)];
            if (node.name.empty()) node.name = "node" + std::to_string(b.node);
        }
    }

    // ---- buffer data --------------------------------------------------------------------------------------

    const std::uint8_t* viewBytes(int viewIndex, std::size_t offset, std::size_t needed, const std::string& what) const {
        if (viewIndex < 0 || std::size_t(viewIndex) >= m_.bufferViews.size())
            fail(what + " refers to buffer view " + std::to_string(viewIndex) + ", which does not exist");
        const tinygltf::BufferView& view = m_.bufferViews[std::size_t(viewIndex)];
        if (view.buffer < 0 || std::size_t(view.buffer) >= m_.buffers.size()) fail(what + ": buffer view has no buffer");
        const auto& data = m_.buffers[std::size_t(view.buffer)].data;
        if (offset + needed > view.byteLength || view.byteOffset + view.byteLength > data.size())
            fail(what + " reaches past the end of its buffer view or buffer");
        return data.data() + view.byteOffset + offset;
    }

    RawElements readRaw(int accessorIndex, const std::string& what) const {
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

    int addView(const void* data, std::size_t bytes, int target, std::size_t stride = 0) {
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
    int addGatheredAttribute(const RawElements& raw, const std::vector<std::uint32_t>& order, bool withMinMax) {
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

    // ---- geometry -----------------------------------------------------------------------------------------

    void rewritePrimitive(const Baked& b) {
        tinygltf::Primitive& prim = m_.meshes[std::size_t(b.outMesh)].primitives[std::size_t(b.primitive)];
        const tinygltf::Primitive orig = prim;
        const std::string where = "mesh " + std::to_string(b.mesh) + " primitive " + std::to_string(b.primitive);
        auto pos = orig.attributes.find("POSITION");
        if (pos == orig.attributes.end()) fail(where + " has no POSITION attribute");
        if (pos->second < 0 || std::size_t(pos->second) >= m_.accessors.size()) fail(where + " POSITION accessor does not exist");
        const std::size_t vertexCount = m_.accessors[std::size_t(pos->second)].count;

        std::vector<std::uint32_t> indices;
        if (orig.indices >= 0) {
            indices = readAccessorIndices(m_, orig.indices, path_, where + " indices");
        } else {
            indices.resize(vertexCount);
            for (std::size_t i = 0; i < vertexCount; ++i) indices[i] = std::uint32_t(i);
        }
        const auto gltfTris = assembleTriangles(orig.mode < 0 ? TINYGLTF_MODE_TRIANGLES : orig.mode, indices);

        const UnwrappedInstance& ui = atlas_.instances[std::size_t(b.instance)];
        const SurfaceMesh& mesh = scene_.instances[std::size_t(b.instance)].mesh;
        auto mismatch = [&](const std::string& what) {
            throw std::invalid_argument(where + " (instance " + std::to_string(b.instance) + "): " + what +
                                        " (scene or UV atlas not made from this file)");
        };
        if (ui.vertexSource.size() != ui.uv.size() || ui.faceSource.size() != ui.triangles.size())
            mismatch("unwrapped arrays of different lengths");
        // glTF vertex behind each unwrapped vertex.
        std::vector<std::uint32_t> gltfVertex(ui.vertexSource.size());
        for (std::size_t k = 0; k < ui.vertexSource.size(); ++k) {
            const int sv = ui.vertexSource[k];
            if (sv < 0 || std::size_t(sv) >= mesh.n_vertices()) mismatch("unwrapped vertex source out of range");
            const int g = mesh.sourceVertex(SurfaceMesh::VertexHandle(sv));
            if (g < 0 || std::size_t(g) >= vertexCount) mismatch("glTF vertex index out of range");
            gltfVertex[k] = std::uint32_t(g);
        }
        // The input's triangle order; each triangle's corners in the input's order (which also undoes the
        // loader's re-winding under mirroring transforms: the output is still placed by the same node).
        std::vector<std::pair<int, std::uint32_t>> order;  // (source glTF triangle, unwrapped triangle)
        order.reserve(ui.triangles.size());
        for (std::size_t t = 0; t < ui.triangles.size(); ++t) {
            const int f = ui.faceSource[t];
            if (f < 0 || std::size_t(f) >= mesh.n_faces()) mismatch("unwrapped face source out of range");
            const int src = mesh.sourceFace(SurfaceMesh::FaceHandle(f));
            if (src < 0 || std::size_t(src) >= gltfTris.size()) mismatch("source triangle out of range");
            order.push_back({src, std::uint32_t(t)});
        }
        std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& c) { return a.first < c.first; });

        std::vector<std::int64_t> outIndexOf(ui.uv.size(), -1);
        std::vector<std::uint32_t> outVertices;  // output vertex → unwrapped vertex
        std::vector<std::uint32_t> outIndices;
        outIndices.reserve(order.size() * 3);
        for (const auto& [src, t] : order) {
            const Triangle& g = gltfTris[std::size_t(src)];
            const auto& u = ui.triangles[t];
            for (int k = 0; k < 3; ++k) {
                int j = 0;
                while (j < 3 && (u[std::size_t(j)] >= ui.uv.size() || gltfVertex[u[std::size_t(j)]] != g[std::size_t(k)])) ++j;
                if (j == 3) mismatch("an unwrapped triangle's corners are not its source triangle's");
                const std::uint32_t uv = u[std::size_t(j)];
                if (outIndexOf[uv] < 0) {
                    outIndexOf[uv] = std::int64_t(outVertices.size());
                    outVertices.push_back(uv);
                }
                outIndices.push_back(std::uint32_t(outIndexOf[uv]));
            }
        }
        std::vector<std::uint32_t> gather(outVertices.size());
        for (std::size_t v = 0; v < outVertices.size(); ++v) gather[v] = gltfVertex[outVertices[v]];

        std::map<std::string, int> attributes;
        for (const auto& [name, accessor] : orig.attributes) {
            if (name == "TEXCOORD_1") continue;
            const RawElements raw = readRaw(accessor, where + " " + name);
            if (raw.count != vertexCount) fail(where + " " + name + " count differs from POSITION count");
            attributes[name] = addGatheredAttribute(raw, gather, name == "POSITION");
        }
        {
            std::vector<float> uv(outVertices.size() * 2);
            for (std::size_t v = 0; v < outVertices.size(); ++v) {
                uv[2 * v] = ui.uv[outVertices[v]].x;
                uv[2 * v + 1] = ui.uv[outVertices[v]].y;
            }
            tinygltf::Accessor a;
            a.bufferView = addView(uv.data(), uv.size() * sizeof(float), kArrayBuffer);
            a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
            a.type = TINYGLTF_TYPE_VEC2;
            a.count = outVertices.size();
            m_.accessors.push_back(std::move(a));
            attributes["TEXCOORD_1"] = int(m_.accessors.size()) - 1;
            // TEXCOORD_n semantics must be continuous from 0: a primitive without TEXCOORD_0 gets the lightmap
            // UVs there too (same accessor; no material of it reads TEXCOORD_0, or the input was invalid).
            if (!attributes.count("TEXCOORD_0")) attributes["TEXCOORD_0"] = attributes["TEXCOORD_1"];
        }
        std::vector<std::map<std::string, int>> targets;
        for (std::size_t t = 0; t < orig.targets.size(); ++t) {
            std::map<std::string, int> target;
            for (const auto& [name, accessor] : orig.targets[t]) {
                const std::string what = where + " target " + std::to_string(t) + " " + name;
                const RawElements raw = readRaw(accessor, what);
                if (raw.count != vertexCount) fail(what + " count differs from POSITION count");
                target[name] = addGatheredAttribute(raw, gather, name == "POSITION");
            }
            targets.push_back(std::move(target));
        }
        tinygltf::Accessor ia;
        ia.type = TINYGLTF_TYPE_SCALAR;
        ia.count = outIndices.size();
        if (outVertices.size() < 65535) {  // 65535 is the primitive-restart value, never an index
            std::vector<std::uint16_t> idx16(outIndices.begin(), outIndices.end());
            ia.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
            ia.bufferView = addView(idx16.data(), idx16.size() * 2, kElementArrayBuffer);
        } else {
            ia.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
            ia.bufferView = addView(outIndices.data(), outIndices.size() * 4, kElementArrayBuffer);
        }
        m_.accessors.push_back(std::move(ia));

        prim.attributes = std::move(attributes);
        prim.targets = std::move(targets);
        prim.indices = int(m_.accessors.size()) - 1;
        prim.mode = TINYGLTF_MODE_TRIANGLES;
    }

    // ---- materials and lightmap textures ------------------------------------------------------------------

    int lightmapSampler() {
        if (sampler_ < 0) {
            tinygltf::Sampler s;
            s.name = "hemibake lightmap";
            s.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
            s.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
            s.wrapS = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
            s.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
            m_.samplers.push_back(s);
            sampler_ = int(m_.samplers.size()) - 1;
        }
        return sampler_;
    }

    int addPngTexture(const std::vector<std::uint8_t>& rgb, int size, const std::string& name) {
        const std::vector<std::uint8_t> png = encodePng(rgb.data(), size, size, 3);
        tinygltf::Image image;
        image.name = name;
        image.mimeType = "image/png";
        image.bufferView = addView(png.data(), png.size(), 0);
        m_.images.push_back(std::move(image));
        tinygltf::Texture texture;
        texture.name = name;
        texture.source = int(m_.images.size()) - 1;
        texture.sampler = lightmapSampler();
        m_.textures.push_back(std::move(texture));
        return int(m_.textures.size()) - 1;
    }

    struct AtlasTexture {
        int texture = -1;
        double scale = 1.0;
    };

    const AtlasTexture& atlasTexture(int atlas) {
        auto it = atlasTextures_.find(atlas);
        if (it != atlasTextures_.end()) return it->second;
        const LightmapImage& lm = lightmaps_[std::size_t(atlas)];
        AtlasTexture t;
        if (options_.mode == GltfWriteOptions::Mode::Lightmap) {
            const float k = lightmapExposureScale(lm);
            t.scale = k;
            t.texture = addPngTexture(lightmapToSrgb8(lm, k), lm.size, "hemibake lightmap " + std::to_string(atlas));
        } else {
            std::vector<int> instances;
            for (const Baked& b : baked_) instances.push_back(b.instance);
            LightmapImage emitted = exitantRadianceAtlas(scene_, atlas_, lm, atlas, instances);
            const float k = lightmapExposureScale(emitted);
            t.scale = k;
            t.texture = addPngTexture(lightmapToSrgb8(emitted, k), lm.size, "hemibake emission " + std::to_string(atlas));
        }
        return atlasTextures_.emplace(atlas, t).first->second;
    }

    void configureMaterial(tinygltf::Material& mat, int atlas) {
        const AtlasTexture& tex = atlasTexture(atlas);
        if (options_.mode == GltfWriteOptions::Mode::Lightmap) {
            tinygltf::Value::Object ext;
            ext["index"] = tinygltf::Value(tex.texture);
            ext["texCoord"] = tinygltf::Value(1);
            ext["intensity"] = tinygltf::Value(tex.scale);
            mat.extensions[kLightmapExtension] = tinygltf::Value(std::move(ext));
            usedExtensions_.insert(kLightmapExtension);
        } else {
            auto& pbr = mat.pbrMetallicRoughness;
            const double alpha = pbr.baseColorFactor.size() == 4 ? pbr.baseColorFactor[3] : 1.0;
            pbr.baseColorFactor = {0.0, 0.0, 0.0, alpha};
            pbr.metallicFactor = 1.0;
            pbr.roughnessFactor = 1.0;
            mat.extensions.clear();
            mat.emissiveFactor = {1.0, 1.0, 1.0};
            mat.emissiveTexture = tinygltf::TextureInfo();
            mat.emissiveTexture.index = tex.texture;
            mat.emissiveTexture.texCoord = 1;
            tinygltf::Value::Object ext;
            ext["emissiveStrength"] = tinygltf::Value(tex.scale);
            mat.extensions[kEmissiveStrengthExtension] = tinygltf::Value(std::move(ext));
            usedExtensions_.insert(kEmissiveStrengthExtension);
        }
    }

    void assignMaterials() {
        std::set<std::pair<int, int>> bakedPrims;
        for (const Baked& b : baked_) bakedPrims.insert({b.outMesh, b.primitive});
        std::set<int> usedElsewhere;
        for (std::size_t m = 0; m < m_.meshes.size(); ++m)
            for (std::size_t p = 0; p < m_.meshes[m].primitives.size(); ++p)
                if (!bakedPrims.count({int(m), int(p)}) && m_.meshes[m].primitives[p].material >= 0)
                    usedElsewhere.insert(m_.meshes[m].primitives[p].material);
        std::map<std::pair<int, int>, int> materialFor;  // (input material or -1, atlas) → output material
        std::set<int> reused;
        for (const Baked& b : baked_) {
            tinygltf::Primitive& prim = m_.meshes[std::size_t(b.outMesh)].primitives[std::size_t(b.primitive)];
            int original = prim.material;
            if (original >= int(originalMaterials_.size())) fail("a primitive refers to a material that does not exist");
            const int atlas = atlas_.instances[std::size_t(b.instance)].atlas;
            auto it = materialFor.find({original, atlas});
            if (it == materialFor.end()) {
                int index;
                if (original < 0) {
                    tinygltf::Material mat;
                    mat.name = "hemibake default (lightmap " + std::to_string(atlas) + ")";
                    mat.pbrMetallicRoughness.baseColorFactor = {0.8, 0.8, 0.8, 1.0};
                    mat.pbrMetallicRoughness.metallicFactor = 0.0;
                    mat.pbrMetallicRoughness.roughnessFactor = 1.0;
                    m_.materials.push_back(std::move(mat));
                    index = int(m_.materials.size()) - 1;
                } else if (!usedElsewhere.count(original) && reused.insert(original).second) {
                    index = original;
                } else {
                    tinygltf::Material mat = originalMaterials_[std::size_t(original)];
                    mat.name = (mat.name.empty() ? "material" + std::to_string(original) : mat.name) + " (lightmap " +
                               std::to_string(atlas) + ")";
                    m_.materials.push_back(std::move(mat));
                    index = int(m_.materials.size()) - 1;
                }
                configureMaterial(m_.materials[std::size_t(index)], atlas);
                it = materialFor.emplace(std::make_pair(original, atlas), index).first;
            }
            prim.material = it->second;
        }
    }

    // ---- images, buffers ----------------------------------------------------------------------------------

    void moveImagesIntoBufferViews() {
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
    void compactBuffers() {
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

    void finishExtensionsAndAsset() {
        for (const auto& e : usedExtensions_)
            if (std::find(m_.extensionsUsed.begin(), m_.extensionsUsed.end(), e) == m_.extensionsUsed.end())
                m_.extensionsUsed.push_back(e);
        // MOZ_lightmap is optional by convention: viewers without it still show the PBR material.
        m_.extensionsRequired.erase(
            std::remove(m_.extensionsRequired.begin(), m_.extensionsRequired.end(), std::string(kLightmapExtension)),
            m_.extensionsRequired.end());
        m_.asset.generator = "hemibake";
        if (m_.asset.version.empty()) m_.asset.version = "2.0";
    }

    tinygltf::Model& m_;
    std::string path_;
    const Scene& scene_;
    const UvAtlas& atlas_;
    const std::vector<LightmapImage>& lightmaps_;
    GltfWriteOptions options_;

    std::vector<tinygltf::Mesh> originalMeshes_;
    std::vector<tinygltf::Material> originalMaterials_;
    std::vector<Baked> baked_;
    int stagingBuffer_ = -1;
    std::vector<std::uint8_t> staging_;
    int sampler_ = -1;
    std::map<int, AtlasTexture> atlasTextures_;
    std::set<std::string> usedExtensions_;
};

}  // namespace

GltfWriteOptions::Mode parseGltfMode(const std::string& name) {
    if (name == "lightmap") return GltfWriteOptions::Mode::Lightmap;
    if (name == "emissive") return GltfWriteOptions::Mode::Emissive;
    throw std::invalid_argument("unknown glTF mode '" + name + "' (lightmap or emissive)");
}

const char* gltfModeName(GltfWriteOptions::Mode mode) {
    return mode == GltfWriteOptions::Mode::Emissive ? "emissive" : "lightmap";
}

std::string lightmapRelativePath(const GltfWriteOptions& options, int atlas) {
    std::string dir = options.lightmapDir;
    while (!dir.empty() && (dir.back() == '/' || dir.back() == '\\')) dir.pop_back();
    return (dir.empty() ? std::string() : dir + "/") + std::to_string(atlas) + ".exr";
}

std::vector<BakedPrimitive> writeLightmappedGlb(const std::string& inputPath, const Scene& scene, const UvAtlas& atlas,
                                                const std::vector<LightmapImage>& lightmaps, const fs::path& outGlb,
                                                const GltfWriteOptions& options) {
    if (atlas.instances.size() != scene.instances.size())
        throw std::invalid_argument("UV atlas has " + std::to_string(atlas.instances.size()) + " instances, the scene " +
                                    std::to_string(scene.instances.size()));
    for (std::size_t a = 0; a < lightmaps.size() && a < atlas.atlases.size(); ++a) {
        const LightmapImage& lm = lightmaps[a];
        if (lm.size != atlas.atlases[a].size ||
            lm.irradianceOverPi.size() != std::size_t(lm.size) * std::size_t(lm.size))
            throw std::invalid_argument("lightmap " + std::to_string(a) + " is " + std::to_string(lm.size) +
                                        " texels wide; its atlas is " + std::to_string(atlas.atlases[a].size));
    }
    tinygltf::Model model = loadModel(inputPath);
    GlbBuilder builder(model, inputPath, scene, atlas, lightmaps, options);
    std::vector<BakedPrimitive> entries = builder.build();

    writeAtomically(outGlb, [&](const fs::path& temp) {
        std::ofstream out(temp, std::ios::binary | std::ios::trunc);
        if (!out) throw std::runtime_error(outGlb.string() + ": cannot open for writing");
        tinygltf::TinyGLTF writer;
        if (!writer.WriteGltfSceneToStream(&model, out, false, true))
            throw std::runtime_error(outGlb.string() + ": tinygltf could not serialize the scene");
        out.close();
        if (!out) throw std::runtime_error(outGlb.string() + ": cannot write");
    });
    return entries;
}

}  // namespace hemibake
