#pragma once
// The GROUND_TRUTH.md analytic cases as hemicube set-ups, shared by the accuracy tests and the accuracy table.
#include <cstdint>
#include <random>
#include <string>

#include "raster/hemicube.h"
#include "support/raster_fixtures.h"

namespace hemibake::test {

// dA at `point` (normal +z) looking at one planar polygon; F is the sum over the scene's elements.
struct PointCase {
    std::string name;
    std::vector<glm::dvec3> polygon;  // counter-clockwise seen from the point
    double groundTruth = 0.0;         // GROUND_TRUTH.md §1 value at `point`
    glm::dvec3 point{0.0};
    double distance = 1.0;            // typical distance to the target, scales the sub-pixel jitter

    PatchMesh mesh() const {
        TriangleSoup soup;
        for (std::size_t k = 1; k + 1 < polygon.size(); ++k) soup.addTriangle(polygon[0], polygon[k], polygon[k + 1]);
        return soup.build();
    }
};

inline std::vector<glm::dvec3> diskPolygon(double radius, double height, int segments) {
    std::vector<glm::dvec3> polygon;
    for (int k = 0; k < segments; ++k) {  // counter-clockwise seen from below
        const double t = -2.0 * std::numbers::pi * k / segments;
        polygon.push_back({radius * std::cos(t), radius * std::sin(t), height});
    }
    return polygon;
}

inline std::vector<PointCase> pointCases() {
    return {
        {"disk r=0.5 h=1", diskPolygon(0.5, 1.0, 1024), diskFormFactor(0.5, 1.0), {0, 0, 0}, 1.0},
        {"disk r=1 h=1", diskPolygon(1.0, 1.0, 1024), diskFormFactor(1.0, 1.0), {0, 0, 0}, 1.0},
        {"parallel corner 1x1 c=1", {{0, 0, 1}, {0, 1, 1}, {1, 1, 1}, {1, 0, 1}}, cornerParallelFormFactor(1, 1, 1), {0, 0, 0}, 1.0},
        {"parallel corner 2x2 c=1", {{0, 0, 1}, {0, 2, 1}, {2, 2, 1}, {2, 0, 1}}, cornerParallelFormFactor(2, 2, 1), {0, 0, 0}, 1.0},
        {"perpendicular a=b=c=1", {{0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1}}, cornerPerpendicularFormFactor(1, 1, 1), {0, 0, 0}, 1.0},
        {"perpendicular a=1 b=2 c=1", {{0, 1, 0}, {1, 1, 0}, {1, 1, 2}, {0, 1, 2}}, cornerPerpendicularFormFactor(1, 2, 1), {0, 0, 0}, 1.0},
    };
}

struct ErrorStats {
    double rms = 0.0, max = 0.0, mean = 0.0;  // relative errors
    double meanFormFactor = 0.0;
    double worstOverBound = 0.0;  // max over samples of |F − exact| / aliasingBound (≤ 1 is guaranteed)
};

// A-priori worst case of one hemicube's aliasing error for a polygon seen from `p` in `frame`: only pixels
// cut by the projected boundary can be wrong, by at most half their weight (the pixel centre decides, so the
// wrong side covers ≤ 1/2 for a boundary straight at pixel scale), and a line touches pixels within a band
// √2 pixels wide. Bound = (√2/2) × Σ over edges of the weight of a one-pixel band along the edge, integrated
// numerically in each face's own coordinates (the exact weights are the kernel × pixel area there).
inline double aliasingBound(const HemicubeFrame& frame, const std::vector<glm::dvec3>& polygon, int resolution) {
    glm::dvec3 t, b;
    frame.tangentFrame(t, b);
    const glm::dvec3 n = glm::normalize(frame.normal);
    auto faceCoordinates = [&](const glm::dvec3& world, int& face, glm::dvec2& uv) {
        const glm::dvec3 d(glm::dot(world - frame.position, t), glm::dot(world - frame.position, b),
                           glm::dot(world - frame.position, n));
        if (d.z >= std::max(std::abs(d.x), std::abs(d.y))) {
            face = 0;
            uv = {d.x / d.z, d.y / d.z};
        } else if (std::abs(d.x) >= std::abs(d.y)) {
            face = d.x > 0 ? 1 : 2;
            uv = {d.y / std::abs(d.x), d.z / std::abs(d.x)};
        } else {
            face = d.y > 0 ? 3 : 4;
            uv = {d.x / std::abs(d.y), d.z / std::abs(d.y)};
        }
    };
    auto density = [](int face, const glm::dvec2& uv) {  // exact weight per unit face area
        const double q = 1.0 + uv.x * uv.x + uv.y * uv.y;
        return (face == 0 ? 1.0 : std::max(uv.y, 0.0)) / (std::numbers::pi * q * q);
    };
    const double pixel = 2.0 / resolution;
    double band = 0.0;
    const int steps = std::max(8, 4096 / static_cast<int>(polygon.size()));
    for (std::size_t e = 0; e < polygon.size(); ++e) {
        const glm::dvec3 a = polygon[e], c = polygon[(e + 1) % polygon.size()];
        int face0;
        glm::dvec2 uv0;
        faceCoordinates(a, face0, uv0);
        for (int k = 1; k <= steps; ++k) {
            int face1;
            glm::dvec2 uv1;
            faceCoordinates(a + (c - a) * (double(k) / steps), face1, uv1);
            if (face1 == face0) band += pixel * glm::length(uv1 - uv0) * 0.5 * (density(face0, uv0) + density(face1, uv1));
            face0 = face1;
            uv0 = uv1;
        }
    }
    return std::sqrt(0.5) * band;
}

// `samples` hemicubes, each randomly rotated and shifted by up to ±1 pixel (at the target distance) in the
// tangent plane, each compared with the exact F for its own position (Lambert's formula): so the statistics
// describe the hemicube alone, not the sample placement (the coaxial disk is rotation-invariant, so rotation
// alone would repeat one lattice alignment).
inline ErrorStats pointCaseErrors(HemicubeRenderer& renderer, const PointCase& c, int samples, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    const double pixel = 2.0 / renderer.resolution() * c.distance;
    ErrorStats stats;
    FormFactorList list;
    for (int k = 0; k < samples; ++k) {
        const glm::dvec3 p = c.point + glm::dvec3(unit(rng) * pixel, unit(rng) * pixel, 0.0);
        const double exact = pointPolygonFormFactor(p, {0, 0, 1}, c.polygon);
        const HemicubeFrame frame = HemicubeFrame::randomlyRotated(p, {0, 0, 1}, rng());
        renderer.renderFormFactors(frame, list);
        const double e = list.sum() / exact - 1.0;
        stats.rms += e * e;
        stats.mean += e;
        stats.max = std::max(stats.max, std::abs(e));
        stats.meanFormFactor += list.sum();
        stats.worstOverBound = std::max(stats.worstOverBound,
                                        std::abs(list.sum() - exact) / aliasingBound(frame, c.polygon, renderer.resolution()));
    }
    stats.rms = std::sqrt(stats.rms / samples);
    stats.mean /= samples;
    stats.meanFormFactor /= samples;
    return stats;
}

// Area form factor source → target by averaging n×n hemicubes at the source's cell centres (§3.3-ii, §3.4).
// Returns the hemicube estimate and, in `quadrature`, the same quadrature of exact point form factors.
struct AreaCase {
    std::string name;
    std::vector<glm::dvec3> target;  // polygon, front facing the source
    double groundTruth = 0.0;        // exact area form factor, §1(a)/(b)
};

inline std::vector<AreaCase> areaCases() {
    auto opposed = [](double d) {
        return std::vector<glm::dvec3>{{0, 0, d}, {0, 1, d}, {1, 1, d}, {1, 0, d}};
    };
    return {
        {"coaxial squares d=0.5", opposed(0.5), parallelRectanglesFormFactor(1, 1, 0.5)},
        {"coaxial squares d=1", opposed(1.0), parallelRectanglesFormFactor(1, 1, 1.0)},
        {"coaxial squares d=2", opposed(2.0), parallelRectanglesFormFactor(1, 1, 2.0)},
        {"perpendicular squares", {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}}, perpendicularRectanglesFormFactor(1, 1, 1)},
    };
}

// Scene: the unit source square [0,1]² (z = 0, facing +z) plus the target.
inline PatchMesh areaCaseMesh(const AreaCase& c) {
    TriangleSoup soup;
    soup.addQuad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0});
    for (std::size_t k = 1; k + 1 < c.target.size(); ++k) soup.addTriangle(c.target[0], c.target[k], c.target[k + 1]);
    return soup.build();
}

struct AreaEstimate {
    double hemicube = 0.0;    // mean F over the sample points, by hemicubes
    double quadrature = 0.0;  // mean exact point F over the same points
    double sourceSeen = 0.0;  // F to the source's own elements (must be 0)
};

inline AreaEstimate areaCaseEstimate(HemicubeRenderer& renderer, const AreaCase& c, int n, std::uint64_t seed) {
    AreaEstimate estimate;
    FormFactorList list;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const glm::dvec3 p((i + 0.5) / n, (j + 0.5) / n, 0.0);
            renderer.renderFormFactors(HemicubeFrame::randomlyRotated(p, {0, 0, 1}, seed + j * n + i), list);
            for (std::size_t k = 0; k < list.size(); ++k)
                (list.elements[k] < 2 ? estimate.sourceSeen : estimate.hemicube) += list.formFactors[k];
            estimate.quadrature += pointPolygonFormFactor(p, {0, 0, 1}, c.target);
        }
    const double count = double(n) * n;
    estimate.hemicube /= count;
    estimate.quadrature /= count;
    estimate.sourceSeen /= count;
    return estimate;
}

}  // namespace hemibake::test
