#pragma once
// A camera view of a lightmapped scene: what a game engine shows after the bake. Each surface is textured with
// a per-texel radiance atlas (ρ·E/π + L_e, W·m⁻²·sr⁻¹), sampled bilinearly through its lightmap UVs, so the
// picture compares pixel for pixel with a path-traced render of the same camera (baker/path_tracer.h uses the
// same pinhole model: vertical field of view, square pixels, row 0 at the top, box-filtered pixels).
//
// Positions are converted to float relative to the eye, so scenes far from the world origin render as well as
// scenes at it. Depth is reversed-Z with an infinite far plane, as in the hemicube.
#include <vector>

#include <glm/glm.hpp>

#include "raster/gl_context.h"

namespace hemibake {

// Triangles sharing one radiance atlas.
struct LightmappedBatch {
    std::vector<glm::dvec3> positions;  // world, metres, 3 per triangle, counter-clockwise seen from the front
    std::vector<glm::vec2> uvs;         // lightmap UV per corner (glTF: origin top-left, v down)
    int atlasSize = 0;                  // square, texels
    const std::vector<glm::vec3>* radiance = nullptr;  // atlasSize², row 0 at v = 0; W·m⁻²·sr⁻¹
    bool doubleSided = false;           // else back faces are black, as the path tracer's single-sided surfaces
};

struct PinholeView {
    glm::dvec3 position{0.0};
    glm::dvec3 forward{0.0, 0.0, -1.0};
    glm::dvec3 up{0.0, 1.0, 0.0};
    double yfovRadians = 0.8;
    double nearM = 1e-3;  // nothing nearer than this to the eye is drawn
    int width = 640, height = 480;
};

// Linear radiance per pixel (width × height, row 0 at the top). Each pixel averages `samplesPerAxis`² regular
// sub-pixel samples; pixels that see nothing get `background` (the sky radiance). Throws GlError on GL failure
// and std::invalid_argument for an empty view or a batch whose arrays do not match.
std::vector<glm::vec3> renderLightmapped(const GlContext& context, const std::vector<LightmappedBatch>& batches,
                                         const PinholeView& view, glm::vec3 background, int samplesPerAxis = 3);

}  // namespace hemibake
