// Emissive surfaces lit by rays (EmissiveAreaLights) against GROUND_TRUTH §1 and §2: the unoccluded term is
// Lambert's formula (exact), shadows come from real Embree rays, and the solver that uses it still solves
// the furnace and keeps the power ledger.
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>

#include <gtest/gtest.h>

#include "baker/solve/solve_scene.h"

#include "baker/direct/direct_light.h"
#include "baker/direct/emissive_area_lights.h"
#include "baker/rays/embree_scene.h"
#include "mesh/scene_builder.h"
#include "mesh/subdivision.h"
#include "mesh/frame_math.h"
#include "mesh/triangle_sampling.h"
#include "support/solver_fixture.h"

using namespace hemibake;
using hemibake::test::furnace;
using hemibake::test::openSceneWithLamp;
using hemibake::test::meanIrradianceOverPi;
using hemibake::test::solveTestScene;

namespace {

// §1(d) parallel, corner-aligned: dA at the origin facing +z, rectangle [0,a]×[0,b] at height c.
double parallelCorner(double a, double b, double c) {
    const double A = a / c, B = b / c, sa = std::sqrt(1 + A * A), sb = std::sqrt(1 + B * B);
    return (A / sa * std::atan(B / sa) + B / sb * std::atan(A / sb)) / (2.0 * M_PI);
}

// §1(d) perpendicular: dA at the origin facing +z, rectangle in the plane y = c, x in [0,a], z in [0,b].
double perpendicularCorner(double a, double b, double c) {
    const double s = std::sqrt(b * b + c * c);
    return (std::atan(a / c) - c / s * std::atan(a / s)) / (2.0 * M_PI);
}

double rectangleAsTriangles(const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3 (&r)[4]) {
    const glm::dvec3 t0[3] = {r[0], r[1], r[2]}, t1[3] = {r[0], r[2], r[3]};
    return EmissiveAreaLights::unoccludedFormFactor(p, n, t0, 3) + EmissiveAreaLights::unoccludedFormFactor(p, n, t1, 3);
}

// A black floor [0,1]² (y = 0, facing up) under a lamp [0,1]² at height h facing down, radiance le, and
// optionally a black blocker plate over x < split at half height.
Scene lampOverFloor(double h, float le, bool blocker, double split = 0.5) {
    SceneBuilder b("lamp over floor");
    const int black = b.addMaterial(glm::vec3(0.0f), glm::vec3(0.0f), false, "black");
    const int lamp = b.addMaterial(glm::vec3(0.0f), glm::vec3(le), false, "lamp");
    b.addQuad({0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}, black, "floor");
    b.addQuad({0, h, 0}, {1, h, 0}, {1, h, 1}, {0, h, 1}, lamp, "lamp");  // faces down
    if (blocker)  // single-sided, facing down like the lamp: its back faces the floor's light path either way
        b.addQuad({-2, h / 2, -2}, {split, h / 2, -2}, {split, h / 2, 3}, {-2, h / 2, 3}, black, "blocker");
    return b.build();
}

PatchMesh meshOf(const Scene& scene) { return subdivide(scene, SubdivisionSettings{0.25, 0.125, 0.25}); }

// The red channel's mean over seeds 1 … calls of irradianceOverPiAt at p (a receiver `view` was made for), and its
// standard error: what an unbiased estimator must match within a few of them.
struct SeedMean {
    double mean, standardError;
};
SeedMean meanOverSeeds(const EmissiveAreaLights& lights, const glm::dvec3& p, const glm::dvec3& n,
                       const EmissiveAreaLights::ReceiverView& view, int calls = 4000) {
    double sum = 0.0, sum2 = 0.0;
    for (int s = 0; s < calls; ++s) {
        const double v = lights.irradianceOverPiAt(p, n, std::uint64_t(s) + 1, view).x;
        sum += v;
        sum2 += v * v;
    }
    const double mean = sum / calls;
    return {mean, std::sqrt(std::max(0.0, sum2 / calls - mean * mean) / calls)};
}

}  // namespace

TEST(EmissiveAreaLights, UnoccludedTermIsLambertsFormula) {
    const glm::dvec3 p(0.0), up(0, 0, 1);
    const double cases[][3] = {{1, 1, 1}, {1, 2, 1}, {2, 2, 1}, {1, 1, 0.1}, {1, 1, 10}, {0.5, 2, 0.5}};
    for (const auto& c : cases) {
        const glm::dvec3 parallel[4] = {{0, 0, c[2]}, {c[0], 0, c[2]}, {c[0], c[1], c[2]}, {0, c[1], c[2]}};
        EXPECT_NEAR(rectangleAsTriangles(p, up, parallel), parallelCorner(c[0], c[1], c[2]), 1e-12);
        const glm::dvec3 perpendicular[4] = {{0, c[2], 0}, {c[0], c[2], 0}, {c[0], c[2], c[1]}, {0, c[2], c[1]}};
        EXPECT_NEAR(rectangleAsTriangles(p, up, perpendicular), perpendicularCorner(c[0], c[1], c[2]), 1e-12);
        // The same wall reaching below the horizon: the hidden half is clipped away, not counted negative.
        const glm::dvec3 through[4] = {{0, c[2], -c[1]}, {c[0], c[2], -c[1]}, {c[0], c[2], c[1]}, {0, c[2], c[1]}};
        EXPECT_NEAR(rectangleAsTriangles(p, up, through), perpendicularCorner(c[0], c[1], c[2]), 1e-12);
    }
    // GROUND_TRUTH §1(d) table values, as a check on the transcription above.
    EXPECT_NEAR(parallelCorner(1, 1, 1), 0.138532, 1e-6);
    EXPECT_NEAR(perpendicularCorner(1, 1, 1), 0.055734, 1e-6);
}

TEST(EmissiveAreaLights, UnshadowedPointsGetTheExactValueWhateverTheSeed) {
    const float le = 3.0f;
    const Scene scene = lampOverFloor(0.5, le, false);
    const EmbreeScene rays(scene);
    const PatchMesh mesh = meshOf(scene);
    const EmissiveAreaLights lights(mesh, rays, 16);
    EXPECT_EQ(lights.triangleCount(), 2u);  // the lamp quad, however finely its elements split it
    EXPECT_NEAR(lights.emittedPowerW(), 3.0 * M_PI * le, 1e-9);
    for (const glm::dvec3& p : {glm::dvec3(0.5, 0, 0.5), glm::dvec3(0.1, 0, 0.9), glm::dvec3(0.97, 0, 0.02)}) {
        // Lamp [0,1]² at height 0.5 from p = four corner-aligned rectangles (§1(d)).
        const double x0 = p.x, x1 = 1 - p.x, z0 = p.z, z1 = 1 - p.z;
        const double exact = le * (parallelCorner(x0, z0, 0.5) + parallelCorner(x1, z0, 0.5) + parallelCorner(x0, z1, 0.5) +
                                   parallelCorner(x1, z1, 0.5));
        for (std::uint64_t seed : {1ull, 2ull, 12345ull}) {
            const glm::dvec3 got = lights.irradianceOverPiAt(p, {0, 1, 0}, seed);
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], exact, 1e-9 * exact) << "seed " << seed;
        }
    }
    // Behind the lamp (above it, where it does not emit) and facing away: nothing.
    EXPECT_EQ(lights.irradianceOverPiAt({0.5, 0.7, 0.5}, {0, -1, 0}, 1), glm::dvec3(0.0));
    EXPECT_EQ(lights.irradianceOverPiAt({0.5, 0.0, 0.5}, {0, -1, 0}, 1), glm::dvec3(0.0));
}

TEST(EmissiveAreaLights, ShadowsComeFromRays) {
    const float le = 3.0f;
    // The blocker covers x < 2 entirely: the whole lamp is hidden from the floor.
    {
        const Scene scene = lampOverFloor(0.5, le, true, 2.0);
        const EmbreeScene rays(scene);
        const EmissiveAreaLights lights(meshOf(scene), rays, 16);
        EXPECT_EQ(lights.irradianceOverPiAt({0.5, 0, 0.5}, {0, 1, 0}, 7), glm::dvec3(0.0));
    }
    // The blocker's edge at x = 0.5, half way up: from the floor's centre it hides exactly the lamp's x < 0.5 half
    // (by symmetry half of the form factor). The ratio estimator is unbiased only in the limit: averaged over
    // seeds it must be within its measured spread of one half.
    const Scene scene = lampOverFloor(0.5, le, true, 0.5);
    const EmbreeScene rays(scene);
    const EmissiveAreaLights lights(meshOf(scene), rays, 64);
    const double full = le * 4.0 * parallelCorner(0.5, 0.5, 0.5);
    double sum = 0.0, sum2 = 0.0;
    const int seeds = 200;
    for (int s = 0; s < seeds; ++s) {
        const double v = lights.irradianceOverPiAt({0.5, 0, 0.5}, {0, 1, 0}, std::uint64_t(s)).x / full;
        sum += v;
        sum2 += v * v;
    }
    const double mean = sum / seeds, sd = std::sqrt(std::max(0.0, sum2 / seeds - mean * mean));
    std::printf("half-shadowed point: visible fraction %.4f (exact 0.5), per-point sd %.4f at 64 rays\n", mean, sd);
    EXPECT_NEAR(mean, 0.5, 4.0 * sd / std::sqrt(double(seeds)) + 1e-3);
    EXPECT_LT(sd, 0.0625);  // stratified rays beat independent ones (binomial sd √(0.25/64) = 0.0625)
}

// §2.A with every face an emitter lit by rays: Σ F over a closed box is 1 at every point, so the direct term is
// exactly L_e and the shooter adds the bounces, E/π = L_e/(1 − ρ).
TEST(EmissiveAreaLights, FurnaceSolvedWithRayTracedEmitters) {
    for (const float rho : {0.5f, 0.9f}) {
        const float le = 2.0f;
        SolveSettings s;
        s.subdivision = {1.0, 0.5, 1.0};
        s.solver.kind = SolverKind::Shoot;
        s.solver.hemicubeResolution = 32;
        s.solver.ambientCorrection = false;
        s.lighting.emitters = EmitterLighting::Rays;
        const auto solved = solveTestScene(furnace(rho, le, false), s);
        ASSERT_TRUE(solved->report.emittersByRays);
        const glm::dvec3 mean = meanIrradianceOverPi(*solved);
        const double expected = le / (1.0 - double(rho));
        std::printf("ray-traced furnace rho %.2f: mean E/pi %.6f, exact %.6f, rel %+.2e\n", rho, mean.x, expected,
                    mean.x / expected - 1.0);
        for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(mean[ch], expected, 0.005 * expected);
    }
}

// The power ledger still balances when emitters do not shoot: what no front face received is booked as escaped.
TEST(EmissiveAreaLights, OpenScenePowerBalances) {
    SceneBuilder b = openSceneWithLamp();
    SolveSettings s;
    s.subdivision = {0.25, 0.125, 0.25};
    s.solver.kind = SolverKind::Shoot;
    s.solver.hemicubeResolution = 64;
    s.solver.ambientCorrection = false;
    s.solver.epsilon = 1e-4;
    s.lighting.emitters = EmitterLighting::Rays;
    const auto solved = solveTestScene(b.build(), s);
    const SolveReport& r = solved->report;
    ASSERT_TRUE(r.emittersByRays);
    const glm::dvec3 in = r.emitterPowerW + r.directPowerW;
    const glm::dvec3 out = r.absorbedPowerW + r.escapedPowerW + r.backfacePowerW + r.unshotPowerW;
    std::printf("ray-traced emitters: in %.6f W, out %.6f W (rel %+.2e)\n", in.x, out.x, out.x / in.x - 1.0);
    for (int c = 0; c < 3; ++c) {
        EXPECT_GT(r.escapedPowerW[c], 0.1 * in[c]);
        EXPECT_NEAR(out[c], in[c], 1e-3 * in[c]) << "channel " << c;
    }
}

// Σ F = 1 inside a closed box at every point, also a hair from its edges and corners, where the nearest emitter
// triangles meet the receiver at right angles and shadow rays skim along the walls: nothing may be lost there.
TEST(EmissiveAreaLights, ClosedBoxClosesAtEdgesAndCorners) {
    const Scene scene = furnace(0.5f, 1.0f, false);
    const EmbreeScene rays(scene);
    const EmissiveAreaLights lights(meshOf(scene), rays, 64);
    for (const double d : {0.3, 0.05, 0.01, 1e-3}) {
        for (const glm::dvec3& p : {glm::dvec3(0.5, 0, 0.5), glm::dvec3(d, 0, 0.5), glm::dvec3(d, 0, d), glm::dvec3(1 - d, 0, 1 - d)}) {
            const glm::dvec3 got = lights.irradianceOverPiAt(p, {0, 1, 0}, 3);
            EXPECT_NEAR(got.x, 1.0, 1e-9) << "floor point " << p.x << ", " << p.z;
        }
    }
}

// The elements bisected from one input triangle are one light (one contour integral per point, not one per element),
// with the same unoccluded value: a lamp quad cut into 128 elements is two triangles.
TEST(EmissiveAreaLights, ElementsOfOneInputTriangleAreOneLight) {
    const Scene scene = lampOverFloor(1.0, 3.0f, false);
    const EmbreeScene rays(scene);
    const PatchMesh fine = subdivide(scene, SubdivisionSettings{0.25, 0.125, 0.25});
    std::size_t lampElements = 0;
    for (const glm::vec3& l : fine.elements.emittedRadiance) lampElements += l.x > 0.0f;
    ASSERT_GT(lampElements, 100u);
    const EmissiveAreaLights lights(fine, rays, 16);
    EXPECT_EQ(lights.triangleCount(), 2u);
    EXPECT_NEAR(lights.emittedPowerW(), 3.0 * M_PI * 3.0, 1e-9);
    // §1(d) at the floor's corner, unshadowed: exact whatever the split.
    const glm::dvec3 p(0.0, 0.0, 0.0), n(0.0, 1.0, 0.0);
    EXPECT_NEAR(lights.irradianceOverPiAt(p, n, 7).x, 3.0 * parallelCorner(1.0, 1.0, 1.0), 1e-9);
}

// A closed cube emitting on every face (ρ 0.9): its 12 input triangles are lit by rays at the default limit, however
// finely the faces are split, and the furnace comes out at L_e/(1 − ρ).
TEST(EmissiveAreaLights, CubeEmittingOnEveryFaceStaysRayTraced) {
    SolveSettings s;
    s.subdivision = {0.5, 0.125, 0.0};  // about 800 emitting elements, far above the limit of 64 set below
    s.solver.hemicubeResolution = 32;
    s.lighting.emitters = EmitterLighting::Rays;
    s.lighting.maxRayTracedEmitters = 64;
    const Scene scene = furnace(0.9f, 1.0f, false);
    const EmbreeScene rays(scene);
    const auto solved = solveScene(scene, s, rays);
    ASSERT_TRUE(solved->report.emittersByRays);
    // Emitter patches at the patch size, not a quarter of it: they shoot only what they reflect.
    EXPECT_EQ(solved->mesh.patches.size(), 6u * 16u);  // a face: 2 triangles bisected 3 times to edges ≤ 0.5 m
    glm::dvec3 sum(0.0);
    double area = 0.0;
    for (std::size_t e = 0; e < solved->mesh.elements.size(); ++e) {
        sum += solved->solution.displayIrradiance(e) * solved->mesh.elements.areaM2[e];
        area += solved->mesh.elements.areaM2[e];
    }
    const glm::dvec3 mean = sum / area / M_PI;
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(mean[ch], 10.0, 0.005 * 10.0);
}

// Emitter triangles far from a receiving element are one value over it (the mean of its edge midpoints, or a point
// source farther out) instead of a contour per point. Unoccluded, the element's value is the mean of the exact
// per-point contours over its points (known answer): small triangles scattered from 0.3 m to 40 m away, some tilted
// so that they face part of the floor only.
TEST(EmissiveAreaLights, FarEmittersAreOneValuePerElement) {
    SceneBuilder b("scattered lamps over a floor");
    const int black = b.addMaterial(glm::vec3(0.0f), glm::vec3(0.0f), false, "black");
    const int lamp = b.addMaterial(glm::vec3(0.0f), glm::vec3(5.0f), false, "lamp");
    b.addQuad({0, 0, 0}, {0, 0, 4}, {4, 0, 4}, {4, 0, 0}, black, "floor");
    struct Lamp {
        glm::dvec3 a, b, c;
    };
    std::vector<Lamp> lamps;
    std::uint64_t state = 12345;
    auto uniform = [&] { return double(splitMix64(state += 0x9E3779B97F4A7C15ull) >> 11) * 0x1.0p-53; };
    for (int i = 0; i < 120; ++i) {
        const double distance = 0.3 * std::pow(40.0 / 0.3, uniform());  // log-uniform from 0.3 to 40 m
        const double angle = 2.0 * M_PI * uniform();
        const glm::dvec3 centre(2.0 + distance * std::cos(angle) * uniform(), 0.2 + distance * (0.1 + 0.9 * uniform()),
                                2.0 + distance * std::sin(angle) * uniform());
        const double size = 0.05 + 0.4 * uniform();
        const glm::dvec3 tilt(uniform() - 0.5, 0.0, uniform() - 0.5);  // normals from straight down to ~35° off
        glm::dvec3 t, s;
        orthonormalBasis(glm::normalize(glm::dvec3(0, -1, 0) + tilt), t, s);
        // Counter-clockwise seen from below, so the triangle emits downwards (towards the floor).
        lamps.push_back({centre + size * t, centre + size * (-0.5 * t - 0.866 * s), centre + size * (-0.5 * t + 0.866 * s)});
        if (glm::dot(glm::cross(lamps.back().b - lamps.back().a, lamps.back().c - lamps.back().a), glm::dvec3(0, 1, 0)) > 0.0)
            std::swap(lamps.back().b, lamps.back().c);
        b.addTriangles({lamps.back().a, lamps.back().b, lamps.back().c}, {{0, 1, 2}}, lamp, "lamp");
    }
    const Scene scene = b.build();
    SceneBuilder floorOnly("floor");
    floorOnly.addQuad({0, 0, 0}, {0, 0, 4}, {4, 0, 4}, {4, 0, 0}, floorOnly.addMaterial(glm::vec3(0.0f)), "floor");
    const Scene unoccluded = floorOnly.build();
    const EmbreeScene rays(unoccluded);  // nothing between the floor and the lamps: every shadow ray is visible
    const PatchMesh mesh = subdivide(scene, SubdivisionSettings{1.0, 0.5, 0.0});
    const EmissiveAreaLights lights(mesh, rays, 4);
    ASSERT_EQ(lights.triangleCount(), lamps.size());
    DirectLightSettings ds;
    ds.punctualLights = false;
    const DirectLight direct(scene, rays, ds, &lights);

    const int samplesPerElement = 64, k = 8;
    double worst = 0.0, worstPoint = 0.0;
    std::size_t floorElements = 0;
    for (std::size_t e = 0; e < mesh.elements.size(); ++e) {
        if (mesh.elements.normal[e].y < 0.5f) continue;
        ++floorElements;
        const glm::dvec3 n(0, 1, 0);
        double exact = 0.0;
        int points = 0;
        forEachSubTriangleCentroid(k, [&](double wa, double wb) {
            const glm::dvec3 p = pointOnElement(mesh.elements, e, wa, wb);
            double sum = 0.0, approximate;
            for (const Lamp& l : lamps) {
                const glm::dvec3 normal = glm::normalize(glm::cross(l.b - l.a, l.c - l.a));
                if (!(glm::dot(p - l.a, normal) > 0.0)) continue;
                const glm::dvec3 v[3] = {l.a, l.b, l.c};
                sum += 5.0 * EmissiveAreaLights::unoccludedFormFactor(p, n, v, 3);
            }
            exact += sum;
            ++points;
            approximate = lights.irradianceOverPiAt(p, n, 3).x;  // a point alone: point sources beyond 24 radii
            worstPoint = std::max(worstPoint, std::abs(approximate - sum) / sum);
        });
        exact /= points;
        const double got = direct.elementIrradianceOverPi(mesh, e, samplesPerElement).x;
        worst = std::max(worst, std::abs(got - exact) / exact);
    }
    ASSERT_GT(floorElements, 30u);
    std::printf("worst element %.3g, worst point %.3g\n", worst, worstPoint);
    EXPECT_LT(worst, 1e-3);
    EXPECT_LT(worstPoint, 1e-3);
}

// A level's lamps, seen from a room far from them: 400 ceiling lamps (one triangle each, all facing down, five
// brightnesses) 40–80 m away, with or without a lamp of the room's own over the floor. Clusters of lamps are taken
// as one point source while their error bounds stay within a budget of the receiver's unoccluded light, so with a
// lamp of its own a receiver looks at far fewer nodes than there are lamps; either way the unoccluded value must
// hold (against Lambert's formula per lamp and point) and so must the shadows: a wall hides the far, bright lamps, so
// picking a lamp within a cluster by anything but its power would bias the visible fraction (checked against a
// shadow ray to every lamp).
TEST(EmissiveAreaLights, FarClustersOfLampsAreOnePointSourceAndKeepTheirShadows) {
    struct Lamp {
        glm::dvec3 a, b, c;
        double le;
    };
    std::vector<Lamp> farLamps;
    for (int i = 0; i < 20; ++i)
        for (int j = 0; j < 20; ++j) {
            const glm::dvec3 centre(40.0 + 2.0 * i, 3.0, -18.0 + 2.0 * j);
            // Counter-clockwise seen from below: emits downwards. Brighter with distance: 1 … 5.
            farLamps.push_back({centre + glm::dvec3(0.1, 0, 0), centre + glm::dvec3(-0.05, 0, 0.0866),
                                centre + glm::dvec3(-0.05, 0, -0.0866), double(i / 4 + 1)});
            if (glm::cross(farLamps.back().b - farLamps.back().a, farLamps.back().c - farLamps.back().a).y > 0.0)
                std::swap(farLamps.back().b, farLamps.back().c);
        }
    // The room's own: a 0.5 m square at 2.5 m over the floor's centre, facing down.
    const std::vector<Lamp> roomLamp = {{{1.75, 2.5, 1.75}, {2.25, 2.5, 1.75}, {2.25, 2.5, 2.25}, 5.0},
                                        {{1.75, 2.5, 1.75}, {2.25, 2.5, 2.25}, {1.75, 2.5, 2.25}, 5.0}};
    auto scene = [&](const std::vector<Lamp>& lamps, bool wall) {
        SceneBuilder b("far ceiling lamps");
        const int black = b.addMaterial(glm::vec3(0.0f), glm::vec3(0.0f), false, "black");
        int materials[5];
        for (int m = 0; m < 5; ++m) materials[m] = b.addMaterial(glm::vec3(0.0f), glm::vec3(float(m + 1)), false, "lamp");
        b.addQuad({0, 0, 0}, {0, 0, 4}, {4, 0, 4}, {4, 0, 0}, black, "floor");
        for (const Lamp& l : lamps) b.addTriangles({l.a, l.b, l.c}, {{0, 1, 2}}, materials[int(l.le) - 1], "lamp");
        if (wall) b.addQuad({20, 0, -40}, {20, 1, -40}, {20, 1, 40}, {20, 0, 40}, black, "wall");  // hides x ≳ 56
        return b.build();
    };
    const glm::dvec3 up(0, 1, 0);
    auto exactAt = [&](const std::vector<Lamp>& lamps, const glm::dvec3& p, const EmbreeScene* visibility) {
        double sum = 0.0;
        for (const Lamp& l : lamps) {
            const glm::dvec3 v[3] = {l.a, l.b, l.c};
            const glm::dvec3 centroid = (l.a + l.b + l.c) / 3.0;
            if (visibility && visibility->occluded(visibility->offsetFromSurface(p, up), visibility->offsetFromSurface(centroid, -up),
                                                   EmbreeScene::RayEnds::Lifted))
                continue;  // both ends lifted off their surfaces, as the estimator's shadow rays are
            sum += l.le * EmissiveAreaLights::unoccludedFormFactor(p, up, v, 3);
        }
        return sum;
    };

    for (const bool ownLamp : {false, true}) {  // unoccluded: the value, and how many nodes a floor element looks at
        std::vector<Lamp> lamps = farLamps;
        if (ownLamp) lamps.insert(lamps.end(), roomLamp.begin(), roomLamp.end());
        const Scene open = scene(lamps, false);
        const PatchMesh mesh = subdivide(open, SubdivisionSettings{1.0, 0.5, 0.0});
        const EmbreeScene rays(open);
        const EmissiveAreaLights lights(mesh, rays, 4);
        ASSERT_EQ(lights.triangleCount(), lamps.size());
        DirectLightSettings ds;
        ds.punctualLights = false;
        const DirectLight direct(open, rays, ds, &lights);
        double worst = 0.0, worstPoint = 0.0;
        std::size_t floorElements = 0, largestView = 0;
        EmissiveAreaLights::ReceiverView view;
        for (std::size_t e = 0; e < mesh.elements.size(); ++e) {
            if (mesh.elements.normal[e].y < 0.5f) continue;
            ++floorElements;
            const glm::dvec3 receiver[3] = {pointOnElement(mesh.elements, e, 1, 0), pointOnElement(mesh.elements, e, 0, 1),
                                            pointOnElement(mesh.elements, e, 0, 0)};
            lights.viewFrom(receiver, up, view);
            largestView = std::max(largestView, view.perPoint.size() + view.constant.size());
            double exact = 0.0;
            int points = 0;
            forEachSubTriangleCentroid(8, [&](double wa, double wb) {
                const glm::dvec3 p = pointOnElement(mesh.elements, e, wa, wb);
                const double here = exactAt(lamps, p, nullptr);
                exact += here;
                ++points;
                worstPoint = std::max(worstPoint, std::abs(lights.irradianceOverPiAt(p, up, 3).x - here) / here);
            });
            exact /= points;
            worst = std::max(worst, std::abs(direct.elementIrradianceOverPi(mesh, e, 64).x - exact) / exact);
        }
        ASSERT_GT(floorElements, 30u);
        std::printf("%s: worst element %.3g, worst point %.3g; at most %zu nodes for %zu lamps per element\n",
                    ownLamp ? "with a lamp of its own" : "far lamps only", worst, worstPoint, largestView, lamps.size());
        EXPECT_LT(worst, 1e-3);
        EXPECT_LT(worstPoint, 1e-3);
        if (ownLamp) {
            EXPECT_LT(largestView, lamps.size() / 10);
        }
    }
    {  // Behind the wall: the mean over floor points against a shadow ray to every lamp.
        const Scene walled = scene(farLamps, true);
        const PatchMesh mesh = subdivide(walled, SubdivisionSettings{1.0, 0.5, 0.0});
        const EmbreeScene rays(walled);
        const EmissiveAreaLights lights(mesh, rays, 1024);
        double got = 0.0, exact = 0.0, unoccluded = 0.0;
        std::uint64_t seed = 0;
        for (double x = 0.25; x < 4.0; x += 0.5)
            for (double z = 0.25; z < 4.0; z += 0.5) {
                const glm::dvec3 p(x, 0.0, z);
                got += lights.irradianceOverPiAt(p, up, ++seed).x;
                exact += exactAt(farLamps, p, &rays);
                unoccluded += exactAt(farLamps, p, nullptr);
            }
        std::printf("behind the wall: visible %.4f of the unoccluded light, estimated %.4f\n", exact / unoccluded,
                    got / unoccluded);
        ASSERT_LT(exact, 0.8 * unoccluded) << "the wall no longer hides the far lamps: the test lost its premise";
        ASSERT_GT(exact, 0.2 * unoccluded);
        EXPECT_NEAR(got / exact, 1.0, 0.01);
    }
}

// The far group starts at 4 median free paths of the emitters' light. A lamp facing a wide plane at distance D: its
// cosine-distributed rays travel D / cosθ with cos²θ uniform, so the median is D·√2. With nothing in front, the
// light escapes and there is no far group.
TEST(EmissiveAreaLights, FarDistanceIsFourMedianFreePathsOfTheEmittersLight) {
    for (const bool plane : {true, false}) {
        constexpr double kD = 2.0;
        SceneBuilder b("lamp under a plane");
        const int black = b.addMaterial(glm::vec3(0.0f), glm::vec3(0.0f), false, "black");
        const int lamp = b.addMaterial(glm::vec3(0.0f), glm::vec3(1.0f), false, "lamp");
        b.addQuad({-0.5, 0, -0.5}, {-0.5, 0, 0.5}, {0.5, 0, 0.5}, {0.5, 0, -0.5}, lamp, "lamp");  // faces up
        if (plane) b.addQuad({-2000, kD, -2000}, {2000, kD, -2000}, {2000, kD, 2000}, {-2000, kD, 2000}, black, "plane");
        const Scene scene = b.build();
        const PatchMesh mesh = subdivide(scene, SubdivisionSettings{1000.0, 1000.0, 0.0});
        const EmbreeScene rays(scene);
        const EmissiveAreaLights lights(mesh, rays, 4);
        if (plane) {
            EXPECT_NEAR(lights.farDistanceM() / (4.0 * std::sqrt(2.0) * kD), 1.0, 0.02) << lights.farDistanceM();
        } else {
            EXPECT_EQ(lights.farDistanceM(), std::numeric_limits<double>::infinity());
        }
    }
}

// Lamps beyond the far distance (other rooms of a level) are cut coarsely and estimated by their own rays, Σ f/pdf:
// no bias, whatever the coarse cut's error; hidden, they add exactly nothing and the room's own lamp stays exact.
TEST(EmissiveAreaLights, FarLampsHaveRaysOfTheirOwnAndNoBias) {
    std::vector<std::array<glm::dvec3, 3>> lamps;
    for (int i = 0; i < 10; ++i)
        for (int j = 0; j < 10; ++j) {
            const glm::dvec3 c(40.0 + 2.0 * i, 3.0, -9.0 + 2.0 * j);
            lamps.push_back({c + glm::dvec3(0.1, 0, 0), c + glm::dvec3(-0.05, 0, -0.0866), c + glm::dvec3(-0.05, 0, 0.0866)});
        }
    lamps.push_back({glm::dvec3(1.75, 2.5, 1.75), glm::dvec3(2.25, 2.5, 1.75), glm::dvec3(2.25, 2.5, 2.25)});  // the room's
    const glm::dvec3 up(0, 1, 0);
    for (const bool wall : {false, true}) {
        SceneBuilder b("far lamps");
        const int black = b.addMaterial(glm::vec3(0.0f), glm::vec3(0.0f), false, "black");
        const int farLamp = b.addMaterial(glm::vec3(0.0f), glm::vec3(100.0f), false, "far lamp");
        const int roomLamp = b.addMaterial(glm::vec3(0.0f), glm::vec3(2.0f), false, "room lamp");
        // A wide black ground (it bounds the lamps' free path to ~3 m: far distance ~17 m), and the lamps, facing down.
        b.addQuad({-200, 0, -200}, {-200, 0, 200}, {200, 0, 200}, {200, 0, -200}, black, "ground");
        for (std::size_t k = 0; k < lamps.size(); ++k) {
            const auto& l = lamps[k];
            const bool down = glm::cross(l[1] - l[0], l[2] - l[0]).y < 0.0;
            b.addTriangles({l[0], down ? l[1] : l[2], down ? l[2] : l[1]}, {{0, 1, 2}}, k + 1 < lamps.size() ? farLamp : roomLamp,
                           "lamp");
        }
        if (wall) b.addQuad({20, 0, -100}, {20, 20, -100}, {20, 20, 100}, {20, 0, 100}, black, "wall");
        const Scene scene = b.build();
        const PatchMesh mesh = subdivide(scene, SubdivisionSettings{1000.0, 1000.0, 0.0});
        const EmbreeScene rays(scene);
        const EmissiveAreaLights lights(mesh, rays, 4);
        ASSERT_GT(lights.farDistanceM(), 10.0);
        ASSERT_LT(lights.farDistanceM(), 30.0);
        auto exactAt = [&](const glm::dvec3& p, std::size_t count) {
            double sum = 0.0;
            for (std::size_t k = 0; k < count; ++k) {
                const glm::dvec3 v[3] = {lamps[k][0], lamps[k][1], lamps[k][2]};
                sum += (k + 1 < lamps.size() ? 100.0 : 2.0) * EmissiveAreaLights::unoccludedFormFactor(p, up, v, 3);
            }
            return sum;
        };
        for (const glm::dvec3 p : {glm::dvec3(1.0, 0.0, 1.0), glm::dvec3(3.5, 0.0, 0.5)}) {
            const glm::dvec3 point[3] = {p, p, p};
            EmissiveAreaLights::ReceiverView view;
            lights.viewFrom(point, up, view);
            EXPECT_FALSE(view.farConstant.empty());
            EXPECT_LT(view.farConstant.size(), 20u) << "the far lamps are cut finely";
            EXPECT_EQ(view.perPoint.size() + view.frontOnly.size() + view.constant.size(), 1u) << "the room's lamp";
            const double roomOnly = exactAt(p, lamps.size()) - exactAt(p, lamps.size() - 1);
            if (wall) {  // the far rays all meet the wall: the room's lamp alone, exactly, whatever the seed
                for (std::uint64_t seed = 1; seed <= 50; ++seed)
                    ASSERT_NEAR(lights.irradianceOverPiAt(p, up, seed, view).x, roomOnly, 1e-12 * roomOnly) << seed;
                continue;
            }
            const auto [mean, standardError] = meanOverSeeds(lights, p, up, view);
            const double exact = exactAt(p, lamps.size());
            std::printf("at (%.1f, %.1f): far lamps %.3g of E, estimated %.6g ± %.2g against %.6g\n", p.x, p.z,
                        1.0 - roomOnly / exact, mean, standardError, exact);
            ASSERT_GT(exact - roomOnly, 1e-3 * exact) << "the far lamps weigh nothing: the test lost its premise";
            EXPECT_NEAR(mean, exact, 4.0 * standardError + 1e-9 * exact);
            EXPECT_GT(standardError, 0.0);
        }
    }
}

// Emitters away from a receiver (≥ kPerPointDistance × their extents) whose planes cross: a lamp reaching below a
// floor element's plane (clipped by it once: the plane is every point's), and a floor element crossing a lamp's
// plane (its front part averaged, for the points in front; those behind see nothing). Against the mean of Lambert's
// formula at 4,096 points of it (zero where a point is behind the lamp).
TEST(EmissiveAreaLights, StraddlingEmittersAwayFromAnElementAreOneValue) {
    const glm::dvec3 up(0, 1, 0);
    const glm::dvec3 receiver[3] = {{-0.25, 0, -0.2}, {0.3, 0, 0.05}, {-0.1, 0, 0.3}};  // crosses z = 0, ≈ 0.3 m radius
    struct Case {
        const char* name;
        std::array<glm::dvec3, 3> lamp;  // emitting side counter-clockwise
    };
    std::vector<Case> cases;
    for (const double d : {2.0, 3.0, 5.0, 10.0}) {
        // Facing −x at x = d, reaching from 0.4 m below the floor's plane to 0.6 m above it.
        cases.push_back({"through the floor's plane", {glm::dvec3(d, -0.4, -0.3), glm::dvec3(d, -0.4, 0.3), glm::dvec3(d, 0.6, 0.0)}});
        // Facing +z in the plane z = 0, which runs through the floor element, 0.2 … 0.8 m above the floor.
        cases.push_back({"its plane through the element", {glm::dvec3(d, 0.2, 0.0), glm::dvec3(d + 0.5, 0.5, 0.0), glm::dvec3(d, 0.8, 0.0)}});
        // Both: facing +z in z = 0, from below the floor's plane.
        cases.push_back({"both", {glm::dvec3(d, -0.3, 0.0), glm::dvec3(d + 0.5, 0.3, 0.0), glm::dvec3(d, 0.5, 0.0)}});
    }
    double worst = 0.0;
    int onePerElement = 0;
    for (const Case& c : cases) {
        const glm::dvec3 normal = glm::normalize(glm::cross(c.lamp[1] - c.lamp[0], c.lamp[2] - c.lamp[0]));
        SceneBuilder b("one lamp");
        b.addTriangles({c.lamp[0], c.lamp[1], c.lamp[2]}, {{0, 1, 2}}, b.addMaterial(glm::vec3(0.0f), glm::vec3(1.0f), false, "lamp"), "lamp");
        b.addQuad({-20, -5, -20}, {-20, -5, 20}, {20, -5, 20}, {20, -5, -20}, b.addMaterial(glm::vec3(0.0f)), "ground");
        const Scene scene = b.build();
        const EmbreeScene rays(scene);
        const EmissiveAreaLights lights(subdivide(scene, SubdivisionSettings{4.0, 2.0, 0.0}), rays, 4);
        ASSERT_EQ(lights.triangleCount(), 1u);
        EmissiveAreaLights::ReceiverView view;
        lights.viewFrom(receiver, up, view);
        const glm::dvec3 v[3] = {c.lamp[0], c.lamp[1], c.lamp[2]};
        // What the points take without a contour of their own: the view's one value, or (the lamp's plane through
        // the element) a value in proportion to their height over that plane in front of it, none behind.
        const bool perPoint = !view.perPoint.empty();
        double exact = 0.0, got = 0.0;
        int points = 0;
        forEachSubTriangleCentroid(64, [&](double wa, double wb) {
            const glm::dvec3 p = wa * receiver[0] + wb * receiver[1] + (1.0 - wa - wb) * receiver[2];
            const bool inFront = glm::dot(p - c.lamp[0], normal) > 0.0;
            const double here = inFront ? EmissiveAreaLights::unoccludedFormFactor(p, up, v, 3) : 0.0;
            exact += here;
            got += perPoint ? here : view.constantUnoccluded.x;
            for (const auto& front : view.frontOnly) got += inFront ? front.formFactorPerM * glm::dot(p - c.lamp[0], normal) : 0.0;
            ++points;
        });
        exact /= points;
        got /= points;
        ASSERT_GT(exact, 0.0) << c.name;
        if (!perPoint && c.lamp[0].x >= 5.0) ++onePerElement;
        const double error = std::abs(got - exact) / exact;
        std::printf("%-32s at x = %4.1f: mean F %.5g, one value %.5g (%+.2e)%s\n", c.name, c.lamp[0].x, exact, got,
                    (got - exact) / exact, perPoint ? " [per point]" : "");
        worst = std::max(worst, error);
    }
    EXPECT_EQ(onePerElement, 6) << "straddling emitters 5 m or more from the element should be one value over it";
    EXPECT_LT(worst, 2e-3);
}

// Two lamps 0.5 m apart, 50 m above a point: one cluster there (one point source). Its shadow rays pick the lamp
// within the cluster by power, and the pdf must say so: a plate hides the bright lamp (9) and leaves the dim one (1),
// so the visible light is the dim lamp's alone; taking the pick as uniform within the cluster would put it at 1/81
// of that.
TEST(EmissiveAreaLights, ShadowRaysPickALampWithinAClusterByItsPower) {
    SceneBuilder b("two lamps far above a point");
    const int black = b.addMaterial(glm::vec3(0.0f), glm::vec3(0.0f), false, "black");
    const int dim = b.addMaterial(glm::vec3(0.0f), glm::vec3(1.0f), false, "dim");
    const int bright = b.addMaterial(glm::vec3(0.0f), glm::vec3(9.0f), false, "bright");
    auto lampAt = [](double x) {  // counter-clockwise seen from below: emits downwards
        return std::array<glm::dvec3, 3>{glm::dvec3(x + 0.1, 50, 0), glm::dvec3(x - 0.05, 50, 0.0866), glm::dvec3(x - 0.05, 50, -0.0866)};
    };
    const auto dimLamp = lampAt(-0.25), brightLamp = lampAt(0.25);
    ASSERT_LT(glm::cross(dimLamp[1] - dimLamp[0], dimLamp[2] - dimLamp[0]).y, 0.0);
    b.addTriangles({dimLamp[0], dimLamp[1], dimLamp[2]}, {{0, 1, 2}}, dim, "dim lamp");
    b.addTriangles({brightLamp[0], brightLamp[1], brightLamp[2]}, {{0, 1, 2}}, bright, "bright lamp");
    b.addQuad({0.05, 49, -0.3}, {0.6, 49, -0.3}, {0.6, 49, 0.3}, {0.05, 49, 0.3}, black, "plate under the bright lamp");
    // The point lies on a floor, as receivers do: the rays' float precision is set by the scene's size.
    b.addQuad({-30, 0, -30}, {-30, 0, 30}, {30, 0, 30}, {30, 0, -30}, black, "floor");
    const Scene scene = b.build();
    const EmbreeScene rays(scene);
    const EmissiveAreaLights lights(subdivide(scene, SubdivisionSettings{1.0, 0.5, 0.0}), rays, 1024);
    ASSERT_EQ(lights.triangleCount(), 2u);
    const glm::dvec3 p(0.0), up(0, 1, 0);
    EmissiveAreaLights::ReceiverView view;
    const glm::dvec3 point[3] = {p, p, p};
    lights.viewFrom(point, up, view);
    ASSERT_EQ(view.perPoint.size() + view.constant.size(), 1u) << "the two lamps are no longer one cluster";
    const glm::dvec3 v[3] = {dimLamp[0], dimLamp[1], dimLamp[2]};
    const double exact = EmissiveAreaLights::unoccludedFormFactor(p, up, v, 3);  // the dim lamp's, L = 1
    const double got = lights.irradianceOverPiAt(p, up, 5).x;
    std::printf("visible: %.5g (the dim lamp's %.5g)\n", got, exact);
    EXPECT_NEAR(got / exact, 1.0, 0.01);
}

// The limit on ray-traced emitters counts input triangles, and the solve decides it once, before subdividing, where
// it sizes emitter patches. An emitting floor crossed by a closed block is cut along the block into more light triangles than it
// has input triangles; counted after the cut, the same limit sent its emitters through rows (from patches sized for
// rays) while the solve had assumed rays.
TEST(EmissiveAreaLights, EmittersCutAlongASolidStayRayTracedAtTheirInputTriangleLimit) {
    SceneBuilder b("emitting floor through a block");
    const int lamp = b.addMaterial(glm::vec3(0.5f), glm::vec3(1.0f), false, "lamp");
    const int grey = b.addMaterial(glm::vec3(0.5f), glm::vec3(0.0f), false, "grey");
    b.addQuad({0, 0, 0}, {0, 0, 2}, {2, 0, 2}, {2, 0, 0}, lamp, "emitting floor");
    b.addBox({0.5, -0.5, 0.5}, {1.1, 0.5, 1.1}, grey, false, "block");
    const Scene scene = b.build();
    SolveSettings s;
    s.subdivision = {1.0, 0.5, 0.0};
    s.solver.hemicubeResolution = 32;
    s.lighting.emitters = EmitterLighting::Rays;
    s.lighting.maxRayTracedEmitters = 2;  // the floor's two input triangles
    const EmbreeScene rays(scene);
    const auto solved = solveScene(scene, s, rays);
    const EmissiveAreaLights lights(solved->mesh, rays, 16);
    EXPECT_EQ(lights.inputTriangleCount(), 2u);
    ASSERT_GT(lights.triangleCount(), 2u) << "the block no longer cuts the floor: the test lost its premise";
    EXPECT_TRUE(solved->report.emittersByRays);
    EXPECT_EQ(solved->report.emitterTrianglesNearOneReceiver, 2u);
    s.lighting.maxRayTracedEmitters = 1;
    const auto shooting = solveScene(scene, s, rays);
    EXPECT_FALSE(shooting->report.emittersByRays);
    EXPECT_GT(shooting->mesh.patches.size(), solved->mesh.patches.size()) << "fallback emitters not on finer patches";
}

// The limit counts the emitter triangles near one receiver, not the level's: lamps (two triangles each) 100 m apart
// along a row are two at a time within any block of cells 4 element sizes wide, however many the row holds; a block
// wide enough to hold several holds exactly as many as fall in its three cells; no element size counts them all.
TEST(EmissiveAreaLights, EmitterLimitCountsTheTrianglesNearOneReceiver) {
    SceneBuilder b("a row of lamps");
    const int lamp = b.addMaterial(glm::vec3(0.5f), glm::vec3(1.0f), false, "lamp");
    const int twoSided = b.addMaterial(glm::vec3(0.5f), glm::vec3(1.0f), true, "two-sided lamp");
    for (int i = 0; i < 50; ++i) {
        const double x = 100.0 * i + 10.0;
        b.addQuad({x, 3, 0}, {x + 0.5, 3, 0}, {x + 0.5, 3, 0.5}, {x, 3, 0.5}, i == 7 ? twoSided : lamp, "lamp");
    }
    const Scene scene = b.build();
    EXPECT_EQ(emitterTrianglesNearOneReceiver(scene, 1.0), 4u);   // cells of 4 m: the two-sided lamp, 2 × 2
    EXPECT_EQ(emitterTrianglesNearOneReceiver(scene, 0.0), 102u);  // one block: every lamp, the two-sided one twice
    // Cells of 400 m hold four lamps each (x = 10, 110, 210, 310 in the first); the block about the cell of lamps
    // 4–7 holds lamps 0–11 with lamp 7's two sides: 13 × 2.
    EXPECT_EQ(emitterTrianglesNearOneReceiver(scene, 100.0), 26u);
    // The same scene 100 km from the origin (cells counted in whole steps far from zero): the same count.
    SceneBuilder far("the row of lamps 100 km away");
    const int farLamp = far.addMaterial(glm::vec3(0.5f), glm::vec3(1.0f), false, "lamp");
    for (int i = 0; i < 50; ++i) {
        const double x = 100.0 * i + 10.0 + 1e5;
        far.addQuad({x, 3, 1e5}, {x + 0.5, 3, 1e5}, {x + 0.5, 3, 1e5 + 0.5}, {x, 3, 1e5 + 0.5}, farLamp, "lamp");
    }
    EXPECT_EQ(emitterTrianglesNearOneReceiver(far.build(), 1.0), 2u);
}

// A densely tessellated emitting panel (a 12 × 12 grid of quads, 288 triangles) over a floor is what the limit
// guards: over it, the solve shoots the emitters and says why; a row of lamps with as many triangles in all, 50 m
// apart (the first over the floor), stays ray traced.
TEST(EmissiveAreaLights, DenseEmitterFallsBackWhereALevelsLampsDoNot) {
    SolveSettings s;
    s.subdivision = {1.0, 0.5, 0.0};
    s.solver.hemicubeResolution = 32;
    s.lighting.emitters = EmitterLighting::Rays;
    s.lighting.maxRayTracedEmitters = 100;
    auto floorWith = [](bool dense) {
        SceneBuilder b(dense ? "dense panel" : "row of lamps");
        const int lamp = b.addMaterial(glm::vec3(0.5f), glm::vec3(1.0f), false, "lamp");
        const int grey = b.addMaterial(glm::vec3(0.5f), glm::vec3(0.0f), false, "grey");
        b.addQuad({-1, 0, -1}, {-1, 0, 2}, {2, 0, 2}, {2, 0, -1}, grey, "floor");
        for (int i = 0; i < 144; ++i) {
            const double x = dense ? 0.1 * (i % 12) : 50.0 * i, z = dense ? 0.1 * (i / 12) : 0.0;
            b.addQuad({x, 2, z}, {x + 0.1, 2, z}, {x + 0.1, 2, z + 0.1}, {x, 2, z + 0.1}, lamp, "lamp");  // facing down
        }
        return b.build();
    };
    const Scene dense = floorWith(true), row = floorWith(false);
    const EmbreeScene denseRays(dense), rowRays(row);
    const auto panel = solveScene(dense, s, denseRays);
    EXPECT_EQ(panel->report.emitterTrianglesNearOneReceiver, 288u);
    EXPECT_FALSE(panel->report.emittersByRays);
    const auto lamps = solveScene(row, s, rowRays);
    EXPECT_EQ(lamps->report.emitterTrianglesNearOneReceiver, 2u);
    EXPECT_TRUE(lamps->report.emittersByRays);
}

// A level's far lamps as the level grows (a sheet of ceiling lamps from 10 × 10 to 60 × 60, 2 m apart, all beyond
// the far distance): the receiver's far cut stays within its cap (on 10 copies of a level the error budget alone
// took 72.9 entries an element against 22.8 on one, and the element's view cost 17.7 against 5.4 µs), and the far
// light stays unbiased with the coarser cut (Σ f/pdf: the cut only shapes where the rays go).
TEST(EmissiveAreaLights, FarCutStaysBoundedAsTheLevelGrows) {
    // A wall facing +z at the sheet's middle: every large cluster of the sheet straddles its plane, and a straddling
    // cluster's error bound is its whole weight, so the budget alone splits them down to single lamps.
    const glm::dvec3 facing(0, 0, 1);
    for (const int side : {10, 30, 60}) {
        std::vector<std::array<glm::dvec3, 3>> lamps;
        for (int i = 0; i < side; ++i)
            for (int j = 0; j < side; ++j) {
                const glm::dvec3 c(30.0 + 2.0 * i, 3.0, -double(side) + 2.0 * j);
                lamps.push_back({c + glm::dvec3(0.1, 0, 0), c + glm::dvec3(-0.05, 0, 0.0866), c + glm::dvec3(-0.05, 0, -0.0866)});
            }
        lamps.push_back({glm::dvec3(1.75, 2.5, 1.75), glm::dvec3(2.25, 2.5, 1.75), glm::dvec3(2.25, 2.5, 2.25)});  // the room's
        SceneBuilder b("far lamps");
        const int black = b.addMaterial(glm::vec3(0.0f), glm::vec3(0.0f), false, "black");
        const int farLamp = b.addMaterial(glm::vec3(0.0f), glm::vec3(100.0f), false, "far lamp");
        const int roomLamp = b.addMaterial(glm::vec3(0.0f), glm::vec3(2.0f), false, "room lamp");
        b.addQuad({-300, 0, -300}, {-300, 0, 300}, {300, 0, 300}, {300, 0, -300}, black, "ground");
        for (std::size_t k = 0; k < lamps.size(); ++k)
            b.addTriangles({lamps[k][0], lamps[k][1], lamps[k][2]}, {{0, 1, 2}}, k + 1 < lamps.size() ? farLamp : roomLamp, "lamp");
        const Scene scene = b.build();
        const PatchMesh mesh = subdivide(scene, SubdivisionSettings{1000.0, 1000.0, 0.0});
        const EmbreeScene rays(scene);
        const EmissiveAreaLights lights(mesh, rays, 4);
        ASSERT_LT(lights.farDistanceM(), 25.0) << "the lamps are not far: the test lost its premise";
        const glm::dvec3 p(1.0, 1.5, 0.5);
        const glm::dvec3 point[3] = {p, p, p};
        EmissiveAreaLights::ReceiverView view;
        lights.viewFrom(point, facing, view);
        // kMaxFarClusters = 32 entries; the budget alone took 10, 27 and 35 here.
        EXPECT_LE(view.farConstant.size(), 32u) << side << " × " << side << " lamps";
        double exact = 0.0;
        for (std::size_t k = 0; k < lamps.size(); ++k) {
            const glm::dvec3 v[3] = {lamps[k][0], lamps[k][1], lamps[k][2]};
            exact += (k + 1 < lamps.size() ? 100.0 : 2.0) * EmissiveAreaLights::unoccludedFormFactor(p, facing, v, 3);
        }
        const auto [mean, standardError] = meanOverSeeds(lights, p, facing, view);
        std::printf("%d x %d far lamps: far cut %zu, estimated %.6g ± %.2g against %.6g\n", side, side,
                    view.farConstant.size(), mean, standardError, exact);
        EXPECT_NEAR(mean, exact, 4.0 * standardError + 1e-9 * exact) << side;
    }
}
