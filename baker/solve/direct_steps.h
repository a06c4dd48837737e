#pragma once
// Elements that follow the steps of direct light, found before the solve. A patch or element that straddles the
// edge of a hot spot (the ceiling above an emitting panel hung 5 cm under it) or of a shadow holds one average for
// a field that jumps: the gather sees the hot spot's light spread over the element's visible part, and its patch
// shoots from places the light never reached. Direct light is known before anything is solved (rays), so the
// steps can be found up front: each element of a first subdivision evaluates it at k² points, and where it spans
// more than `contrast` of its maximum the element asks to be halved; repeated `levels` times, down to
// elementSize × minSizeFraction. No re-solve: the solve runs once on the refined mesh.
#include "baker/rays/embree_scene.h"
#include "baker/solve/solve_settings.h"
#include "mesh/subdivision.h"

namespace hemibake {

struct DirectStepReport {
    std::size_t regions = 0;     // elements that asked to be halved, over all levels
    int levels = 0;              // levels that found any
    double smallestSizeM = 0.0;  // the finest size asked for (0 when none)
};

// Refinement regions (added to `base`'s, which the first subdivision uses) where direct light steps within an
// element. Empty when settings.directSteps.levels is 0 or the scene has no ray-traced light. Deterministic; runs
// in parallel (oneTBB). Throws std::invalid_argument on bad settings.
RefinementRequest findDirectLightSteps(const Scene& scene, const EmbreeScene& rays, const SolveSettings& settings,
                                       const RefinementRequest& base, DirectStepReport* report = nullptr);

}  // namespace hemibake
