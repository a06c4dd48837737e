#pragma once
// Adaptive subdivision: refine where light changes (shadow and light boundaries), leave smooth regions coarse.
#include <memory>

#include "baker/bake_settings.h"
#include "baker/exposed_area.h"
#include "baker/radiosity_solver.h"
#include "mesh/subdivision.h"

namespace hemibake {

class EmbreeScene;
class HemicubePool;

// Elements that differ from an edge neighbour by more than `threshold` (relative, on the channel sum of the
// displayed radiosity) and are still larger than `targetSizeM` become refinement regions.
RefinementRequest findRadiosityDiscontinuities(const PatchMesh& mesh, const RadiositySolution& solution, double threshold,
                                               double targetSizeM);

struct RadiosityBake {
    PatchMesh mesh;
    RadiositySolution solution;
    SolveReport report;
    std::unique_ptr<HemicubePool> pool;  // bound to `mesh`: later stages (final gather) reuse it
    std::size_t elementsBeforeRefinement = 0;
    std::size_t refinementRegions = 0;
    ExposedAreaReport exposedArea;  // of the final mesh
    RadiosityBake();
    ~RadiosityBake();
    // Pinned: `pool` points at `mesh`, so moving the bake would leave it reading a moved-from mesh.
    RadiosityBake(const RadiosityBake&) = delete;
    RadiosityBake& operator=(const RadiosityBake&) = delete;
};

// Subdivide, solve, and (settings.adaptive.levels > 0) refine and solve again.
std::unique_ptr<RadiosityBake> solveWithRefinement(const Scene& scene, const BakeSettings& settings, const EmbreeScene& rays,
                                  const SolveProgress& progress = {});

}  // namespace hemibake
