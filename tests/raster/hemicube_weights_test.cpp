// raster/hemicube_weights: exact per-pixel delta form factors (GROUND_TRUTH.md §1(d), §3.1).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "raster/hemicube_weights.h"

namespace hemibake {
namespace {

class WeightsAtResolution : public ::testing::TestWithParam<int> {};

TEST_P(WeightsAtResolution, SumToOneExactlyBeforeAndAfterNormalising) {
    const HemicubeWeights weights(GetParam());
    EXPECT_EQ(weights.pixelCount(), 3u * GetParam() * GetParam());
    // The exact per-pixel sum telescopes to 4·F_par(1,1) + 4·Σ sides = 1: no discretisation error at all,
    // unlike the midpoint rule's +0.544/R² (§3.1).
    EXPECT_NEAR(weights.rawExactSum(), 1.0, 1e-10);
    EXPECT_NEAR(weights.sum(), 1.0, 1e-12);
    double floatSum = 0.0;
    for (float w : weights.weightsFloat()) floatSum += w;
    EXPECT_NEAR(floatSum, 1.0, 1e-6);  // float storage only rounds each weight (≤ 6e-8 relative)
    for (double w : weights.weights()) ASSERT_GT(w, 0.0);
}

TEST_P(WeightsAtResolution, AreSymmetric) {
    // Mirrored pixels sum the same four corner values in another order: they may differ by the long-double
    // cancellation error (a few ulps of 0.14 at 2^-64, ~1e-19 absolute) plus a double rounding.
    auto tol = [](double v) { return 1e-19 + 1e-15 * v; };
    const int r = GetParam();
    const HemicubeWeights weights(r);
    const auto w = weights.weights();
    const int width = weights.atlasWidth();
    auto at = [&](int face, int i, int j) {
        const PixelRect vp = weights.faceViewport(face);
        return w[static_cast<std::size_t>(vp.y + j) * width + vp.x + i];
    };
    for (int j = 0; j < r; ++j)
        for (int i = 0; i < r; ++i) {
            const double v = at(0, i, j);
            ASSERT_NEAR(at(0, r - 1 - i, j), v, tol(v));
            ASSERT_NEAR(at(0, i, r - 1 - j), v, tol(v));
            ASSERT_NEAR(at(0, j, i), v, tol(v));
        }
    for (int face = 1; face < HemicubeWeights::kFaceCount; ++face)
        for (int j = 0; j < r / 2; ++j)
            for (int i = 0; i < r; ++i) {
                const double v = at(1, i, j);
                ASSERT_NEAR(at(face, i, j), v, tol(v));
                ASSERT_NEAR(at(face, r - 1 - i, j), v, tol(v));
            }
}

// Independent check of exactness: 8×8-point Gauss-Legendre quadrature of the kernel over single pixels (the
// kernel is smooth at pixel scale, so the quadrature is exact to ~1e-15 relative).
double gaussPixel(bool side, double x0, double x1, double y0, double y1) {
    const double nodes[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
                             0.1834346424956498,  0.5255324099163290,  0.7966664774136267,  0.9602898564975363};
    const double weights[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                               0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
    double sum = 0.0;
    for (int a = 0; a < 8; ++a)
        for (int b = 0; b < 8; ++b) {
            const double x = 0.5 * (x0 + x1) + 0.5 * (x1 - x0) * nodes[a];
            const double y = 0.5 * (y0 + y1) + 0.5 * (y1 - y0) * nodes[b];
            const double kernel = (side ? y : 1.0) / (std::numbers::pi * std::pow(1.0 + x * x + y * y, 2.0));
            sum += weights[a] * weights[b] * kernel;
        }
    return sum * 0.25 * (x1 - x0) * (y1 - y0);
}

TEST_P(WeightsAtResolution, EveryPixelIsItsExactFormFactor) {
    const int r = GetParam();
    const HemicubeWeights weights(r);
    const auto w = weights.weights();
    double worst = 0.0;
    for (int face = 0; face < 2; ++face) {
        const PixelRect vp = weights.faceViewport(face);
        for (int j = 0; j < vp.height; ++j)
            for (int i = 0; i < vp.width; ++i) {
                const double x0 = double(2 * i - r) / r, x1 = double(2 * i + 2 - r) / r;
                const double y0 = face == 0 ? double(2 * j - r) / r : double(2 * j) / r;
                const double y1 = y0 + 2.0 / r;
                const double exact = gaussPixel(face != 0, x0, x1, y0, y1) / weights.rawExactSum();
                const double stored = w[static_cast<std::size_t>(vp.y + j) * weights.atlasWidth() + vp.x + i];
                worst = std::max(worst, std::abs(stored / exact - 1.0));
            }
    }
    // R = 2 pixels span a whole quadrant, where 8×8 Gauss is only good to ~1e-9.
    EXPECT_LT(worst, r == 2 ? 1e-8 : 1e-11) << "R = " << r;
}

INSTANTIATE_TEST_SUITE_P(Resolutions, WeightsAtResolution, ::testing::Values(2, 16, 64, 256));

TEST(HemicubeWeights, CentrePixelMatchesTheMidpointDeltaFormFactor) {
    // §3.1 "max dF (centre)"; the midpoint formula dA/(π(1+x²+y²)²) is within (1/R)² of exact there.
    const struct { int r; double centre; } table[] = {{16, 4.90e-3}, {32, 1.24e-3}, {64, 3.11e-4}, {128, 7.77e-5}, {256, 1.94e-5}};
    for (const auto& row : table) {
        const HemicubeWeights weights(row.r);
        const std::size_t centre = static_cast<std::size_t>(row.r / 2) * weights.atlasWidth() + row.r / 2;
        const double w = weights.weights()[centre];
        EXPECT_NEAR(w, row.centre, 0.01 * row.centre) << "R = " << row.r;
        const double x = 1.0 / row.r, area = 4.0 / (row.r * row.r);
        const double midpoint = area / (std::numbers::pi * std::pow(1.0 + 2.0 * x * x, 2.0));
        EXPECT_NEAR(w, midpoint, 2.0 / (row.r * row.r) * midpoint) << "R = " << row.r;
        double maxWeight = 0.0;
        for (double v : weights.weights()) maxWeight = std::max(maxWeight, v);
        EXPECT_EQ(maxWeight, w) << "the centre pixels carry the largest weight";
    }
}

TEST(HemicubeWeights, FaceBlocksMatchTheirAnalyticShares) {
    // The front face holds 4·F_par(1,1,1) (§1(d): 4 × 0.138532 ... of the unit-distance face); each side the rest/4.
    const HemicubeWeights weights(64);
    const auto w = weights.weights();
    double front = 0.0;
    const PixelRect vp = weights.faceViewport(0);
    for (int j = 0; j < vp.height; ++j)
        for (int i = 0; i < vp.width; ++i) front += w[static_cast<std::size_t>(j) * weights.atlasWidth() + i];
    EXPECT_NEAR(front, 4.0 * cornerFormFactorParallel(1.0, 1.0), 1e-13);
    EXPECT_NEAR(cornerFormFactorParallel(1.0, 1.0), 0.138532, 5e-7);
    EXPECT_NEAR(front + 4.0 * 2.0 * cornerFormFactorPerpendicular(1.0, 1.0), 1.0, 1e-14);
}

TEST(HemicubeWeights, CornerFormulasMatchGroundTruthTables) {
    // §1(d) with c = 1 (scale-free: a/c, b/c).
    EXPECT_NEAR(cornerFormFactorParallel(1.0, 2.0), 0.167375, 5e-7);
    EXPECT_NEAR(cornerFormFactorParallel(2.0, 2.0), 0.207757, 5e-7);
    EXPECT_NEAR(cornerFormFactorParallel(10.0, 10.0), 0.247971, 5e-7);  // a = b = 1, c = 0.1
    EXPECT_NEAR(cornerFormFactorPerpendicular(1.0, 1.0), 0.055734, 5e-7);
    EXPECT_NEAR(cornerFormFactorPerpendicular(1.0, 2.0), 0.095068, 5e-7);
    EXPECT_NEAR(cornerFormFactorPerpendicular(2.0, 1.0), 0.068697, 5e-7);
    EXPECT_NEAR(cornerFormFactorPerpendicular(4.0, 4.0), 0.181278, 5e-7);  // a = b = 2, c = 0.5
    EXPECT_NEAR(cornerFormFactorParallel(-1.0, 2.0), -0.167375, 5e-7);  // signed for inclusion-exclusion
}

TEST(HemicubeWeights, RejectsOddResolutions) {
    EXPECT_THROW(HemicubeWeights(63), std::invalid_argument);
    EXPECT_THROW(HemicubeWeights(0), std::invalid_argument);
}

}  // namespace
}  // namespace hemibake
