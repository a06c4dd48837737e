#include "raster/hemicube_weights.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace hemibake {

namespace {

double compensatedSum(std::span<const double> values) {  // Neumaier
    double sum = 0.0, compensation = 0.0;
    for (double v : values) {
        const double t = sum + v;
        compensation += std::abs(sum) >= std::abs(v) ? (sum - t) + v : (v - t) + sum;
        sum = t;
    }
    return sum + compensation;
}

// Pixel weights are differences of four corner values of size ~0.1, so their absolute error is a few ulps of
// 0.1; in long double (64-bit mantissa) that keeps even R = 512 corner pixels (2e-9) accurate to ~1e-11.
long double parallelCorner(long double x, long double y) {
    const long double sx = std::sqrt(1.0L + x * x);
    const long double sy = std::sqrt(1.0L + y * y);
    return (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy)) / (2.0L * std::numbers::pi_v<long double>);
}

long double perpendicularCorner(long double x, long double z) {
    const long double s = std::sqrt(1.0L + z * z);
    return (std::atan(x) - std::atan(x / s) / s) / (2.0L * std::numbers::pi_v<long double>);
}

}  // namespace

double cornerFormFactorParallel(double x, double y) { return static_cast<double>(parallelCorner(x, y)); }

double cornerFormFactorPerpendicular(double x, double z) { return static_cast<double>(perpendicularCorner(x, z)); }

HemicubeWeights::HemicubeWeights(int resolution) : resolution_(resolution) {
    if (resolution < 2 || resolution % 2 != 0)
        throw std::invalid_argument("HemicubeWeights: resolution must be even and >= 2, got " +
                                    std::to_string(resolution));
    const int r = resolution;
    const int half = r / 2;
    viewports_ = {PixelRect{0, 0, r, r}, PixelRect{r, 0, r, half}, PixelRect{r, half, r, half},
                  PixelRect{2 * r, 0, r, half}, PixelRect{2 * r, half, r, half}};

    const std::size_t width = static_cast<std::size_t>(atlasWidth());
    weights_.assign(width * static_cast<std::size_t>(atlasHeight()), 0.0);
    rayLengthPerDepth_.assign(weights_.size(), 0.0f);
    // Pixel edge i sits at (2i - R)/R: an exact integer numerator keeps mirrored pixels bit-identical.
    auto edge = [r](int i) { return static_cast<long double>(2 * i - r) / r; };
    auto centre = [r](int i) { return static_cast<double>(2 * i + 1 - r) / r; };

    for (int face = 0; face < kFaceCount; ++face) {
        const PixelRect vp = viewports_[face];
        for (int j = 0; j < vp.height; ++j) {
            for (int i = 0; i < vp.width; ++i) {
                const long double x0 = edge(i), x1 = edge(i + 1);
                long double weight;
                double v;
                if (face == 0) {
                    const long double y0 = edge(j), y1 = edge(j + 1);
                    weight = parallelCorner(x1, y1) - parallelCorner(x0, y1) - parallelCorner(x1, y0) +
                             parallelCorner(x0, y0);
                    v = centre(j);
                } else {
                    // Rows start at the horizon: z in [2j/R, 2(j+1)/R].
                    const long double z0 = edge(j + half), z1 = edge(j + half + 1);
                    weight = perpendicularCorner(x1, z1) - perpendicularCorner(x0, z1) - perpendicularCorner(x1, z0) +
                             perpendicularCorner(x0, z0);
                    v = centre(j + half);
                }
                const double u = centre(i);
                const std::size_t index = static_cast<std::size_t>(vp.y + j) * width + static_cast<std::size_t>(vp.x + i);
                weights_[index] = static_cast<double>(weight);
                rayLengthPerDepth_[index] = static_cast<float>(std::sqrt(1.0 + u * u + v * v));
            }
        }
    }

    // Compensated sums: a plain running sum over 2e5+ terms could drift towards the 1e-12 budget.
    rawExactSum_ = compensatedSum(weights_);
    weightsFloat_.resize(weights_.size());
    for (std::size_t k = 0; k < weights_.size(); ++k) {
        weights_[k] /= rawExactSum_;
        weightsFloat_[k] = static_cast<float>(weights_[k]);
    }
    sum_ = compensatedSum(weights_);
}

}  // namespace hemibake
