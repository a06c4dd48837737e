// Each piece of lightmap surface gets its own final-gather lattice (texel_lattice.h). Known answers on synthetic
// atlases: a rectangle of (4k + 1) × (4m + 1) texels, wherever it lies in the atlas, has lattice lines on all four
// edges, so it needs exactly (k + 1)(m + 1) lattice hemicubes and no texel lacks a neighbour.
#include <gtest/gtest.h>

#include "baker/lightmap/texel_lattice.h"

using namespace hemibake;

namespace {

constexpr double kTexelM = 0.0625;  // 16 texels/m

// Adds a w × h rectangle of texels at atlas (x0, y0), lying flat in the world at `originM` (normal +y) with the
// atlas's texel spacing, as one chart of `instance`.
void addRectangle(AtlasTexels& t, int x0, int y0, int w, int h, glm::dvec3 originM, int instance = 0) {
    for (int y = y0; y < y0 + h; ++y)
        for (int x = x0; x < x0 + w; ++x) {
            t.x.push_back(std::uint16_t(x));
            t.y.push_back(std::uint16_t(y));
            t.position.push_back(originM + glm::dvec3((x - x0) * kTexelM, 0.0, (y - y0) * kTexelM));
            t.normal.emplace_back(0.0f, 1.0f, 0.0f);
            t.instance.push_back(instance);
            t.face.push_back(0);
            t.barycentric.emplace_back(1.0f, 0.0f, 0.0f);
            t.centreInside.push_back(1);
        }
}

bool onLattice(const AtlasTexels& t, const std::vector<LatticeShift>& s, std::size_t i, int coarse) {
    return (t.x[i] + coarse - s[i].x) % coarse == 0 && (t.y[i] + coarse - s[i].y) % coarse == 0;
}

}  // namespace

TEST(TexelLattice, RectanglesGetLatticeLinesOnEveryEdge) {
    AtlasTexels t;
    t.size = 64;
    // Three charts at awkward atlas offsets, far apart in the world: 9 × 13, 5 × 5 and 17 × 9 texels.
    struct Rect { int x0, y0, w, h; };
    const Rect rects[] = {{3, 2, 9, 13}, {15, 7, 5, 5}, {23, 30, 17, 9}};
    for (int r = 0; r < 3; ++r) addRectangle(t, rects[r].x0, rects[r].y0, rects[r].w, rects[r].h, glm::dvec3(10.0 * r, 0.0, 0.0));
    const TexelGrid grid(t);
    const std::vector<LatticeShift> shift = latticeShifts(t, grid, 4, kTexelM);
    ASSERT_EQ(shift.size(), t.count());
    std::size_t first = 0;
    for (const Rect& r : rects) {
        const std::size_t count = std::size_t(r.w * r.h);
        std::size_t lattice = 0;
        for (std::size_t i = first; i < first + count; ++i) {
            EXPECT_EQ(shift[i].x, shift[first].x);  // one piece, one lattice
            EXPECT_EQ(shift[i].y, shift[first].y);
            lattice += onLattice(t, shift, i, 4);
        }
        // The four corners are lattice points, and so (4k + 1 wide) every fourth texel between them.
        EXPECT_TRUE(onLattice(t, shift, first, 4));
        EXPECT_TRUE(onLattice(t, shift, first + count - 1, 4));
        EXPECT_EQ(lattice, std::size_t((r.w / 4 + 1) * (r.h / 4 + 1)));
        first += count;
    }
}

// The same two rectangles side by side in the atlas, touching: one continuous in the world (one piece: one shift)
// and one far away (its own piece, aligned to its own edges).
TEST(TexelLattice, PiecesFollowTheWorldNotTheAtlas) {
    AtlasTexels t;
    t.size = 32;
    addRectangle(t, 2, 1, 5, 5, glm::dvec3(0.0));
    addRectangle(t, 7, 1, 5, 5, glm::dvec3(5 * kTexelM, 0.0, 0.0));  // continues the first in the world
    addRectangle(t, 12, 1, 5, 5, glm::dvec3(40.0, 0.0, 0.0));         // beside it in the atlas only
    const std::vector<LatticeShift> shift = latticeShifts(t, TexelGrid(t), 4, kTexelM);
    // The first two form one 10 × 5 piece: its lattice cannot have lines on both x edges (9 is not a multiple of 4),
    // so its shift is one of the two that align an x edge; the third, 5 × 5, is aligned on all four edges.
    for (std::size_t i = 0; i < 50; ++i) {
        EXPECT_EQ(shift[i].x, shift[0].x);
        EXPECT_EQ(shift[i].y, shift[0].y);
    }
    EXPECT_TRUE(onLattice(t, shift, 0, 4) || onLattice(t, shift, 29, 4));  // x = 2 or x = 11 on a line
    EXPECT_EQ((1 + 4 - shift[0].y) % 4, 0);                                           // y = 1 on a line
    EXPECT_TRUE(onLattice(t, shift, 50, 4));
    EXPECT_TRUE(onLattice(t, shift, 74, 4));
    EXPECT_EQ((12 + 4 - shift[50].x) % 4, 0);
}

// A lattice step of 1 gathers every texel: nothing to align.
TEST(TexelLattice, CoarseStepOneShiftsNothing) {
    AtlasTexels t;
    t.size = 16;
    addRectangle(t, 3, 3, 6, 6, glm::dvec3(0.0));
    for (const LatticeShift& s : latticeShifts(t, TexelGrid(t), 1, kTexelM)) EXPECT_EQ(s.x + s.y, 0);
}
