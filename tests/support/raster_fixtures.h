#pragma once
// Analytic set-ups for the raster tests, built directly as PatchMesh arrays (one element and one patch per
// triangle), plus the exact form factors of GROUND_TRUTH.md §1 to compare against.
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "mesh/patches.h"

namespace hemibake::test {

class TriangleSoup {
public:
    // Counter-clockwise seen from the front (the side the normal points to).
    void addTriangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) { triangles_.push_back({a, b, c}); }
    void addQuad(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2, const glm::dvec3& p3) {
        addTriangle(p0, p1, p2);
        addTriangle(p0, p2, p3);
    }
    // A planar quad p0 + s·u + t·v, s,t in [0,1], split into n×n conforming cells; front is u × v.
    void addGrid(const glm::dvec3& p0, const glm::dvec3& u, const glm::dvec3& v, int n) {
        auto at = [&](int i, int j) { return p0 + (double(i) / n) * u + (double(j) / n) * v; };
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) addQuad(at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
    }
    // A regular polygon fan approximating a disk; its front faces along `front`.
    void addDisk(const glm::dvec3& centre, const glm::dvec3& front, double radius, int segments) {
        const glm::dvec3 n = glm::normalize(front);
        const glm::dvec3 a = glm::normalize(glm::cross(n, std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
        const glm::dvec3 b = glm::cross(n, a);  // a × b = n: counter-clockwise seen from the front
        for (int k = 0; k < segments; ++k) {
            const double t0 = 2.0 * std::numbers::pi * k / segments, t1 = 2.0 * std::numbers::pi * (k + 1) / segments;
            addTriangle(centre, centre + radius * (std::cos(t0) * a + std::sin(t0) * b),
                        centre + radius * (std::cos(t1) * a + std::sin(t1) * b));
        }
    }
    // An axis-aligned closed box with faces pointing inwards, each face an n×n conforming grid.
    void addInwardBox(const glm::dvec3& lo, const glm::dvec3& hi, int n) {
        const glm::dvec3 s = hi - lo;
        const glm::dvec3 x(s.x, 0, 0), y(0, s.y, 0), z(0, 0, s.z);
        addGrid(lo, x, y, n);      // z = lo, normal +z
        addGrid(lo + z, y, x, n);  // z = hi, normal -z
        addGrid(lo, z, x, n);      // y = lo, normal +y
        addGrid(lo + y, x, z, n);  // y = hi, normal -y
        addGrid(lo, y, z, n);      // x = lo, normal +x
        addGrid(lo + x, z, y, n);  // x = hi, normal -x
    }
    void translate(const glm::dvec3& offset) {
        for (auto& t : triangles_)
            for (auto& p : t) p += offset;
    }
    // Triangles first.. (all by default) mapped to rotation · p + offset.
    void transform(const glm::dmat3& rotation, const glm::dvec3& offset, std::size_t first = 0) {
        for (std::size_t k = first; k < triangles_.size(); ++k)
            for (auto& p : triangles_[k]) p = rotation * p + offset;
    }
    std::size_t size() const { return triangles_.size(); }

    // One element per triangle, each its own patch; vertices not shared (shared positions are bit-identical).
    PatchMesh build() const {
        PatchMesh mesh;
        ElementArrays& e = mesh.elements;
        glm::dvec3 lo(1e300), hi(-1e300);
        for (const auto& t : triangles_) {
            const auto first = static_cast<std::uint32_t>(e.vertices.size());
            for (const auto& p : t) {
                e.vertices.push_back(p);
                e.vertexLightmapUv.push_back(glm::vec3(0.0f));
                lo = glm::min(lo, p);
                hi = glm::max(hi, p);
            }
            const glm::dvec3 cross = glm::cross(t[1] - t[0], t[2] - t[0]);
            const auto index = static_cast<std::uint32_t>(e.triangles.size());
            e.triangles.push_back({first, first + 1, first + 2});
            e.normal.push_back(glm::vec3(glm::normalize(cross)));
            e.centroid.push_back((t[0] + t[1] + t[2]) / 3.0);
            e.areaM2.push_back(0.5 * glm::length(cross));
            e.reflectance.push_back(glm::vec3(0.5f));
            e.emittedRadiance.push_back(glm::vec3(0.0f));
            e.patch.push_back(index);
            e.instance.push_back(0);
            e.sourceFace.push_back(index);
            e.backSide.push_back(0);
            PatchArrays& p = mesh.patches;
            p.firstElement.push_back(index);
            p.elementCount.push_back(1);
            p.areaM2.push_back(e.areaM2.back());
            p.centroid.push_back(e.centroid.back());
            p.normal.push_back(e.normal.back());
            p.reflectance.push_back(e.reflectance.back());
            p.emittedRadiance.push_back(e.emittedRadiance.back());
            p.instance.push_back(0);
        }
        mesh.origin = 0.5 * (lo + hi);
        mesh.sceneDiagonalM = glm::length(hi - lo);
        return mesh;
    }

private:
    std::vector<std::array<glm::dvec3, 3>> triangles_;
};

// Lambert's contour formula (GROUND_TRUTH.md §1): exact F(dA at p, normal n → planar polygon), the polygon
// wholly in front of p and unoccluded.
inline double pointPolygonFormFactor(const glm::dvec3& p, const glm::dvec3& n, const std::vector<glm::dvec3>& polygon) {
    double sum = 0.0;
    for (std::size_t i = 0; i < polygon.size(); ++i) {
        const glm::dvec3 a = polygon[i] - p, b = polygon[(i + 1) % polygon.size()] - p;
        const glm::dvec3 c = glm::cross(a, b);
        const double beta = std::atan2(glm::length(c), glm::dot(a, b));
        sum += beta * glm::dot(n, c) / glm::length(c);
    }
    return std::abs(sum) / (2.0 * std::numbers::pi);
}

// §1(a) coaxial parallel rectangles a×b at separation c.
inline double parallelRectanglesFormFactor(double a, double b, double c) {
    const double X = a / c, Y = b / c;
    const double sx = std::sqrt(1 + X * X), sy = std::sqrt(1 + Y * Y);
    return 2.0 / (std::numbers::pi * X * Y) *
           (std::log(std::sqrt((1 + X * X) * (1 + Y * Y) / (1 + X * X + Y * Y))) + X * sy * std::atan(X / sy) +
            Y * sx * std::atan(Y / sx) - X * std::atan(X) - Y * std::atan(Y));
}

// §1(b) perpendicular rectangles sharing an edge of length l; rectangle 1 is l×w, rectangle 2 is l×h.
inline double perpendicularRectanglesFormFactor(double l, double w, double h) {
    const double W = w / l, H = h / l, W2 = W * W, H2 = H * H, s = std::sqrt(H2 + W2);
    const double a = (1 + W2) * (1 + H2) / (1 + W2 + H2);
    const double b = W2 * (1 + W2 + H2) / ((1 + W2) * (W2 + H2));
    const double c = H2 * (1 + H2 + W2) / ((1 + H2) * (H2 + W2));
    return 1.0 / (std::numbers::pi * W) *
           (W * std::atan(1 / W) + H * std::atan(1 / H) - s * std::atan(1 / s) +
            0.25 * (std::log(a) + W2 * std::log(b) + H2 * std::log(c)));
}

// §1(c) differential area → coaxial disk.
inline double diskFormFactor(double r, double h) { return r * r / (r * r + h * h); }

// §1(d) corner-aligned parallel rectangle a×b at distance c.
inline double cornerParallelFormFactor(double a, double b, double c) {
    const double A = a / c, B = b / c, sa = std::sqrt(1 + A * A), sb = std::sqrt(1 + B * B);
    return (A / sa * std::atan(B / sa) + B / sb * std::atan(A / sb)) / (2.0 * std::numbers::pi);
}

// §1(d) perpendicular corner-aligned rectangle: plane y = c, x in [0,a], z in [0,b].
inline double cornerPerpendicularFormFactor(double a, double b, double c) {
    const double s = std::sqrt(b * b + c * c);
    return (std::atan(a / c) - c / s * std::atan(a / s)) / (2.0 * std::numbers::pi);
}

// Two flat furnaces 3 km apart, 1 × 1 m and 4 mm tall (the gap between two parts), turned off the axes so no wall's
// coordinates are exact in float; each is its own instance (so its own island, mesh/islands.h). `on(b, p)` maps a
// point of the unit box [-0.5, 0.5]² × [-h, h] into furnace b.
struct FlatFurnaces {
    static constexpr double kHalfHeightM = 0.002;
    glm::dmat3 turn = glm::dmat3(glm::rotate(glm::dmat4(1.0), 0.7, glm::normalize(glm::dvec3(1.0, 2.0, 3.0))));
    std::array<glm::dvec3, 2> centres{glm::dvec3(0.0, 0.0, 0.0), glm::dvec3(3000.0, 1.0, -2.0)};
    PatchMesh mesh;
    FlatFurnaces() {
        TriangleSoup soup;
        std::size_t firstOfSecond = 0;
        for (int b = 0; b < 2; ++b) {
            const std::size_t first = soup.size();
            if (b == 1) firstOfSecond = first;
            soup.addInwardBox({-0.5, -0.5, -kHalfHeightM}, {0.5, 0.5, kHalfHeightM}, 5);
            soup.transform(turn, centres[std::size_t(b)], first);
        }
        mesh = soup.build();
        for (std::size_t e = firstOfSecond; e < mesh.elements.size(); ++e) mesh.elements.instance[e] = 1;
    }
    glm::dvec3 on(std::size_t b, const glm::dvec3& p) const { return centres[b] + turn * p; }
    glm::dvec3 direction(const glm::dvec3& d) const { return turn * d; }

    struct SurfacePoint {
        glm::dvec3 position, normal;
    };
    // Per furnace `perFurnace` pairs of points: one on the floor (every 8th at x = −0.499, the next at y = 0.499: 1 mm
    // from the edges) and one on the wall x = 0.5 at a height within ±wallSpread × kHalfHeightM; `draw` receives
    // each point in turn, so a caller can take further random numbers between points.
    template <class Rng, class Draw>
    void samplePoints(Rng& rng, int perFurnace, double wallSpread, Draw&& draw) const {
        std::uniform_real_distribution<double> u(-0.499, 0.499), h(-wallSpread * kHalfHeightM, wallSpread * kHalfHeightM);
        for (std::size_t b = 0; b < 2; ++b)
            for (int k = 0; k < perFurnace; ++k) {
                const double x = k % 8 == 0 ? -0.499 : u(rng), y = k % 8 == 1 ? 0.499 : u(rng);
                draw(SurfacePoint{on(b, {x, y, -kHalfHeightM}), direction({0, 0, 1})});
                draw(SurfacePoint{on(b, {0.5, x, h(rng)}), direction({-1, 0, 0})});
            }
    }
};

}  // namespace hemibake::test
