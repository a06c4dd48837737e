#pragma once
// Lightmap UV unwrapping of a whole scene: charts → parameterization → packing → per-instance unwrapped
// vertex sets carrying TEXCOORD_1.
//
// Charts cut the mesh, so seam vertices are duplicated: every chart has its own vertices. Per instance the
// result is an "unwrapped mesh" — arrays the glTF writer emits instead of the input vertex set:
//   uv[k]           TEXCOORD_1 of unwrapped vertex k, in [0,1], glTF convention (origin top-left, v down);
//                   texel (i, j) of an atlas of size S has its centre at ((i+0.5)/S, (j+0.5)/S)
//   vertexSource[k] the SurfaceMesh vertex it copies (position, normal, TEXCOORD_0 come from there)
//   triangles[t]    unwrapped triangle t (indices into the unwrapped vertices), same winding as the input
//   faceSource[t]   the SurfaceMesh face it copies (SurfaceMesh::sourceFace gives the glTF triangle index)
// Every unwrapped triangle has positive signed area in (u, v) taken as plain numbers (charts are never
// mirrored), i.e. it appears clockwise in the image with v down; no UV triangle is flipped or degenerate.
// Each chart owns a contiguous run of unwrapped vertices and triangles (AtlasChart::first*/count).
// All charts of one instance lie in one atlas (UnwrappedInstance::atlas), so a glTF primitive needs a
// single lightmap texture.
//
// Existing UVs: with keepExistingUv, an instance that carries TEXCOORD_1 with every coordinate inside [0,1]
// keeps it exactly (its unwrapped vertices are its SurfaceMesh vertices, one pseudo-chart) and gets an atlas
// of its own, sized so that its mean density is texelsPerUnit (clamped to maxAtlasSize). Overlapping or
// mirrored existing UVs are used as they are. Existing UVs outside [0,1] are ignored with a warning and the
// instance is unwrapped like the others.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mesh/charts.h"
#include "mesh/pack.h"
#include "mesh/parameterize.h"
#include "mesh/scene.h"

namespace hemibake {

struct UnwrapSettings {
    double texelsPerUnit = 128.0;  // lightmap texels per metre
    int maxAtlasSize = 1024;       // texels (square atlases, at most 8192)
    int paddingTexels = 2;         // free texels between charts (≥ 2 recommended for bilinear + dilation)
    int borderTexels = 1;          // free texels at the atlas edge
    bool allowRotation = true;
    bool powerOfTwo = false;       // atlas sizes: powers of two, else multiples of sizeMultiple
    int sizeMultiple = 4;
    bool keepExistingUv = false;   // instances with TEXCOORD_1 in [0,1] keep theirs (own atlas each)
    ChartSettings charts;
    ParameterizeSettings parameterize;

    PackSettings packSettings() const;
};

struct UnwrappedInstance {
    std::int32_t atlas = -1;    // the atlas all its charts are in (-1: no triangles)
    bool existingUv = false;    // TEXCOORD_1 from the input kept
    std::vector<glm::vec2> uv;                          // per unwrapped vertex, TEXCOORD_1
    std::vector<std::int32_t> vertexSource;             // unwrapped vertex → SurfaceMesh vertex index
    std::vector<std::array<std::uint32_t, 3>> triangles;  // unwrapped triangles
    std::vector<std::int32_t> faceSource;               // unwrapped triangle → SurfaceMesh face index
    std::uint32_t firstChart = 0, chartCount = 0;       // its charts in UvAtlas::charts
    std::array<std::int32_t, 4> rect{0, 0, 0, 0};       // x, y, width, height: bounding box of its charts, texels
};

struct AtlasChart {
    std::int32_t instance = -1;
    std::int32_t atlas = -1;
    std::uint32_t firstVertex = 0, vertexCount = 0;  // run in the instance's unwrapped vertices
    std::uint32_t firstTriangle = 0, triangleCount = 0;  // run in the instance's unwrapped triangles
    ParamMethod method = ParamMethod::Planar;
    bool scaledDown = false;
    double texelsPerUnit = 0.0;  // density actually used
    std::int32_t x = 0, y = 0, width = 0, height = 0;  // footprint rectangle in the atlas, texels
    std::uint32_t footprintTexels = 0;
    double areaM2 = 0.0;
    StretchStats stretch;
};

struct AtlasPage {
    std::int32_t size = 0;              // square, texels
    std::uint32_t charts = 0;
    std::uint64_t coveredTexels = 0;    // texels covered by some chart (kCoverageShrinkTexels raster of the final UVs)
    std::uint64_t overlappingTexels = 0;  // texels covered by two charts (0 unless existing UVs overlap)
    double utilization = 0.0;           // coveredTexels / size²
};

struct UnwrapStats {
    std::size_t instances = 0;
    std::size_t existingUvInstances = 0;
    std::size_t triangles = 0;
    std::size_t charts = 0;          // after parameterization splits
    std::size_t planarCharts = 0;
    std::size_t lscmCharts = 0;
    std::size_t perTriangleCharts = 0;
    std::size_t chartSplits = 0;     // non-disk and failed-parameterization splits
    std::size_t scaledDownCharts = 0;
    std::size_t badUvTriangles = 0;  // flipped/degenerate UV triangles in the result (0 unless the input has zero-area triangles)
    std::uint64_t coveredTexels = 0;
    std::uint64_t atlasTexels = 0;
    std::uint64_t overlappingTexels = 0;
    double utilization = 0.0;        // coveredTexels / atlasTexels
    StretchStats stretch;            // over all unwrapped (not existing) charts
    double chartSeconds = 0.0, parameterizeSeconds = 0.0, packSeconds = 0.0, totalSeconds = 0.0;
};

struct UvAtlas {
    double texelsPerUnit = 0.0;
    std::vector<UnwrappedInstance> instances;  // parallel to Scene::instances
    std::vector<AtlasChart> charts;
    std::vector<AtlasPage> atlases;
    UnwrapStats stats;
    std::vector<std::string> warnings;
};

UvAtlas unwrapScene(const Scene& scene, const UnwrapSettings& settings = {});

}  // namespace hemibake
