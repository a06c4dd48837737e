#pragma once
// Chart parameterization for lightmap unwrapping.
//
// Planar charts are projected orthogonally onto their plane (exact: zero stretch). Curved charts are flattened
// with least-squares conformal maps (Lévy et al. 2002): two far-apart vertices (extremes along the chart's
// principal direction in its best-fit plane) are pinned at their projected positions and the conformal energy
// is minimized through the normal equations with Eigen's SimplicialLDLT.
//
// Every result is checked: a UV triangle must have positive signed area of at least `minAreaRatio` times its
// 3D area (no flips, no degenerate triangles), and the chart's UV boundary must not cross itself. A chart that
// fails is halved along its principal axis and its parts are parameterized again, recursively; past
// `maxSplitDepth` a part falls back to per-triangle planar projection, which cannot fail. So a result never
// has flipped or degenerate UV triangles (input triangles of zero 3D area excepted — the loader drops those).
//
// UVs are in metres: every chart is scaled uniformly so that its UV area equals its surface area (1 UV unit =
// 1 m). Front faces (counter-clockwise around their normal) are counter-clockwise in UV (u right, v up).
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "mesh/charts.h"

namespace hemibake {

enum class ParamMethod : std::uint8_t { Planar, Lscm, PerTriangle, Existing };
const char* paramMethodName(ParamMethod m);

struct ParameterizeSettings {
    double minAreaRatio = 1e-3;    // UV area / 3D area below this (after area normalization) = degenerate
    double planarToleranceRad = 1e-3;  // parts of split charts with all normals within this are projected
    int maxSplitDepth = 10;        // failed charts are halved at most this deep, then go per-triangle
    bool checkBoundaryOverlap = true;
};

// Distortion of the map from UV (metres) to the surface (Sander et al. 2001). Per triangle, with singular
// values Γ ≥ γ of the Jacobian: L2 = √((Γ²+γ²)/2), angle distortion Γ/γ (1 = conformal), area distortion
// max(Γγ, 1/(Γγ)) (1 = area-preserving). Means are weighted by 3D area; l2 is the area-weighted RMS as in
// Sander's L2(M). An isometric chart has every figure equal to 1.
struct StretchStats {
    double l2 = 1.0;
    double linf = 1.0;       // max Γ
    double meanAngle = 1.0;  // area-weighted mean of Γ/γ
    double maxAngle = 1.0;
    double meanArea = 1.0;   // area-weighted mean of max(Γγ, 1/Γγ)
    double maxArea = 1.0;
    double areaM2 = 0.0;     // 3D area the means are weighted over

    void merge(const StretchStats& other);
};

struct ParamChart {
    std::int32_t sourceChart = -1;  // the ChartSet chart it came from (several ParamCharts after a split)
    ParamMethod method = ParamMethod::Planar;
    std::vector<std::int32_t> faces;                   // mesh face indices
    std::vector<std::int32_t> vertices;                // chart-local vertex → mesh vertex index
    std::vector<std::array<std::int32_t, 3>> triangles;  // per face (same order), chart-local vertex indices
    std::vector<glm::dvec2> uv;                        // per chart-local vertex, metres
    double areaM2 = 0.0;
    StretchStats stretch;
};

struct ParameterizeStats {
    std::size_t planar = 0;
    std::size_t lscm = 0;
    std::size_t perTriangle = 0;       // charts made by the last-resort per-triangle fallback
    std::size_t splits = 0;            // charts split because their parameterization failed or was not a disk
    std::size_t failedLscm = 0;        // LSCM solves rejected (flips, degenerate, overlap, solver failure)
    std::size_t flippedOrDegenerate = 0;  // UV triangles in the final result with area ≤ minAreaRatio·area (should be 0)
    StretchStats stretch;
};

struct ParameterizationResult {
    std::vector<ParamChart> charts;
    ParameterizeStats stats;
};

ParameterizationResult parameterizeCharts(const SurfaceMesh& mesh, const ChartSet& charts,
                                          const ParameterizeSettings& settings = {});

// ---- Building blocks (public for tests) ------------------------------------------------------------------

// Builds the chart-local vertex list and triangles of `faces` (ParamChart without UVs).
ParamChart makeLocalChart(ChartWorkspace& ws, std::span<const std::int32_t> faces);
// Orthogonal projection onto the plane with normal n through the chart (UV in metres, counter-clockwise).
void projectPlanar(const SurfaceMesh& mesh, ParamChart& chart, const glm::dvec3& n);
// LSCM; false if the solver fails. UVs are then scaled to preserve the chart's total area.
bool solveLscm(const SurfaceMesh& mesh, ParamChart& chart);
// Uniform scale so that UV area = 3D area. False if the UV area is not positive.
bool normalizeArea(const SurfaceMesh& mesh, ParamChart& chart);
// Number of UV triangles with signed area ≤ minAreaRatio × their 3D area (zero-area input triangles, as the
// loader's degeneracy test defines them, are not counted).
std::size_t countBadTriangles(const SurfaceMesh& mesh, const ParamChart& chart, double minAreaRatio);
// True if two non-adjacent boundary edges of the chart cross in UV.
bool boundaryOverlaps(const ParamChart& chart);
StretchStats measureStretch(const SurfaceMesh& mesh, const ParamChart& chart);

}  // namespace hemibake
