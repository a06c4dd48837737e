#pragma once
// The lightmap stage's knobs: unwrap density and atlas, texel samples, final-gather placement, dilation, seams.
#include <string>

#include "mesh/texels.h"
#include "mesh/uv_atlas.h"

namespace hemibake {

enum class TexelMode {
    Interpolate,  // texels interpolate the element solution (fast)
    Gather,       // texels gather from a final hemicube each, placed adaptively (quality; every preset)
};
const char* texelModeName(TexelMode mode);
TexelMode parseTexelMode(const std::string& name);  // throws std::invalid_argument

// How a gathered texel sees the solved scene (both see the same elements, texel light and sky).
enum class FinalGather {
    Rays,      // stratified cosine rays through Embree (every preset): the hemicube's accuracy at a fifth of its time
    Hemicube,  // a radiance hemicube of gatherResolution through OSMesa
};
const char* finalGatherName(FinalGather method);
FinalGather parseFinalGather(const std::string& name);  // throws std::invalid_argument

// The most rays per gathered texel a bake accepts (1,024²: the ray count of an R = 1,024 hemicube's front face).
constexpr int kMaxGatherRays = 1 << 20;

struct LightmapSettings {
    double texelsPerUnit = 0.0;     // texels per metre; 0 = from the preset and scene size (defaultTexelsPerUnit)
    int maxAtlasSize = 1024;
    int paddingTexels = 2;
    TexelMode mode = TexelMode::Gather;
    int latticeStep = 4;            // Elias-style placement: hemicubes on every 4th texel first (power of two)
    FinalGather finalGather = FinalGather::Rays;
    // Rays per gathered texel (FinalGather::Rays), rounded down to a square of strata; 0 = R² of the gather
    // resolution below (every preset: 4,096 at medium's R = 64). On the generated 10k levels 4,096 rays gave the
    // per-texel and per-object errors of R = 64 hemicubes (docs/performance.md, "A final gather by rays").
    int gatherRays = 0;
    // Final-gather hemicube resolution R; 0 = the solve's (every preset). A gather sees only bounced light and sky
    // (direct light is traced per texel): half the solve's R keeps room means and costs per-texel accuracy (clean 10k
    // level at medium: final gather −30 %, per texel 1.90 → 2.84 % RMS; docs/performance.md, session 20).
    int gatherResolution = 0;
    double interpolationTolerance = 0.05;  // interpolate a texel when its lattice neighbours agree within this
    double invalidBackfaceFraction = 0.1;  // a texel whose hemicube sees more back faces is inside geometry
    // Final gathers see ray-traced direct light per texel instead of per element (texel_light.h): right next to a
    // hot spot smaller than an element, e.g. the top of a light panel hung under a ceiling.
    bool gatherTexelDirect = true;
    // Experimental, off: texels facing a surface closer than an eighth of an element (a panel hung under a ceiling)
    // are gathered again, each pass seeing the texels' light of the one before (one bounce in the gap per pass),
    // until a pass changes them by less than gapTolerance of their light, at most gapPasses times. Right in the
    // HangingPanel room at 8 texels/m (−27 % → −6 %); on level_small at 4 texels/m it darkened the panels (−10 points)
    // and cost +160 s, not understood yet.
    int gapPasses = 0;
    double gapTolerance = 0.005;
    int dilationTexels = 2;         // padding texels filled from their chart's edge
    bool stitchSeams = true;
    bool keepExistingUv = false;    // use TEXCOORD_1 from the input where present
    TexelSettings texels;           // where each texel samples the surface (mesh/texels.h)
};

// The unwrap settings a bake uses (texelsPerUnit must be resolved, > 0).
UnwrapSettings unwrapSettingsFor(const LightmapSettings& lightmap);
// Preset default density: about 64 texels along the scene diagonal per preset step, with a floor per metre.
double defaultTexelsPerUnit(const std::string& preset, double sceneDiagonalM);

}  // namespace hemibake
