#pragma once
// Patches and elements by conforming longest-edge bisection on OpenMesh: a mesh is bisected until every
// face's longest edge is at most the patch size (those faces are the patches), then further until it is at
// most the element size (those faces are the elements, each remembering its patch). Conforming splits keep
// vertices shared, so element values can be interpolated across element and patch boundaries.
#include <functional>
#include <vector>

#include "mesh/patches.h"
#include "mesh/scene.h"

namespace hemibake {

struct SubdivisionStats {
    std::size_t patches = 0;
    std::size_t elements = 0;
    std::size_t emitterPatches = 0;
    std::size_t emitterElements = 0;
};

// Places where the elements must be finer than the element size (adaptive refinement after a first solve):
// every element whose centroid lies within radiusM of a point is bisected until its longest edge ≤ sizeM.
struct RefinementRequest {
    struct Region {
        glm::dvec3 centre;
        double radiusM;
        double sizeM;
    };
    std::vector<Region> regions;
};

PatchMesh subdivide(const Scene& scene, const SubdivisionSettings& settings, const RefinementRequest* refinement = nullptr);

// Counts only, without building the arrays (for `hemibake info`).
SubdivisionStats countSubdivision(const Scene& scene, const SubdivisionSettings& settings);

// Bisects the longest edge of every face longer than maxEdgeM until none is. Face properties are copied to
// both halves; vertex UVs and normals are interpolated. Returns the number of splits.
std::size_t bisectLongEdges(SurfaceMesh& mesh, double maxEdgeM);
// The same, where each face's limit comes from `maxEdgeForFace(centroid)` (≤ 0: leave the face alone).
std::size_t bisectLongEdges(SurfaceMesh& mesh, const std::function<double(const glm::dvec3&)>& maxEdgeForFace);

}  // namespace hemibake
