#pragma once
// Where the final-gather lattice lies on each piece of lightmap surface.
//
// Adaptive placement (lightmap_baker.cpp) gathers a hemicube on every coarse-th texel and interpolates the texels
// between lattice points that agree; a texel whose interpolation needs a lattice point off its chart must gather
// its own hemicube. With one lattice for the whole atlas a chart's edges fall anywhere between lattice lines, and on
// a level (charts ≈ 10 × 12 texels, reveals and jambs 2–4 wide) over half the final gathers were such chart-edge
// texels. So each piece of continuous surface gets its own lattice origin: of the coarse² possible shifts, the one
// that needs the fewest hemicubes for lack of neighbours (lattice points plus unsupported texels). A rectangular
// chart then has a lattice line on its near edges, and on its far edges too when its size allows.
#include <cstdint>
#include <vector>

#include "mesh/texels.h"

namespace hemibake {

// One atlas's texels on its grid, for neighbour lookups.
struct TexelGrid {
    const AtlasTexels& t;
    std::vector<std::int32_t> at;  // size² → texel index or -1
    explicit TexelGrid(const AtlasTexels& texels);
    // The texel at (x, y), or -1 (off the atlas, or not covered).
    std::int32_t find(int x, int y) const {
        if (x < 0 || y < 0 || x >= t.size || y >= t.size) return -1;
        return at[std::size_t(y) * std::size_t(t.size) + std::size_t(x)];
    }
};

// Neighbours can stand in for each other only on one continuous piece of surface: same instance, similar
// normal, and as far apart in the world as in the atlas (a chart boundary breaks that).
bool continuousTexels(const AtlasTexels& t, std::size_t a, std::size_t b, double maxDistanceM);

// World distance within which a lattice neighbour `step` texels away still counts as continuous.
inline double latticeReachM(int step, double texelSizeM) { return 3.0 * 1.5 * 1.41421356237309505 * step * texelSizeM; }

// Per texel, the shift (0 … coarseStep−1 in x and in y) of its piece's lattice: the texel is on the coarse lattice
// when (x + coarseStep − shiftX) and (y + coarseStep − shiftY) are multiples of coarseStep. Pieces are the texels
// joined through 4-neighbours that are continuousTexels at latticeReachM(1, texelSizeM). coarseStep is a power of two
// ≥ 1 (1: every shift 0). Deterministic; thread-safe (reads only its arguments).
struct LatticeShift {
    std::uint8_t x = 0, y = 0;
};
std::vector<LatticeShift> latticeShifts(const AtlasTexels& texels, const TexelGrid& grid, int coarseStep, double texelSizeM);

}  // namespace hemibake
