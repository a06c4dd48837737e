#pragma once
// Conservative occlusion culling for hemicubes (issue 16): a hemicube in one room of a level should not draw the
// other rooms. Each render first draws a few occluder chunks (the largest-looking ones: area / distance²) depth
// only, reads that depth back, and keeps, per face, only the chunks whose bounding box is not entirely behind it
// (a min-depth pyramid over the box's screen rectangle); a few rounds of that, each drawing twice as many of the
// largest-looking chunks still kept. The final render then draws the survivors in their usual
// order from a cleared depth buffer, so ids and gathers are identical to an unculled render: a culled chunk has
// no fragment that could have passed the depth test, and the nearest occluder at every pixel always survives.
#include <cstddef>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "raster/hemicube_weights.h"

namespace hemibake {

// What the renderer does before drawing. Typical values are the defaults.
struct OcclusionCullingSettings {
    bool enabled = true;
    // Scenes with fewer chunks than this are drawn frustum-culled only: with a few thousand triangles the extra
    // depth pass and readback cost more than they save (SceneBuffers chunks hold 32 triangles).
    std::size_t minChunks = 256;
    // The first round's occluders, as a fraction of the scene's chunks (at least one); each later round draws
    // twice as many of the largest-looking chunks not yet hidden. Occluders are drawn twice (depth pass, then in the
    // final render), so small first rounds waste least where little is hidden. level_small (46k triangles, R = 64):
    // 0.005 … 0.02 with 2 … 4 rounds all gave 4.6 … 5.0 ms per item hemicube, against 8.0 ms unculled.
    double occluderFraction = 0.01;
    // Depth-pass rounds (each one flush and readback of the depth atlas).
    int rounds = 3;
};

// Min-reduction pyramid over a depth image (reversed-Z: smaller = farther, 0 = nothing drawn): minOver() gives a
// value ≤ every depth in a pixel rectangle, reading at most 4×4 cells. Not thread-safe; reuse across renders.
class DepthPyramid {
public:
    // Rebuilds from `depth` (width × height, row-major). Allocates only when the size grows.
    void build(std::span<const float> depth, int width, int height);
    // ≤ min depth over pixels [x0, x1] × [y0, y1] (inclusive, clamped by the caller to the image).
    float minOver(int x0, int y0, int x1, int y1) const;

private:
    struct Level {
        int width = 0, height = 0;
        std::vector<float> depth;
    };
    std::vector<Level> levels_;
};

// One hemicube face as the vertex shader sees it (hemicube.cpp): view = rows · (p − eye); clip x = view.x,
// y = view.y·yScale − view.z·yOffset, w = view.z, depth = nearM / view.z.
struct FaceProjection {
    glm::vec3 right, up, forward;
    float yScale = 1.0f, yOffset = 0.0f;
    PixelRect viewport;
};

// True when nothing inside the box [boxMin, boxMax] (relative to the same origin as eye) can win a pixel of this
// face against `pyramid`, i.e. the box's nearest depth is below the minimum stored depth over its screen
// rectangle (with a margin for float rounding), or the box covers no pixel of the face. A box reaching the near
// plane is never hidden. Thread-safe (reads only).
bool boxHiddenOnFace(const glm::vec3& boxMin, const glm::vec3& boxMax, const glm::vec3& eye, float nearM,
                     const FaceProjection& face, const DepthPyramid& pyramid);

}  // namespace hemibake
