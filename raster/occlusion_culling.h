#pragma once
// Conservative occlusion culling for hemicubes (issue 16): a hemicube in one room of a level should not draw the
// other rooms. Each render first draws a few occluder chunks (the largest-looking ones: area / distance²), shaded,
// into its cleared target, reads the depth back, and keeps, per face, only the chunks whose bounding box is not
// entirely behind it (a min-depth pyramid over the box's screen rectangle; whole subtrees of the chunk tree at
// once); a few rounds of that, each drawing twice as many of the largest-looking chunks still kept. Then the
// survivors not yet drawn are drawn on top. Every chunk is drawn at most once, and a culled chunk has no fragment
// that could have passed the depth test, so ids and gathers equal an unculled render's except where two fragments
// tie exactly in depth (coplanar overlapping faces): there the first drawn wins, and the occluders are drawn first.
#include <cstddef>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "raster/hemicube_weights.h"

namespace hemibake {

// What the renderer does before drawing. Typical values are the defaults.
struct OcclusionCullingSettings {
    bool enabled = true;
    // Scenes with fewer chunks than this are drawn frustum-culled only: with a few thousand triangles the
    // readbacks cost more than culling saves (SceneBuffers chunks hold 16 triangles).
    std::size_t minChunks = 256;
    // The first round's occluders, as a fraction of the scene's chunks (at least one); each later round draws
    // twice as many of the largest-looking chunks not yet hidden. level_small (74k triangles, 32-triangle chunks,
    // R = 64, occluders drawn once): 0.005 … 0.02 with 3 … 5 rounds all gave 2.5 … 2.8 ms per item hemicube
    // (0.01 with 4 rounds: 2.5), 2 rounds with 0.005 gave 3.8 ms; unculled 8.6 ms.
    double occluderFraction = 0.01;
    // Culling rounds (each one flush and readback of the depth atlas).
    int rounds = 4;
};

// Min-reduction pyramid over a depth image (reversed-Z: smaller = farther, 0 = nothing drawn): minOver() gives a
// value ≤ every depth in a pixel rectangle, reading at most 8×8 cells. Not thread-safe; reuse across renders.
class DepthPyramid {
public:
    // Rebuilds from `depth` (width × height, row-major). Allocates only when the size grows.
    void build(std::span<const float> depth, int width, int height);
    // ≤ min depth over pixels [x0, x1] × [y0, y1] (inclusive, clamped by the caller to the image), reading at most
    // 8 × 8 cells of the finest level that allows it (8 × 8 rather than 4 × 4: 5 % fewer triangles drawn on level_small).
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
