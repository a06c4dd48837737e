// DirectLight: E/π from point, spot and directional lights against closed forms, hard and soft shadows, and the
// element means used by the baker.
#include <numbers>
#include <gtest/gtest.h>

#include <cmath>

#include "baker/direct/direct_light.h"
#include "mesh/scene_builder.h"
#include "mesh/subdivision.h"

using namespace hemibake;

namespace {


// A square floor at y = 0 facing +y, half-size `half`.
void addFloor(SceneBuilder& b, int material, double half) {
    b.addQuad({-half, 0, half}, {half, 0, half}, {half, 0, -half}, {-half, 0, -half}, material, "floor");
}

PunctualLight pointLight(glm::dvec3 position, glm::vec3 intensity) {
    PunctualLight l;
    l.type = LightType::Point;
    l.position = position;
    l.intensity = intensity;
    return l;
}

void expectRelative(const glm::dvec3& actual, const glm::dvec3& expected, double tolerance, const std::string& what) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(actual[c], expected[c], tolerance * std::abs(expected[c])) << what << " channel " << c;
}

}  // namespace

TEST(DirectLight, PointLightFollowsInverseSquareAndCosine) {
    SceneBuilder b;
    addFloor(b, b.addMaterial(glm::vec3(0.5f)), 10.0);
    const glm::dvec3 lightPos(0.3, 2.0, -0.2);
    const glm::vec3 intensity(10.0f, 20.0f, 5.0f);
    b.addLight(pointLight(lightPos, intensity));
    const Scene scene = b.build();
    const EmbreeScene rays(scene);
    const DirectLight direct(scene, rays, {});

    for (const glm::dvec3 p : {glm::dvec3(0, 0, 0), glm::dvec3(1.5, 0, -2), glm::dvec3(-4, 0, 3), glm::dvec3(7, 0, 7)}) {
        const double d = glm::length(lightPos - p);
        const double cosTheta = lightPos.y / d;
        const glm::dvec3 expected = glm::dvec3(intensity) * cosTheta / (std::numbers::pi * d * d);
        expectRelative(direct.irradianceOverPiAt(p, {0, 1, 0}, 0), expected, 1e-6, "point light");
    }
    // Facing away from the light (the underside): nothing.
    EXPECT_EQ(direct.irradianceOverPiAt({0, 0, 0}, {0, -1, 0}, 0), glm::dvec3(0.0));
}

TEST(DirectLight, BlockerCastsAnExactShadow) {
    SceneBuilder b;
    const int grey = b.addMaterial(glm::vec3(0.5f));
    addFloor(b, grey, 10.0);
    b.addQuad({-0.5, 1, 0.5}, {0.5, 1, 0.5}, {0.5, 1, -0.5}, {-0.5, 1, -0.5}, grey, "blocker");
    const glm::vec3 intensity(4.0f);
    b.addLight(pointLight({0, 2, 0}, intensity));
    const Scene scene = b.build();
    const EmbreeScene rays(scene);
    const DirectLight direct(scene, rays, {});

    // The blocker halfway up hides the floor's [-1, 1]² square.
    for (const glm::dvec3 p : {glm::dvec3(0, 0, 0), glm::dvec3(0.9, 0, 0.9), glm::dvec3(-0.5, 0, 0.7)})
        EXPECT_EQ(direct.irradianceOverPiAt(p, {0, 1, 0}, 0), glm::dvec3(0.0));
    const glm::dvec3 lit(1.2, 0, 0);
    const double d = glm::length(glm::dvec3(0, 2, 0) - lit);
    expectRelative(direct.irradianceOverPiAt(lit, {0, 1, 0}, 0), glm::dvec3(intensity) * (2.0 / d) / (std::numbers::pi * d * d), 1e-6, "lit");
}

TEST(DirectLight, ShadowHoldsAtAPointTouchingTheBlocker) {
    SceneBuilder b;
    const int grey = b.addMaterial(glm::vec3(0.5f));
    addFloor(b, grey, 10.0);
    b.addQuad({0, 0, -1}, {0, 0, 1}, {0, 0.5, 1}, {0, 0.5, -1}, grey, "low wall");  // x = 0, 0.5 m high
    const glm::vec3 intensity(2.0f);
    b.addLight(pointLight({-1, 1, 0}, intensity));
    const Scene scene = b.build();
    const EmbreeScene rays(scene);
    const DirectLight direct(scene, rays, {});
    // 10 µm from the wall's foot: far closer than rayEpsilonM(), and still in its shadow.
    ASSERT_GT(rays.rayEpsilonM(), 1e-5);
    EXPECT_EQ(direct.irradianceOverPiAt({1e-5, 0, 0}, {0, 1, 0}, 0), glm::dvec3(0.0));
    EXPECT_EQ(direct.irradianceOverPiAt({0.5, 0, 0.3}, {0, 1, 0}, 0), glm::dvec3(0.0));
    const glm::dvec3 lit(5, 0, 0);  // its ray to the light clears the wall at y = 5/6
    const double d = glm::length(glm::dvec3(-1, 1, 0) - lit);
    expectRelative(direct.irradianceOverPiAt(lit, {0, 1, 0}, 0), glm::dvec3(intensity) * (1.0 / d) / (std::numbers::pi * d * d), 1e-6, "lit");
}

TEST(DirectLight, SpotConeFallsOffBetweenInnerAndOuterAngles) {
    SceneBuilder b;
    addFloor(b, b.addMaterial(glm::vec3(0.5f)), 10.0);
    PunctualLight spot = pointLight({0, 2, 0}, glm::vec3(8.0f, 6.0f, 2.0f));
    spot.type = LightType::Spot;
    spot.direction = {0, -1, 0};
    const double inner = 20.0 * std::numbers::pi / 180.0, outer = 30.0 * std::numbers::pi / 180.0;
    spot.innerConeAngle = float(inner);
    spot.outerConeAngle = float(outer);
    b.addLight(spot);
    const Scene scene = b.build();
    const EmbreeScene rays(scene);
    const DirectLight direct(scene, rays, {});

    auto unattenuated = [&](double angle) {
        const double d = 2.0 / std::cos(angle);
        return glm::dvec3(spot.intensity) * std::cos(angle) / (std::numbers::pi * d * d);
    };
    auto at = [&](double angleDeg) {
        const double angle = angleDeg * std::numbers::pi / 180.0;
        return direct.irradianceOverPiAt({2.0 * std::tan(angle), 0, 0}, {0, 1, 0}, 0);
    };
    expectRelative(at(0.0), unattenuated(0.0), 1e-6, "axis");
    expectRelative(at(10.0), unattenuated(10.0 * std::numbers::pi / 180.0), 1e-6, "inside the inner cone");
    expectRelative(at(19.5), unattenuated(19.5 * std::numbers::pi / 180.0), 1e-6, "just inside the inner cone");
    EXPECT_EQ(at(30.5), glm::dvec3(0.0));
    EXPECT_EQ(at(45.0), glm::dvec3(0.0));
    // Between the cones: KHR's (cos − cos outer)/(cos inner − cos outer), clamped and squared (float cone angles).
    const double angle = 25.0 * std::numbers::pi / 180.0;
    const double t = (std::cos(angle) - std::cos(double(spot.outerConeAngle))) /
                     (std::cos(double(spot.innerConeAngle)) - std::cos(double(spot.outerConeAngle)));
    const glm::dvec3 between = at(25.0);
    expectRelative(between, unattenuated(angle) * (t * t), 1e-6, "between the cones");
    EXPECT_GT(between.x, 0.0);
    EXPECT_LT(between.x, unattenuated(angle).x);
}

TEST(DirectLight, DirectionalLightGivesIntensityTimesCosine) {
    SceneBuilder b;
    addFloor(b, b.addMaterial(glm::vec3(0.5f)), 10.0);
    PunctualLight sun;
    sun.type = LightType::Directional;
    sun.intensity = {3.0f, 2.0f, 1.0f};
    sun.direction = glm::normalize(glm::vec3(-1.0f, -2.0f, -0.5f));
    b.addLight(sun);
    const Scene scene = b.build();
    const EmbreeScene rays(scene);
    const DirectLight direct(scene, rays, {});
    const glm::dvec3 toSun = -glm::dvec3(sun.direction);

    expectRelative(direct.irradianceOverPiAt({2, 0, -3}, {0, 1, 0}, 0), glm::dvec3(sun.intensity) * toSun.y / std::numbers::pi, 1e-6, "floor");
    for (const glm::vec3 n : {glm::normalize(glm::vec3(1, 1, 0)), glm::normalize(glm::vec3(0.2f, 0.3f, 1.0f)), glm::vec3(1, 0, 0)}) {
        const double cosTheta = glm::dot(glm::dvec3(n), toSun);
        ASSERT_GT(cosTheta, 0.0);
        expectRelative(direct.irradianceOverPiAt({0, 0.5, 0}, n, 7), glm::dvec3(sun.intensity) * cosTheta / std::numbers::pi, 1e-6, "tilted");
    }
    EXPECT_EQ(direct.irradianceOverPiAt({0, 0.5, 0}, glm::normalize(glm::vec3(-1, -1, 0)), 0), glm::dvec3(0.0));
}

TEST(DirectLight, SoftSunKeepsUnoccludedIrradianceAndBlursTheShadowEdge) {
    SceneBuilder b;
    const int grey = b.addMaterial(glm::vec3(0.5f));
    addFloor(b, grey, 10.0);
    b.addQuad({-10, 1, 10}, {0, 1, 10}, {0, 1, -10}, {-10, 1, -10}, grey, "half-plane roof");  // x < 0 at y = 1
    PunctualLight sun;
    sun.type = LightType::Directional;
    sun.intensity = glm::vec3(5.0f);
    sun.direction = {0, -1, 0};
    b.addLight(sun);
    const Scene scene = b.build();
    const EmbreeScene rays(scene);
    const DirectLight hard(scene, rays, {});
    DirectLightSettings softSettings;
    softSettings.sunAngularDiameterRad = 0.1f;  // penumbra ±5 cm wide under a roof 1 m up
    softSettings.sunSamples = 64;
    const DirectLight soft(scene, rays, softSettings);
    const double full = 5.0 / std::numbers::pi;

    const glm::dvec3 open(2, 0, 0);
    EXPECT_EQ(soft.irradianceOverPiAt(open, {0, 1, 0}, 3), hard.irradianceOverPiAt(open, {0, 1, 0}, 3));
    EXPECT_NEAR(soft.irradianceOverPiAt(open, {0, 1, 0}, 3).x, full, 1e-12);
    EXPECT_EQ(soft.irradianceOverPiAt({-2, 0, 0}, {0, 1, 0}, 3), glm::dvec3(0.0));

    const double inside = soft.irradianceOverPiAt({-0.03, 0, 0}, {0, 1, 0}, 11).x;
    const double edge = soft.irradianceOverPiAt({0, 0, 0}, {0, 1, 0}, 12).x;
    const double outside = soft.irradianceOverPiAt({0.03, 0, 0}, {0, 1, 0}, 13).x;
    EXPECT_GT(inside, 0.0);
    EXPECT_LT(inside, edge);
    EXPECT_NEAR(edge / full, 0.5, 0.1);  // half the disk hidden, up to the stratified jitter
    EXPECT_LT(edge, outside);
    EXPECT_LT(outside, full);
}

TEST(DirectLight, ElementMeansIntegrateTheFluxOnAFloor) {
    SceneBuilder b;
    addFloor(b, b.addMaterial(glm::vec3(0.5f)), 2.0);
    const double intensity = 3.0, height = 1.0;
    b.addLight(pointLight({0, height, 0}, glm::vec3(float(intensity))));
    const Scene scene = b.build();
    const EmbreeScene rays(scene);
    const DirectLight direct(scene, rays, {});
    const PatchMesh patches = subdivide(scene, {0.5, 0.125, 0.0});

    const std::vector<glm::dvec3> values = elementsIrradianceOverPi(direct, patches, 16);
    ASSERT_EQ(values.size(), patches.elements.size());
    double fluxOverPi = 0.0;
    for (std::size_t e = 0; e < values.size(); ++e) fluxOverPi += values[e].x * patches.elements.areaM2[e];
    // Flux onto the 4 m × 4 m floor = I·Ω, Ω = 4·asin(ab / sqrt((a² + h²)(b² + h²))) with half-sides a = b = 2.
    const double solidAngle = 4.0 * std::asin(4.0 / std::sqrt(5.0 * 5.0));
    EXPECT_NEAR(fluxOverPi, intensity * solidAngle / std::numbers::pi, 2e-4 * intensity * solidAngle / std::numbers::pi);

    // One sample per element is the centroid; the parallel sweep equals element-by-element calls.
    for (std::size_t e : {std::size_t(0), values.size() / 2, values.size() - 1}) {
        expectRelative(direct.elementIrradianceOverPi(patches, e, 1),
                       direct.irradianceOverPiAt(patches.elements.centroid[e], patches.elements.normal[e], 0), 1e-12, "centroid");
        EXPECT_EQ(direct.elementIrradianceOverPi(patches, e, 16), values[e]);
    }
    EXPECT_THROW(DirectLight(scene, rays, {0.0f, 0, false}), std::invalid_argument);
}
