#include "raster/occlusion_culling.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hemibake {

void DepthPyramid::build(std::span<const float> depth, int width, int height) {
    if (levels_.empty()) levels_.resize(1);
    levels_[0].width = width;
    levels_[0].height = height;
    levels_[0].depth.assign(depth.begin(), depth.begin() + std::size_t(width) * std::size_t(height));
    std::size_t level = 0;
    while (levels_[level].width > 1 || levels_[level].height > 1) {
        if (levels_.size() == level + 1) levels_.emplace_back();
        const Level& fine = levels_[level];
        Level& coarse = levels_[level + 1];
        coarse.width = (fine.width + 1) / 2;
        coarse.height = (fine.height + 1) / 2;
        coarse.depth.resize(std::size_t(coarse.width) * std::size_t(coarse.height));
        for (int y = 0; y < coarse.height; ++y) {
            const int y0 = 2 * y, y1 = std::min(2 * y + 1, fine.height - 1);
            for (int x = 0; x < coarse.width; ++x) {
                const int x0 = 2 * x, x1 = std::min(2 * x + 1, fine.width - 1);
                const float* row0 = &fine.depth[std::size_t(y0) * fine.width];
                const float* row1 = &fine.depth[std::size_t(y1) * fine.width];
                coarse.depth[std::size_t(y) * coarse.width + x] =
                    std::min(std::min(row0[x0], row0[x1]), std::min(row1[x0], row1[x1]));
            }
        }
        ++level;
    }
    levels_.resize(level + 1);
}

float DepthPyramid::minOver(int x0, int y0, int x1, int y1) const {
    std::size_t level = 0;
    while (level + 1 < levels_.size() && ((x1 >> level) - (x0 >> level) > 7 || (y1 >> level) - (y0 >> level) > 7))
        ++level;
    const Level& l = levels_[level];
    float result = std::numeric_limits<float>::infinity();
    for (int y = y0 >> level; y <= std::min(y1 >> level, l.height - 1); ++y)
        for (int x = x0 >> level; x <= std::min(x1 >> level, l.width - 1); ++x)
            result = std::min(result, l.depth[std::size_t(y) * l.width + x]);
    return result;
}

bool boxHiddenOnFace(const glm::vec3& boxMin, const glm::vec3& boxMax, const glm::vec3& eye, float nearM,
                     const FaceProjection& face, const DepthPyramid& pyramid) {
    float minForward = std::numeric_limits<float>::infinity();
    float xMin = std::numeric_limits<float>::infinity(), xMax = -xMin, yMin = xMin, yMax = -xMin;
    for (int corner = 0; corner < 8; ++corner) {
        const glm::vec3 p(corner & 1 ? boxMax.x : boxMin.x, corner & 2 ? boxMax.y : boxMin.y,
                          corner & 4 ? boxMax.z : boxMin.z);
        const glm::vec3 d = p - eye;
        const float forward = glm::dot(face.forward, d);
        // Near the eye plane the projection blows up (and the clipper takes over): never call such a box hidden.
        if (!(forward > 2.0f * nearM)) return false;
        minForward = std::min(minForward, forward);
        const float x = glm::dot(face.right, d) / forward;
        const float y = glm::dot(face.up, d) / forward * face.yScale - face.yOffset;
        xMin = std::min(xMin, x);
        xMax = std::max(xMax, x);
        yMin = std::min(yMin, y);
        yMax = std::max(yMax, y);
    }
    // Pixel i covers [i, i + 1) in window coordinates; one pixel of margin each way covers rounding of the
    // projection against the GPU's.
    const PixelRect& vp = face.viewport;
    const float px0 = vp.x + 0.5f * (xMin + 1.0f) * vp.width, px1 = vp.x + 0.5f * (xMax + 1.0f) * vp.width;
    const float py0 = vp.y + 0.5f * (yMin + 1.0f) * vp.height, py1 = vp.y + 0.5f * (yMax + 1.0f) * vp.height;
    const int x0 = std::max(vp.x, int(std::floor(px0)) - 1), x1 = std::min(vp.x + vp.width - 1, int(std::floor(px1)) + 1);
    const int y0 = std::max(vp.y, int(std::floor(py0)) - 1), y1 = std::min(vp.y + vp.height - 1, int(std::floor(py1)) + 1);
    if (x0 > x1 || y0 > y1) return true;  // the box projects outside this face: it reaches none of its pixels
    // Reversed-Z: a fragment passes when its depth is greater than the stored one. Every fragment of the box is
    // at most nearM / minForward; the margin (2^-12 relative, vs 2^-20 for the back-face push and float ulps of
    // interpolation) keeps rounding from turning a tie into a pass.
    const float boxNearestDepth = nearM / minForward;
    return boxNearestDepth < pyramid.minOver(x0, y0, x1, y1) * (1.0f - 1.0f / 4096.0f);
}

}  // namespace hemibake
