#pragma once
// Adaptive subdivision: refine where light changes (shadow and light boundaries), leave smooth regions coarse.
#include "baker/solve/radiosity_solution.h"
#include "mesh/subdivision.h"

namespace hemibake {

// Elements that differ from an edge neighbour by more than `threshold` (relative, on the channel sum of the
// displayed radiosity) and are still larger than `targetSizeM` become refinement regions. Thread-safe.
RefinementRequest findRadiosityDiscontinuities(const PatchMesh& mesh, const RadiositySolution& solution, double threshold,
                                               double targetSizeM);

}  // namespace hemibake
