// Numerical stability at the extremes (issue 4): scale, distance from the origin, emitter brightness, thin walls.
#include <gtest/gtest.h>

#include "mesh/gltf_loader.h"
#include "mesh/scene_builder.h"
#include "support/gltf_fixture.h"
#include "support/solver_fixture.h"

using namespace hemibake;
using hemibake::test::meanIrradianceOverPi;
using hemibake::test::solveTestScene;

namespace {

Scene transformed(Scene scene, double scale, const glm::dvec3& offset) {
    for (MeshInstance& inst : scene.instances) {
        for (auto v : inst.mesh.vertices()) inst.mesh.point(v) = inst.mesh.point(v) * scale + OpenMesh::Vec3d(offset.x, offset.y, offset.z);
        inst.mesh.update_face_normals();
    }
    return scene;
}

Scene withEmissionScaled(Scene scene, float k) {
    for (Material& m : scene.materials) m.emittedRadiance *= k;
    return scene;
}

// Coarse elements on purpose: these tests compare a scene with itself under a transformation, not with ground
// truth. The hemicube is not coarse: a transformed scene rounds differently, so ties among the patches' unshot
// powers can break the other way and the shots come in another order with other random hemicube rotations. At
// R = 32 that alone moves a surface by up to 0.84 % (seed 2 against seed 1 at scale 1), which once passed for an
// absolute length hidden at ×1e-3 (0.46 %); at R = 128 seeds differ by ≤ 0.07 % and so do the scales.
SolveSettings cornellSettings(double scale) {
    SolveSettings s;
    s.subdivision = {0.25 * scale, 0.125 * scale, 0.0};
    s.solver.kind = SolverKind::Shoot;
    s.solver.hemicubeResolution = 128;
    return s;
}

std::vector<glm::dvec3> perSurface(const hemibake::test::SolvedTestScene& s) {
    std::vector<glm::dvec3> out;
    for (std::size_t i = 0; i < s.scene.instances.size(); ++i) out.push_back(meanIrradianceOverPi(s, int(i)));
    return out;
}

void expectSameSurfaces(const std::vector<glm::dvec3>& a, const std::vector<glm::dvec3>& b, double relative,
                        const char* what) {
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(b[i][c], a[i][c], relative * a[i][c]) << what << ", surface " << i << " channel " << c;
}

class CornellExtremes : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        cornell_ = new Scene(loadGltf(hemibake::test::sharedScene("cornell_box.gltf")));
        reference_ = new std::vector<glm::dvec3>(perSurface(*solveTestScene(*cornell_, cornellSettings(1.0))));
    }
    static void TearDownTestSuite() {
        delete cornell_;
        delete reference_;
    }
    static Scene* cornell_;
    static std::vector<glm::dvec3>* reference_;
};
Scene* CornellExtremes::cornell_ = nullptr;
std::vector<glm::dvec3>* CornellExtremes::reference_ = nullptr;

}  // namespace

// Irradiance is scale invariant at fixed radiance: E/π per surface must not move with the units.
TEST_F(CornellExtremes, ScaledByOneThousandth) {
    expectSameSurfaces(*reference_, perSurface(*solveTestScene(transformed(*cornell_, 1e-3, {}), cornellSettings(1e-3))), 2e-3,
                       "scale 1e-3");
}

TEST_F(CornellExtremes, ScaledByOneThousand) {
    expectSameSurfaces(*reference_, perSurface(*solveTestScene(transformed(*cornell_, 1e3, {}), cornellSettings(1e3))), 2e-3,
                       "scale 1e3");
}

TEST_F(CornellExtremes, TranslatedFarFromOrigin) {
    expectSameSurfaces(*reference_,
                       perSurface(*solveTestScene(transformed(*cornell_, 1.0, {1e5, 1e5, -1e5}), cornellSettings(1.0))), 2e-3,
                       "1e5 m from the origin");
}

// The equation is linear in the emission: 1e-6 and 1e6 scale every value exactly (to rounding).
TEST_F(CornellExtremes, EmissionScalesLinearly) {
    for (float k : {1e-6f, 1e6f}) {
        const auto scaled = perSurface(*solveTestScene(withEmissionScaled(*cornell_, k), cornellSettings(1.0)));
        std::vector<glm::dvec3> unscaled;
        for (const glm::dvec3& v : scaled) unscaled.push_back(v / double(k));
        expectSameSurfaces(*reference_, unscaled, 1e-4, k < 1.0f ? "emission x1e-6" : "emission x1e6");
    }
}

// Two closed rooms sharing a 1 mm wall: the dark one must stay dark (no leak through near planes or depth).
TEST(ThinWall, OneMillimetreWallLetsNoLightThrough) {
    SceneBuilder b("two rooms");
    const int white = b.addMaterial(glm::vec3(0.5f));
    const int lamp = b.addMaterial(glm::vec3(0.5f), glm::vec3(10.0f));
    b.addBox({0, 0, 0}, {2, 2.5, 3}, white, true, "lit");
    b.addBox({2.001, 0, 0}, {4.001, 2.5, 3}, white, true, "dark");
    // A lamp on the lit side of the wall, 1 cm from it, shining at it.
    b.addQuad({1.99, 0.5, 1.0}, {1.99, 0.5, 2.0}, {1.99, 1.5, 2.0}, {1.99, 1.5, 1.0}, lamp, "lamp");
    SolveSettings s;
    s.subdivision = {1.0, 0.25, 0.0};
    s.solver.kind = SolverKind::Shoot;
    s.solver.hemicubeResolution = 64;
    const auto solved = solveTestScene(b.build(), s);
    glm::dvec3 lit(0.0), dark(0.0);
    for (std::size_t e = 0; e < solved->mesh.elements.size(); ++e) {
        const bool isDark = solved->mesh.elements.centroid[e].x > 2.0005;
        (isDark ? dark : lit) += solved->solution.irradiance[e] * solved->mesh.elements.areaM2[e];
    }
    ASSERT_GT(lit.x, 0.0);
    EXPECT_LT(dark.x, 1e-3 * lit.x);  // issue 4's bound
    RecordProperty("darkOverLit", std::to_string(dark.x / lit.x));
}
