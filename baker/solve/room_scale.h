#pragma once
// Element sizes that follow the rooms, not the scene: a level's diagonal says nothing about how big its rooms are.
// Each element of a first subdivision measures its mean free path with a few cosine-weighted rays (how far light
// leaving it travels before it lands, 4V/S in a closed convex room); where roomFraction × that is below the element
// size, a refinement region asks for elements that small. Open surfaces (half their rays escape) and elements
// inside geometry (half their hits are back faces) keep the preset's size.
#include "baker/rays/embree_scene.h"
#include "baker/solve/solve_settings.h"
#include "mesh/subdivision.h"

namespace hemibake {

struct RoomScaleReport {
    std::size_t regions = 0;        // elements that asked for a finer size
    double smallestSizeM = 0.0;     // the finest size asked for (0 when none)
    double medianFreePathM = 0.0;   // over the measured elements that hit something, area-weighted
};

// Refinement regions for `scene` subdivided with `settings.subdivision` (empty when roomScale.roomFraction is 0).
// Deterministic; runs in parallel (oneTBB). Throws std::invalid_argument on negative settings.
RefinementRequest findRoomScaleRegions(const Scene& scene, const EmbreeScene& rays, const SolveSettings& settings,
                                       RoomScaleReport* report = nullptr);

}  // namespace hemibake
