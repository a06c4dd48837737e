// ElementRayScene into the input's faces (each hit's element found inside its face) against the elements' own BVH:
// the same element, side and distance for every ray, on a scene with what the faces way must get right: a floor cut
// along a block sunk into it (the buried part has no element: a ray there goes on), a double-sided panel (the side
// facing the ray), single-sided faces seen from behind (a Back hit), and elements of every size from refinement.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "baker/rays/element_ray_scene.h"
#include "baker/rays/embree_scene.h"
#include "mesh/scene_builder.h"
#include "mesh/subdivision.h"
#include "support/test_meshes.h"

using namespace hemibake;
using hemibake::test::addSolidBox;

namespace {

Scene cutScene() {
    SceneBuilder b("faces");
    const int grey = b.addMaterial(glm::vec3(0.5f));
    const int twoSided = b.addMaterial(glm::vec3(0.5f), glm::vec3(0.0f), true, "panel");
    b.addQuad({-4, -4, 0}, {4, -4, 0}, {4, 4, 0}, {-4, 4, 0}, grey, "floor");               // faces +z
    addSolidBox(b, {-1.3, -0.7, -0.4}, {0.9, 1.1, 1.2}, grey, "block");                      // sunk 0.4 m into the floor
    b.addQuad({2, -3, 0.5}, {2, 3, 0.5}, {2, 3, 2.5}, {2, -3, 2.5}, twoSided, "panel");      // x = 2, both sides
    b.addQuad({-3.5, 3, 0}, {3.5, 3, 0}, {3.5, 3, 2.2}, {-3.5, 3, 2.2}, grey, "wall");       // y = 3, faces −y
    return b.build();
}

// Unit directions spread over the sphere (Fibonacci), n of them.
std::vector<glm::dvec3> sphereDirections(int n) {
    std::vector<glm::dvec3> dirs;
    for (int i = 0; i < n; ++i) {
        const double z = 1.0 - (i + 0.5) * 2.0 / n, r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = i * 2.399963229728653;
        dirs.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
    }
    return dirs;
}

// Least barycentric coordinate of point p in element e (negative outside).
double insideness(const PatchMesh& mesh, std::uint32_t e, const glm::dvec3& p) {
    const ElementArrays& el = mesh.elements;
    const glm::dvec3 a = el.vertices[el.triangles[e][0]], b = el.vertices[el.triangles[e][1]], c = el.vertices[el.triangles[e][2]];
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double n2 = glm::dot(n, n);
    const double w1 = glm::dot(glm::cross(p - a, c - a), n) / n2, w2 = glm::dot(glm::cross(b - a, p - a), n) / n2;
    return std::min({w1, w2, 1.0 - w1 - w2});
}

// The point of a hit's element at its barycentrics.
glm::dvec3 pointOf(const PatchMesh& mesh, const ElementHit& h) {
    const ElementArrays& el = mesh.elements;
    const auto& t = el.triangles[h.element];
    return (1.0 - h.b1 - h.b2) * el.vertices[t[0]] + h.b1 * el.vertices[t[1]] + h.b2 * el.vertices[t[2]];
}

}  // namespace

TEST(ElementRayScene, InputFacesFindTheElementsOwnBvhsHits) {
    const Scene scene = cutScene();
    SubdivisionSettings settings;
    settings.patchSizeM = 1.0;
    settings.elementSizeM = 0.35;
    settings.cutAlongSolids = true;
    RefinementRequest request;  // finer elements around one corner of the block: elements of every size in one face
    request.regions.push_back({glm::dvec3(0.9, 1.1, 0.0), 0.8, 0.08});
    const PatchMesh mesh = subdivide(scene, settings, &request);
    ASSERT_GT(mesh.solidCuts.facesCut, 0u);
    ASSERT_GT(mesh.solidCuts.areaDroppedM2, 1.0);  // the floor under the block, the block below the floor
    const EmbreeScene input(scene);
    const ElementRayScene bvh(mesh), faces(mesh, input);
    EXPECT_GT(bvh.twinElements(), 0u);
    EXPECT_EQ(faces.twinElements(), bvh.twinElements());
    EXPECT_EQ(faces.rayOffsetM(), bvh.rayOffsetM());

    // Origins all around: above the floor on both sides of the panel and the block, behind the wall, under the floor
    // (single-sided faces from behind), and just above the floor beside the block (grazing rays along the cut).
    const std::vector<glm::dvec3> origins = {{0, -2, 1}, {3, 0, 1.5}, {1.5, 0, 1.5}, {-2.5, 2, 0.3}, {0, 3.5, 1},
                                             {0.5, -2, -1}, {-1.4, 0, 0.02}, {1.0, 1.2, 0.01}, {3.9, 3.9, 3}};
    const std::vector<glm::dvec3> dirs = sphereDirections(4096);
    std::vector<ElementHit> a(dirs.size()), b(dirs.size());
    const double positionToleranceM = EmbreeScene::kRayEpsilonRelative * scene.bounds().diagonal();
    std::size_t hits = 0, backHits = 0, twinBacks = 0, agreeElement = 0, onEdges = 0;
    for (const glm::dvec3& o : origins) {
        bvh.trace(o, dirs, a);
        faces.trace(o, dirs, b);
        for (std::size_t k = 0; k < dirs.size(); ++k) {
            ASSERT_EQ(int(b[k].kind), int(a[k].kind)) << "origin " << o.x << " " << o.y << " " << o.z << ", ray " << k;
            if (a[k].kind == ElementHit::Kind::Sky) continue;
            ++hits;
            backHits += a[k].kind == ElementHit::Kind::Back;
            twinBacks += mesh.elements.backSide[a[k].element];
            EXPECT_NEAR(b[k].distanceM, a[k].distanceM, 1e-5 * (1.0 + a[k].distanceM)) << "ray " << k;
            if (b[k].element == a[k].element) {
                // The same point of it, to float precision of a hit on the face: the face's (u, v) are float over the
                // whole 8 m floor, the element's own over 8 cm, so compared in metres against the project's bound
                // on float position error (EmbreeScene::kRayEpsilonRelative of the diagonal, ≈ 60 ulps).
                ++agreeElement;
                EXPECT_LT(glm::length(pointOf(mesh, b[k]) - pointOf(mesh, a[k])), positionToleranceM) << "ray " << k;
                continue;
            }
            // Another element only where the hit lies on the two elements' shared edge (float rounding decides).
            const glm::dvec3 p = o + a[k].distanceM * dirs[k];
            EXPECT_GT(insideness(mesh, a[k].element, p), -1e-5) << "ray " << k;
            EXPECT_LT(insideness(mesh, a[k].element, p), 1e-4) << "ray " << k << ": well inside the BVH's element";
            EXPECT_GT(insideness(mesh, b[k].element, p), -1e-4) << "ray " << k << ": not at the faces way's element";
            EXPECT_EQ(mesh.elements.backSide[b[k].element], mesh.elements.backSide[a[k].element]);
            ++onEdges;
        }
    }
    EXPECT_GT(hits, origins.size() * dirs.size() / 2);
    EXPECT_GT(backHits, 1000u);   // single-sided faces seen from behind
    EXPECT_GT(twinBacks, 1000u);  // the panel's back copies, seen from the side they face
    EXPECT_LT(onEdges, hits / 1000 + 1) << agreeElement << " of " << hits << " agree";
}

TEST(ElementRayScene, ARayThroughAHoleInAFaceGoesOnToWhatIsBehind) {
    // A floor cut along a block sunk into it has no element inside the block. A ray from inside the block (the only
    // place one can start to meet that part of the floor) crosses the floor there and meets the block's bottom from
    // behind, as the elements' own BVH, which has nothing there, finds it.
    SceneBuilder sb("hole");
    const int grey = sb.addMaterial(glm::vec3(0.5f));
    sb.addQuad({-2, -2, 0}, {2, -2, 0}, {2, 2, 0}, {-2, 2, 0}, grey, "floor");
    addSolidBox(sb, {-0.5, -0.5, -0.2}, {0.5, 0.5, 0.5}, grey, "block");
    sb.addQuad({-2, -2, -1}, {2, -2, -1}, {2, 2, -1}, {-2, 2, -1}, grey, "below");
    const Scene scene = sb.build();
    SubdivisionSettings settings;
    settings.patchSizeM = 1.0;
    settings.elementSizeM = 0.5;
    const PatchMesh mesh = subdivide(scene, settings);
    const EmbreeScene input(scene);
    const ElementRayScene bvh(mesh), faces(mesh, input);
    const std::vector<glm::dvec3> down = {glm::normalize(glm::dvec3(0.1, 0.05, -1.0))};
    std::vector<ElementHit> a(1), b(1);
    ASSERT_GT(mesh.solidCuts.piecesDropped, 0u);
    bvh.trace(glm::dvec3(0, 0, 0.1), down, a);
    faces.trace(glm::dvec3(0, 0, 0.1), down, b);
    ASSERT_EQ(int(a[0].kind), int(ElementHit::Kind::Back));
    EXPECT_GT(a[0].distanceM, 0.3);  // past the floor's missing part (0.1 m) to the block's bottom (0.3 m down)
    EXPECT_EQ(int(b[0].kind), int(a[0].kind));
    EXPECT_EQ(b[0].element, a[0].element);
    EXPECT_NEAR(b[0].distanceM, a[0].distanceM, 1e-6);
}
