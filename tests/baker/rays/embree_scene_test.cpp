// EmbreeScene: hits name the right instance/face at the right distance, thin walls occlude, segment ends on
// surfaces do not self-occlude, and a scene 1e5 m from the origin answers exactly like one at the origin.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <span>
#include <limits>
#include <thread>
#include <vector>

#include "baker/rays/embree_scene.h"
#include "mesh/scene_builder.h"

using namespace hemibake;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Instance 0: unit quad at z = 0 facing +z; instance 1: a 2 m quad at z = -2 facing +z;
// instance 2: a 1 mm thick solid wall (6 quads, instances 2..7) between x = 3 and x = 5.
Scene testScene(const glm::dvec3& offset) {
    SceneBuilder b("embree");
    const int grey = b.addMaterial(glm::vec3(0.5f));
    auto at = [&](double x, double y, double z) { return offset + glm::dvec3(x, y, z); };
    b.addQuad(at(0, 0, 0), at(1, 0, 0), at(1, 1, 0), at(0, 1, 0), grey, "near");
    b.addQuad(at(-1, -1, -2), at(1, -1, -2), at(1, 1, -2), at(-1, 1, -2), grey, "far");
    b.addBox(at(3, 0, -1), at(5, 2, -0.999), grey, false, "wall");
    return b.build();
}

// 1,000 unit directions spread over the sphere (Fibonacci).
std::vector<glm::dvec3> sphereDirections() {
    std::vector<glm::dvec3> dirs;
    for (int i = 0; i < 1000; ++i) {
        const double z = 1.0 - (i + 0.5) / 500.0, r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = i * 2.399963229728653;
        dirs.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
    }
    return dirs;
}

}  // namespace

TEST(EmbreeScene, HitReportsInstanceFaceDistanceAndSide) {
    const Scene scene = testScene(glm::dvec3(0.0));
    const EmbreeScene rays(scene);

    // addQuad splits p0 p1 p2 | p0 p2 p3: (0.25, 0.75) lies in the second triangle, (0.75, 0.25) in the first.
    auto hit = rays.intersect({0.25, 0.75, 5.0}, {0, 0, -2.0}, kInf);  // a non-unit direction: distances stay metres
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->instance, 0u);
    EXPECT_EQ(hit->face, 1u);
    EXPECT_NEAR(hit->distanceM, 5.0, 1e-6);
    EXPECT_NEAR(glm::length(hit->position - glm::dvec3(0.25, 0.75, 0.0)), 0.0, 1e-6);
    EXPECT_NEAR(glm::length(hit->geometricNormal - glm::dvec3(0, 0, 1)), 0.0, 1e-12);
    EXPECT_TRUE(hit->frontFacing);

    hit = rays.intersect({0.75, 0.25, -0.5}, {0, 0, 1}, kInf);  // from below: the back of the first triangle
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->instance, 0u);
    EXPECT_EQ(hit->face, 0u);
    EXPECT_NEAR(hit->distanceM, 0.5, 1e-6);
    EXPECT_FALSE(hit->frontFacing);

    hit = rays.intersect({-0.5, 0.5, 3.0}, {0, 0, -1}, kInf);  // misses the near quad, lands on the far one
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->instance, 1u);
    EXPECT_NEAR(hit->distanceM, 5.0, 1e-6);

    EXPECT_FALSE(rays.intersect({0.25, 0.75, 5.0}, {0, 0, -1}, 4.9));  // tMax before the surface
    EXPECT_FALSE(rays.occludedRay({0.25, 0.75, 5.0}, {0, 0, -1}, 4.9));
    EXPECT_TRUE(rays.occludedRay({0.25, 0.75, 5.0}, {0, 0, -1}, 5.1));
    EXPECT_FALSE(rays.intersect({-5, -5, 5.0}, {0, 0, -1}, kInf));  // misses everything
    EXPECT_THROW(rays.intersect({0, 0, 0}, {0, 0, 0}, kInf), std::invalid_argument);
}

TEST(EmbreeScene, MillimetreWallOccludesAndEndpointsDoNotSelfOcclude) {
    const Scene scene = testScene(glm::dvec3(0.0));
    const EmbreeScene rays(scene);
    ASSERT_LT(2.0 * rays.rayEpsilonM(), 1e-3);  // the epsilon must be far below the wall's thickness

    // Through the wall, including exactly along the diagonal shared by each face's two triangles.
    for (double t : {0.1, 0.5, 0.77, 1.0, 1.5})
        EXPECT_TRUE(rays.occluded({3.0 + t, t, -1.5}, {3.0 + t, t, -0.5})) << t;
    EXPECT_FALSE(rays.occluded({2.5, 1.0, -1.5}, {2.5, 1.0, -0.5}));  // beside it

    // From a point on the wall's front face (z = -0.999): the open side is clear, the back face (1 mm away) is not.
    const glm::dvec3 onFront(4.0, 1.0, -0.999);
    EXPECT_FALSE(rays.occluded(onFront, {4.0, 1.0, 0.5}));
    EXPECT_FALSE(rays.occluded(onFront, {4.3, 1.2, 0.5}));
    EXPECT_TRUE(rays.occluded(onFront, {4.0, 1.0, -1.5}));
    EXPECT_TRUE(rays.occluded(rays.offsetFromSurface(onFront, {0, 0, 1}), {4.0, 1.0, -1.5}));
    // The segment between the two faces, 1 mm long, ends on both and crosses nothing.
    EXPECT_FALSE(rays.occluded(onFront, {4.0, 1.0, -1.0}));
}

TEST(EmbreeScene, LiftedEndsSeeSurfacesCloserThanTheEpsilon) {
    const Scene scene = testScene(glm::dvec3(0.0));
    const EmbreeScene rays(scene);
    // 5 µm in front of the wall's front face (z = -0.999), well inside rayEpsilonM().
    const glm::dvec3 p(4.0, 1.0, -0.999 + 5e-6);
    ASSERT_GT(rays.rayEpsilonM(), 5e-6);
    const auto hit = rays.intersect(p, {0, 0, -1}, kInf, EmbreeScene::RayEnds::Lifted);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->distanceM, 5e-6, 1e-6);
    EXPECT_TRUE(hit->frontFacing);
    EXPECT_NEAR(hit->position.z, -0.999, 1e-9);
    // The skipped default start passes the front face and stops at the back face, 1 mm further.
    const auto skipped = rays.intersect(p, {0, 0, -1}, kInf);
    ASSERT_TRUE(skipped);
    EXPECT_FALSE(skipped->frontFacing);
    EXPECT_TRUE(rays.occluded(p, {4.0, 1.0, -0.999 - 5e-6}, EmbreeScene::RayEnds::Lifted));
    // Lifted ends exclude nothing, so a lifted point is never hidden by the surface it was lifted from.
    EXPECT_FALSE(rays.occluded(rays.offsetFromSurface({4.0, 1.0, -0.999}, {0, 0, 1}), {4.9, 1.9, 0.5}, EmbreeScene::RayEnds::Lifted));
}

TEST(EmbreeScene, SceneFarFromOriginGivesTheSameHits) {
    const glm::dvec3 offset(1e5, -1e5, 1e5);
    const Scene nearScene = testScene(glm::dvec3(0.0));
    const Scene farScene = testScene(offset);
    const EmbreeScene nearRays(nearScene), farRays(farScene);
    EXPECT_NEAR(glm::length(farRays.origin() - nearRays.origin() - offset), 0.0, 1e-9);

    const glm::dvec3 origins[] = {{0.25, 0.75, 5.0}, {0.7, 0.2, 5.0}, {-0.5, 0.5, 3.0}, {4.0, 1.0, 2.0}, {3.9, 0.3, 0.0}};
    const glm::dvec3 dirs[] = {{0, 0, -1}, {0.01, 0.02, -1}, {0.1, -0.05, -1}, {0, 0, -1}, {0.2, 0.1, -1}};
    for (int i = 0; i < 5; ++i) {
        const auto a = nearRays.intersect(origins[i], dirs[i], kInf);
        const auto b = farRays.intersect(origins[i] + offset, dirs[i], kInf);
        ASSERT_TRUE(a) << i;
        ASSERT_TRUE(b) << i;
        EXPECT_EQ(a->instance, b->instance) << i;
        EXPECT_EQ(a->face, b->face) << i;
        EXPECT_NEAR(a->distanceM, b->distanceM, 1e-6) << i;
        EXPECT_NEAR(glm::length(b->position - offset - a->position), 0.0, 1e-6) << i;
        EXPECT_EQ(a->frontFacing, b->frontFacing) << i;
    }
    // The 1 mm wall still occludes (in world float, 1e5 m has a 7.8 mm step and the wall would collapse).
    EXPECT_TRUE(farRays.occluded(offset + glm::dvec3(4.0, 1.0, -1.5), offset + glm::dvec3(4.0, 1.0, -0.5)));
    EXPECT_FALSE(farRays.occluded(offset + glm::dvec3(4.0, 1.0, -0.999), offset + glm::dvec3(4.0, 1.0, 0.5)));
    EXPECT_TRUE(farRays.occluded(offset + glm::dvec3(4.0, 1.0, -0.999), offset + glm::dvec3(4.0, 1.0, -1.5)));
}

TEST(EmbreeScene, ConcurrentQueriesAgreeWithSerialOnes) {
    const Scene scene = testScene(glm::dvec3(0.0));
    const EmbreeScene rays(scene);
    std::vector<int> serial(4096), parallel(4096);
    auto query = [&](int i) {
        const glm::dvec3 o(-1.0 + 6.0 * (i % 64) / 63.0, -0.5 + 2.5 * (i / 64) / 63.0, 3.0);
        const auto hit = rays.intersect(o, {0.0, 0.0, -1.0}, kInf);
        return hit ? int(hit->instance * 16 + hit->face) : -1;
    };
    for (int i = 0; i < 4096; ++i) serial[std::size_t(i)] = query(i);
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t)
        threads.emplace_back([&, t] {
            for (int i = t; i < 4096; i += 4) parallel[std::size_t(i)] = query(i);
        });
    for (auto& th : threads) th.join();
    EXPECT_EQ(serial, parallel);
    EXPECT_GT(std::count_if(serial.begin(), serial.end(), [](int v) { return v >= 0; }), 1000);
}

// countOccluded traces packets of 16: ray by ray it must answer what occludedRay does, for any count (not a multiple
// of 16 included), both ray-end conventions and a finite tMax, near the origin and 1e5 m from it.
TEST(EmbreeScene, PacketOcclusionCountsWhatSingleRaysSee) {
    for (const glm::dvec3 offset : {glm::dvec3(0.0), glm::dvec3(1e5, -1e5, 1e5)}) {
        const Scene scene = testScene(offset);
        const EmbreeScene rays(scene);
        const std::vector<glm::dvec3> dirs = sphereDirections();
        const glm::dvec3 origins[] = {offset + glm::dvec3(0.5, 0.5, 1.0), rays.offsetFromSurface(offset + glm::dvec3(0.5, 0.5, 0.0), {0, 0, 1}),
                                      offset + glm::dvec3(4.0, 1.0, -0.5)};
        for (const glm::dvec3& o : origins)
            for (const auto ends : {EmbreeScene::RayEnds::OnSurface, EmbreeScene::RayEnds::Lifted})
                for (const double tMax : {kInf, 2.5})
                    for (const std::size_t count : {std::size_t(1000), std::size_t(37), std::size_t(0)}) {
                        const std::span<const glm::dvec3> some(dirs.data(), count);
                        std::size_t single = 0;
                        for (const glm::dvec3& d : some) single += rays.occludedRay(o, d, tMax, ends) ? 1 : 0;
                        EXPECT_EQ(rays.countOccluded(o, some, tMax, ends), single) << "count " << count << " tMax " << tMax;
                        if (count == 1000 && tMax == kInf) {
                            EXPECT_GT(single, 50u);  // each origin sees occluders (77 at least)
                        }
                    }
    }
}

// intersectSides traces packets of 16: ray by ray it must find what intersect does (hit or not, instance, distance,
// side), for counts not a multiple of 16, both ray-end conventions and a finite tMax, near the origin and 1e5 m from
// it; and it refuses a result span of the wrong size.
TEST(EmbreeScene, PacketHitSidesAreWhatSingleRaysHit) {
    for (const glm::dvec3 offset : {glm::dvec3(0.0), glm::dvec3(1e5, -1e5, 1e5)}) {
        const Scene scene = testScene(offset);
        const EmbreeScene rays(scene);
        const std::vector<glm::dvec3> dirs = sphereDirections();
        const glm::dvec3 origins[] = {offset + glm::dvec3(0.5, 0.5, 1.0), rays.offsetFromSurface(offset + glm::dvec3(0.5, 0.5, 0.0), {0, 0, 1}),
                                      offset + glm::dvec3(4.0, 1.0, -0.5), offset + glm::dvec3(0.5, 0.5, -1.0)};  // the last under "near"
        std::size_t hits = 0, backs = 0;
        for (const glm::dvec3& o : origins)
            for (const auto ends : {EmbreeScene::RayEnds::OnSurface, EmbreeScene::RayEnds::Lifted})
                for (const double tMax : {kInf, 2.5})
                    for (const std::size_t count : {std::size_t(1000), std::size_t(37), std::size_t(0)}) {
                        const std::span<const glm::dvec3> some(dirs.data(), count);
                        std::vector<HitSide> sides(count);
                        rays.intersectSides(o, some, tMax, ends, sides);
                        for (std::size_t k = 0; k < count; ++k) {
                            const std::optional<Hit> hit = rays.intersect(o, some[k], tMax, ends);
                            ASSERT_EQ(sides[k].hit, hit.has_value()) << "ray " << k << " of " << count;
                            if (!hit) continue;
                            EXPECT_EQ(sides[k].instance, hit->instance);
                            EXPECT_EQ(sides[k].distanceM, hit->distanceM);
                            EXPECT_EQ(sides[k].frontFacing, hit->frontFacing);
                            ++hits;
                            backs += hit->frontFacing ? 0 : 1;
                        }
                    }
        EXPECT_GT(hits, 1000u);
        EXPECT_GT(backs, 50u);  // both sides are met
        std::vector<HitSide> tooFew(3);
        EXPECT_THROW(rays.intersectSides(origins[0], dirs, kInf, EmbreeScene::RayEnds::OnSurface, tooFew), std::invalid_argument);
    }
}
