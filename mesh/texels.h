#pragma once
// Lightmap texels: where on the surface each covered atlas texel samples.
//
// Coverage is conservative: every texel that a chart triangle touches (overlaps by more than
// kCoverageShrinkTexels = 1e-3 texel, which absorbs float rounding of the stored UVs) gets exactly one sample.
// The sample point is the texel centre when the centre lies inside a triangle of the atlas, else the closest
// point (in UV) on the triangles touching the texel, stepped borderInsetTexels toward that triangle's centroid
// (at most half way): chart edges are often concave corners, where every estimator — hemicube or path tracer —
// is at its worst. Among several candidates (neighbouring triangles, or overlapping existing UVs) the closest
// wins, ties going to the first in chart order. The world position is
// interpolated in double with the sample's barycentric coordinates; the normal is the face's geometric normal
// (the side counter-clockwise winding faces).
//
// The position is then nudged off the surface along that normal by
//     offset = normalOffsetRelative × the bounding-box diagonal of the texel's island   metres
// (default 1e-5: 10 µm for a 1 m scene, 1 mm for a 100 m level; an island is the scene unless its parts lie far
// apart, mesh/islands.h), but at least normalOffsetFloatSteps float steps at the island's farthest coordinate from
// the scene's centre (binds only for an island far from it: 0.9 mm at 1.8 km). Relative to sizes, never to the
// distance from the origin: the ray tracer and the rasterizer work relative to the scene's centre, so a level 1e6 m
// out needs no larger offset, and an offset of 1e-5 × |position| pushed its samples metres off their surfaces
// (and a 0.5 mm scene's by 2 % of its size). Moving samples out of nearby intersecting geometry is the baker's job.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "mesh/uv_atlas.h"

namespace hemibake {

struct TexelSettings {
    double normalOffsetRelative = 1e-5;  // × the diagonal of the texel's island (mesh/islands.h); 0: no nudge
    double normalOffsetFloatSteps = 4.0;   // at least this many float steps at the island's farthest coordinate
    double coverageShrinkTexels = kCoverageShrinkTexels;
    double borderInsetTexels = 0.25;  // texels whose centre is outside the chart sample this far inside it
};

// The covered texels of one atlas as structure-of-arrays, in row-major order (y, then x).
struct AtlasTexels {
    std::int32_t atlas = 0;
    std::int32_t size = 0;
    std::vector<std::uint16_t> x, y;           // texel column, row (row 0 at the top, v down)
    std::vector<glm::dvec3> position;          // world space, nudged along the normal
    std::vector<glm::vec3> normal;             // unit geometric normal of the face
    std::vector<std::int32_t> instance;        // Scene::instances index
    std::vector<std::int32_t> face;            // SurfaceMesh face index within the instance
    std::vector<glm::vec3> barycentric;        // of the (un-nudged) sample, weights of the face's corners in
                                               // the order of its unwrapped triangle
    std::vector<std::uint8_t> centreInside;    // 1: sample at the texel centre; 0: closest point of the chart

    std::size_t count() const { return x.size(); }
};

std::vector<AtlasTexels> computeTexels(const Scene& scene, const UvAtlas& atlas, const TexelSettings& settings = {});

}  // namespace hemibake
