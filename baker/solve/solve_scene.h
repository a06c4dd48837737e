#pragma once
// The solve stage's entry point: subdivide the scene (elements no larger than their room asks, no element or patch
// straddling a wall), trim elements to their exposed area, solve, and refine where radiosity steps
// (settings.adaptive). What later stages need of the solve is in SolvedScene.
#include <memory>

#include "baker/solve/direct_steps.h"
#include "baker/solve/exposed_area.h"
#include "baker/solve/radiosity_solver.h"
#include "baker/solve/room_scale.h"
#include "baker/solve/separate_sides.h"
#include "baker/solve/solve_settings.h"
#include "mesh/patches.h"

namespace hemibake {

class ElementRayScene;
class EmbreeScene;
class HemicubePool;

struct SolvedScene {
    PatchMesh mesh;
    RadiositySolution solution;
    SolveReport report;
    std::unique_ptr<HemicubePool> pool;  // bound to `mesh`: later stages (final gather) reuse it
    // Rays into `mesh`'s elements, built when shooting rows are sampled by rays: the final gather by rays reuses it.
    std::unique_ptr<ElementRayScene> elementRays;
    std::size_t elementsBeforeRefinement = 0;
    std::size_t refinementRegions = 0;
    RoomScaleReport roomScale;      // elements refined to follow the rooms (before any adaptive level)
    DirectStepReport directSteps;   // elements refined where direct light steps (before the solve)
    ExposedAreaReport exposedArea;  // of the final mesh
    SideSeparationReport sides;     // of the final mesh
    SolvedScene();
    ~SolvedScene();
    // Pinned: `pool` points at `mesh`, so moving it would leave the pool reading a moved-from mesh.
    SolvedScene(const SolvedScene&) = delete;
    SolvedScene& operator=(const SolvedScene&) = delete;
};

// Subdivide, solve, and (settings.adaptive.levels > 0) refine and solve again. `rays` must be of `scene`.
// Throws std::invalid_argument on bad settings. Uses every core (oneTBB); not re-entrant per pool.
std::unique_ptr<SolvedScene> solveScene(const Scene& scene, const SolveSettings& settings, const EmbreeScene& rays,
                                        const SolveProgress& progress = {});

}  // namespace hemibake
