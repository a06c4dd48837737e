#pragma once
// Elias-style energy-preserving reduction of a weighted radiance hemicube: each level replaces 2×2 pixels by
// their sum (the pixels already hold weight × radiance), so every level's total is the full hemicube's E/π.
// Summing is done in double; odd sizes carry their last row/column into a half-covered output pixel.
#include <vector>

#include <glm/glm.hpp>

namespace hemibake {

struct WeightedRadianceImage {
    int width = 0;
    int height = 0;
    std::vector<glm::dvec3> pixels;  // row-major, weight × radiance (W·m⁻²·sr⁻¹)

    glm::dvec3 total() const;  // compensated sum
};

// One level: ⌈w/2⌉ × ⌈h/2⌉ pixels, each the sum of its (up to) 2×2 source pixels.
WeightedRadianceImage reduce2x2(const WeightedRadianceImage& image);

// All levels from `image` (level 0, copied) down to 1×1.
std::vector<WeightedRadianceImage> reductionPyramid(const WeightedRadianceImage& image);

}  // namespace hemibake
