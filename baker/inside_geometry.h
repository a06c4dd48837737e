#pragma once
// Texels whose sample point lies inside or underneath geometry (a floor texel under a box that stands on it): no
// viewer ever sees them, the bake refills them from their neighbours, and a path tracer finds them black, so
// comparisons leave them out. The criterion is the bake's (LightmapSettings::invalidBackfaceFraction): more than
// `maxBackfaceFraction` of the cosine-weighted hemisphere above the texel shows back faces of single-sided
// surfaces. Estimated with a fixed stratified set of cosine-weighted rays (n × n strata, one ray at each
// stratum's centre), so the answer is deterministic.
#include <cstdint>
#include <vector>

#include "baker/embree_scene.h"
#include "mesh/texels.h"

namespace hemibake {

inline constexpr double kDefaultMaxBackfaceFraction = 0.1;

// One flag per texel of `texels` (1 = inside geometry).
std::vector<std::uint8_t> texelsInsideGeometry(const Scene& scene, const EmbreeScene& rays, const AtlasTexels& texels,
                                               double maxBackfaceFraction = kDefaultMaxBackfaceFraction, int strata = 8);

}  // namespace hemibake
