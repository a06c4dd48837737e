#pragma once
// Receivers and shooters that never straddle a separating surface (issue 15). Levels are built from parts that
// overlap: a floor slab runs under every wall, a wall reaches into the ceiling slab, a crate is sunk into the
// floor. A coarse element of the slab then lies in two rooms at once, takes light on one side and gives its
// average to both; a patch gathers on one side and shoots from a centroid on the other. The exposed-area trimming
// (exposed_area.h) removes the buried part under the wall but keeps both sides in one element.
//
// What this does, before the exposed areas are measured:
//  1. Elements: an element straddles when its k × k sample points, lifted just off its face, fall into more than
//     one group of points that see each other (a wall standing on the face separates them; points buried inside
//     the wall are left out). Straddling elements are bisected (a refinement region over each, at half its
//     longest edge) and the scene subdivided again, until none straddles or the edge reaches the minimum size:
//     the elements along a wall's footprint end up narrower than the wall, each on one side of it or under it.
//     Only the band along the wall is refined; open floor keeps its size.
//  2. Patches: each patch is split into the groups of its elements that see each other through their shared
//     vertices (adjacent elements whose lifted centroids are mutually visible), so a patch only shoots what
//     it gathered on its own side. Elements buried under the wall join their patch's largest group (they
//     receive nothing either way).
// The alternative (a conforming subdivision clipping each face against the solids that cross it) was not taken:
// it needs robust 3-D polygon clipping against arbitrary, often non-closed artist meshes; the bisection reuses
// the conforming mesh and the ray tracer, and its only cost is smaller elements along walls (docs/architecture.md).
#include <cstddef>

#include "mesh/patches.h"
#include "mesh/scene.h"
#include "mesh/subdivision.h"
#include "baker/solve/solve_settings.h"

namespace hemibake {

class EmbreeScene;

struct SideSeparationReport {
    int levels = 0;                        // re-subdivisions made
    std::size_t regions = 0;               // refinement regions over straddling elements
    std::size_t straddlingElementsLeft = 0;  // still straddling at the minimum size
    std::size_t patchesSplit = 0;          // patches whose elements formed more than one group
    std::size_t patchesAdded = 0;          // patches created by those splits
    double seconds = 0.0;
};

// Does element e straddle a separating surface (see above)? Thread-safe (const queries only).
bool elementStraddles(const EmbreeScene& rays, const PatchMesh& mesh, std::size_t e, const SideSeparationSettings& s);

// subdivide(scene, sizes, request), with straddling elements bisected as in 1. and patches split as in 2.
// `request` (may be null) holds the caller's own refinement regions (adaptive refinement). With
// settings.enabled false it is exactly subdivide(). Throws what subdivide throws.
PatchMesh subdivideApart(const Scene& scene, const EmbreeScene& rays, const SubdivisionSettings& sizes,
                         const RefinementRequest* request, const SideSeparationSettings& settings,
                         SideSeparationReport* report = nullptr);

// Step 2 alone: splits every patch into groups of mutually visible adjacent elements; elements are reordered
// within their patch's run so each new patch's elements stay contiguous; patch sums are recomputed. Returns the
// number of patches added.
std::size_t splitPatchesBySide(const EmbreeScene& rays, PatchMesh& mesh, const SideSeparationSettings& settings,
                               std::size_t* patchesSplit = nullptr);

}  // namespace hemibake
