#pragma once
// Error figures of a result A against a reference B: two bakes (or a bake and a `reference --texels` output),
// texel for texel over the covered texels of the bake's layout, or two images of equal size, pixel for pixel.
//
// Definitions (every texel contributes its three channels as three samples; B is the reference):
//   floor_c             = kFloorFractionOfMean × mean over the compared texels of |b_c|, per channel c, so the
//                         darkest corners of a lit scene do not dominate (if B is black in a channel, the
//                         floor is that fraction of B's mean over all channels, and at the least FLT_MIN)
//   relative error      r = |a − b| / max(|b|, floor_c); signed relative error (a − b) / max(|b|, floor_c)
//   meanRelativeError   mean of r
//   p95RelativeError    95th percentile of r, nearest rank (the value at position ceil(0.95·n) in ascending order)
//   maxRelativeError    max of r
//   meanSignedRelativeError  mean of the signed relative error (bias: < 0 when A is darker than B)
//   rmse                sqrt(mean of (a − b)²), in the values' units (W·m⁻²·sr⁻¹ for lightmaps)
//   relativeMse         mean of (a − b)² / (b² + floor_c²)
//   relativeRmseAgainstTruth   when B is a path-traced estimate that carries its standard error σ_b per texel
//                       (`reference --texels` writes it beside each atlas): A's RMS error against the noise-free
//                       answer, relative to the mean m of B over the texel's primitive (over the image for texels of
//                       none): sqrt(max(0, mean of ((a − b)² − σ_b²) / (m_c² + floor_c²))). E[(a − b)²] = (a − t)² + σ_b²
//                       when B's noise is independent of A, and m carries no texel's noise, so the figure is unbiased
//                       and a result better than the reference's own noise still scores (a per-texel denominator b
//                       would correlate with the noise and bias it by ≈ 4·δ·σ²/t²)
//   referenceNoiseRelativeRms  sqrt(mean of σ_b² / (m_c² + floor_c²)): B's own noise on that scale
//   meanA, meanB        per channel means over the compared texels
// The floor is computed once over all compared texels (global), so the per-atlas and per-primitive figures
// use the same scale as the global ones.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace hemibake {

inline constexpr double kFloorFractionOfMean = 0.01;
inline constexpr double kPercentile = 0.95;

struct ErrorStats {
    std::uint64_t texels = 0;  // texels (or pixels) compared
    double meanRelativeError = 0.0;
    double meanSignedRelativeError = 0.0;
    double p95RelativeError = 0.0;
    double maxRelativeError = 0.0;
    double rmse = 0.0;
    double relativeMse = 0.0;
    double relativeRmseAgainstTruth = -1.0;   // < 0: B carries no standard error
    double referenceNoiseRelativeRms = -1.0;  // < 0: B carries no standard error
    glm::dvec3 meanA{0.0}, meanB{0.0};

    bool knowsReferenceNoise() const { return referenceNoiseRelativeRms >= 0.0; }
};

// One image pair: a lightmap atlas of both sides, or the two images.
struct ComparedImage {
    std::string name;  // atlas file relative to the bake directory, or the image file name
    int width = 0, height = 0;
    std::vector<glm::vec3> a, b;            // width × height, rows top to bottom
    std::vector<glm::vec3> bStandardError;  // B's standard error per pixel and channel, or empty (B is exact)
    std::vector<std::uint8_t> compared;     // 1 where a texel is compared (covered), per pixel
    std::vector<std::int32_t> primitive;    // per pixel: index into Comparison::primitives, −1 = none
    std::uint64_t insideTexels = 0;         // covered texels left out: inside or under geometry
    // Results, filled by computeErrors:
    std::vector<glm::vec3> signedRelativeError;  // per pixel and channel; NaN where not compared
    ErrorStats stats;
};

struct PrimitiveComparison {
    nlohmann::json entry;  // the bake.json primitives[] entry (node, mesh, primitive, lightmap, rect)
    ErrorStats stats;
};

struct Comparison {
    std::string mode;  // "lightmaps" or "images"
    std::string a, b;  // the inputs as given
    glm::dvec3 floor{0.0};
    ErrorStats global;
    std::vector<ComparedImage> images;
    std::vector<PrimitiveComparison> primitives;
    std::vector<std::string> warnings;

    nlohmann::json toJson() const;  // "hemibake-compare/1"
};

// Fills floor, global, per-image and per-primitive figures and the signed error maps of `c.images`.
// Throws std::invalid_argument when an image's arrays do not match its size.
void computeErrors(Comparison& c);

// Two images of equal size (any format OpenImageIO reads; EXR for linear values). Throws InputError naming the
// file for unreadable inputs or mismatched sizes.
Comparison compareImageFiles(const std::filesystem::path& a, const std::filesystem::path& b);

// Two bake directories (bake.json) or `reference --texels` outputs (reference.json). Covered texels come from the
// bake's layout (loadBakeLayout of A, else of B, else of the bake a reference was made from); when no layout can
// be loaded, texels non-zero in A or B are compared instead (with a warning). Unless `includeInsideGeometry`,
// covered texels inside or under geometry (baker/inside_geometry.h: never seen, refilled by the bake, black to a
// path tracer) are left out and counted in ComparedImage::insideTexels. Primitives are the bake.json list;
// each owns the texels of its instance (matched by lightmap file and rectangle). Throws InputError with a
// one-line message naming the file when the two do not share a layout (lightmap files, primitives, sizes).
// B's `<atlas>.stderr.exr` files, when all are there, give the reference-noise figures.
Comparison compareLightmapDirectories(const std::filesystem::path& a, const std::filesystem::path& b,
                                      bool includeInsideGeometry = false);

// Either of the above, by what the paths are (both directories or both files).
Comparison compareInputs(const std::filesystem::path& a, const std::filesystem::path& b, bool includeInsideGeometry = false);

nlohmann::json toJson(const ErrorStats& s);

// Per pixel, the signed relative error of the channel whose error is largest in magnitude (NaN = not compared):
// the scalar the false-colour map shows, so no channel's error is hidden.
std::vector<float> worstChannelError(const ComparedImage& image);

}  // namespace hemibake
