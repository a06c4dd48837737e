// Issue 17: seams judged from the written files, independent of the stitcher and of its own figure. A torus (smooth
// everywhere, so its unwrap cuts charts across smooth surface) under a slanted sun and a sky is baked to disk; the
// test reads back the glb (tinygltf: positions and TEXCOORD_1) and the EXR atlas, finds every mesh edge whose two
// triangles place it in two different atlas spots, and samples the atlas bilinearly as a GPU does (texel centres
// at (i + ½)/size, clamped) at points along the edge on both sides. Stitched, the two sides agree; the same bake
// with stitching off shows the seams this check exists to catch.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <tuple>

#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include "baker/output/exr_io.h"
#include "baker/pipeline/bake_scene.h"
#include "baker/pipeline/presets.h"
#include "mesh/gltf_loader.h"
#include "support/gltf_fixture.h"

using namespace hemibake;
using hemibake::test::GltfFixture;
using hemibake::test::TempDir;

namespace {

// Torus about the y axis (major radius 1 m, minor 0.35 m) standing 0.5 m above the origin, outward facing; 48 × 24
// segments keep neighbouring faces within 11.3°, well inside 15° (the stitcher's notion of smooth).
std::string writeTorusScene(const TempDir& dir) {
    const int nu = 64, nv = 32;
    const double R = 1.0, r = 0.35;
    std::vector<float> p;
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            const double u = 2 * M_PI * i / nu, v = 2 * M_PI * j / nv;
            p.insert(p.end(), {float((R + r * std::cos(v)) * std::cos(u)), float(0.5 + r * std::sin(v)),
                               float(-(R + r * std::cos(v)) * std::sin(u))});
        }
    auto id = [&](int j, int i) { return std::uint32_t((j % nv) * nu + (i % nu)); };
    std::vector<std::uint32_t> t;
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) t.insert(t.end(), {id(j, i), id(j, i + 1), id(j + 1, i + 1), id(j, i), id(j + 1, i + 1), id(j + 1, i)});
    GltfFixture g;
    const int material = g.addMaterial({{"name", "clay"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.7, 0.6, 0.5, 1.0}}}}});
    g.addNode({{"name", "torus"}, {"mesh", g.addMesh(g.addPositions(p), g.addIndicesU32(t), material)}});
    g.json()["extensionsUsed"] = {"KHR_lights_punctual"};
    g.json()["extensions"] = {{"KHR_lights_punctual", {{"lights", {{{"type", "directional"}, {"intensity", 3.0}}}}}}};
    // −Z turned about x by −50° and about y by 30°: the sun comes in slanted, so the torus shadows its own hole.
    const double ax = -50.0 * M_PI / 180.0, ay = 30.0 * M_PI / 180.0;
    const glm::dquat q = glm::angleAxis(ay, glm::dvec3(0, 1, 0)) * glm::angleAxis(ax, glm::dvec3(1, 0, 0));
    g.addNode({{"name", "sun"}, {"rotation", {q.x, q.y, q.z, q.w}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    return g.writeGltf(dir, "torus");
}

template <typename T>
const T* accessorData(const tinygltf::Model& m, int accessor) {
    const tinygltf::Accessor& a = m.accessors.at(std::size_t(accessor));
    const tinygltf::BufferView& v = m.bufferViews.at(std::size_t(a.bufferView));
    return reinterpret_cast<const T*>(m.buffers.at(std::size_t(v.buffer)).data.data() + v.byteOffset + a.byteOffset);
}

// GPU bilinear filtering of the atlas at glTF UV (u, v): texel centres at ((x + ½)/size, (y + ½)/size), clamp to edge.
glm::dvec3 bilinear(const LightmapImage& img, glm::dvec2 uv) {
    const double fx = uv.x * img.size - 0.5, fy = uv.y * img.size - 0.5;
    const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
    const double tx = fx - x0, ty = fy - y0;
    auto at = [&](int x, int y) {
        x = std::clamp(x, 0, img.size - 1);
        y = std::clamp(y, 0, img.size - 1);
        return glm::dvec3(img.irradianceOverPi[img.index(x, y)]);
    };
    return (1 - ty) * ((1 - tx) * at(x0, y0) + tx * at(x0 + 1, y0)) + ty * ((1 - tx) * at(x0, y0 + 1) + tx * at(x0 + 1, y0 + 1));
}

// Samples per seam edge, evenly spaced, ends left out: finer than the stitcher's own spacing on these edges (they
// span 1–3 texels), and not aligned with it.
constexpr int kSamplesPerEdge = 15;

struct WrittenSeams {
    std::size_t seamEdges = 0, samples = 0;
    double maxRelative = 0.0, meanRelative = 0.0;  // |a − b| / max(mean(a, b), 5 % of the atlas mean), channel sums
};

// Reads OUT/torus.glb and its EXR and measures every seam across faces within 15°.
WrittenSeams measureWrittenSeams(const std::string& out) {
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    EXPECT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, out + "/torus.glb")) << err;
    const LightmapImage atlas = readLightmapExr(out + "/lightmaps/0.exr");
    double atlasMean = 0.0, covered = 0.0;
    for (std::size_t i = 0; i < atlas.irradianceOverPi.size(); ++i)
        if (atlas.state[i] == TexelState::Covered) {
            const glm::vec3 c = atlas.irradianceOverPi[i];
            atlasMean += double(c.x) + c.y + c.z, covered += 1.0;
        }
    atlasMean /= std::max(covered, 1.0);
    EXPECT_GT(covered, 1000.0);

    // Triangles as (welded position ids, their UVs); the writer splits vertices at seams, positions stay exact.
    std::map<std::tuple<float, float, float>, int> weld;
    std::vector<glm::dvec3> pos;
    struct Corner { int id; glm::dvec2 uv; };
    std::vector<std::array<Corner, 3>> tris;
    for (const tinygltf::Mesh& mesh : model.meshes)
        for (const tinygltf::Primitive& prim : mesh.primitives) {
            const tinygltf::Accessor& pa = model.accessors.at(std::size_t(prim.attributes.at("POSITION")));
            const float* xyz = accessorData<float>(model, prim.attributes.at("POSITION"));
            const float* st = accessorData<float>(model, prim.attributes.at("TEXCOORD_1"));
            std::vector<int> ids(pa.count);
            for (std::size_t i = 0; i < pa.count; ++i) {
                const auto key = std::make_tuple(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
                auto [it, fresh] = weld.emplace(key, int(pos.size()));
                if (fresh) pos.emplace_back(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
                ids[i] = it->second;
            }
            const tinygltf::Accessor& ia = model.accessors.at(std::size_t(prim.indices));
            const bool wide = ia.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
            EXPECT_TRUE(wide || ia.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
            auto index = [&](std::size_t k) -> std::size_t {
                return wide ? accessorData<std::uint32_t>(model, prim.indices)[k] : accessorData<std::uint16_t>(model, prim.indices)[k];
            };
            for (std::size_t k = 0; k + 2 < ia.count; k += 3) {
                std::array<Corner, 3> tri;
                for (int c = 0; c < 3; ++c) {
                    const std::size_t i = index(k + std::size_t(c));
                    tri[c] = {ids[i], glm::dvec2(st[2 * i], st[2 * i + 1])};
                }
                tris.push_back(tri);
            }
        }
    auto normal = [&](const std::array<Corner, 3>& t) {
        return glm::normalize(glm::cross(pos[t[1].id] - pos[t[0].id], pos[t[2].id] - pos[t[0].id]));
    };
    struct Side { std::size_t tri; glm::dvec2 uvA, uvB; };  // uvA at the edge's smaller id
    std::map<std::pair<int, int>, std::vector<Side>> edges;
    for (std::size_t f = 0; f < tris.size(); ++f)
        for (int c = 0; c < 3; ++c) {
            const Corner &a = tris[f][c], &b = tris[f][(c + 1) % 3];
            if (a.id < b.id) edges[{a.id, b.id}].push_back({f, a.uv, b.uv});
            else edges[{b.id, a.id}].push_back({f, b.uv, a.uv});
        }
    WrittenSeams s;
    const double floor = 0.05 * atlasMean;
    for (const auto& [key, sides] : edges) {
        EXPECT_EQ(sides.size(), 2u) << "the torus is closed: every edge has two triangles";
        if (sides.size() != 2) continue;
        const Side &x = sides[0], &y = sides[1];
        const double texel = 1.0 / atlas.size;
        if (glm::length(x.uvA - y.uvA) < 1e-3 * texel && glm::length(x.uvB - y.uvB) < 1e-3 * texel) continue;  // not a seam
        if (glm::dot(normal(tris[x.tri]), normal(tris[y.tri])) < std::cos(15.0 * M_PI / 180.0)) continue;
        ++s.seamEdges;
        for (int k = 1; k < kSamplesPerEdge + 1; ++k) {
            const double w = k / double(kSamplesPerEdge + 1);
            const glm::dvec3 a = bilinear(atlas, glm::mix(x.uvA, x.uvB, w)), b = bilinear(atlas, glm::mix(y.uvA, y.uvB, w));
            const double sa = a.x + a.y + a.z, sb = b.x + b.y + b.z;
            const double rel = std::abs(sa - sb) / std::max(0.5 * (sa + sb), floor);
            s.maxRelative = std::max(s.maxRelative, rel);
            s.meanRelative += rel;
            ++s.samples;
        }
    }
    s.meanRelative /= double(std::max<std::size_t>(s.samples, 1));
    return s;
}

WrittenSeams bakeAndMeasure(bool stitch) {
    TempDir dir;
    const std::string gltf = writeTorusScene(dir), out = dir.file("out");
    const Scene scene = loadGltf(gltf);
    BakeSettings settings = presetSettings("draft", scene.bounds().diagonal());
    settings.solve.lighting.skyRadiance = glm::vec3(0.2f, 0.25f, 0.3f);
    settings.lightmap.texelsPerUnit = 24;
    settings.lightmap.stitchSeams = stitch;
    settings.output.preview = false;
    const BakeResult result = bakeScene(scene, settings, BakeOutput{gltf, out});
    const WrittenSeams s = measureWrittenSeams(out);
    std::printf("stitch %s: %zu seam edges, %zu samples: written lightmap max %.4f, mean %.5f (the stitcher's own figure: max %.4f after %d sweeps)\n",
                stitch ? "on" : "off", s.seamEdges, s.samples, s.maxRelative, s.meanRelative,
                result.report.lightmap->seams.maxRelativeAfter, result.report.lightmap->seams.sweeps);
    return s;
}

}  // namespace

TEST(WrittenLightmapSeams, AgreeAcrossEverySmoothSeamWhenStitched) {
    const WrittenSeams stitched = bakeAndMeasure(true);
    EXPECT_GT(stitched.seamEdges, 20u);
    EXPECT_LT(stitched.maxRelative, 0.02);
    const WrittenSeams raw = bakeAndMeasure(false);
    EXPECT_EQ(raw.seamEdges, stitched.seamEdges);
    EXPECT_GT(raw.maxRelative, 0.05) << "without stitching the seams must show, or this check proves nothing";
}
