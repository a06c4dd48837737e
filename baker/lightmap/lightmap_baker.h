#pragma once
// Lightmap texel values (E/π) from a solved scene. Punctual lights are evaluated at every texel with shadow
// rays (crisp shadows at texel resolution); the rest (emitters, interreflection, sky) comes from final-gather
// hemicubes placed Elias-style: a coarse lattice first, then midpoints only where the lattice neighbours
// disagree, interpolation where they agree.
#include <functional>
#include <vector>

#include "baker/lightmap/lightmap.h"
#include "baker/lightmap/lightmap_settings.h"
#include "baker/lightmap/texel_light.h"
#include "baker/solve/radiosity_solution.h"
#include "baker/solve/solve_settings.h"
#include "mesh/patches.h"
#include "mesh/texels.h"
#include "mesh/uv_atlas.h"

namespace hemibake {

class EmbreeScene;
class HemicubePool;
struct SolvedScene;

struct LightmapStats {
    std::size_t texels = 0;
    std::size_t rendered = 0;      // texels gathered (rays or a hemicube): the four below
    std::size_t renderedLattice = 0;      // on the coarse lattice (1 in latticeStep² texels)
    std::size_t renderedUnsupported = 0;  // a neighbour interpolation needs is off the chart, out of sight or inside
    std::size_t renderedDisagreeing = 0;  // the neighbours were there but disagreed beyond the tolerance
    std::size_t renderedChartEnds = 0;    // with the lattice: a chart's ends on lattice rows and columns, its corners
    // The unsupported ones by the first neighbour found missing: off the chart (its edge, or another piece of surface
    // beside it in the atlas), inside geometry (a wall's foot), or out of sight (something stands between them).
    struct UnsupportedBy {
        std::size_t chartEdge = 0, insideGeometry = 0, outOfSight = 0;
    } renderedUnsupportedBy;
    std::size_t interpolated = 0;  // texels interpolated from agreeing lattice neighbours
    std::size_t interpolatedBesideChartEdges = 0;  // of those, along a row or column to a chart's end
    std::size_t probedBesideChartEdges = 0;  // texels whose interpolation beside a chart's edge their probe checked
    std::size_t invalid = 0;       // texels inside geometry (mostly back faces seen), refilled from neighbours
    std::size_t dilated = 0;       // padding texels filled (by dilate(), before seam stitching)
    TexelLightStats texelDirect;  // how the final gathers see direct light per texel (texel_light.h)
    std::size_t gapTexels = 0;   // texels re-gathered across gaps narrower than elements (refineGaps)
    int gapPasses = 0;
    double gapLastChange = 0.0;  // what the last gap pass changed, relative to the gap texels' light
    int gatherRaysPerTexel = 0;            // final gather by rays: rays per gathered texel (0: hemicubes)
    std::uint64_t gatherRaysTraced = 0;    // final gather by rays: all of them, gap passes included
    std::uint64_t gatherRaysEscaped = 0;   // of those, rays that met no surface (the sky's, or nothing)
    std::uint64_t gatherStoppedInside = 0;  // gathered texels found inside geometry by their probe (ray_gatherer.h)
    // Wall-clock seconds of the lightmap stage's parts (bake.json "lightmap.seconds"): where a large level's time goes.
    struct Seconds {
        double setup = 0.0;       // emitters as the texels see them, element interpolation, gather set-up
        double direct = 0.0;      // ray-traced direct light at every texel
        double texelLight = 0.0;  // the light inside elements the gathers see (texel_light.h)
        double gather = 0.0;      // adaptive placement and its final gathers
        double refill = 0.0;      // texels inside geometry refilled from their neighbours
        double gaps = 0.0;        // gap passes (refineGaps)
        double dilateAndSeams = 0.0;  // padding and seam stitching (bake_scene, after bakeLightmaps)
    } seconds;
    double renderedFraction() const { return texels ? double(rendered) / double(texels) : 0.0; }
};

// What the lightmap stage is doing: direct light at every texel first (shadow rays), then each texel's indirect
// light (final gathers, or interpolation from the elements).
enum class LightmapPhase { DirectLight, Texels };
// Texels done of `total` in `phase`; called on the baking thread, between parallel work, with `done` rising to
// `total` in each phase. May throw to cancel the bake.
using LightmapProgress = std::function<void(LightmapPhase phase, std::size_t done, std::size_t total)>;

// E/π per texel of every atlas (Covered where a texel is, Empty elsewhere), from `solved` (its pool renders the
// final gathers) and `rays` of `scene`. Lighting and the gather seed come from `solve`, the settings the scene
// was solved with. Uses every core; throws what the renderer throws.
std::vector<LightmapImage> bakeLightmaps(const Scene& scene, const SolvedScene& solved, const UvAtlas& atlas,
                                         const std::vector<AtlasTexels>& texels, const EmbreeScene& rays,
                                         const LightmapSettings& settings, const SolveSettings& solve, LightmapStats& stats,
                                         const LightmapProgress& progress = {});

// Fills Empty texels next to Covered ones with the mean of their covered 8-neighbours, `iterations` rings deep.
std::size_t dilate(LightmapImage& image, int iterations);

}  // namespace hemibake
