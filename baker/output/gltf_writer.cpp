#include "baker/output/gltf_writer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "baker/output/exitant_radiance_atlas.h"
#include "baker/output/gltf_buffers.h"
#include "baker/output/png_preview.h"
#include "baker/util/atomic_output.h"
#include "mesh/errors.h"
#include "mesh/gltf_accessor.h"
#include "mesh/gltf_loader.h"

namespace hemibake {

namespace {

namespace fs = std::filesystem;

constexpr const char* kLightmapExtension = "MOZ_lightmap";
constexpr const char* kEmissiveStrengthExtension = "KHR_materials_emissive_strength";

class GlbBuilder {
public:
    GlbBuilder(tinygltf::Model& model, const std::string& path, const Scene& scene, const UvAtlas& atlas,
               const std::vector<LightmapImage>& lightmaps, const GltfWriteOptions& options)
        : m_(model), path_(path), scene_(scene), atlas_(atlas), lightmaps_(lightmaps), options_(options), buffers_(model, path) {}

    std::vector<BakedPrimitive> build() {
        for (const char* unsupported : {"EXT_meshopt_compression", "KHR_draco_mesh_compression"})
            if (std::find(m_.extensionsUsed.begin(), m_.extensionsUsed.end(), unsupported) != m_.extensionsUsed.end())
                throw InputError(path_, std::string("uses ") + unsupported + ", which the glTF writer cannot carry over");
        originalMeshes_ = m_.meshes;
        originalMaterials_ = m_.materials;

        selectBakedInstances();
        assignMeshes();
        for (const Baked& b : baked_) rewritePrimitive(b);
        assignMaterials();
        buffers_.moveImagesIntoBufferViews();
        buffers_.finish();
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
            const std::array<std::uint32_t, 3>& g = gltfTris[std::size_t(src)];
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
            const RawElements raw = buffers_.readRaw(accessor, where + " " + name);
            if (raw.count != vertexCount) fail(where + " " + name + " count differs from POSITION count");
            attributes[name] = buffers_.addGatheredAttribute(raw, gather, name == "POSITION");
        }
        {
            std::vector<float> uv(outVertices.size() * 2);
            for (std::size_t v = 0; v < outVertices.size(); ++v) {
                uv[2 * v] = ui.uv[outVertices[v]].x;
                uv[2 * v + 1] = ui.uv[outVertices[v]].y;
            }
            tinygltf::Accessor a;
            a.bufferView = buffers_.addView(uv.data(), uv.size() * sizeof(float), kArrayBuffer);
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
                const RawElements raw = buffers_.readRaw(accessor, what);
                if (raw.count != vertexCount) fail(what + " count differs from POSITION count");
                target[name] = buffers_.addGatheredAttribute(raw, gather, name == "POSITION");
            }
            targets.push_back(std::move(target));
        }
        tinygltf::Accessor ia;
        ia.type = TINYGLTF_TYPE_SCALAR;
        ia.count = outIndices.size();
        if (outVertices.size() < 65535) {  // 65535 is the primitive-restart value, never an index
            std::vector<std::uint16_t> idx16(outIndices.begin(), outIndices.end());
            ia.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
            ia.bufferView = buffers_.addView(idx16.data(), idx16.size() * 2, kElementArrayBuffer);
        } else {
            ia.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
            ia.bufferView = buffers_.addView(outIndices.data(), outIndices.size() * 4, kElementArrayBuffer);
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
        image.bufferView = buffers_.addView(png.data(), png.size(), 0);
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
    GltfBufferEditor buffers_;
    int sampler_ = -1;
    std::map<int, AtlasTexture> atlasTextures_;
    std::set<std::string> usedExtensions_;
};

}  // namespace

namespace {

// tinygltf reads an absent camera zfar (an infinite projection) as 0 and always writes it back, and the validator
// rejects zfar 0: drop it again from the GLB's JSON chunk.
std::string withoutAbsentCameraFar(std::string glb) {
    auto u32 = [&](std::size_t at) {
        std::uint32_t v = 0;
        std::memcpy(&v, glb.data() + at, 4);
        return v;
    };
    if (glb.size() < 20 || u32(12 + 4) != 0x4E4F534Au) return glb;  // not a GLB with a JSON chunk first
    const std::size_t jsonLength = u32(12);
    if (20 + jsonLength > glb.size()) return glb;
    nlohmann::json json = nlohmann::json::parse(glb.substr(20, jsonLength), nullptr, false);
    if (json.is_discarded() || !json.contains("cameras")) return glb;
    bool changed = false;
    for (auto& camera : json["cameras"]) {
        auto perspective = camera.find("perspective");
        if (perspective == camera.end() || !perspective->is_object()) continue;
        auto zfar = perspective->find("zfar");
        if (zfar != perspective->end() && zfar->is_number() && zfar->get<double>() == 0.0) {
            perspective->erase(zfar);
            changed = true;
        }
    }
    if (!changed) return glb;
    std::string text = json.dump();
    while (text.size() % 4) text += ' ';
    std::string out = glb.substr(0, 12);
    const std::string rest = glb.substr(20 + jsonLength);
    const auto put = [&](std::size_t at, std::uint32_t v) { std::memcpy(out.data() + at, &v, 4); };
    out.resize(20);
    put(12, std::uint32_t(text.size()));
    put(16, 0x4E4F534Au);
    out += text;
    out += rest;
    put(8, std::uint32_t(out.size()));
    return out;
}

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
    tinygltf::Model model = loadModelKeepingImages(inputPath);
    GlbBuilder builder(model, inputPath, scene, atlas, lightmaps, options);
    std::vector<BakedPrimitive> entries = builder.build();

    std::ostringstream glb;
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToStream(&model, glb, false, true))
        throw std::runtime_error(outGlb.string() + ": tinygltf could not serialize the scene");
    const std::string bytes = withoutAbsentCameraFar(glb.str());
    writeAtomically(outGlb, [&](const fs::path& temp) {
        std::ofstream out(temp, std::ios::binary | std::ios::trunc);
        if (!out) throw std::runtime_error(outGlb.string() + ": cannot open for writing");
        out.write(bytes.data(), std::streamsize(bytes.size()));
        out.close();
        if (!out) throw std::runtime_error(outGlb.string() + ": cannot write");
    });
    return entries;
}

}  // namespace hemibake
