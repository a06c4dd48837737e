// Patches and elements: conforming bisection preserves area, bounds edge lengths, and keeps each patch's
// elements contiguous; emitters are finer; double-sided surfaces get a back copy.
#include <set>

#include <gtest/gtest.h>

#include "mesh/errors.h"
#include "mesh/scene_builder.h"
#include "mesh/subdivision.h"

using namespace hemibake;

namespace {

double maxEdge(const PatchMesh& pm, std::size_t e) {
    const auto& t = pm.elements.triangles[e];
    const auto& v = pm.elements.vertices;
    return std::max({glm::length(v[t[0]] - v[t[1]]), glm::length(v[t[1]] - v[t[2]]), glm::length(v[t[2]] - v[t[0]])});
}

Scene roomWithLamp(bool lampDoubleSided = false, glm::dvec3 offset = glm::dvec3(0.0)) {
    SceneBuilder b("room");
    const int white = b.addMaterial(glm::vec3(0.7f));
    const int lamp = b.addMaterial(glm::vec3(0.5f), glm::vec3(10.0f), lampDoubleSided);
    b.addBox(offset + glm::dvec3(0, 0, 0), offset + glm::dvec3(2, 1, 3), white, true);
    b.addQuad(offset + glm::dvec3(0.8, 0.99, 1.2), offset + glm::dvec3(1.2, 0.99, 1.2),
              offset + glm::dvec3(1.2, 0.99, 1.8), offset + glm::dvec3(0.8, 0.99, 1.8), lamp, "lamp");
    return b.build();
}

}  // namespace

TEST(Subdivision, AreaPreservedAndEdgesBounded) {
    const Scene scene = roomWithLamp();
    SubdivisionSettings s;
    s.patchSizeM = 0.5;
    s.elementSizeM = 0.125;
    const PatchMesh pm = subdivide(scene, s);
    double area = 0.0;
    for (std::size_t e = 0; e < pm.elements.size(); ++e) {
        area += pm.elements.areaM2[e];
        EXPECT_LE(maxEdge(pm, e), s.elementSizeM * (1 + 1e-6));  // the documented split tolerance
    }
    EXPECT_NEAR(area, scene.surfaceAreaM2(), 1e-9 * area);
    double patchArea = 0.0;
    for (std::size_t p = 0; p < pm.patches.size(); ++p) patchArea += pm.patches.areaM2[p];
    EXPECT_NEAR(patchArea, area, 1e-9 * area);
}

TEST(Subdivision, PatchesOwnContiguousElementRuns) {
    const PatchMesh pm = subdivide(roomWithLamp(), {0.5, 0.125, 0.0});
    std::size_t expectedFirst = 0;
    for (std::size_t p = 0; p < pm.patches.size(); ++p) {
        EXPECT_EQ(pm.patches.firstElement[p], expectedFirst);
        ASSERT_GT(pm.patches.elementCount[p], 0u);
        double sum = 0.0;
        for (std::uint32_t e = pm.patches.firstElement[p]; e < pm.patches.firstElement[p] + pm.patches.elementCount[p]; ++e) {
            EXPECT_EQ(pm.elements.patch[e], p);
            EXPECT_GT(glm::dot(pm.elements.normal[e], pm.patches.normal[p]), 0.999f);
            sum += pm.elements.areaM2[e];
        }
        EXPECT_NEAR(sum, pm.patches.areaM2[p], 1e-12 * sum);
        expectedFirst += pm.patches.elementCount[p];
    }
    EXPECT_EQ(expectedFirst, pm.elements.size());
}

TEST(Subdivision, EmittersAreSubdividedFiner) {
    SubdivisionSettings s{0.5, 0.125, 0.0};
    const PatchMesh pm = subdivide(roomWithLamp(), s);
    double largestEmitterPatch = 0.0, largestOtherPatch = 0.0;
    for (std::size_t p = 0; p < pm.patches.size(); ++p) {
        const bool emitter = pm.patches.emittedRadiance[p].x > 0.0f;
        (emitter ? largestEmitterPatch : largestOtherPatch) =
            std::max(emitter ? largestEmitterPatch : largestOtherPatch, pm.patches.areaM2[p]);
    }
    // Patch size /4 ⇒ emitter patches at most (0.125)²/2 m² (right triangles of that leg length).
    EXPECT_LE(largestEmitterPatch, 0.125 * 0.125 / 2 * (1 + 1e-5));
    EXPECT_GT(largestOtherPatch, largestEmitterPatch);
}

TEST(Subdivision, DoubleSidedSurfacesGetABackCopy) {
    const PatchMesh single = subdivide(roomWithLamp(false), {0.5, 0.125, 0.0});
    const PatchMesh both = subdivide(roomWithLamp(true), {0.5, 0.125, 0.0});
    std::size_t lampFront = 0, lampBack = 0;
    for (std::size_t e = 0; e < both.elements.size(); ++e) {
        if (both.elements.emittedRadiance[e].x == 0.0f) continue;
        if (both.elements.backSide[e]) {
            ++lampBack;
            EXPECT_NEAR(both.elements.normal[e].y, 1.0f, 1e-6f);
        } else {
            ++lampFront;
            EXPECT_NEAR(both.elements.normal[e].y, -1.0f, 1e-6f);
        }
    }
    EXPECT_GT(lampFront, 0u);
    EXPECT_EQ(lampFront, lampBack);
    EXPECT_EQ(both.elements.size(), single.elements.size() + lampBack);
}

TEST(Subdivision, FarFromOriginKeepsGeometry) {
    const glm::dvec3 far(1e5, -2e5, 3e5);
    const PatchMesh near = subdivide(roomWithLamp(), {0.5, 0.125, 0.0});
    const PatchMesh away = subdivide(roomWithLamp(false, far), {0.5, 0.125, 0.0});
    ASSERT_EQ(near.elements.size(), away.elements.size());
    for (std::size_t e = 0; e < near.elements.size(); ++e) {
        EXPECT_NEAR(away.elements.areaM2[e], near.elements.areaM2[e], 1e-9);
        EXPECT_NEAR(glm::length(away.elements.centroid[e] - far - near.elements.centroid[e]), 0.0, 1e-9);
    }
    EXPECT_NEAR(glm::length(away.origin - far - near.origin), 0.0, 1e-9);
}

TEST(Subdivision, InvalidSettingsAreRejected) {
    EXPECT_THROW(subdivide(roomWithLamp(), {0.0, 0.1, 0.0}), std::invalid_argument);
    EXPECT_THROW(subdivide(roomWithLamp(), {0.5, -1.0, 0.0}), std::invalid_argument);
}

// Two squares of different sizes sharing part of an edge at a right angle: without conforming, each side's
// bisection vertices would fall mid-edge on the other (T-junctions).
TEST(Subdivision, TouchingBoundariesConform) {
    SceneBuilder b("corner");
    const int m = b.addMaterial(glm::vec3(0.5f));
    b.addQuad({0, 0, 0}, {0, 0, 3}, {3, 0, 3}, {3, 0, 0}, m, "floor 3 m");   // edge x = 0 spans z ∈ [0, 3]
    b.addQuad({0, 0, 0}, {0, 1, 0}, {0, 1, 2}, {0, 0, 2}, m, "wall 2 m");    // edge y = 0 spans z ∈ [0, 2]
    const PatchMesh pm = subdivide(b.build(), {0.7, 0.7, 0.0});
    // Every vertex on the shared line (x = 0, y = 0, z ≤ 2) must be a vertex of both instances.
    std::set<long> zOf[2];
    for (std::size_t e = 0; e < pm.elements.size(); ++e)
        for (std::uint32_t v : pm.elements.triangles[e]) {
            const glm::dvec3& p = pm.elements.vertices[v];
            if (std::abs(p.x) < 1e-12 && std::abs(p.y) < 1e-12 && p.z <= 2.0 + 1e-12)
                zOf[pm.elements.instance[e]].insert(std::lround(p.z * 1e9));
        }
    EXPECT_GT(zOf[0].size(), 2u);
    EXPECT_EQ(zOf[0], zOf[1]);
}

// A 100 km floor at `hemibake info`'s default 5 cm elements needs 10¹³ of them: it used to bisect until the process
// was killed for its memory. Element indices are 32-bit; more than they hold is an error before any bisection.
TEST(Subdivision, MoreElementsThanAnIndexHoldsIsAnError) {
    SceneBuilder b("level.gltf");
    const int m = b.addMaterial(glm::vec3(0.5f));
    b.addQuad({0, 0, 0}, {0, 0, 1e5}, {1e5, 0, 1e5}, {1e5, 0, 0}, m, "floor");
    const Scene scene = b.build();
    SubdivisionSettings s;  // 0.25 m patches, 0.05 m elements
    try {
        subdivide(scene, s);
        FAIL() << "expected an InputError";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("level.gltf: subdividing at element size 0.05 m (patch size 0.25 m) needs at least "
                                              "9.2376e+12 elements, more than hemibake can index (4294967295)", 0), 0u)
            << e.what();
    }
    EXPECT_THROW(countSubdivision(scene, s), InputError);
    s.patchSizeM = s.elementSizeM = 1000.0;  // at least 23,000 elements: fine
    EXPECT_GE(subdivide(scene, s).elements.size(), 23'000u);
}

// A sliver whose apex lies within the boundary tolerance (1e-7 of the scene's diagonal) of its own base edge, as the
// mesh fuzzer found (tests/fuzz/corpus_unwrap): mending T-junctions used to split the base at the apex, leaving two
// faces of no area, a patch of no area that was skipped and elements naming that missing patch.
TEST(Subdivision, SliverWithItsApexOnItsOwnBoundaryEdgeKeepsItsArea) {
    SceneBuilder b("sliver");
    const int m = b.addMaterial(glm::vec3(0.5f));
    b.addQuad({0, 0, 0}, {0, 0, 10}, {10, 0, 10}, {10, 0, 0}, m, "floor");  // diagonal ≈ 14 m: tolerance 1.4 µm
    b.addTriangles({{0, 1, 0}, {1, 1, 0}, {0.5, 1, 1e-7}}, {{0, 1, 2}}, m, "sliver 0.1 µm high");
    const Scene scene = b.build();
    ASSERT_EQ(scene.triangleCount(), 3u);
    const PatchMesh pm = subdivide(scene, {20.0, 20.0, 0.0});
    double sliverArea = 0.0;
    for (std::size_t e = 0; e < pm.elements.size(); ++e) {
        ASSERT_LT(pm.elements.patch[e], pm.patches.size());
        if (pm.elements.instance[e] == 1) sliverArea += pm.elements.areaM2[e];
    }
    EXPECT_NEAR(sliverArea, 0.5 * 1e-7, 1e-3 * 0.5 * 1e-7);
    for (std::size_t p = 0; p < pm.patches.size(); ++p) EXPECT_GT(pm.patches.areaM2[p], 0.0);
}
