// glTF loading: what a valid file turns into, and the one clear error every malformed file gets.
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

#include "mesh/errors.h"
#include "mesh/gltf_loader.h"
#include "support/gltf_fixture.h"
#include "support/hostile_gltf.h"

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

// glTF requires TEXCOORD_n where a texture reads it; a file without them still loads, with a warning and every
// vertex at UV (0, 0) (never whatever memory the vertex was built in: a NaN there made a bake NaN).
TEST(GltfLoader, TexturedMaterialWithoutItsTexcoordsIsNamedInAWarning) {
    TempDir dir;
    GltfFixture g;
    const int pos = g.addPositions({0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0});
    const int material = g.addMaterial(
        {{"name", "painted"},
         {"pbrMetallicRoughness",
          {{"baseColorFactor", {0.5, 0.5, 0.5, 1.0}}, {"baseColorTexture", {{"index", 0}}}, {"metallicFactor", 0.0}}}});
    g.json()["textures"] = {{{"source", 0}}};
    // A valid 1 × 1 PNG.
    g.json()["images"] = {{{"uri", "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mNk+M9QDwADhgGAWjR9awAAAABJRU5ErkJggg=="}}};
    g.addNode({{"name", "painted"}, {"mesh", g.addMesh(pos, g.addIndicesU16({0, 1, 2, 0, 2, 3}), material, 4)}});
    const Scene scene = loadGltf(g.writeGltf(dir, "untextured"));
    ASSERT_EQ(scene.report.warnings.size(), 1u);
    EXPECT_NE(scene.report.warnings[0].find("no TEXCOORD_0"), std::string::npos) << scene.report.warnings[0];
    ASSERT_EQ(scene.instances.size(), 1u);
    const SurfaceMesh& mesh = scene.instances[0].mesh;
    for (const auto v : mesh.vertices()) EXPECT_EQ(mesh.texcoord2D(v), SurfaceMesh::TexCoord2D(0.0f));
    const glm::vec3 rho = scene.reflectance(scene.instances[0].material, glm::vec2(0.0f));
    for (int c = 0; c < 3; ++c) EXPECT_TRUE(std::isfinite(rho[c]) && rho[c] >= 0.0f && rho[c] <= 0.999f) << rho[c];
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
    expectInputError(dir.file("broken.gltf"), "parse error at line 1, column 34");
    std::ofstream(dir.file("fake.glb")) << "PK\x03\x04 zip file";
    expectInputError(dir.file("fake.glb"), "bad magic");
}

TEST(GltfLoaderBadInput, TruncatedGlb) {
    TempDir dir;
    std::vector<std::uint8_t> bytes = hemibake::test::unitQuadFixture().glbBytes();
    for (std::size_t keep : {std::size_t(8), std::size_t(20), bytes.size() / 2, bytes.size() - 4}) {
        const std::string path = dir.file("cut" + std::to_string(keep) + ".glb");
        std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(keep));
        expectInputError(path, keep < 12 ? "truncated binary glTF: " + std::to_string(keep) + " bytes, less than its 12-byte header"
                                         : "truncated binary glTF: its header says " + std::to_string(bytes.size()) +
                                               " bytes, the file has " + std::to_string(keep));
    }
}

TEST(GltfLoaderBadInput, MissingExternalBin) {
    TempDir dir;
    const std::string path = hemibake::test::unitQuadFixture().writeGltf(dir, "nobin");
    std::filesystem::remove(dir.file("nobin.bin"));
    expectInputError(path, "File not found : nobin.bin");
}

TEST(GltfLoaderBadInput, AccessorOutOfBufferRange) {
    TempDir dir;
    GltfFixture g = hemibake::test::unitQuadFixture();
    g.json()["accessors"][0]["count"] = 1000;
    expectInputError(g.writeGltf(dir, "range"), "reads past the end");
    GltfFixture h = hemibake::test::unitQuadFixture();
    h.json()["bufferViews"][0]["byteLength"] = 1u << 30;
    expectInputError(h.writeGltf(dir, "view"), "POSITION (accessor 0): buffer view 0 lies outside its buffer (60 bytes)");
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
    expectInputError(g.writeGltf(dir, "cycle"), "node 0 is its own ancestor (cycle in the node hierarchy)");
    GltfFixture h = hemibake::test::unitQuadFixture();
    h.json()["meshes"][0]["primitives"][0]["material"] = 5;
    expectInputError(h.writeGltf(dir, "material"), "mesh 0 primitive 0 refers to material 5, which does not exist");
}

// ---- issue 17: input that passes tinygltf's parser but not what comes after it ----

// A 20,000-deep chain used to overflow the stack of the recursive node walk (segfault). It is legal glTF and loads,
// every level's transform composed: the quad sits 20,000 × 1 mm along +X.
// A buffer URI that is an absolute path (an RFC 3986 absolute-path reference) names that file whether the glTF is
// named by an absolute or a relative path. tinygltf joins every URI to the glTF's folder, so it used to load only
// when named relatively: a bake loaded, and `reference --texels`, which reopens bake.json's absolute path, failed.
TEST(GltfLoaderExtremes, BufferUriThatIsAnAbsolutePathLoadsHoweverTheGltfIsNamed) {
    TempDir dir;
    const std::string written = hemibake::test::unitQuadFixture().writeGltf(dir, "quad");
    std::ifstream in(written);
    nlohmann::json j = nlohmann::json::parse(in);
    const std::string bin = std::filesystem::absolute(dir.file("quad.bin")).string();
    ASSERT_EQ(bin.front(), '/');
    j["buffers"][0]["uri"] = bin;
    std::filesystem::create_directories(dir.path() / "elsewhere");
    const std::string moved = std::filesystem::absolute(dir.path() / "elsewhere" / "quad.gltf").string();
    std::ofstream(moved) << j.dump();
    const Scene byAbsolutePath = loadGltf(moved);
    ASSERT_EQ(byAbsolutePath.instances.size(), 1u);
    EXPECT_EQ(byAbsolutePath.instances[0].mesh.n_faces(), 2u);
    const std::string relative = std::filesystem::relative(moved).string();
    ASSERT_NE(relative.front(), '/');
    EXPECT_EQ(loadGltf(relative).instances[0].mesh.n_faces(), 2u);
    // A relative URI still resolves against the glTF's folder: the same file beside a glTF named absolutely.
    j["buffers"][0]["uri"] = "quad.bin";
    const std::string beside = std::filesystem::absolute(dir.path() / "beside.gltf").string();
    std::ofstream(beside) << j.dump();
    EXPECT_EQ(loadGltf(beside).instances[0].mesh.n_faces(), 2u);
}

TEST(GltfLoaderExtremes, DeepHierarchyLoadsWithEveryLevelApplied) {
    TempDir dir;
    const Scene scene = loadGltf(hemibake::test::deepHierarchyFixture(20000).writeGltf(dir, "deep"));
    EXPECT_EQ(scene.report.nodes, 20000u);
    ASSERT_EQ(scene.instances.size(), 1u);
    EXPECT_EQ(scene.instances[0].source.nodeName, "leaf");
    const glm::dvec3 v = vertex(scene.instances[0], 2);  // local (1, 0, 1)
    EXPECT_NEAR(v.x, 1.0 + 20.0, 1e-9);
    EXPECT_NEAR(v.y, 0.0, 1e-12);
    EXPECT_NEAR(v.z, 1.0, 1e-12);
}

// glTF node hierarchies are disjoint trees. A node listed as a child twice (or as a root and a child) would be
// baked twice; a chain of nodes each listing the next twice was walked 2^depth times (a hang).
TEST(GltfLoaderExtremes, NodeReachedTwiceIsRejected) {
    TempDir dir;
    GltfFixture g = hemibake::test::unitQuadFixture();
    const int shared = 0;
    g.addNode({{"name", "twice"}, {"children", {shared, shared}}});
    expectInputError(g.writeGltf(dir, "twice"), "node 'quad' (node 0) is reached twice from the scene (a node may have only one parent)");

    GltfFixture chain = hemibake::test::deepHierarchyFixture(64);
    for (std::size_t i = 1; i < 64; ++i) chain.json()["nodes"][i]["children"] = {int(i) - 1, int(i) - 1};
    expectInputError(chain.writeGltf(dir, "chain"), "node 'leaf' (node 0) is reached twice from the scene");
}

// A node scaled by 1e30 used to load and then exhaust memory in unwrapping ("hemibake: out of memory", no file, no
// cause). World coordinates beyond 1e8 m are rejected at load, naming the node.
TEST(GltfLoaderExtremes, WorldCoordinatesBeyondTheLimitAreRejected) {
    TempDir dir;
    GltfFixture g = hemibake::test::unitQuadFixture();
    g.json()["nodes"][0]["scale"] = {1e30, 1e30, 1e30};
    expectInputError(g.writeGltf(dir, "huge"), "node 'quad' (node 0): mesh 0 primitive 0 reaches world coordinate 1e+30 m, "
                                               "beyond hemibake's limit of 1e+08 m from the origin");
    GltfFixture far = hemibake::test::unitQuadFixture();
    far.json()["nodes"][0]["translation"] = {0.0, -1.5e8, 0.0};
    expectInputError(far.writeGltf(dir, "far"), "reaches world coordinate 1.5e+08 m");
}

// The limit is no scale judgement: a 100 km level, a 1 mm scene, and a 1 mm scene 6,400 km from the origin (an
// Earth-centred georeferenced tile) all load with their coordinates intact.
TEST(GltfLoaderExtremes, LargeSmallAndFarScenesLoad) {
    TempDir dir;
    struct Case {
        const char* name;
        double scale, offset;
    };
    for (const Case& c : {Case{"level100km", 1e5, 0.0}, Case{"mm", 1e-3, 0.0}, Case{"mmFar", 1e-3, 6.4e6}}) {
        SCOPED_TRACE(c.name);
        GltfFixture g = hemibake::test::unitQuadFixture();
        g.json()["nodes"][0]["scale"] = {c.scale, c.scale, c.scale};
        g.json()["nodes"][0]["translation"] = {0.0, c.offset, 0.0};
        const Scene scene = loadGltf(g.writeGltf(dir, c.name));
        EXPECT_TRUE(scene.report.warnings.empty());
        ASSERT_EQ(scene.triangleCount(), 2u);
        EXPECT_NEAR(scene.surfaceAreaM2(), c.scale * c.scale, 1e-9 * c.scale * c.scale);
        const glm::dvec3 v = vertex(scene.instances[0], 2);
        EXPECT_EQ(v.x, c.scale);
        EXPECT_EQ(v.y, c.offset);
    }
}

// A finite transform can still overflow positions: 1e30 m coordinates scaled by 1e300.
TEST(GltfLoaderExtremes, NonFiniteWorldCoordinatesAfterTheTransformAreRejected) {
    TempDir dir;
    GltfFixture g;
    const int pos = g.addPositions({0, 0, 0, 0, 0, 1e30f, 1e30f, 0, 1e30f});
    g.addNode({{"name", "overflow"}, {"mesh", g.addMesh(pos, -1)}, {"scale", {1e300, 1e300, 1e300}}});
    expectInputError(g.writeGltf(dir, "overflow"),
                     "node 'overflow' (node 0): mesh 0 primitive 0 has non-finite world coordinates after the node transform");
}

// A zero matrix used to drop the node's triangles without a word. Now a warning names the node; the rest bakes.
TEST(GltfLoaderExtremes, SingularTransformIsNamedInAWarning) {
    TempDir dir;
    const Scene scene = loadGltf(hemibake::test::singularNodeFixture(true).writeGltf(dir, "singular"));
    ASSERT_EQ(scene.instances.size(), 1u);
    EXPECT_EQ(scene.instances[0].source.nodeName, "floor");
    EXPECT_EQ(scene.report.degenerateTriangles, 2u);
    ASSERT_EQ(scene.report.warnings.size(), 1u);
    EXPECT_EQ(scene.report.warnings[0],
              "node 'flat' (node 0): its transform is singular and collapses 2 of its 2 triangles to zero area; they are dropped");
}

// With nothing else in the scene the error says why there is nothing to bake.
TEST(GltfLoaderExtremes, OnlySingularTransformsIsAnErrorNamingThem) {
    TempDir dir;
    expectInputError(hemibake::test::singularNodeFixture(false).writeGltf(dir, "flat"),
                     "the scene has no triangles to bake: node 'flat' (node 0) has a singular transform that collapses its "
                     "2 triangles to zero area");
}

// Scenes that hide objects under a zero scale get one warning per node up to 8, then one line for the rest.
TEST(GltfLoaderExtremes, ManySingularNodesAreSummedUp) {
    TempDir dir;
    GltfFixture g = hemibake::test::unitQuadFixture();
    for (int i = 0; i < 11; ++i) g.addNode({{"name", "hidden" + std::to_string(i)}, {"mesh", 0}, {"scale", {0.0, 0.0, 0.0}}});
    const Scene scene = loadGltf(g.writeGltf(dir, "hidden"));
    EXPECT_EQ(scene.triangleCount(), 2u);
    ASSERT_EQ(scene.report.warnings.size(), 9u);
    EXPECT_EQ(scene.report.warnings[7].rfind("node 'hidden7' (node 8): its transform is singular", 0), 0u) << scene.report.warnings[7];
    EXPECT_EQ(scene.report.warnings[8], "and 3 more nodes whose singular transforms collapse triangles to zero area (dropped)");
}

// A transform singular only along a flat mesh's normal collapses nothing: no warning, and the normals survive
// (the inverse transpose does not exist; the cofactor matrix carries them).
TEST(GltfLoaderExtremes, SingularAlongTheNormalKeepsAFlatMesh) {
    TempDir dir;
    GltfFixture g;
    const std::vector<float> normals = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
    const int n = g.addAccessor(g.addView(normals.data(), normals.size() * sizeof(float)), 5126, "VEC3", 4);
    const int pos = g.addPositions({0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0});
    g.addNode({{"name", "decal"}, {"mesh", g.addMesh(pos, g.addIndicesU16({0, 1, 2, 0, 2, 3}), -1, 4, {{"NORMAL", n}})},
               {"scale", {2.0, 0.0, 2.0}}});
    const Scene scene = loadGltf(g.writeGltf(dir, "decal"));
    EXPECT_TRUE(scene.report.warnings.empty());
    ASSERT_EQ(scene.triangleCount(), 2u);
    EXPECT_NEAR(scene.surfaceAreaM2(), 4.0, 1e-12);
    const SurfaceMesh& mesh = scene.instances[0].mesh;
    for (auto v : mesh.vertices()) EXPECT_EQ(mesh.normal(v)[1], 1.0) << "vertex " << v.idx();
}

// Cameras and spot lights need a direction; under a zero matrix they have none and are skipped with a warning
// (their direction used to be NaN).
TEST(GltfLoaderExtremes, CamerasAndLightsUnderASingularTransformAreSkipped) {
    TempDir dir;
    GltfFixture g = hemibake::test::unitQuadFixture();
    g.json()["cameras"] = {{{"name", "eye"}, {"type", "perspective"}, {"perspective", {{"yfov", 1.0}, {"znear", 0.01}}}}};
    g.json()["extensionsUsed"] = {"KHR_lights_punctual"};
    g.json()["extensions"] = {{"KHR_lights_punctual", {{"lights", {{{"name", "spot"}, {"type", "spot"}, {"intensity", 1.0}, {"spot", {{"outerConeAngle", 0.5}}}},
                                                                    {{"name", "bulb"}, {"type", "point"}, {"intensity", 1.0}}}}}}};
    const std::vector<double> zero(16, 0.0);
    g.addNode({{"name", "rig"}, {"matrix", zero}, {"camera", 0}});
    g.addNode({{"name", "lamp"}, {"matrix", zero}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    g.addNode({{"name", "bulbNode"}, {"matrix", zero}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
    const Scene scene = loadGltf(g.writeGltf(dir, "rig"));
    EXPECT_TRUE(scene.cameras.empty());
    ASSERT_EQ(scene.lights.size(), 1u);  // a point light needs no direction
    EXPECT_EQ(scene.lights[0].name, "bulb");
    ASSERT_EQ(scene.report.warnings.size(), 2u);
    EXPECT_EQ(scene.report.warnings[0], "camera 'eye' on node 'rig' (node 1) is skipped: the node's transform is singular");
    EXPECT_EQ(scene.report.warnings[1], "light 'spot' on node 'lamp' (node 2) is skipped: the node's transform is singular");
}

// Sparse accessors are read as glTF defines them: the base view (or zeros) with the sparse values substituted.
TEST(GltfLoaderExtremes, SparseAccessorsAreRead) {
    TempDir dir;
    const Scene scene = loadGltf(hemibake::test::sparseQuadFixture().writeGltf(dir, "sparse"));
    ASSERT_EQ(scene.instances.size(), 1u);
    const glm::dvec3 expected[4] = {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}};
    for (int i = 0; i < 4; ++i) {
        const glm::dvec3 v = vertex(scene.instances[0], i);
        EXPECT_EQ(v, expected[i]) << "vertex " << i << ": " << v.x << " " << v.y << " " << v.z;
    }
    EXPECT_NEAR(scene.surfaceAreaM2(), 1.0, 1e-12);

    // Without a base view the accessor starts as zeros.
    GltfFixture noBase = hemibake::test::sparseQuadFixture();
    noBase.json()["accessors"][0].erase("bufferView");
    const Scene zeros = loadGltf(noBase.writeGltf(dir, "nobase"));
    // Corner 1 is not substituted: zero, like corner 0, so triangle (0, 1, 2) has no area and is dropped.
    ASSERT_EQ(zeros.triangleCount(), 1u);
    EXPECT_EQ(zeros.report.degenerateTriangles, 1u);
    EXPECT_NEAR(zeros.surfaceAreaM2(), 0.5, 1e-12);
    const SurfaceMesh& m = zeros.instances[0].mesh;
    ASSERT_EQ(m.n_vertices(), 3u);  // (0, 2, 3)
    EXPECT_EQ(vertex(zeros.instances[0], 0), glm::dvec3(0.0));
    EXPECT_EQ(vertex(zeros.instances[0], 1), glm::dvec3(1, 0, 1));
    EXPECT_EQ(vertex(zeros.instances[0], 2), glm::dvec3(1, 0, 0));
}

TEST(GltfLoaderExtremes, BrokenSparseAccessorsAreNamed) {
    TempDir dir;
    expectInputError(hemibake::test::sparseQuadFixture(9).writeGltf(dir, "index"),
                     "mesh 0 primitive 0 POSITION (accessor 0): sparse index 9 out of range (4 elements)");
    GltfFixture shortValues = hemibake::test::sparseQuadFixture();
    shortValues.json()["bufferViews"][2]["byteLength"] = 12;  // two VEC3 floats need 24
    expectInputError(shortValues.writeGltf(dir, "values"),
                     "POSITION (accessor 0) sparse values reads past the end of buffer view 2 (24 bytes at offset 0, view 12 bytes)");
    GltfFixture tooMany = hemibake::test::sparseQuadFixture();
    tooMany.json()["accessors"][0]["sparse"]["count"] = 5;
    expectInputError(tooMany.writeGltf(dir, "count"), "has a sparse count of 5 (must be 1 to 4)");
}

// An accessor without a buffer view reads as zeros; nothing but memory bounds its count.
TEST(GltfLoaderExtremes, ViewlessAccessorWithAbsurdCountIsRejected) {
    TempDir dir;
    GltfFixture g = hemibake::test::unitQuadFixture();
    g.json()["accessors"][0].erase("bufferView");
    g.json()["accessors"][0]["count"] = 1000000000000ull;
    expectInputError(g.writeGltf(dir, "zeros"), "POSITION (accessor 0) has no buffer view and 1000000000000 elements");
}

// tinygltf decodes base64 up to the first bad character, and quoted the whole URI in its error (megabytes on one
// line). Each problem is named in a few words, with the buffer.
TEST(GltfLoaderExtremes, MalformedBase64DataUrisAreNamed) {
    TempDir dir;
    const GltfFixture quad = hemibake::test::unitQuadFixture();
    const std::string embedded = quad.writeGltf(dir, "embedded", true);
    std::ifstream in(embedded);
    const nlohmann::json good = nlohmann::json::parse(in);
    const std::string uri = good["buffers"][0]["uri"];
    const std::string prefix = "data:application/octet-stream;base64,";
    const std::string data = uri.substr(prefix.size());  // 80 characters for 60 bytes
    ASSERT_EQ(data.size(), 80u);
    struct Case {
        const char* name;
        std::string uri;
        std::string problem;
    };
    const Case cases[] = {
        {"badchar", prefix + data.substr(0, 20) + "!!" + data.substr(22), "buffer 0: data URI is not valid base64: '!' at position 20 of its 80 data characters"},
        {"trailing", prefix + data + "@@@@", "buffer 0: data URI is not valid base64: '@' at position 80 of its 84 data characters"},
        {"short", prefix + data.substr(0, 72), "buffer 0: data URI holds 54 bytes, but its byteLength is 60"},
        {"empty", prefix, "buffer 0: data URI holds no data"},
        {"plain", "data:application/octet-stream," + data, "buffer 0: data URI is not base64-encoded"},
        {"ragged", prefix + data.substr(0, 77), "buffer 0: data URI is not valid base64: 77 data characters do not form whole groups of 4"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        nlohmann::json j = good;
        j["buffers"][0]["uri"] = c.uri;
        const std::string path = dir.file(std::string(c.name) + ".gltf");
        std::ofstream(path) << j.dump();
        expectInputError(path, c.problem);
        try {
            loadGltf(path);
        } catch (const InputError& e) {
            EXPECT_EQ(std::string(e.what()).find(data.substr(30, 20)), std::string::npos) << "quotes the data: " << e.what();
        }
    }
}

// A baseColor texture whose embedded PNG does not decode fails the load, naming the image.
TEST(GltfLoaderExtremes, UndecodableTextureIsNamed) {
    TempDir dir;
    expectInputError(hemibake::test::corruptTextureFixture().writeGltf(dir, "corrupt"),
                     "image 0 could not be decoded (corrupt, or not a PNG or JPEG)");
    expectInputError(hemibake::test::corruptTextureFixture().writeGlb(dir, "corrupt"), "image 0 could not be decoded");
}
