#pragma once
// Light as the final gather sees it inside an element: per lightmap texel instead of the element's average.
//
// A texel's gather hemicube sees the first bounce of direct light on the surfaces around it. Elements hold that
// bounce as one average, which is right for receivers far away and wrong near a hot spot much smaller than an
// element: the top of a light panel hung 5 cm under a ceiling sees the ceiling's bright footprint of the panel,
// which a 1.6 m element spreads thin (the panel tops came out −4 … −76 % on the generated levels). The texels
// already carry direct light at their own resolution, so the gather reads it there, through the lightmap UVs.
//
// Each element's share is normalised so that, averaged over the element, it equals the element's own ray-traced
// direct light: the texels only place the light inside the element and can never move power between elements
// (nor across a wall whose foot a texel straddles: an element that gets no direct light shows none). The lightmap
// stage also re-gathers texels across gaps narrower than elements with every texel's gathered light shown unscaled
// (lightmap_baker.cpp, refineGaps): there the texels are right and the elements are not.
#include <cstddef>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "mesh/patches.h"
#include "mesh/texels.h"
#include "mesh/uv_atlas.h"
#include "raster/scene_buffers.h"

namespace hemibake {

struct TexelLightStats {
    std::size_t elementsMapped = 0;    // elements that show texel light
    std::size_t elementsNoUv = 0;      // lit elements left flat: back sides, or no UV triangle holds them
    std::size_t elementsDisagree = 0;  // lit elements left flat: the texels' mean over them is off by more than 2×
    double seconds = 0.0;
};

// The gather's TexelLight from light per texel (`texelOverPi[a][i]`, E/π of texel i of atlas a) and the same light
// per element (`elementOverPi`, E/π as the solve has it). Lowers `gatherRadiance` (per element, W·m⁻²·sr⁻¹) by
// ρ·E/π wherever the texels take that light over. Each element's texels are scaled to its own value (see above),
// except on elements that cover a texel flagged in `unscaledTexels` (per atlas, per texel; e.g. texels gathered
// again across a gap, more right than the elements there): those show the texels as they are. Back sides of double-sided surfaces (no texels) and elements
// without that light stay flat. Thread-safe for distinct outputs; uses every core.
std::shared_ptr<TexelLight> makeTexelLight(const Scene& scene, const PatchMesh& mesh, const UvAtlas& atlas,
                                           const std::vector<AtlasTexels>& texels,
                                           const std::vector<std::vector<glm::dvec3>>& texelOverPi,
                                           const std::vector<glm::dvec3>& elementOverPi,
                                           std::vector<glm::vec3>& gatherRadiance, TexelLightStats& stats,
                                           const std::vector<std::vector<std::uint8_t>>* unscaledTexels = nullptr);

}  // namespace hemibake
