#pragma once
// Does the lightmap say what the solver said? Per surface (scene instance), the mean over its texels of the
// lightmap's E/π against the mean, over the same texels, of the solver's value for the element each texel's
// sample lies on. The two are computed differently (elements: the shooting solution, constant per element;
// texels: a final gather per texel, or interpolation), so their agreement checks the texel stage end to end;
// bake.json reports it per surface. Texels inside geometry (under a block standing on the floor) are left out:
// the bake refills them from their neighbours on purpose, while the elements there are dark.
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "baker/lightmap/lightmap.h"
#include "baker/solve/radiosity_solution.h"
#include "mesh/patches.h"
#include "mesh/scene.h"
#include "mesh/texels.h"

namespace hemibake {

struct SurfaceAgreement {
    int instance = -1;
    std::string nodeName;
    glm::dvec3 elementMean{0.0};   // E/π, W·m⁻²·sr⁻¹, of the elements under the compared texels
    glm::dvec3 lightmapMean{0.0};  // E/π of the compared texels (centre on the surface, not inside geometry)
    std::size_t texels = 0;
    // |lightmap − element| / element on the channel sum (0 when both are black).
    double relativeDifference() const;
};

// One entry per instance with compared texels. `lightmaps` and `insideGeometry` (one flag per texel, as from
// texelsInsideGeometry) are indexed by atlas, as `texels`.
std::vector<SurfaceAgreement> compareSurfaceMeans(const Scene& scene, const PatchMesh& mesh, const RadiositySolution& solution,
                                                  const std::vector<AtlasTexels>& texels,
                                                  const std::vector<LightmapImage>& lightmaps,
                                                  const std::vector<std::vector<std::uint8_t>>& insideGeometry);

}  // namespace hemibake
