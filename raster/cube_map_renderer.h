#pragma once
// A full cube map of outgoing radiance seen from a point in free space (a light probe): what a probe stores
// before it is projected into spherical harmonics.
//
// The six faces render into one 3R×2R float atlas (face f at column f % 3, row f / 3) with per-face viewports,
// so one clear and one readback serve the whole cube. As in the hemicube (hemicube.h): reversed-Z with an
// infinite far plane, and back faces drawn opaque, black and tagged, so a probe inside a closed solid sees
// the solid's inside and can be detected. Each texel's alpha carries the hit distance with its class in the
// sign: > 0 front face at that distance (metres), < 0 back face at −alpha, 0 nothing hit (sky radiance).
//
// Texel (i, j) of face f (i to the right, j up, from the lower-left corner) looks along
// forward + s·right + t·up with s = −1 + (2i + 1)/R, t = −1 + (2j + 1)/R (see cubeFaceBasis).
#include <array>
#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "raster/chunk_culling.h"
#include "raster/scene_buffers.h"

namespace hemibake {

struct CubeFaceBasis {
    glm::dvec3 forward, right, up;  // right = forward × up (counter-clockwise triangles seen from the front stay front-facing)
};

// Faces in order +X, −X, +Y, −Y, +Z, −Z.
const CubeFaceBasis& cubeFaceBasis(int face);

// One rendered cube map, in the atlas layout (3R wide, 2R high, rows bottom to top as GL reads them back).
struct CubeMapImage {
    int resolution = 0;
    std::vector<glm::vec4> pixels;  // rgb radiance (W·m⁻²·sr⁻¹), a = signed hit distance (see above)

    static constexpr int kFaceCount = 6;
    int atlasWidth() const { return 3 * resolution; }
    int atlasHeight() const { return 2 * resolution; }
    const glm::vec4& at(int face, int i, int j) const {
        return pixels[std::size_t((face / 3) * resolution + j) * std::size_t(atlasWidth()) +
                      std::size_t((face % 3) * resolution + i)];
    }
    // Unnormalised direction of texel (i, j)'s centre on `face`.
    glm::dvec3 direction(int face, int i, int j) const;
};

class CubeMapRenderer {
public:
    // Anything nearer to the probe than this × the scene diagonal is clipped. Reversed-Z keeps depth precision
    // independent of it, so it can be tiny; a probe nearer than this to a surface sees through it.
    static constexpr double kNearPlanePerDiagonal = 5e-6;

    // `scene` (and its context) must outlive the renderer. Binds the context while creating GL objects.
    CubeMapRenderer(const SceneBuffers& scene, int resolution);
    CubeMapRenderer(const CubeMapRenderer&) = delete;
    CubeMapRenderer& operator=(const CubeMapRenderer&) = delete;

    // Element radiance from SceneBuffers::setElementRadiance; `skyRadiance` where nothing is hit.
    void render(const glm::dvec3& position, glm::vec3 skyRadiance, CubeMapImage& out);

    int resolution() const { return resolution_; }
    double nearPlaneM() const { return nearPlaneM_; }
    const SceneBuffers& scene() const { return *scene_; }
    std::size_t lastChunksDrawn() const { return lastChunksDrawn_; }

private:
    const SceneBuffers* scene_;
    int resolution_;
    double nearPlaneM_;
    GlObject framebuffer_;
    GlObject colorBuffer_;
    GlObject depthBuffer_;
    GlObject program_;
    GLint eyeUniform_ = -1, faceRowsUniform_ = -1, nearUniform_ = -1, radianceUniform_ = -1;
    ChunkRuns runs_;  // one face's multi-draw ranges
    std::size_t lastChunksDrawn_ = 0;
};

}  // namespace hemibake
