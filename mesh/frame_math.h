#pragma once
// Small shared math for sampling: a tangent frame around a normal, and a seedable integer mixer.
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

namespace hemibake {

// Duff et al. 2017, "Building an Orthonormal Basis, Revisited": branchless, continuous except where n.z
// changes sign. t × b = n for unit n.
inline void orthonormalBasis(const glm::dvec3& n, glm::dvec3& t, glm::dvec3& b) {
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z);
    const double c = n.x * n.y * a;
    t = {1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x};
    b = {c, sign + n.y * n.y * a, -n.y};
}

// SplitMix64 finalizer: decorrelates seeds (and seeds a stream from any integer).
inline std::uint64_t splitMix64(std::uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

}  // namespace hemibake
