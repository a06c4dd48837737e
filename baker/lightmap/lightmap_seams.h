#pragma once
// Chart seams: one mesh edge, two places in the atlas. Bilinear filtering on either side must see the same
// light, or the seam shows. Seam samples every quarter texel along each such edge (every half texel left 2.7 %
// differences between the samples on a torus, read back from the written files; a quarter leaves 1.8 %);
// stitching projects the two sides' bilinear footprints onto agreement (Kaczmarz sweeps: each step makes one
// sample pair equal with the least change to its texels), which leaves everything away from seams as baked. Only seams across smooth
// surface count (faces within ~15°): across a crease the light is discontinuous and must stay so.
#include <vector>

#include "baker/lightmap/lightmap.h"
#include "mesh/scene.h"
#include "mesh/uv_atlas.h"

namespace hemibake {

struct SeamStats {
    std::size_t seamEdges = 0;
    std::size_t samples = 0;
    double maxRelativeBefore = 0.0;   // max over samples of |a − b| / max(mean(a, b), floor), channel sum
    double maxRelativeAfter = 0.0;
    double meanRelativeBefore = 0.0;
    double meanRelativeAfter = 0.0;
    int sweeps = 0;  // Kaczmarz sweeps run (they stop when converged)
};

// Measures seams and, when `stitch`, stitches them in place with at most `sweeps` Kaczmarz sweeps (fewer when no
// sample pair differs by more than 1e-4 of the seams' mean). Not thread-safe on the same images.
SeamStats stitchSeams(const Scene& scene, const UvAtlas& atlas, std::vector<LightmapImage>& lightmaps, bool stitch,
                      int sweeps = 512);

}  // namespace hemibake
