#pragma once
// Texels whose sample point lies inside or underneath geometry (a floor texel under a box that stands on it): no
// viewer ever sees them, the bake refills them from their neighbours, and a path tracer finds them black, so
// comparisons leave them out. The criterion is the bake's (LightmapSettings::invalidBackfaceFraction): more than
// `maxBackfaceFraction` of the cosine-weighted hemisphere above the texel shows back faces of single-sided
// surfaces. Estimated with a fixed stratified set of cosine-weighted rays (n × n strata, one ray at each
// stratum's centre), so the answer is deterministic.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "baker/rays/embree_scene.h"
#include "mesh/texels.h"

namespace hemibake {

inline constexpr double kDefaultMaxBackfaceFraction = 0.1;

// Is what a ray met (EmbreeScene::intersectSides) the back face of a single-sided surface?
bool isSingleSidedBackface(const Scene& scene, const HitSide& side);

// The fraction of the cosine-weighted hemisphere above surface point p (unit normal n: the side the point
// receives on) that shows back faces of single-sided surfaces, from the strata × strata rays described above.
double backfaceFractionAt(const Scene& scene, const EmbreeScene& rays, const glm::dvec3& p, const glm::dvec3& n,
                          int strata = 8);

// backfaceFractionAt(...) > maxBackfaceFraction, but stops tracing as soon as the remaining rays cannot change
// the answer: the same answer, in fewer rays whenever it is clear early (an open point against a high limit).
bool pointInsideGeometry(const Scene& scene, const EmbreeScene& rays, const glm::dvec3& p, const glm::dvec3& n,
                         double maxBackfaceFraction = kDefaultMaxBackfaceFraction, int strata = 8);

// One flag per texel of `texels` (1 = inside geometry).
std::vector<std::uint8_t> texelsInsideGeometry(const Scene& scene, const EmbreeScene& rays, const AtlasTexels& texels,
                                               double maxBackfaceFraction = kDefaultMaxBackfaceFraction, int strata = 8);

}  // namespace hemibake
