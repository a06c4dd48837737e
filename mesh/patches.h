#pragma once
// The solver's view of the scene: flat structure-of-arrays patches (shooters) and elements (receivers),
// sized for millions of elements. Every element belongs to exactly one patch; a patch's elements are the
// contiguous run [firstElement, firstElement + elementCount).
//
// Double-sided materials produce two elements per surface triangle, one per side, each with its own
// radiosity: the back copy has reversed winding and a flipped normal, so "front-facing" always means
// "the side this element receives on". Rasterizers can therefore cull or mark back faces uniformly.
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "mesh/scene.h"

namespace hemibake {

// What cutting faces along solids did (mesh/solid_cuts.h).
struct SolidCutStats {
    std::size_t solids = 0;         // closed solids found
    std::size_t facesCut = 0;       // input triangles split into pieces
    std::size_t facesCutAtGaps = 0; // of those, split along a solid hanging in front of them (gap cuts)
    std::size_t facesDropped = 0;   // input triangles with nothing left outside the solids
    std::size_t piecesDropped = 0;  // pieces of cut triangles inside a solid
    double areaDroppedM2 = 0.0;     // area inside solids, removed

    // Adds another mesh's counts (`solids` is the scene's, not summed).
    SolidCutStats& operator+=(const SolidCutStats& o) {
        facesCut += o.facesCut;
        facesCutAtGaps += o.facesCutAtGaps;
        facesDropped += o.facesDropped;
        piecesDropped += o.piecesDropped;
        areaDroppedM2 += o.areaDroppedM2;
        return *this;
    }
};

struct ElementArrays {
    std::vector<glm::dvec3> vertices;                   // world space, shared between elements of one instance side
    std::vector<glm::vec2> vertexLightmapUv;            // TEXCOORD_1 per vertex (0,0 until UVs exist)
    std::vector<std::array<std::uint32_t, 3>> triangles;  // per element, counter-clockwise seen from its front
    std::vector<glm::vec3> normal;                      // unit, pointing to the receiving side
    std::vector<glm::dvec3> centroid;
    std::vector<double> areaM2;
    std::vector<glm::vec3> reflectance;      // ρ, averaged over the element, in [0, 0.999]
    std::vector<glm::vec3> emittedRadiance;  // L_e, W·m⁻²·sr⁻¹
    std::vector<std::uint32_t> patch;
    std::vector<std::uint32_t> instance;     // Scene::instances index
    std::vector<std::uint32_t> sourceFace;   // triangle index in the instance as loaded
    std::vector<std::uint8_t> backSide;      // 1 for the back copy of a double-sided surface

    std::size_t size() const { return triangles.size(); }
    // Keeps the first n elements (vertices untouched). Not thread-safe.
    void truncateElements(std::size_t n) {
        triangles.resize(n), normal.resize(n), centroid.resize(n), areaM2.resize(n), reflectance.resize(n);
        emittedRadiance.resize(n), patch.resize(n), instance.resize(n), sourceFace.resize(n), backSide.resize(n);
    }
};

struct PatchArrays {
    std::vector<std::uint32_t> firstElement;
    std::vector<std::uint32_t> elementCount;
    std::vector<double> areaM2;
    std::vector<glm::dvec3> centroid;
    std::vector<glm::vec3> normal;           // area-weighted mean of its elements' normals, unit
    std::vector<glm::vec3> reflectance;      // area-weighted mean of its elements
    std::vector<glm::vec3> emittedRadiance;  // area-weighted mean of its elements
    std::vector<std::uint32_t> instance;

    std::size_t size() const { return firstElement.size(); }
};

struct PatchMesh {
    ElementArrays elements;
    PatchArrays patches;
    // Rendering and hemicube placement work relative to this point, in float, so that a scene 1e5 m from the
    // world origin keeps sub-millimetre precision. It is the centre of the scene's bounds.
    glm::dvec3 origin{0.0};
    double sceneDiagonalM = 0.0;
    SolidCutStats solidCuts;  // what cutting along solids did (mesh/solid_cuts.h); zero when off
};

// Recomputes patch p's area, centroid, normal and area-weighted reflectance and emission from its elements, as
// mesh/subdivision.cpp forms them (after elements change area or move between patches). Not thread-safe for
// the same patch.
void recomputePatchSums(PatchMesh& mesh, std::size_t p);

struct SubdivisionSettings {
    double patchSizeM = 0.25;         // longest edge of a shooting patch
    double elementSizeM = 0.05;       // longest edge of a receiving element (≤ patch size)
    double emitterPatchSizeM = 0.0;   // longest edge of an emitter patch; 0 = patchSizeM / 4 (the solve
                                      // uses patchSizeM when rays carry emitters' light: baker/solve/solve_scene.cpp)
    // Cut faces where closed solids cross them and drop the buried parts (mesh/solid_cuts.h), so no patch or
    // element lies on both sides of a wall standing in a slab. Typical: on.
    bool cutAlongSolids = true;
    // Also cut faces along the outline of a solid hanging in front of them closer than elementSizeM × this (a light
    // panel 5 cm under a ceiling), so its gap's trapped light is not averaged with the open surface around it.
    // Typical: 1/8 (0.22 m gaps at 1.75 m elements); 0 = off. Needs cutAlongSolids.
    double gapCutFraction = 0.125;
};

}  // namespace hemibake
