#pragma once
// One hemicube, two read-outs: the item buffer (which element each pixel sees → sparse form factors, for
// shooting) and the radiance buffer (what each pixel sees → E/π, for gathering).
//
// All five faces render into one 3R×R atlas (layout in hemicube_weights.h) with per-face viewports, so one
// clear and one readback serve the whole hemicube. Visibility uses reversed-Z (depth = near/distance, cleared
// to 0, GL_GREATER, infinite far plane): float depth then has the same relative precision at every distance,
// which is what lets the near plane be tiny relative to the scene without z-fighting far away.
//
// Back faces are drawn, not culled: a back-facing fragment is opaque, black and tagged kBackfaceId. It hides
// what lies behind it and contributes nothing ("the back of a single-sided surface sees nothing"); the weight
// it covers is reported so callers can detect sample points inside geometry.
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "raster/chunk_culling.h"
#include "raster/hemicube_reduction.h"
#include "raster/hemicube_weights.h"
#include "raster/occlusion_culling.h"
#include "raster/scene_buffers.h"

namespace hemibake {

// Where a hemicube sits: world position, unit normal (the front face's direction), and a rotation about the
// normal. Rotating every hemicube by a different angle turns the pixel lattice's structured aliasing into
// unbiased noise (GROUND_TRUTH.md §3.3-ii: +11 % coherent errors without it).
struct HemicubeFrame {
    glm::dvec3 position{0.0};
    glm::dvec3 normal{0.0, 0.0, 1.0};
    double rotationRadians = 0.0;

    // Rotation angle drawn reproducibly from `seed` (e.g. hash of element index and sweep number).
    static HemicubeFrame randomlyRotated(const glm::dvec3& position, const glm::dvec3& normal, std::uint64_t seed);
    // Orthonormal tangent, bitangent with tangent × bitangent = normal, rotated by rotationRadians.
    void tangentFrame(glm::dvec3& tangent, glm::dvec3& bitangent) const;
};

// Sparse row of form factors seen from one hemicube: F(dA → element) per visible element.
struct FormFactorList {
    std::vector<std::uint32_t> elements;
    std::vector<double> formFactors;
    double skyFraction = 0.0;       // weight of pixels that saw nothing
    double backfaceFraction = 0.0;  // weight of pixels that saw the back of a surface
    double minDepthM = std::numeric_limits<double>::infinity();  // nearest hit (front or back), from the eye

    std::size_t size() const { return elements.size(); }
    double sum() const;  // Σ F = 1 − skyFraction − backfaceFraction (up to rounding)
    void clear();
};

// What a renderer drew, summed over its renders: for reports and culling benchmarks.
struct HemicubeDrawTotals {
    std::uint64_t hemicubes = 0;  // renders (item or radiance)
    std::uint64_t triangles = 0;  // triangles submitted, summed over the five faces (occluder pass included)
    std::uint64_t occluderTriangles = 0;  // of those, drawn in occlusion culling's depth pass
    std::uint64_t occlusionCulledHemicubes = 0;  // renders that ran occlusion culling
    HemicubeDrawTotals& operator+=(const HemicubeDrawTotals& o) {
        hemicubes += o.hemicubes;
        triangles += o.triangles;
        occluderTriangles += o.occluderTriangles;
        occlusionCulledHemicubes += o.occlusionCulledHemicubes;
        return *this;
    }
    HemicubeDrawTotals& operator-=(const HemicubeDrawTotals& o) {
        hemicubes -= o.hemicubes;
        triangles -= o.triangles;
        occluderTriangles -= o.occluderTriangles;
        occlusionCulledHemicubes -= o.occlusionCulledHemicubes;
        return *this;
    }
};

struct RadianceGather {
    glm::dvec3 irradianceOverPi{0.0};  // E/π = Σ w·L, W·m⁻²·sr⁻¹
    double skyFraction = 0.0;
    double backfaceFraction = 0.0;
};

class HemicubeRenderer {
public:
    static constexpr std::uint32_t kSkyId = 0xFFFFFFFFu;
    static constexpr std::uint32_t kBackfaceId = 0xFFFFFFFEu;
    // The eye sits this far (× scene diagonal) above the surface along the normal: more than the float
    // quantisation of positions relative to the scene centre (~6e-8 × diagonal), so a sample never sees its
    // own surface or coplanar neighbours at the horizon, yet small enough that the slab it skips below the eye
    // is negligible (a strip of height ε at distance d changes F by O(ε²/d²)).
    static constexpr double kEyeOffsetPerDiagonal = 1e-5;
    // With parts kilometres apart (several islands, mesh/islands.h) a frame takes the eye offset of its own island's
    // diagonal instead, raised to this many float steps at the island's distance from the origin (floats hold
    // positions there): ten copies of a level 1 km apart would otherwise look from 37 mm above every surface, out of
    // the 1-5 cm gaps between their parts. A scene of one island keeps exactly the offset above.
    static constexpr double kEyeOffsetFloatSteps = 4.0;
    // Half the eye offset: reversed-Z keeps depth precision independent of the near plane, so it can be this
    // close; anything nearer than it to the eye is clipped (the leak at concave corners shrinks with it).
    static constexpr double kNearPlanePerEyeOffset = 0.5;

    // `scene` (and its context) must outlive the renderer. Binds the context while creating GL objects. `occlusion`
    // changes what is drawn, never what is seen (ids and gathers are identical with it off).
    HemicubeRenderer(const SceneBuffers& scene, int resolution, const OcclusionCullingSettings& occlusion = {});
    HemicubeRenderer(const HemicubeRenderer&) = delete;
    HemicubeRenderer& operator=(const HemicubeRenderer&) = delete;

    // Item buffer → form factors. `out` is cleared first; no allocation once its capacity has warmed up.
    void renderFormFactors(const HemicubeFrame& frame, FormFactorList& out);
    // The form factor (cosine-weighted share of the hemisphere) of whatever the last renderFormFactors hit nearer
    // than `distanceM` to the eye: ≈ 1 for a surface a few cm in front of it, ≈ 0.1 beside a wall 10 cm away.
    double formFactorNearerThan(double distanceM) const;
    // Radiance buffer (element radiance from SceneBuffers::setElementRadiance, plus its TexelLight if set) → E/π,
    // in double.
    RadianceGather gatherRadiance(const HemicubeFrame& frame, glm::vec3 skyRadiance);
    glm::dvec3 gatherIrradianceOverPi(const HemicubeFrame& frame, glm::vec3 skyRadiance) {
        return gatherRadiance(frame, skyRadiance).irradianceOverPi;
    }
    // Per-pixel weight × radiance in the atlas layout (sum = gatherIrradianceOverPi), for reduction/inspection.
    void renderWeightedRadiance(const HemicubeFrame& frame, glm::vec3 skyRadiance, WeightedRadianceImage& out);

    int resolution() const { return weights_.resolution(); }
    const HemicubeWeights& weights() const { return weights_; }
    const SceneBuffers& scene() const { return *scene_; }
    // The eye offset of a frame at p (see kEyeOffsetFloatSteps). Thread-safe.
    double eyeOffsetAtM(const glm::dvec3& p) const;
    // Of the last frame drawn; before any, the scene's (kEyeOffsetPerDiagonal × its diagonal).
    double eyeOffsetM() const { return eyeOffsetM_; }
    double nearPlaneM() const { return nearPlaneM_; }
    // Chunks drawn (summed over faces) by the last render: for benchmarks and culling tests.
    std::size_t lastChunksDrawn() const { return lastChunksDrawn_; }
    // Every render since construction. Not thread-safe against a render on this renderer.
    const HemicubeDrawTotals& drawTotals() const { return drawTotals_; }

private:
    enum class Target { Items, Radiance };
    void draw(const HemicubeFrame& frame, Target target, glm::vec3 skyRadiance);
    struct Uniforms;
    // Draws the occluders with the bound program (into the cleared target, marking them in chunkOccluderRound_) and
    // clears the face bits of chunks hidden behind them (occlusion_culling.h). Returns the chunks drawn.
    std::size_t cullOccludedChunks(const glm::vec3& eye, const FaceProjection (&faces)[HemicubeWeights::kFaceCount],
                                   const Uniforms& uniforms);
    // One multi-draw of the chunks of `list` (ascending) that `keep(c)` accepts on `face` (runs merged); adds their
    // triangles to `triangles`; returns how many chunks.
    template <class Keep>
    std::size_t drawChunks(const FaceProjection& face, const Uniforms& uniforms, std::span<const std::uint32_t> list,
                           Keep keep, std::uint64_t& triangles);
    void readRadiance();

    const SceneBuffers* scene_;
    HemicubeWeights weights_;
    double eyeOffsetM_;
    double nearPlaneM_;
    std::vector<double> islandEyeOffsetM_;  // per island, only with two or more

    GlObject framebuffer_;
    GlObject itemBuffer_;
    GlObject radianceBuffer_;
    GlObject depthBuffer_;
    GlObject itemProgram_;
    GlObject radianceProgram_;
    struct Uniforms {
        GLint eye = -1, faceRows = -1, yTransform = -1, nearM = -1, radiance = -1, texelLight = -1, texelLightScale = -1,
              texelLightOn = -1;
    } itemUniforms_, radianceUniforms_;

    // Scratch, sized once.
    std::vector<std::uint32_t> ids_;
    std::vector<float> depths_;
    std::vector<glm::vec4> radiance_;
    std::vector<double> accumulator_;  // per element, zero between renders
    ChunkRuns runs_;  // one face's multi-draw ranges
    std::vector<std::uint8_t> chunkFaces_;  // per chunk, bit f: drawn on face f
    // The chunks some face still draws, ascending: every per-chunk loop of a render after the frustum walk runs over
    // these, not over the level (the frustum keeps about half of the 100k level's 60k chunks, occlusion then a few
    // percent; looping over all 60k per face and per culling round cost 10–12 % per hemicube there, BM_LevelHemicubes).
    std::vector<std::uint32_t> liveChunks_;
    std::vector<std::uint32_t> batchChunks_;  // one occluder round's chunks, ascending
    OcclusionCullingSettings occlusion_;
    DepthPyramid depthPyramid_;
    std::vector<std::pair<float, std::uint32_t>> occluderCandidates_;  // (−area / squared distance, chunk)
    std::vector<std::uint8_t> nodeFaces_;  // per chunk-tree node: the faces its undrawn chunks are still drawn on
    std::vector<std::uint8_t> chunkOccluderRound_;  // per chunk: the culling round that drew it, 0 = not an occluder
    std::size_t lastChunksDrawn_ = 0;
    HemicubeDrawTotals drawTotals_;
};

}  // namespace hemibake
