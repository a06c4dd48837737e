#pragma once
// Exact per-pixel delta form factors of a hemicube, in the atlas layout the renderer draws into.
//
// Unit half-width hemicube on dA (normal +z): full front face z = 1 (R×R pixels) and four half side faces
// (R wide × R/2 high, covering z in [0, 1]). Each pixel's weight is the exact form factor from dA to the
// pixel's rectangle (GROUND_TRUTH.md §1(d) corner formulas by inclusion-exclusion), not the midpoint
// approximation whose sum overshoots 1 by 0.544/R² (§3.1): a hemicube full of radiance L must gather
// exactly L, or a ρ = 0.999 furnace drifts by (Σ-1)/(1-ρ) (§2.E).
//
// Atlas: 3R wide × R high, rows bottom-up (glReadPixels order), row-major:
//   x in [0, R)   : front face
//   x in [R, 2R)  : side faces 1 (rows [0, R/2)) and 2 (rows [R/2, R))
//   x in [2R, 3R) : side faces 3 (rows [0, R/2)) and 4 (rows [R/2, R))
// Side-face rows count upwards from the horizon (row 0 touches z = 0).
#include <array>
#include <cstddef>
#include <span>
#include <vector>

namespace hemibake {

struct PixelRect {
    int x = 0, y = 0, width = 0, height = 0;
};

class HemicubeWeights {
public:
    static constexpr int kFaceCount = 5;  // 0 = front, 1..4 = half side faces

    // R must be even and ≥ 2.
    explicit HemicubeWeights(int resolution);

    int resolution() const { return resolution_; }
    int atlasWidth() const { return 3 * resolution_; }
    int atlasHeight() const { return resolution_; }
    std::size_t pixelCount() const { return weights_.size(); }
    PixelRect faceViewport(int face) const { return viewports_[face]; }

    // Normalised weights (Σ = 1), atlas layout. Double for accumulation; float for shaders/exports.
    std::span<const double> weights() const { return weights_; }
    std::span<const float> weightsFloat() const { return weightsFloat_; }
    // |direction through the pixel centre| for a face at unit distance: hit distance = forward depth × this.
    std::span<const float> rayLengthPerDepth() const { return rayLengthPerDepth_; }

    double rawExactSum() const { return rawExactSum_; }  // Σ of the exact weights before normalising (1 ± 1e-15)
    double sum() const { return sum_; }                  // Σ of the stored normalised weights, in double

private:
    int resolution_;
    std::array<PixelRect, kFaceCount> viewports_;
    std::vector<double> weights_;
    std::vector<float> weightsFloat_;
    std::vector<float> rayLengthPerDepth_;
    double rawExactSum_ = 0.0;
    double sum_ = 0.0;
};

// Exact form factors from dA (origin, normal +z) to axis-aligned rectangles with one corner on an axis,
// signed so that inclusion-exclusion over corners gives any rectangle (GROUND_TRUTH.md §1(d), c = 1).
// Parallel: rectangle [0,x]×[0,y] in the plane z = 1. Odd in x and in y.
double cornerFormFactorParallel(double x, double y);
// Perpendicular: rectangle x' in [0,x], z' in [0,z] in the plane y' = 1 (z ≥ 0). Odd in x.
double cornerFormFactorPerpendicular(double x, double z);

}  // namespace hemibake
