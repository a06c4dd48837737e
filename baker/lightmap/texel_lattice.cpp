#include "baker/lightmap/texel_lattice.h"

#include <numeric>

#include <glm/glm.hpp>

namespace hemibake {

TexelGrid::TexelGrid(const AtlasTexels& texels) : t(texels), at(std::size_t(texels.size) * std::size_t(texels.size), -1) {
    for (std::size_t i = 0; i < t.count(); ++i) at[std::size_t(t.y[i]) * std::size_t(t.size) + t.x[i]] = std::int32_t(i);
}

bool continuousTexels(const AtlasTexels& t, std::size_t a, std::size_t b, double maxDistanceM) {
    return t.instance[a] == t.instance[b] && glm::dot(t.normal[a], t.normal[b]) > 0.9f &&
           glm::length(t.position[a] - t.position[b]) <= maxDistanceM;
}

namespace {

std::uint32_t findRoot(std::vector<std::uint32_t>& parent, std::uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
}

}  // namespace

std::vector<LatticeShift> latticeShifts(const AtlasTexels& texels, const TexelGrid& grid, int coarseStep, double texelSizeM) {
    const std::size_t n = texels.count();
    std::vector<LatticeShift> shift(n);
    if (coarseStep <= 1 || n == 0) return shift;

    // Pieces: union-find over right and lower neighbours.
    std::vector<std::uint32_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0u);
    const double reachM = latticeReachM(1, texelSizeM);
    for (std::size_t i = 0; i < n; ++i)
        for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
            const std::int32_t j = grid.find(texels.x[i] + dx, texels.y[i] + dy);
            if (j < 0 || !continuousTexels(texels, i, std::size_t(j), reachM)) continue;
            const std::uint32_t a = findRoot(parent, std::uint32_t(i)), b = findRoot(parent, std::uint32_t(j));
            if (a != b) parent[std::max(a, b)] = std::min(a, b);
        }
    std::vector<std::uint32_t> piece(n);
    for (std::size_t i = 0; i < n; ++i) piece[i] = findRoot(parent, std::uint32_t(i));
    // Texels grouped by piece (counting sort by root).
    std::vector<std::uint32_t> start(n + 1, 0), members(n);
    for (std::size_t i = 0; i < n; ++i) ++start[piece[i] + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    {
        std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
        for (std::size_t i = 0; i < n; ++i) members[fill[piece[i]]++] = std::uint32_t(i);
    }

    const auto inPiece = [&](std::size_t i, int dx, int dy) {
        const std::int32_t j = grid.find(texels.x[i] + dx, texels.y[i] + dy);
        return j >= 0 && piece[std::size_t(j)] == piece[i];
    };
    // Hemicubes a texel needs for lack of neighbours with the lattice shifted by (sx, sy): 1 on the lattice, 1 when a
    // neighbour its interpolation takes (two along an edge, four at a cell's corners) is off the piece, else 0 (it
    // may still gather if the neighbours disagree, which the shift cannot know).
    const auto cost = [&](std::size_t i, int sx, int sy) {
        const int xs = texels.x[i] + coarseStep - sx, ys = texels.y[i] + coarseStep - sy;
        int step = coarseStep;
        while (step > 1 && (xs % step || ys % step)) step /= 2;
        if (step == coarseStep) return 1;
        const bool oddX = (xs / step) % 2 == 1, oddY = (ys / step) % 2 == 1;
        if (oddX && oddY)
            return inPiece(i, -step, -step) && inPiece(i, step, -step) && inPiece(i, -step, step) && inPiece(i, step, step) ? 0 : 1;
        const int ux = oddX ? step : 0, uy = oddY ? step : 0;
        return inPiece(i, -ux, -uy) && inPiece(i, ux, uy) ? 0 : 1;
    };
    for (std::size_t p = 0; p < n; ++p) {
        if (start[p + 1] == start[p]) continue;
        int best = -1;
        LatticeShift bestShift;
        for (int sy = 0; sy < coarseStep; ++sy)
            for (int sx = 0; sx < coarseStep; ++sx) {
                int total = 0;
                for (std::uint32_t k = start[p]; k < start[p + 1] && (best < 0 || total < best); ++k)
                    total += cost(members[k], sx, sy);
                if (best < 0 || total < best) best = total, bestShift = {std::uint8_t(sx), std::uint8_t(sy)};
            }
        for (std::uint32_t k = start[p]; k < start[p + 1]; ++k) shift[members[k]] = bestShift;
    }
    return shift;
}

}  // namespace hemibake
