// The lightmapped glb (CONVENTIONS.md "Lightmaps in glTF"): real files in, real glb out, read back with tinygltf,
// checked attribute by attribute against the SurfaceMesh and UV atlas, and run through the Khronos validator.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include "baker/output/gltf_writer.h"
#include "baker/output/png_preview.h"
#include "mesh/errors.h"
#include "mesh/gltf_accessor.h"
#include "mesh/gltf_loader.h"
#include "mesh/uv_atlas.h"
#include "support/gltf_fixture.h"
#include "support/gltf_validator.h"
#include "support/srgb_reference.h"

namespace hemibake {
namespace {

namespace fs = std::filesystem;
using test::GltfFixture;
using test::TempDir;


// ---- the input scene -----------------------------------------------------------------------------------------

// Cube corner g of the unit cube, and the per-vertex data the fixture gives it.
glm::vec3 cubeCorner(int g) { return glm::vec3(float(g & 1), float((g >> 1) & 1), float((g >> 2) & 1)); }
std::array<std::uint8_t, 3> cubeColor(int g) {
    return {std::uint8_t(g * 30), std::uint8_t(255 - g * 30), std::uint8_t(7 * g)};
}
glm::vec2 cubeUv0(int g) { return glm::vec2(0.1f + 0.1f * float(g), 0.9f - 0.05f * float(g)); }

// Two nodes place one textured cube mesh (one of them mirrored, under a parent); a floor quad without a material
// is a triangle strip. The base-colour image is an external PNG and the buffer an external .bin.
std::string writeTestScene(const TempDir& dir) {
    GltfFixture g;
    std::vector<float> pos, nrm, uv0;
    std::vector<std::uint8_t> color;
    for (int i = 0; i < 8; ++i) {
        const glm::vec3 p = cubeCorner(i);
        const glm::vec3 n = glm::normalize(p - glm::vec3(0.5f));
        pos.insert(pos.end(), {p.x, p.y, p.z});
        nrm.insert(nrm.end(), {n.x, n.y, n.z});
        uv0.insert(uv0.end(), {cubeUv0(i).x, cubeUv0(i).y});
        const auto c = cubeColor(i);
        color.insert(color.end(), {c[0], c[1], c[2], 0});  // 4-byte stride, as glTF requires for vertex data
    }
    const int positions = g.addPositions(pos);
    const int normals = g.addAccessor(g.addView(nrm.data(), nrm.size() * 4), 5126, "VEC3", 8);
    const int texcoords = g.addAccessor(g.addView(uv0.data(), uv0.size() * 4), 5126, "VEC2", 8);
    const int colors = g.addAccessor(g.addView(color.data(), color.size(), 4), 5121, "VEC3", 8);
    g.json()["accessors"][std::size_t(colors)]["normalized"] = true;
    // Corner index g = x + 2y + 4z; counter-clockwise seen from outside.
    const std::vector<std::uint16_t> cube = {0, 6, 2, 0, 4, 6,  1, 7, 5, 1, 3, 7,  0, 5, 4, 0, 1, 5,
                                             2, 7, 3, 2, 6, 7,  0, 3, 1, 0, 2, 3,  4, 7, 6, 4, 5, 7};
    const int cubeIndices = g.addIndicesU16(cube);

    // A 2x2 base-colour texture in a file beside the glTF.
    const std::vector<std::uint8_t> texels = {255, 128, 64, 32, 200, 100, 90, 90, 250, 180, 180, 180};
    const std::vector<std::uint8_t> png = encodePng(texels.data(), 2, 2, 3);
    std::ofstream(dir.file("albedo.png"), std::ios::binary).write(reinterpret_cast<const char*>(png.data()), std::streamsize(png.size()));
    g.json()["images"] = {{{"uri", "albedo.png"}}};
    g.json()["textures"] = {{{"source", 0}}};
    const int textured = g.addMaterial({{"name", "textured"},
                                        {"pbrMetallicRoughness",
                                         {{"baseColorFactor", {0.9, 0.9, 0.9, 1.0}}, {"baseColorTexture", {{"index", 0}}}}}});
    const int cubeMesh = g.addMesh(positions, cubeIndices, textured, 4,
                                   {{"NORMAL", normals}, {"TEXCOORD_0", texcoords}, {"COLOR_0", colors}});
    g.json()["meshes"][std::size_t(cubeMesh)]["name"] = "cube";

    const int floorPositions = g.addPositions({-3, -1, -3, -3, -1, 3, 3, -1, 3, 3, -1, -3});
    const int floorMesh = g.addMesh(floorPositions, g.addIndicesU16({1, 2, 0, 3}), -1, 5);  // triangle strip

    const double s = std::sin(0.3), c = std::cos(0.3);
    g.addNode({{"name", "left"}, {"mesh", cubeMesh}, {"translation", {-2.0, 0.0, 0.5}},
               {"rotation", {0.0, s, 0.0, c}}, {"scale", {1.0, 2.0, 1.0}}});
    const int right = g.addChildNode({{"name", "right"}, {"mesh", cubeMesh}, {"translation", {2.0, 0.0, 0.0}},
                                      {"scale", {-1.0, 1.0, 1.0}}});  // mirrored
    g.addNode({{"name", "parent"}, {"translation", {0.0, 0.5, 0.0}}, {"children", {right}}});
    g.addNode({{"mesh", floorMesh}});  // unnamed
    return g.writeGltf(dir, "scene");
}

struct Bake {
    Scene scene;
    UvAtlas atlas;
    std::vector<LightmapImage> lightmaps;
};

// Lightmaps with a known pattern scaled by 1 + atlas index (so every atlas has its own k); texel (0,0) is Empty.
Bake prepare(const std::string& path, const UnwrapSettings& settings) {
    Bake b;
    b.scene = loadGltf(path);
    b.atlas = unwrapScene(b.scene, settings);
    for (std::size_t a = 0; a < b.atlas.atlases.size(); ++a) {
        LightmapImage lm;
        lm.resize(b.atlas.atlases[a].size);
        for (int y = 0; y < lm.size; ++y)
            for (int x = 0; x < lm.size; ++x) {
                lm.irradianceOverPi[lm.index(x, y)] =
                    float(1 + a) * glm::vec3(0.002f * float(x + 1), 0.003f * float(y + 1), 0.05f * float((7 * x + 3 * y) % 11));
                lm.state[lm.index(x, y)] = TexelState::Covered;
            }
        lm.state[0] = TexelState::Empty;
        b.lightmaps.push_back(std::move(lm));
    }
    return b;
}

std::vector<int> bakedInstances(const Bake& b) {
    std::vector<int> out;
    for (std::size_t i = 0; i < b.atlas.instances.size(); ++i)
        if (b.atlas.instances[i].atlas >= 0 && !b.atlas.instances[i].triangles.empty()) out.push_back(int(i));
    return out;
}

// Nearest-rank 99.9th percentile of max(R,G,B) over non-Empty texels, computed here independently.
double expectedScale(const LightmapImage& lm) {
    std::vector<float> v;
    for (std::size_t t = 0; t < lm.irradianceOverPi.size(); ++t)
        if (lm.state[t] != TexelState::Empty)
            v.push_back(std::max({lm.irradianceOverPi[t].x, lm.irradianceOverPi[t].y, lm.irradianceOverPi[t].z}));
    std::sort(v.begin(), v.end());
    return v[std::size_t(std::ceil(0.999 * double(v.size()))) - 1];
}

// ---- reading the output ----------------------------------------------------------------------------------------

tinygltf::Model loadGlb(const fs::path& path) {
    tinygltf::TinyGLTF loader;
    tinygltf::Model model;
    std::string err, warn;
    EXPECT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, path.string())) << err;
    return model;
}

glm::dmat4 localMatrix(const tinygltf::Node& node) {
    if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());
    glm::dmat4 m(1.0);
    if (node.translation.size() == 3) m = glm::translate(m, glm::dvec3(node.translation[0], node.translation[1], node.translation[2]));
    if (node.rotation.size() == 4) m *= glm::mat4_cast(glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]));
    if (node.scale.size() == 3) m = glm::scale(m, glm::dvec3(node.scale[0], node.scale[1], node.scale[2]));
    return m;
}

glm::dmat4 worldMatrix(const tinygltf::Model& model, int node) {
    std::map<int, int> parent;
    for (std::size_t n = 0; n < model.nodes.size(); ++n)
        for (int child : model.nodes[n].children) parent[child] = int(n);
    glm::dmat4 m = localMatrix(model.nodes[std::size_t(node)]);
    for (auto it = parent.find(node); it != parent.end(); it = parent.find(it->second))
        m = localMatrix(model.nodes[std::size_t(it->second)]) * m;
    return m;
}

int nodeNamed(const tinygltf::Model& model, const std::string& name) {
    for (std::size_t n = 0; n < model.nodes.size(); ++n)
        if (model.nodes[n].name == name) return int(n);
    return -1;
}

std::vector<std::uint8_t> imageBytes(const tinygltf::Model& model, int imageIndex) {
    const tinygltf::Image& image = model.images[std::size_t(imageIndex)];
    const tinygltf::BufferView& view = model.bufferViews[std::size_t(image.bufferView)];
    const auto& data = model.buffers[std::size_t(view.buffer)].data;
    return std::vector<std::uint8_t>(data.begin() + std::ptrdiff_t(view.byteOffset),
                                     data.begin() + std::ptrdiff_t(view.byteOffset + view.byteLength));
}

// The decoded 8-bit value of channel c at texel (x, y) of a texture's image (tinygltf decodes PNGs on load).
int texel8(const tinygltf::Model& model, int texture, int x, int y, int c) {
    const tinygltf::Image& image = model.images[std::size_t(model.textures[std::size_t(texture)].source)];
    return image.image[(std::size_t(y) * std::size_t(image.width) + std::size_t(x)) * std::size_t(image.component) + std::size_t(c)];
}

// A texel whose centre lies well inside unwrapped triangle t; returns false if none does.
bool texelInside(const UnwrappedInstance& ui, std::size_t t, int size, int& tx, int& ty, glm::dvec3& bary) {
    glm::dvec2 p[3];
    for (int k = 0; k < 3; ++k) p[k] = glm::dvec2(ui.uv[ui.triangles[t][std::size_t(k)]]) * double(size);
    const double area = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const glm::dvec2 c(x + 0.5, y + 0.5);
            auto edge = [&](glm::dvec2 a, glm::dvec2 e) { return ((e.x - a.x) * (c.y - a.y) - (e.y - a.y) * (c.x - a.x)) / area; };
            const double w0 = edge(p[1], p[2]), w1 = edge(p[2], p[0]), w2 = 1.0 - w0 - w1;
            if (std::min({w0, w1, w2}) > 0.05) {
                tx = x;
                ty = y;
                bary = {w0, w1, w2};
                return true;
            }
        }
    return false;
}

// Geometry of every baked primitive against the SurfaceMesh and UV atlas: counts, TEXCOORD_1, positions and
// normals through the node matrices, triangle order and winding, and the bake.json entry.
void expectGeometryMatches(const tinygltf::Model& model, const Bake& b, const std::vector<BakedPrimitive>& entries) {
    const std::vector<int> baked = bakedInstances(b);
    ASSERT_EQ(entries.size(), baked.size());
    for (std::size_t e = 0; e < entries.size(); ++e) {
        const int i = baked[e];
        const BakedPrimitive& entry = entries[e];
        const UnwrappedInstance& ui = b.atlas.instances[std::size_t(i)];
        const SurfaceMesh& mesh = b.scene.instances[std::size_t(i)].mesh;
        SCOPED_TRACE("entry " + std::to_string(e) + " node '" + entry.node + "'");
        const int node = nodeNamed(model, entry.node);
        ASSERT_GE(node, 0);
        ASSERT_EQ(model.nodes[std::size_t(node)].mesh, entry.mesh);
        ASSERT_LT(std::size_t(entry.primitive), model.meshes[std::size_t(entry.mesh)].primitives.size());
        EXPECT_EQ(entry.lightmap, "lightmaps/" + std::to_string(ui.atlas) + ".exr");
        for (int k = 0; k < 4; ++k) EXPECT_EQ(entry.rect[k], ui.rect[std::size_t(k)]);
        const tinygltf::Primitive& prim = model.meshes[std::size_t(entry.mesh)].primitives[std::size_t(entry.primitive)];
        EXPECT_EQ(prim.mode, TINYGLTF_MODE_TRIANGLES);
        ASSERT_TRUE(prim.attributes.count("TEXCOORD_1"));
        ASSERT_TRUE(prim.attributes.count("POSITION"));
        const std::vector<double> uv1 = readAccessorFloats(model, prim.attributes.at("TEXCOORD_1"), 2, "out", "uv1");
        const std::vector<double> pos = readAccessorFloats(model, prim.attributes.at("POSITION"), 3, "out", "pos");
        const std::vector<std::uint32_t> idx = readAccessorIndices(model, prim.indices, "out", "indices");
        ASSERT_EQ(uv1.size() / 2, ui.uv.size()) << "TEXCOORD_1 count";
        ASSERT_EQ(pos.size() / 3, ui.uv.size()) << "POSITION count";
        ASSERT_EQ(idx.size(), 3 * ui.triangles.size());
        std::vector<double> nrm;
        if (b.scene.instances[std::size_t(i)].hasNormals) {
            ASSERT_TRUE(prim.attributes.count("NORMAL"));
            nrm = readAccessorFloats(model, prim.attributes.at("NORMAL"), 3, "out", "normal");
        }

        // Output vertex → unwrapped vertex by TEXCOORD_1 (coincident input vertices may share a UV: then the one
        // at the same place).
        using Uv = std::pair<float, float>;
        std::multimap<Uv, std::uint32_t> byUv;
        for (std::size_t k = 0; k < ui.uv.size(); ++k) byUv.emplace(Uv{ui.uv[k].x, ui.uv[k].y}, std::uint32_t(k));
        const glm::dmat4 world = worldMatrix(model, node);
        const glm::dmat3 normalMatrix = glm::transpose(glm::inverse(glm::dmat3(world)));
        auto outUv = [&](std::size_t v) { return Uv{float(uv1[2 * v]), float(uv1[2 * v + 1])}; };
        double worst = 0.0;
        for (std::size_t v = 0; v < ui.uv.size(); ++v) {
            auto [lo, hi] = byUv.equal_range(outUv(v));
            ASSERT_NE(lo, hi) << "output vertex " << v << " has a TEXCOORD_1 the atlas does not";
            const glm::dvec3 p = glm::dvec3(world * glm::dvec4(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2], 1.0));
            glm::dvec3 n(0.0);
            if (!nrm.empty()) n = glm::normalize(normalMatrix * glm::dvec3(nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]));
            // Closest in position, then in normal (coincident input vertices can differ in their normals only).
            double best = 1e30, bestNormal = 1e30;
            for (auto it = lo; it != hi; ++it) {
                const auto handle = SurfaceMesh::VertexHandle(ui.vertexSource[it->second]);
                const auto sp = mesh.point(handle);
                const auto sn = mesh.normal(handle);
                const double d = glm::length(p - glm::dvec3(sp[0], sp[1], sp[2]));
                const double dn = nrm.empty() ? 0.0 : glm::length(n - glm::dvec3(sn[0], sn[1], sn[2]));
                if (d + dn < best + bestNormal) {
                    best = d;
                    bestNormal = dn;
                }
            }
            worst = std::max(worst, best);
            EXPECT_LT(bestNormal, 1e-5) << "output vertex " << v << ": normal differs from the SurfaceMesh's";
        }
        EXPECT_LT(worst, 1e-5) << "unwrapped positions (through the node matrices) differ from the SurfaceMesh";

        // Triangles: the atlas's triangles (matched by their corners' UVs), in the input's order and winding.
        using UvTriangle = std::array<Uv, 3>;
        std::multimap<UvTriangle, std::size_t> triangleOf;
        for (std::size_t t = 0; t < ui.triangles.size(); ++t) {
            UvTriangle key;
            for (int k = 0; k < 3; ++k) {
                const glm::vec2 uv = ui.uv[ui.triangles[t][std::size_t(k)]];
                key[std::size_t(k)] = Uv{uv.x, uv.y};
            }
            std::sort(key.begin(), key.end());
            triangleOf.emplace(key, t);
        }
        const double mirror = glm::determinant(glm::dmat3(world)) < 0.0 ? -1.0 : 1.0;
        int previousSource = -1;
        std::set<std::size_t> seen;
        for (std::size_t t = 0; t < idx.size() / 3; ++t) {
            UvTriangle key{outUv(idx[3 * t]), outUv(idx[3 * t + 1]), outUv(idx[3 * t + 2])};
            std::sort(key.begin(), key.end());
            auto [lo, hi] = triangleOf.equal_range(key);
            while (lo != hi && seen.count(lo->second)) ++lo;
            ASSERT_NE(lo, hi) << "output triangle " << t << " is not an unwrapped triangle";
            const auto it = lo;
            seen.insert(it->second);
            const int f = ui.faceSource[it->second];
            const int source = mesh.sourceFace(SurfaceMesh::FaceHandle(f));
            EXPECT_GE(source, previousSource) << "triangles out of the input's order";
            previousSource = source;
            glm::dvec3 P[3];
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t v = idx[3 * t + std::size_t(k)];
                P[k] = glm::dvec3(world * glm::dvec4(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2], 1.0));
            }
            const auto fn = mesh.normal(SurfaceMesh::FaceHandle(f));
            // glTF flips the front face under a mirroring node, so the stored winding is the input's.
            EXPECT_GT(mirror * glm::dot(glm::cross(P[1] - P[0], P[2] - P[0]), glm::dvec3(fn[0], fn[1], fn[2])), 0.0)
                << "triangle " << t << " has the wrong winding";
        }
        EXPECT_EQ(seen.size(), ui.triangles.size());
    }
}

// Emissive mode: each baked material is black with an emissive texture on TEXCOORD_1 scaled by its strength k.
void expectEmissiveTexels(const tinygltf::Model& model, const Bake& b, const std::vector<BakedPrimitive>& entries) {
    EXPECT_NE(std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), "KHR_materials_emissive_strength"),
              model.extensionsUsed.end());
    EXPECT_EQ(std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), "MOZ_lightmap"), model.extensionsUsed.end());
    const std::vector<int> baked = bakedInstances(b);
    for (std::size_t e = 0; e < entries.size(); ++e) {
        SCOPED_TRACE("entry " + std::to_string(e));
        const int i = baked[e];
        const UnwrappedInstance& ui = b.atlas.instances[std::size_t(i)];
        const LightmapImage& lm = b.lightmaps[std::size_t(ui.atlas)];
        const tinygltf::Material& mat =
            model.materials[std::size_t(model.meshes[std::size_t(entries[e].mesh)].primitives[std::size_t(entries[e].primitive)].material)];
        EXPECT_FALSE(mat.extensions.count("MOZ_lightmap"));
        for (int c = 0; c < 3; ++c) EXPECT_EQ(mat.pbrMetallicRoughness.baseColorFactor[std::size_t(c)], 0.0);
        ASSERT_GE(mat.emissiveTexture.index, 0);
        EXPECT_EQ(mat.emissiveTexture.texCoord, 1);
        ASSERT_TRUE(mat.extensions.count("KHR_materials_emissive_strength"));
        const double k = mat.extensions.at("KHR_materials_emissive_strength").Get("emissiveStrength").GetNumberAsDouble();
        EXPECT_GT(k, 0.0);
        for (int c = 0; c < 3; ++c) EXPECT_EQ(mat.emissiveFactor[std::size_t(c)], 1.0);
        const tinygltf::Image& image = model.images[std::size_t(model.textures[std::size_t(mat.emissiveTexture.index)].source)];
        EXPECT_EQ(image.mimeType, "image/png");
        EXPECT_GE(image.bufferView, 0);

        // A few texels well inside triangles: sRGB((ρ(uv0 there) × texel + L_e) / k).
        int checked = 0;
        for (std::size_t t = 0; t < ui.triangles.size() && checked < 4; t += 3) {
            int x, y;
            glm::dvec3 w;
            if (!texelInside(ui, t, lm.size, x, y, w)) continue;
            glm::vec2 uv0(0.0f);
            for (int k3 = 0; k3 < 3; ++k3) {
                const auto tc = b.scene.instances[std::size_t(i)].mesh.texcoord2D(
                    SurfaceMesh::VertexHandle(ui.vertexSource[ui.triangles[t][std::size_t(k3)]]));
                uv0 += float(w[k3]) * glm::vec2(tc[0], tc[1]);
            }
            const glm::vec3 rho = b.scene.reflectance(b.scene.instances[std::size_t(i)].material, uv0);
            const glm::vec3 value = rho * lm.irradianceOverPi[lm.index(x, y)] +
                                     b.scene.materials[std::size_t(b.scene.instances[std::size_t(i)].material)].emittedRadiance;
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(texel8(model, mat.emissiveTexture.index, x, y, c), test::srgb8(double(value[c]) / k), 1.0)
                    << "texel " << x << "," << y << " channel " << c;
            ++checked;
        }
        EXPECT_GT(checked, 0);
    }
}

UnwrapSettings smallAtlases() {
    UnwrapSettings s;
    s.texelsPerUnit = 10.0;
    s.maxAtlasSize = 48;  // the floor and the cubes do not fit one atlas: several lightmaps, cloned materials
    return s;
}

// ---- tests -----------------------------------------------------------------------------------------------------

TEST(GltfWriter, LightmapModeWritesAValidGlbWithTexcoord1AndMozLightmap) {
    TempDir dir;
    const std::string input = writeTestScene(dir);
    const Bake b = prepare(input, smallAtlases());
    ASSERT_EQ(bakedInstances(b).size(), 3u);
    ASSERT_GE(b.atlas.atlases.size(), 2u) << "test set-up: want more than one atlas";
    const fs::path glb = dir.path() / "out" / "scene.glb";
    const std::vector<BakedPrimitive> entries = writeLightmappedGlb(input, b.scene, b.atlas, b.lightmaps, glb);
    ASSERT_TRUE(fs::is_regular_file(glb));
    {
        std::ifstream in(glb, std::ios::binary);
        char magic[4];
        in.read(magic, 4);
        EXPECT_EQ(std::string(magic, 4), "glTF");
    }
    const tinygltf::Model model = loadGlb(glb);
    expectGeometryMatches(model, b, entries);

    // One buffer (the BIN chunk), no external references.
    ASSERT_EQ(model.buffers.size(), 1u);
    EXPECT_TRUE(model.buffers[0].uri.empty());
    for (const auto& image : model.images) {
        EXPECT_TRUE(image.uri.empty()) << image.uri;
        EXPECT_GE(image.bufferView, 0);
    }

    // The two placements of the cube mesh got a mesh each; the unnamed floor node got a name.
    ASSERT_EQ(entries[0].node, "left");
    ASSERT_EQ(entries[1].node, "right");
    EXPECT_NE(entries[0].mesh, entries[1].mesh);
    EXPECT_EQ(entries[2].node, "node3");

    // Attributes other than TEXCOORD_1 are the input's values in the input's types.
    for (int e = 0; e < 2; ++e) {
        const tinygltf::Primitive& prim = model.meshes[std::size_t(entries[std::size_t(e)].mesh)].primitives[0];
        const tinygltf::Accessor& colorAccessor = model.accessors[std::size_t(prim.attributes.at("COLOR_0"))];
        EXPECT_EQ(colorAccessor.componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE);
        EXPECT_TRUE(colorAccessor.normalized);
        const auto pos = readAccessorFloats(model, prim.attributes.at("POSITION"), 3, "out", "pos");
        const auto col = readAccessorFloats(model, prim.attributes.at("COLOR_0"), 3, "out", "color");
        const auto uv0 = readAccessorFloats(model, prim.attributes.at("TEXCOORD_0"), 2, "out", "uv0");
        for (std::size_t v = 0; v < pos.size() / 3; ++v) {
            const int g = int(pos[3 * v]) + 2 * int(pos[3 * v + 1]) + 4 * int(pos[3 * v + 2]);
            for (int c = 0; c < 3; ++c) EXPECT_EQ(std::lround(col[3 * v + std::size_t(c)] * 255.0), cubeColor(g)[std::size_t(c)]);
            EXPECT_EQ(float(uv0[2 * v]), cubeUv0(g).x);
            EXPECT_EQ(float(uv0[2 * v + 1]), cubeUv0(g).y);
        }
    }

    // MOZ_lightmap on each baked material, pointing at its atlas's PNG.
    EXPECT_NE(std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), "MOZ_lightmap"), model.extensionsUsed.end());
    EXPECT_EQ(std::find(model.extensionsRequired.begin(), model.extensionsRequired.end(), "MOZ_lightmap"),
              model.extensionsRequired.end());
    const std::vector<int> baked = bakedInstances(b);
    for (std::size_t e = 0; e < entries.size(); ++e) {
        SCOPED_TRACE("entry " + std::to_string(e));
        const int atlas = b.atlas.instances[std::size_t(baked[e])].atlas;
        const LightmapImage& lm = b.lightmaps[std::size_t(atlas)];
        const tinygltf::Primitive& prim = model.meshes[std::size_t(entries[e].mesh)].primitives[std::size_t(entries[e].primitive)];
        ASSERT_GE(prim.material, 0);
        const tinygltf::Material& mat = model.materials[std::size_t(prim.material)];
        ASSERT_TRUE(mat.extensions.count("MOZ_lightmap"));
        const tinygltf::Value& ext = mat.extensions.at("MOZ_lightmap");
        EXPECT_EQ(ext.Get("texCoord").GetNumberAsInt(), 1);
        const double k = expectedScale(lm);
        EXPECT_NEAR(ext.Get("intensity").GetNumberAsDouble(), k, 1e-6 * k);
        const int texture = ext.Get("index").GetNumberAsInt();
        ASSERT_GE(texture, 0);
        ASSERT_LT(std::size_t(texture), model.textures.size());
        const tinygltf::Image& image = model.images[std::size_t(model.textures[std::size_t(texture)].source)];
        EXPECT_EQ(image.mimeType, "image/png");
        ASSERT_GE(image.bufferView, 0) << "the lightmap must be in a buffer view, not a data URI";
        const auto bytes = imageBytes(model, model.textures[std::size_t(texture)].source);
        ASSERT_GT(bytes.size(), 8u);
        EXPECT_EQ(bytes[0], 0x89);
        EXPECT_EQ(bytes[1], 'P');
        ASSERT_EQ(image.width, lm.size);
        ASSERT_EQ(image.height, lm.size);
        EXPECT_EQ(image.bits, 8);
        for (auto [x, y] : {std::pair{0, 0}, std::pair{1, 0}, std::pair{3, 7}, std::pair{lm.size - 1, 2},
                            std::pair{lm.size - 1, lm.size - 1}, std::pair{lm.size / 2, lm.size - 3}})
            for (int c = 0; c < 3; ++c) {
                const std::size_t t = lm.index(x, y);
                const int expected = lm.state[t] == TexelState::Empty ? 0 : test::srgb8(double(lm.irradianceOverPi[t][c]) / k);
                EXPECT_EQ(texel8(model, texture, x, y, c), expected) << "texel " << x << "," << y << " channel " << c;
            }
        // The material keeps its PBR data.
        if (e < 2) {
            EXPECT_EQ(mat.pbrMetallicRoughness.baseColorFactor[0], 0.9);
            EXPECT_GE(mat.pbrMetallicRoughness.baseColorTexture.index, 0);
        } else {
            EXPECT_NEAR(mat.pbrMetallicRoughness.baseColorFactor[0], 0.8, 1e-9);  // hemibake's default material
            EXPECT_EQ(mat.pbrMetallicRoughness.metallicFactor, 0.0);
        }
    }
    // Primitives on different atlases do not share a material.
    std::map<int, int> atlasOfMaterial;
    for (std::size_t e = 0; e < entries.size(); ++e) {
        const int material = model.meshes[std::size_t(entries[e].mesh)].primitives[std::size_t(entries[e].primitive)].material;
        const int atlas = b.atlas.instances[std::size_t(baked[e])].atlas;
        auto [it, inserted] = atlasOfMaterial.emplace(material, atlas);
        EXPECT_EQ(it->second, atlas) << "material " << material << " is used on two atlases";
    }
    // The input's base-colour image came along unchanged (same PNG bytes).
    std::ifstream albedo(dir.file("albedo.png"), std::ios::binary);
    const std::vector<std::uint8_t> albedoBytes((std::istreambuf_iterator<char>(albedo)), std::istreambuf_iterator<char>());
    const tinygltf::Material& cubeMaterial = model.materials[std::size_t(model.meshes[std::size_t(entries[0].mesh)].primitives[0].material)];
    const int albedoTexture = cubeMaterial.pbrMetallicRoughness.baseColorTexture.index;
    EXPECT_EQ(imageBytes(model, model.textures[std::size_t(albedoTexture)].source), albedoBytes);

    EXPECT_GLTF_VALID(glb.string());
}

TEST(GltfWriter, OneAtlasSharesOneMaterialAndWritesFromAGlbInput) {
    TempDir dir;
    GltfFixture g = test::unitQuadFixture();
    const std::string input = g.writeGlb(dir, "quad");
    UnwrapSettings s;
    s.texelsPerUnit = 16.0;
    const Bake b = prepare(input, s);
    const fs::path glb = dir.path() / "quad-out.glb";
    const auto entries = writeLightmappedGlb(input, b.scene, b.atlas, b.lightmaps, glb);
    ASSERT_EQ(entries.size(), 1u);
    EXPECT_EQ(entries[0].node, "quad");
    const tinygltf::Model model = loadGlb(glb);
    expectGeometryMatches(model, b, entries);
    EXPECT_EQ(model.materials.size(), 1u);
    EXPECT_GLTF_VALID(glb.string());
}

TEST(GltfWriter, EmissiveModeBakesReflectanceTimesTexelIntoTheEmissiveTexture) {
    TempDir dir;
    const std::string input = writeTestScene(dir);
    const Bake b = prepare(input, smallAtlases());
    const fs::path glb = dir.path() / "emissive.glb";
    GltfWriteOptions options;
    options.mode = GltfWriteOptions::Mode::Emissive;
    const auto entries = writeLightmappedGlb(input, b.scene, b.atlas, b.lightmaps, glb, options);
    const tinygltf::Model model = loadGlb(glb);
    expectGeometryMatches(model, b, entries);
    expectEmissiveTexels(model, b, entries);
    EXPECT_GLTF_VALID(glb.string());
}

TEST(GltfWriter, CreatesMissingFoldersAndNeverLeavesAPartialFile) {
    TempDir dir;
    const std::string input = writeTestScene(dir);
    const Bake b = prepare(input, smallAtlases());
    const fs::path glb = dir.path() / "a" / "b" / "c" / "scene.glb";
    writeLightmappedGlb(input, b.scene, b.atlas, b.lightmaps, glb);
    ASSERT_TRUE(fs::is_regular_file(glb));
    EXPECT_GLTF_VALID(glb.string());
    const auto listing = [](const fs::path& d) {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(d)) names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    };
    EXPECT_EQ(listing(glb.parent_path()), std::vector<std::string>{"scene.glb"});
    std::ifstream before(glb, std::ios::binary);
    const std::string goodBytes((std::istreambuf_iterator<char>(before)), std::istreambuf_iterator<char>());

    // A scene that does not belong to the input fails mid-way (after the input was re-read): the existing glb
    // stays as it was and no temp file is left.
    GltfFixture other = test::unitQuadFixture();
    const std::string otherInput = other.writeGltf(dir, "other");
    const Bake wrong = prepare(otherInput, smallAtlases());
    EXPECT_ANY_THROW(writeLightmappedGlb(input, wrong.scene, wrong.atlas, wrong.lightmaps, glb));
    std::ifstream after(glb, std::ios::binary);
    EXPECT_EQ(std::string((std::istreambuf_iterator<char>(after)), std::istreambuf_iterator<char>()), goodBytes);
    EXPECT_EQ(listing(glb.parent_path()), std::vector<std::string>{"scene.glb"});

    // Lightmaps that do not match the atlases.
    std::vector<LightmapImage> tooSmall = b.lightmaps;
    tooSmall[0].resize(tooSmall[0].size / 2);
    EXPECT_THROW(writeLightmappedGlb(input, b.scene, b.atlas, tooSmall, glb), std::invalid_argument);

    // The glb is complete in memory but cannot be moved into place (a folder holds the name).
    const fs::path blocked = dir.path() / "blocked.glb";
    fs::create_directories(blocked / "keep");
    EXPECT_ANY_THROW(writeLightmappedGlb(input, b.scene, b.atlas, b.lightmaps, blocked));
    EXPECT_TRUE(fs::is_directory(blocked / "keep"));
    for (const auto& e : fs::directory_iterator(dir.path()))
        EXPECT_EQ(e.path().filename().string().rfind(".tmp-", 0), std::string::npos) << e.path();

    // A missing input is an input error.
    EXPECT_THROW(writeLightmappedGlb(dir.file("missing.gltf"), b.scene, b.atlas, b.lightmaps, dir.path() / "x.glb"), InputError);
    EXPECT_FALSE(fs::exists(dir.path() / "x.glb"));
}

TEST(GltfWriter, CornellBoxAt128TexelsPerMetrePassesTheValidator) {
    const std::string input = std::string(HEMIBAKE_SHARED_DIR) + "/scenes/cornell_box.gltf";
    if (!fs::exists(input)) GTEST_SKIP() << input << " not found";
    UnwrapSettings s;
    s.texelsPerUnit = 128.0;
    const Bake b = prepare(input, s);
    ASSERT_FALSE(bakedInstances(b).empty());
    TempDir dir;
    for (auto mode : {GltfWriteOptions::Mode::Lightmap, GltfWriteOptions::Mode::Emissive}) {
        SCOPED_TRACE(gltfModeName(mode));
        GltfWriteOptions options;
        options.mode = mode;
        const fs::path glb = dir.path() / (std::string("cornell_box-") + gltfModeName(mode) + ".glb");
        const auto entries = writeLightmappedGlb(input, b.scene, b.atlas, b.lightmaps, glb, options);
        EXPECT_EQ(entries.size(), bakedInstances(b).size());
        const tinygltf::Model model = loadGlb(glb);
        expectGeometryMatches(model, b, entries);
        if (mode == GltfWriteOptions::Mode::Emissive) expectEmissiveTexels(model, b, entries);
        EXPECT_GLTF_VALID(glb.string());
    }
}

TEST(GltfWriter, ModeNamesAndLightmapPaths) {
    EXPECT_EQ(parseGltfMode("lightmap"), GltfWriteOptions::Mode::Lightmap);
    EXPECT_EQ(parseGltfMode("emissive"), GltfWriteOptions::Mode::Emissive);
    EXPECT_THROW(parseGltfMode("Emissive"), std::invalid_argument);
    GltfWriteOptions o;
    EXPECT_EQ(lightmapRelativePath(o, 3), "lightmaps/3.exr");
    o.lightmapDir = "maps/";
    EXPECT_EQ(lightmapRelativePath(o, 0), "maps/0.exr");
}

}  // namespace
}  // namespace hemibake
