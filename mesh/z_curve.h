#pragma once
// A Z-curve (Morton order) through points: consecutive points on it lie close in space. Work done in that order
// (the shooter's sweeps, the final gather's points) keeps touching the same part of the ray tracer's
// BVH: on 30 copies of a level, 2,048 points × 256 rays cost 270 ns a ray in one copy, 407 ns shuffled over the
// level (bench/bench_rays.cpp; docs/performance.md, session 32).
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace hemibake {

// Each point's place on a Z-curve through `points`, quantised to 2²¹ cells per axis within their bounding box
// (relative: the same order at 1 mm or 100 km from the origin). Ties (equal codes) keep index order; non-finite
// coordinates count as the box's low side. Thread-safe.
std::vector<std::uint32_t> zCurveRanks(std::span<const glm::dvec3> points);

// The indices of `points` in Z-curve order (the inverse of zCurveRanks). Thread-safe.
std::vector<std::uint32_t> zCurveOrder(std::span<const glm::dvec3> points);

}  // namespace hemibake
