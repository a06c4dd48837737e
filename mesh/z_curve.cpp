#include "mesh/z_curve.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace hemibake {

namespace {

// The low 21 bits of v, two zero bits after each (bit i moves to bit 3i).
std::uint64_t spreadBitsBy3(std::uint64_t v) {
    v &= 0x1FFFFF;
    v = (v | v << 32) & 0x1F00000000FFFFull;
    v = (v | v << 16) & 0x1F0000FF0000FFull;
    v = (v | v << 8) & 0x100F00F00F00F00Full;
    v = (v | v << 4) & 0x10C30C30C30C30C3ull;
    v = (v | v << 2) & 0x1249249249249249ull;
    return v;
}

// (code, index) of every point, sorted.
std::vector<std::pair<std::uint64_t, std::uint32_t>> sortedCodes(std::span<const glm::dvec3> points) {
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    for (const glm::dvec3& p : points)
        for (int axis = 0; axis < 3; ++axis)
            if (std::isfinite(p[axis])) lo[axis] = std::min(lo[axis], p[axis]), hi[axis] = std::max(hi[axis], p[axis]);
    const double cells = double((1u << 21) - 1);
    std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(points.size());
    for (std::size_t k = 0; k < points.size(); ++k) {
        std::uint64_t code = 0;
        for (int axis = 0; axis < 3; ++axis) {
            const double extent = hi[axis] - lo[axis];
            double t = extent > 0.0 ? (points[k][axis] - lo[axis]) / extent : 0.0;
            t = std::isfinite(t) ? std::clamp(t, 0.0, 1.0) : 0.0;
            code |= spreadBitsBy3(std::uint64_t(t * cells)) << axis;
        }
        keyed[k] = {code, std::uint32_t(k)};
    }
    std::sort(keyed.begin(), keyed.end());
    return keyed;
}

}  // namespace

std::vector<std::uint32_t> zCurveRanks(std::span<const glm::dvec3> points) {
    const auto keyed = sortedCodes(points);
    std::vector<std::uint32_t> rank(points.size());
    for (std::uint32_t k = 0; k < keyed.size(); ++k) rank[keyed[k].second] = k;
    return rank;
}

std::vector<std::uint32_t> zCurveOrder(std::span<const glm::dvec3> points) {
    const auto keyed = sortedCodes(points);
    std::vector<std::uint32_t> order(points.size());
    for (std::size_t k = 0; k < keyed.size(); ++k) order[k] = keyed[k].second;
    return order;
}

}  // namespace hemibake
