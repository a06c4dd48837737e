#include "raster/hemicube_reduction.h"

#include <cmath>
#include <cstddef>

namespace hemibake {

glm::dvec3 WeightedRadianceImage::total() const {
    glm::dvec3 sum(0.0), compensation(0.0);  // Neumaier, per channel
    for (const glm::dvec3& p : pixels) {
        for (int c = 0; c < 3; ++c) {
            const double t = sum[c] + p[c];
            compensation[c] += std::abs(sum[c]) >= std::abs(p[c]) ? (sum[c] - t) + p[c] : (p[c] - t) + sum[c];
            sum[c] = t;
        }
    }
    return sum + compensation;
}

WeightedRadianceImage reduce2x2(const WeightedRadianceImage& image) {
    WeightedRadianceImage out;
    out.width = (image.width + 1) / 2;
    out.height = (image.height + 1) / 2;
    out.pixels.assign(static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height), glm::dvec3(0.0));
    for (int y = 0; y < image.height; ++y) {
        const glm::dvec3* row = &image.pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width)];
        glm::dvec3* target = &out.pixels[static_cast<std::size_t>(y / 2) * static_cast<std::size_t>(out.width)];
        for (int x = 0; x < image.width; ++x) target[x / 2] += row[x];
    }
    return out;
}

std::vector<WeightedRadianceImage> reductionPyramid(const WeightedRadianceImage& image) {
    std::vector<WeightedRadianceImage> levels{image};
    while (levels.back().width > 1 || levels.back().height > 1) levels.push_back(reduce2x2(levels.back()));
    return levels;
}

}  // namespace hemibake
