#pragma once
// Islands: groups of a scene's parts that lie near each other, each with its own length scale.
//
// Lengths that must stand above rounding error (ray epsilons, offsets off a surface, welding tolerances) were sized
// by the whole scene's diagonal. A level whose parts lie kilometres apart then gave every part the lengths of a
// 3.7 km scene: a 15 mm ray epsilon where its parts overlap by 1-5 cm, so elements counted as covered and texels as
// inside geometry, and each copy's surfaces baked a median 15-23 % off the same copy alone (docs/performance.md,
// sessions 42 and 43). Sized by its island, a part keeps the lengths it has alone, raised only where float precision
// requires: Embree and the rasterizer hold positions as floats relative to the scene's centre, so an island 1.5 km
// from it cannot use an epsilon below a few float steps there (floatStepM).
//
// Two parts belong to one island when the gap between their bounding boxes is at most the larger box's diagonal (a
// chair beside a table, two plates facing each other, rooms sharing walls; not copies of a room a kilometre apart);
// islands are the connected groups of that relation. A scene of one island, which every level whose parts touch is,
// keeps exactly the lengths it had before islands: there the float term never exceeds the relative one (see
// lengthM).
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "mesh/patches.h"
#include "mesh/scene.h"

namespace hemibake {

// The spacing of floats near a coordinate of magnitude `magnitudeM` (an upper bound: 2⁻²³ of it).
inline double floatStepM(double magnitudeM) { return magnitudeM * 0x1p-23; }

class SceneIslands {
public:
    // Groups parts given by their bounding boxes (empty or non-finite boxes form islands of their own that islandAt
    // never returns). `frameCentre` is where float coordinates are taken from (the scene bounds' centre). A sweep along
    // the longest axis: O(n log n) plus the pairs whose boxes come close along it. Throws std::bad_alloc only.
    SceneIslands(std::span<const Bounds> partBounds, const glm::dvec3& frameCentre);
    // The scene's instances as parts, its bounds' centre as the frame centre.
    static SceneIslands ofScene(const Scene& scene);
    // The elements grouped by instance (ElementArrays::instance) as parts, the vertices of each instance's elements
    // giving its box; floats taken from `frameCentre` (where the consumer holds its floats from).
    static SceneIslands ofElements(const ElementArrays& elements, const glm::dvec3& frameCentre);

    std::size_t size() const { return bounds_.size(); }
    std::size_t islandOfPart(std::size_t part) const { return islandOfPart_[part]; }
    const Bounds& bounds(std::size_t island) const { return bounds_[island]; }

    // The island whose box holds p; else the nearest of the islands whose boxes meet p's cell of the lookup grid, or
    // of all islands when none does (ties to the lower index); 0 when there are none. Thread-safe; O(1) with one
    // island, else a cell's few candidates.
    std::size_t islandAt(const glm::dvec3& p) const;

    // max(relative × the island's diagonal, floatSteps × floatStepM(its farthest coordinate from the frame centre)).
    // In a scene of one island the second term is at most floatSteps × 2⁻²⁴ × the diagonal, so with floatSteps ≤
    // relative × 2²⁴ (67 for the ray epsilon's 4e-6) the length is exactly relative × the diagonal, as before.
    double lengthM(std::size_t island, double relative, double floatSteps) const;
    double lengthAtM(const glm::dvec3& p, double relative, double floatSteps) const {
        return lengthM(islandAt(p), relative, floatSteps);
    }
    // The largest lengthM over the islands (0 with none): for a tolerance that must hold everywhere at once.
    double largestLengthM(double relative, double floatSteps) const;
    // The largest island's bounding-box diagonal (0 with none): the extent a bake's sizes follow, so copies of a level
    // kilometres apart are sized as the level alone. Equals the scene's diagonal when its parts form one island.
    double largestDiagonalM() const;

private:
    double distanceToIsland(std::size_t island, const glm::dvec3& p) const;

    std::vector<std::uint32_t> islandOfPart_;
    std::vector<Bounds> bounds_;
    std::vector<double> farthestM_;  // per island: its largest |coordinate − frame centre| over the three axes
    // Lookup grid over the non-empty islands' boxes (only with two islands or more).
    Bounds gridBounds_;
    glm::ivec3 cells_{0};
    glm::dvec3 cellSizeM_{1.0};
    std::vector<std::uint32_t> cellStart_, cellIslands_;
    std::size_t cellIndex(const glm::ivec3& c) const {
        return (std::size_t(c.z) * std::size_t(cells_.y) + std::size_t(c.y)) * std::size_t(cells_.x) + std::size_t(c.x);
    }
};

}  // namespace hemibake
