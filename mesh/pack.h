#pragma once
// Chart packing for lightmap atlases (xatlas-style bitmap packing).
//
// Each chart (UVs in metres) is turned to its minimal-area oriented bounding box (best edge direction of its
// convex hull), made landscape, scaled to `texelsPerUnit` and rasterized conservatively into a footprint: every
// texel the chart's triangles touch (see forEachTouchedTexel), in 4 orientations (0°, 90°, 180°, 270°;
// duplicates of symmetric charts dropped). Charts are placed largest first on a square canvas that stores the
// occupied texels as sorted runs per row, so a chart can drop into holes and notches of others (arcs nest
// into arcs). Each chart goes where the square holding everything placed so far grows least (xatlas' metric),
// ties going to the smaller extent area, then the higher, then the left-most position. A chart's footprint
// grown by `paddingTexels` (square dilation) may not overlap any other footprint, so at least
// `paddingTexels` free texels separate any two charts; footprints also keep `borderTexels` from the edge.
//
// Atlas size: when everything fits one `maxAtlasSize` canvas, the atlas is the used square rounded up to a
// multiple of `sizeMultiple` (or a power of two). Otherwise atlases are filled group by group (a group is an
// instance: all its charts share an atlas), each group going into the current atlas if all its charts fit,
// and every atlas is cut to its used square. A chart larger than an atlas, or a group that cannot fit one
// empty atlas, is scaled down until it fits (warning).
//
// Texel coordinates: x right, y down (rows from the top); texel (i, j) covers [i, i+1] × [j, j+1] and its
// centre is at UV ((i + 0.5)/size, (j + 0.5)/size) — glTF TEXCOORD_1 (origin top-left, v down). Packing only
// rotates and translates (never mirrors), so every chart keeps the orientation of its parameterization.
#include <array>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace hemibake {

// Calls visit(i, j) for every texel whose square, shrunk by `shrink` texels on each side, intersects the
// triangle abc (texel coordinates). shrink = 0 is closed conservative coverage (texels merely touched at an
// edge count); a small positive shrink ignores contact thinner than `shrink`. Exact for any triangle,
// including slivers and degenerate ones.
template <class Visit>
void forEachTouchedTexel(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c, double shrink, Visit&& visit) {
    const glm::dvec2 p[3] = {a, b, c};
    const double ymin = std::min({a.y, b.y, c.y}), ymax = std::max({a.y, b.y, c.y});
    if (!std::isfinite(ymin) || !std::isfinite(ymax)) return;
    const long j0 = long(std::ceil(ymin - 1.0 + shrink)), j1 = long(std::floor(ymax - shrink));
    for (long j = j0; j <= j1; ++j) {
        const double lo = double(j) + shrink, hi = double(j + 1) - shrink;
        double xmin = INFINITY, xmax = -INFINITY;
        for (int k = 0; k < 3; ++k) {
            const glm::dvec2& u = p[k];
            const glm::dvec2& v = p[(k + 1) % 3];
            if (u.y >= lo && u.y <= hi) {
                xmin = std::min(xmin, u.x);
                xmax = std::max(xmax, u.x);
            }
            for (double line : {lo, hi}) {
                if ((u.y < line && v.y > line) || (u.y > line && v.y < line)) {
                    const double x = u.x + (line - u.y) * (v.x - u.x) / (v.y - u.y);
                    xmin = std::min(xmin, x);
                    xmax = std::max(xmax, x);
                }
            }
        }
        if (!(xmin <= xmax)) continue;
        const long i0 = long(std::ceil(xmin - 1.0 + shrink)), i1 = long(std::floor(xmax - shrink));
        for (long i = i0; i <= i1; ++i) visit(i, j);
    }
}

// Footprints are rasterized with this shrink (texels); consumers of the final float UVs (texels, tests) use
// kCoverageShrinkTexels, larger by more than float rounding of UVs, so every texel they see as covered is
// inside the packer's footprint.
inline constexpr double kPackShrinkTexels = 2.5e-4;
inline constexpr double kCoverageShrinkTexels = 1e-3;

struct PackSettings {
    double texelsPerUnit = 128.0;  // texels per UV unit (per metre for hemibake's charts)
    int maxAtlasSize = 1024;       // texels (at most 8192); further atlases are opened when one is full
    int paddingTexels = 2;         // free texels between the footprints of any two charts (≥ 0)
    int borderTexels = 1;          // free texels between footprints and the atlas edge
    bool allowRotation = true;     // minimal-area oriented bounding box, then 0° or 90°
    bool powerOfTwo = false;       // atlas sizes powers of two (else multiples of sizeMultiple)
    int sizeMultiple = 4;
    bool keepGroupsTogether = true;  // all charts of one group share an atlas
};

struct PackChartInput {
    std::span<const glm::dvec2> uv;                        // chart UVs (metres)
    std::span<const std::array<std::int32_t, 3>> triangles;  // indices into uv
    std::int32_t group = 0;                                // e.g. the instance
};

struct PackedChart {
    std::int32_t atlas = -1;
    // Atlas texel coordinates of a chart point: T = scale · R(angleRad) · uv + offset; UV = T / atlas size.
    double angleRad = 0.0;
    double scale = 0.0;  // texels per UV unit actually used (texelsPerUnit unless scaled down)
    glm::dvec2 offset{0.0};
    std::int32_t x = 0, y = 0, width = 0, height = 0;  // footprint bounding rectangle, texels
    std::uint32_t footprintTexels = 0;                 // texels touched (packer raster)
    bool scaledDown = false;

    glm::dvec2 toTexels(const glm::dvec2& uv) const {
        double c = std::cos(angleRad), s = std::sin(angleRad);
        if (std::abs(c) < 1e-15) c = 0.0;  // exact quarter turns, as the packer rasterized them
        if (std::abs(s) < 1e-15) s = 0.0;
        return scale * glm::dvec2(c * uv.x - s * uv.y, s * uv.x + c * uv.y) + offset;
    }
};

struct PackResult {
    std::vector<PackedChart> charts;               // parallel to the input
    std::vector<std::int32_t> atlasSize;           // per atlas, texels (square)
    std::vector<std::uint64_t> atlasFootprintTexels;  // per atlas, Σ chart footprints
    std::size_t scaledDownCharts = 0;
    std::vector<std::string> warnings;

    double utilization() const;  // Σ footprints / Σ atlas texels
};

// A group whose charts do not fit one empty maxAtlasSize atlas even at the smallest scale: each chart takes at least
// one texel plus its padding, so too many charts for the atlas size and padding cannot share one atlas.
class PackError : public std::runtime_error {
public:
    PackError(std::int32_t group, std::size_t charts, const std::string& message)
        : std::runtime_error(message), group_(group), charts_(charts) {}
    std::int32_t group() const { return group_; }
    std::size_t charts() const { return charts_; }

private:
    std::int32_t group_;
    std::size_t charts_;
};

// Throws PackError when a group cannot fit one atlas (with keepGroupsTogether; else when one chart cannot).
PackResult packCharts(std::span<const PackChartInput> charts, const PackSettings& settings);

}  // namespace hemibake
