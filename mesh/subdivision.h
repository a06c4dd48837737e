#pragma once
// Patches and elements by conforming longest-edge bisection on OpenMesh: a mesh is bisected until every
// face's longest edge is at most the patch size (those faces are the patches), then further until it is at
// most the element size (those faces are the elements, each remembering its patch). Conforming splits keep
// vertices shared, so element values can be interpolated across element and patch boundaries.
#include "mesh/patches.h"
#include "mesh/scene.h"

namespace hemibake {

struct SubdivisionStats {
    std::size_t patches = 0;
    std::size_t elements = 0;
    std::size_t emitterPatches = 0;
    std::size_t emitterElements = 0;
};

PatchMesh subdivide(const Scene& scene, const SubdivisionSettings& settings);

// Counts only, without building the arrays (for `hemibake info`).
SubdivisionStats countSubdivision(const Scene& scene, const SubdivisionSettings& settings);

// Bisects the longest edge of every face longer than maxEdgeM until none is. Face properties are copied to
// both halves; vertex UVs and normals are interpolated. Returns the number of splits.
std::size_t bisectLongEdges(SurfaceMesh& mesh, double maxEdgeM);

}  // namespace hemibake
