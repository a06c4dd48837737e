#pragma once
// The baked scene as an engine would show it: every baked surface textured with ρ × lightmap + L_e (bilinear),
// seen from a glTF camera or any pinhole, rendered with OSMesa. The bake writes one from the scene's first
// camera as a preview; `hemibake render` renders any view of a bake for side-by-side comparison with
// `hemibake reference --camera` (same pinhole model, same pixel footprint).
#include <vector>

#include <glm/glm.hpp>

#include "baker/lightmap/lightmap.h"
#include "baker/util/rgb_image.h"
#include "mesh/scene.h"
#include "mesh/uv_atlas.h"

namespace hemibake {

// Image height for a camera: from its aspect ratio when the file gives one, else square.
int imageHeightFor(const Camera& camera, int width);

// Linear radiance image (W·m⁻²·sr⁻¹). `lightmaps` are indexed by atlas. Pixels that see nothing hold `sky`; each
// pixel is the box-filtered mean of samplesPerAxis² regular sub-pixel samples.
RgbImage renderBakedScene(const Scene& scene, const UvAtlas& atlas, const std::vector<LightmapImage>& lightmaps,
                          const Camera& camera, int width, int height, glm::vec3 sky, int samplesPerAxis = 3);

}  // namespace hemibake
