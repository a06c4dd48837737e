#pragma once
// Small shared math for sampling: a tangent frame around a normal, a seedable integer mixer, dominant axes.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace hemibake {

// The z component of the 2-D cross product: twice the signed area of the triangle (0, a, b).
inline double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

// Index (0 = x, 1 = y, 2 = z) of v's largest component, ties to the first: the axis a box is longest along.
inline int largestComponent(const glm::dvec3& v) { return v.x >= v.y && v.x >= v.z ? 0 : (v.y >= v.z ? 1 : 2); }

// The cube face direction d points into, 2·axis + (negative ? 1 : 0): +x, −x, +y, −y, +z, −z.
inline int cubeFaceOf(const glm::dvec3& d) {
    const int axis = largestComponent(glm::abs(d));
    return 2 * axis + (d[axis] < 0.0 ? 1 : 0);
}

// Duff et al. 2017, "Building an Orthonormal Basis, Revisited": branchless, continuous except where n.z
// changes sign. t × b = n for unit n.
inline void orthonormalBasis(const glm::dvec3& n, glm::dvec3& t, glm::dvec3& b) {
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z);
    const double c = n.x * n.y * a;
    t = {1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x};
    b = {c, sign + n.y * n.y * a, -n.y};
}

// Shirley–Chiu concentric map of the unit square onto the unit disk: keeps strata compact.
inline glm::dvec2 concentricDisk(double u, double v) {
    const double a = 2.0 * u - 1.0, b = 2.0 * v - 1.0;
    if (a == 0.0 && b == 0.0) return {0.0, 0.0};
    if (std::abs(a) > std::abs(b)) {
        const double phi = M_PI / 4.0 * (b / a);
        return {a * std::cos(phi), a * std::sin(phi)};
    }
    const double phi = M_PI / 2.0 - M_PI / 4.0 * (a / b);
    return {b * std::cos(phi), b * std::sin(phi)};
}

// Malley's method: a cosine-weighted direction about unit n (frame t, b, n) from a point of the unit square
// (pdf = cosθ/π). For many directions about one normal: the frame built once.
inline glm::dvec3 cosineDirection(const glm::dvec3& t, const glm::dvec3& b, const glm::dvec3& n, double u1, double u2) {
    const glm::dvec2 d = concentricDisk(u1, u2);
    const double z = std::sqrt(std::max(0.0, 1.0 - glm::dot(d, d)));
    return glm::normalize(d.x * t + d.y * b + z * n);
}

// The same about unit n, its frame from orthonormalBasis.
inline glm::dvec3 cosineDirection(const glm::dvec3& n, double u1, double u2) {
    glm::dvec3 t, b;
    orthonormalBasis(n, t, b);
    return cosineDirection(t, b, n, u1, u2);
}

// The largest strata count whose square is at most `rays` (at least 1): stratified ray counts are squares.
inline int strataForRays(long long rays) {
    int strata = 1;
    while ((long long)(strata + 1) * (strata + 1) <= rays) ++strata;
    return strata;
}

// Appends strata² cosine-weighted directions about unit n (frame t, b, n): one jittered point per stratum of the unit
// square, mapped by Malley's method on the concentric disk, so each is 1/strata² of the projected hemisphere.
// `uniform()` draws from [0, 1), twice per direction.
template <class Uniform>
void appendStratifiedCosineDirections(const glm::dvec3& t, const glm::dvec3& b, const glm::dvec3& n, int strata,
                                      Uniform& uniform, std::vector<glm::dvec3>& out) {
    const double s = double(strata);
    for (int sy = 0; sy < strata; ++sy)
        for (int sx = 0; sx < strata; ++sx) {
            const glm::dvec2 d = concentricDisk((sx + uniform()) / s, (sy + uniform()) / s);
            const double z = std::sqrt(std::max(0.0, 1.0 - glm::dot(d, d)));
            out.push_back(glm::normalize(d.x * t + d.y * b + z * n));
        }
}

// SplitMix64 finalizer: decorrelates seeds (and seeds a stream from any integer).
inline std::uint64_t splitMix64(std::uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

}  // namespace hemibake
