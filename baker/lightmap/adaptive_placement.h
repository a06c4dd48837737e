#pragma once
// Where the final gather is taken and where texels are interpolated instead (Elias-style adaptive placement), over
// one atlas's texels. A coarse lattice and each chart's ends on its rows and columns are gathered first; then, level by
// level, edge midpoints and cell centres are interpolated where their neighbours agree and gathered where they do not.
// Beside a chart's edge, where a lattice neighbour is off the chart, a texel is interpolated along its row or column to
// the chart's end, if its own probe (64 of its gather's rays) agrees.
#include <cstdint>
#include <functional>
#include <vector>

#include <glm/glm.hpp>

#include "baker/lightmap/lightmap_baker.h"
#include "baker/lightmap/lightmap_settings.h"
#include "mesh/texels.h"

namespace hemibake {

class EmbreeScene;

// One atlas's texels on its grid, for neighbour lookups.
struct TexelGrid {
    const AtlasTexels& t;
    std::vector<std::int32_t> at;  // size² → texel index or -1
    explicit TexelGrid(const AtlasTexels& texels) : t(texels), at(std::size_t(texels.size) * std::size_t(texels.size), -1) {
        for (std::size_t i = 0; i < t.count(); ++i) at[std::size_t(t.y[i]) * std::size_t(t.size) + t.x[i]] = std::int32_t(i);
    }
    std::int32_t find(int x, int y) const {
        if (x < 0 || y < 0 || x >= t.size || y >= t.size) return -1;
        return at[std::size_t(y) * std::size_t(t.size) + std::size_t(x)];
    }
};

// Neighbours can stand in for each other only on one continuous piece of surface: same instance, similar
// normal, and as far apart in the world as in the atlas (a chart boundary breaks that).
bool continuousSurface(const AtlasTexels& t, std::size_t a, std::size_t b, double maxDistanceM);

// E/π gathered at texels `ids` (without direct light), and each one's share of rays that met back faces.
using GatherFn = std::function<void(const std::vector<std::uint32_t>&, std::vector<glm::dvec3>&, std::vector<float>&)>;
// A texel's probe: E/π from a 64-ray subset of its gather, and that E/π's standard error (channels summed).
using ProbeFn = std::function<void(const std::vector<std::uint32_t>&, std::vector<glm::dvec3>&, std::vector<double>&)>;

// Fills `value` (E/π gathered or interpolated, without direct light) and `invalid` (1: inside geometry) for every
// texel of `texels`, gathering only where placement needs it. `direct` (per texel, or empty) is added to the scale the
// interpolation tolerance applies to. `probe` empty: no texel is interpolated along rows and columns beside a chart's
// edge (every one there is gathered). `advanced` gets the texels finished after each phase (over the run, every
// texel). Counts in `stats`. Throws what `gather` and `probe` throw; calls them on this thread.
void placeGathers(const AtlasTexels& texels, const LightmapSettings& settings, double texelSizeM, const EmbreeScene& rays,
                  const GatherFn& gather, const ProbeFn& probe, const std::vector<glm::dvec3>& direct, LightmapStats& stats,
                  std::vector<glm::dvec3>& value, std::vector<std::uint8_t>& invalid,
                  const std::function<void(std::size_t)>& advanced);

}  // namespace hemibake
