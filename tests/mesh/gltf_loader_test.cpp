// glTF loading: what a valid file turns into, and the one clear error every malformed file gets.
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

#include "mesh/errors.h"
#include "mesh/gltf_loader.h"
#include "support/gltf_fixture.h"

using namespace hemibake;
using hemibake::test::GltfFixture;
using hemibake::test::TempDir;

namespace {

// Asserts that loading fails with an InputError whose message names the file and contains `problem`.
void expectInputError(const std::string& path, const std::string& problem) {
    try {
        loadGltf(path);
        FAIL() << "expected an error for " << path;
    } catch (const InputError& e) {
        const std::string message = e.what();
        EXPECT_EQ(message.rfind(path, 0), 0u) << message;
        EXPECT_NE(message.find(problem), std::string::npos) << message;
        EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
    }
}

glm::dvec3 vertex(const MeshInstance& inst, int i) {
    const auto p = inst.mesh.point(SurfaceMesh::VertexHandle(i));
    return {p[0], p[1], p[2]};
}

}  // namespace

TEST(GltfLoader, CornellBoxFromShared) {
    const Scene scene = loadGltf(hemibake::test::sharedScene("cornell_box.gltf"));
    EXPECT_EQ(scene.report.meshNodes, 8u);
    EXPECT_EQ(scene.cameras.size(), 1u);
    EXPECT_EQ(scene.triangleCount(), 46u);
    EXPECT_EQ(scene.report.degenerateTriangles, 0u);
    // Light: L_e = (17, 12, 4), area 0.01365 m² (GROUND_TRUTH §5: 130 × 105 mm).
    const glm::dvec3 power = scene.emittedPowerWatts();
    const double area = 0.13 * 0.105;
    EXPECT_NEAR(power.x, M_PI * 17.0 * area, 1e-3 * M_PI * 17.0 * area);
    EXPECT_NEAR(power.y, M_PI * 12.0 * area, 1e-3 * M_PI * 12.0 * area);
    EXPECT_NEAR(power.z, M_PI * 4.0 * area, 1e-3 * M_PI * 4.0 * area);
    const Camera& cam = scene.cameras[0];
    EXPECT_NEAR(cam.position.x, 0.278, 1e-6);
    EXPECT_NEAR(cam.position.z, -0.8, 1e-6);
    EXPECT_NEAR(cam.forward.z, 1.0, 1e-6);
    EXPECT_NEAR(scene.surfaceAreaM2(), 0.308231 + 0.297265 + 0.303377 + 0.306889 + 0.306905 + 0.137349 + 0.24703 + 0.01365,
                1e-4);
}

TEST(GltfLoader, TrsTransformIsApplied) {
    TempDir dir;
    GltfFixture g = hemibake::test::unitQuadFixture();
    // Rotate 90° about X (quaternion x = sin45, w = cos45), scale 2, translate (10, 0, 0).
    const double s = std::sqrt(0.5);
    g.json()["nodes"][0]["rotation"] = {s, 0.0, 0.0, s};
    g.json()["nodes"][0]["scale"] = {2.0, 2.0, 2.0};
    g.json()["nodes"][0]["translation"] = {10.0, 0.0, 0.0};
    const Scene scene = loadGltf(g.writeGltf(dir, "trs"));
    ASSERT_EQ(scene.instances.size(), 1u);
    // Local (0,0,1) → scaled (0,0,2) → rotated about X by 90°: (0,-2,0) → translated (10,-2,0).
    const glm::dvec3 v = vertex(scene.instances[0], 1);
    EXPECT_NEAR(v.x, 10.0, 1e-9);
    EXPECT_NEAR(v.y, -2.0, 1e-9);
    EXPECT_NEAR(v.z, 0.0, 1e-9);
    EXPECT_NEAR(scene.surfaceAreaM2(), 4.0, 1e-9);
}

TEST(GltfLoader, MatrixTransformAndHierarchyCompose) {
    TempDir dir;
    GltfFixture g = hemibake::test::unitQuadFixture();
    nlohmann::json child = g.json()["nodes"][0];
    child["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 5, 0, 1};  // translate y by 5 (column-major)
    g.json()["nodes"] = nlohmann::json::array();
    g.json()["scenes"][0]["nodes"] = nlohmann::json::array();
    const int childIndex = g.addChildNode(child);
    g.addNode({{"name", "parent"}, {"translation", {0.0, 0.0, 3.0}}, {"children", {childIndex}}});
    const Scene scene = loadGltf(g.writeGltf(dir, "matrix"));
    const glm::dvec3 v = vertex(scene.instances[0], 2);  // local (1,0,1)
    EXPECT_NEAR(v.x, 1.0, 1e-12);
    EXPECT_NEAR(v.y, 5.0, 1e-12);
    EXPECT_NEAR(v.z, 4.0, 1e-12);
    EXPECT_EQ(scene.report.nodes, 2u);
    EXPECT_EQ(scene.report.meshNodes, 1u);
}

TEST(GltfLoader, ProbeNodesGiveWorldPositions) {
    TempDir dir;
    GltfFixture g = hemibake::test::unitQuadFixture();
    // A probe under a translated parent, one flagged false, one with a non-boolean flag: only the first counts.
    const int probe = g.addChildNode({{"name", "probe"}, {"translation", {1.0, 2.0, 3.0}}, {"extras", {{"hemibake_probe", true}}}});
    g.addNode({{"name", "group"}, {"translation", {0.0, 0.5, 0.0}}, {"children", {probe}}});
    g.addNode({{"name", "off"}, {"translation", {9.0, 9.0, 9.0}}, {"extras", {{"hemibake_probe", false}}}});
    g.addNode({{"name", "odd"}, {"translation", {7.0, 7.0, 7.0}}, {"extras", {{"hemibake_probe", "yes"}}}});
    const Scene scene = loadGltf(g.writeGltf(dir, "probes"));
    ASSERT_EQ(scene.probePositions.size(), 1u);
    EXPECT_NEAR(scene.probePositions[0].x, 1.0, 1e-12);
    EXPECT_NEAR(scene.probePositions[0].y, 2.5, 1e-12);
    EXPECT_NEAR(scene.probePositions[0].z, 3.0, 1e-12);
}

TEST(GltfLoader, MirroringTransformKeepsFrontFaceUp) {
    TempDir dir;
    GltfFixture g = hemibake::test::unitQuadFixture();
    g.json()["nodes"][0]["scale"] = {-1.0, 1.0, 1.0};
    const Scene scene = loadGltf(g.writeGltf(dir, "mirror"));
    for (auto f : scene.instances[0].mesh.faces()) EXPECT_NEAR(scene.instances[0].mesh.normal(f)[1], 1.0, 1e-12);
}

TEST(GltfLoader, IndexTypesStripsFansAndNonIndexed) {
    TempDir dir;
    GltfFixture g;
    const std::vector<float> quad = {0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0};
    g.addNode({{"mesh", g.addMesh(g.addPositions(quad), g.addIndicesU8({0, 1, 2, 0, 2, 3}))}});
    g.addNode({{"mesh", g.addMesh(g.addPositions(quad), g.addIndicesU32({0, 1, 2, 0, 2, 3}))}});
    // Strip 1,0,2,3 → (1,0,2), then reversed (0,2,3)→(2,0,3)... both facing +Y once the winding is fixed.
    g.addNode({{"mesh", g.addMesh(g.addPositions(quad), g.addIndicesU16({1, 2, 0, 3}), -1, 5)}});
    g.addNode({{"mesh", g.addMesh(g.addPositions(quad), g.addIndicesU16({0, 1, 2, 3}), -1, 6)}});
    g.addNode({{"mesh", g.addMesh(g.addPositions({0, 0, 0, 0, 0, 1, 1, 0, 1}), -1)}});
    const Scene scene = loadGltf(g.writeGltf(dir, "indices"));
    ASSERT_EQ(scene.instances.size(), 5u);
    const std::size_t expected[5] = {2, 2, 2, 2, 1};
    for (std::size_t i = 0; i < 5; ++i) {
        EXPECT_EQ(scene.instances[i].mesh.n_faces(), expected[i]) << "instance " << i;
        for (auto f : scene.instances[i].mesh.faces())
            EXPECT_NEAR(scene.instances[i].mesh.normal(f)[1], 1.0, 1e-12) << "instance " << i;
    }
}

TEST(GltfLoader, PointsAndLinesAreSkippedWithWarning) {
    TempDir dir;
    GltfFixture g = hemibake::test::unitQuadFixture();
    g.addNode({{"mesh", g.addMesh(g.addPositions({0, 0, 0, 1, 1, 1}), -1, -1, 1)}});
    const Scene scene = loadGltf(g.writeGltf(dir, "lines"));
    EXPECT_EQ(scene.instances.size(), 1u);
    EXPECT_EQ(scene.report.skippedPrimitives, 1u);
    ASSERT_FALSE(scene.report.warnings.empty());
    EXPECT_NE(scene.report.warnings[0].find("skipped"), std::string::npos);
}

TEST(GltfLoader, DegenerateTrianglesAreDroppedAndCounted) {
    TempDir dir;
    GltfFixture g;
    // Quad plus one collinear triangle and one with a repeated index.
    const int pos = g.addPositions({0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0, 2, 0, 2});
    g.addNode({{"mesh", g.addMesh(pos, g.addIndicesU16({0, 1, 2, 0, 2, 3, 0, 2, 4, 1, 1, 3}))}});
    const Scene scene = loadGltf(g.writeGltf(dir, "degenerate"));
    EXPECT_EQ(scene.triangleCount(), 2u);
    EXPECT_EQ(scene.report.degenerateTriangles, 2u);
}

TEST(GltfLoader, MaterialsLightsAndEmissiveStrength) {
    TempDir dir;
    GltfFixture g = hemibake::test::unitQuadFixture();
    const int m = g.addMaterial({{"name", "lamp"},
                                 {"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 1.5, 0.25, 1.0}}}},
                                 {"emissiveFactor", {1.0, 0.5, 0.0}},
                                 {"doubleSided", true},
                                 {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 8.0}}}}}});
    g.json()["meshes"][0]["primitives"][0]["material"] = m;
    g.json()["extensionsUsed"] = {"KHR_materials_emissive_strength", "KHR_lights_punctual"};
    g.json()["extensions"] = {{"KHR_lights_punctual",
                               {{"lights", {{{"type", "spot"}, {"color", {1.0, 0.5, 0.25}}, {"intensity", 4.0},
                                             {"spot", {{"innerConeAngle", 0.1}, {"outerConeAngle", 0.5}}}}}}}}};
    g.addNode({{"name", "spot"},
               {"translation", {0.0, 2.0, 0.0}},
               {"rotation", {-std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5)}},  // -Z rotated to -Y: points down
               {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    const Scene scene = loadGltf(g.writeGltf(dir, "materials"));
    const Material& mat = scene.materials.at(0);
    EXPECT_FLOAT_EQ(mat.reflectanceFactor.x, 0.5f);
    EXPECT_FLOAT_EQ(mat.reflectanceFactor.y, 0.999f);  // clamped, with a warning
    EXPECT_FLOAT_EQ(mat.emittedRadiance.x, 8.0f);
    EXPECT_FLOAT_EQ(mat.emittedRadiance.y, 4.0f);
    EXPECT_TRUE(mat.doubleSided);
    EXPECT_FALSE(scene.report.warnings.empty());
    ASSERT_EQ(scene.lights.size(), 1u);
    const PunctualLight& l = scene.lights[0];
    EXPECT_EQ(l.type, LightType::Spot);
    EXPECT_FLOAT_EQ(l.intensity.y, 2.0f);
    EXPECT_NEAR(l.position.y, 2.0, 1e-12);
    EXPECT_NEAR(l.direction.y, -1.0, 1e-6);
    EXPECT_FLOAT_EQ(l.outerConeAngle, 0.5f);
    EXPECT_NEAR(scene.emittedPowerWatts().x, M_PI * 8.0 * 1.0, 1e-9);
}

TEST(GltfLoader, GlbAndEmbeddedBuffersLoad) {
    TempDir dir;
    const GltfFixture g = hemibake::test::unitQuadFixture();
    EXPECT_EQ(loadGltf(g.writeGlb(dir, "quad")).triangleCount(), 2u);
    EXPECT_EQ(loadGltf(g.writeGltf(dir, "embedded", true)).triangleCount(), 2u);
}

// ---- bad input: each gets one line naming the file and the problem ----

TEST(GltfLoaderBadInput, MissingFile) {
    TempDir dir;
    expectInputError(dir.file("nope.gltf"), "file not found");
}

TEST(GltfLoaderBadInput, NotGltf) {
    TempDir dir;
    std::ofstream(dir.file("text.gltf")) << "hello, I am not JSON";
    expectInputError(dir.file("text.gltf"), "not a glTF file");
    std::ofstream(dir.file("broken.gltf")) << "{ \"asset\": { \"version\": \"2.0\" }, ";
    expectInputError(dir.file("broken.gltf"), "");
    std::ofstream(dir.file("fake.glb")) << "PK\x03\x04 zip file";
    expectInputError(dir.file("fake.glb"), "bad magic");
}

TEST(GltfLoaderBadInput, TruncatedGlb) {
    TempDir dir;
    std::vector<std::uint8_t> bytes = hemibake::test::unitQuadFixture().glbBytes();
    for (std::size_t keep : {std::size_t(8), std::size_t(20), bytes.size() / 2, bytes.size() - 4}) {
        const std::string path = dir.file("cut" + std::to_string(keep) + ".glb");
        std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(keep));
        expectInputError(path, "");
    }
}

TEST(GltfLoaderBadInput, MissingExternalBin) {
    TempDir dir;
    const std::string path = hemibake::test::unitQuadFixture().writeGltf(dir, "nobin");
    std::filesystem::remove(dir.file("nobin.bin"));
    expectInputError(path, "");
}

TEST(GltfLoaderBadInput, AccessorOutOfBufferRange) {
    TempDir dir;
    GltfFixture g = hemibake::test::unitQuadFixture();
    g.json()["accessors"][0]["count"] = 1000;
    expectInputError(g.writeGltf(dir, "range"), "reads past the end");
    GltfFixture h = hemibake::test::unitQuadFixture();
    h.json()["bufferViews"][0]["byteLength"] = 1u << 30;
    expectInputError(h.writeGltf(dir, "view"), "");
}

TEST(GltfLoaderBadInput, NanPositions) {
    TempDir dir;
    GltfFixture g;
    const int pos = g.addPositions({0, 0, 0, 0, 0, 1, std::nanf(""), 0, 1});
    g.addNode({{"mesh", g.addMesh(pos, -1)}});
    expectInputError(g.writeGltf(dir, "nan"), "non-finite");
}

TEST(GltfLoaderBadInput, IndexOutOfRange) {
    TempDir dir;
    GltfFixture g;
    const int pos = g.addPositions({0, 0, 0, 0, 0, 1, 1, 0, 1});
    g.addNode({{"mesh", g.addMesh(pos, g.addIndicesU16({0, 1, 7}))}});
    expectInputError(g.writeGltf(dir, "index"), "index 7 out of range");
}

TEST(GltfLoaderBadInput, EmptyScene) {
    TempDir dir;
    GltfFixture g;
    for (const char* key : {"buffers", "bufferViews", "accessors", "meshes"}) g.json().erase(key);
    expectInputError(g.writeGltf(dir, "empty", true), "no triangles");
    GltfFixture onlyLines;
    onlyLines.addNode({{"mesh", onlyLines.addMesh(onlyLines.addPositions({0, 0, 0, 1, 1, 1}), -1, -1, 1)}});
    expectInputError(onlyLines.writeGltf(dir, "lines"), "no triangles");
}

TEST(GltfLoaderBadInput, NodeCycleAndDanglingReferences) {
    TempDir dir;
    GltfFixture g = hemibake::test::unitQuadFixture();
    g.json()["nodes"][0]["children"] = {0};
    expectInputError(g.writeGltf(dir, "cycle"), "");
    GltfFixture h = hemibake::test::unitQuadFixture();
    h.json()["meshes"][0]["primitives"][0]["material"] = 5;
    expectInputError(h.writeGltf(dir, "material"), "");
}
