// Adaptive placement (adaptive_placement.h) on a real floor chart, with its real Embree scene for the sight tests,
// against a known field of E/π: interpolation between equal values is exact, so every texel must come out as the field.
#include <gtest/gtest.h>

#include <algorithm>

#include "baker/lightmap/adaptive_placement.h"
#include "baker/rays/embree_scene.h"
#include "mesh/scene_builder.h"
#include "mesh/texels.h"
#include "mesh/uv_atlas.h"

using namespace hemibake;

namespace {

constexpr int kLatticeStep = 4;  // the medium preset's

struct Floor {
    Scene scene;
    std::vector<AtlasTexels> texels;
    double texelSizeM = 1.0 / 32.0;
};

// A 1 m floor square at 32 texels/m: one chart of about 33 × 33 texels.
Floor makeFloor() {
    SceneBuilder b("floor");
    const int grey = b.addMaterial(glm::vec3(0.5f));
    b.addQuad({0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}, grey, "floor");
    Floor f{b.build(), {}};
    UnwrapSettings unwrap;
    unwrap.texelsPerUnit = 32.0;
    f.texels = computeTexels(f.scene, unwrapScene(f.scene, unwrap));
    return f;
}

struct Placed {
    std::vector<glm::dvec3> value;
    LightmapStats stats;
    std::size_t advanced = 0;
};

// Places gathers over the floor's chart where `field` (E/π per texel, grey) is what a gather sees; `probeSees` is what
// a probe sees (with no noise), or nullptr for no probe at all.
Placed place(const Floor& f, const std::vector<double>& field, const std::vector<double>* probeSees) {
    const EmbreeScene rays(f.scene);
    const AtlasTexels& t = f.texels[0];
    LightmapSettings settings;
    settings.latticeStep = kLatticeStep;
    const GatherFn gather = [&](const std::vector<std::uint32_t>& ids, std::vector<glm::dvec3>& out, std::vector<float>& back) {
        out.resize(ids.size());
        back.assign(ids.size(), 0.0f);
        for (std::size_t k = 0; k < ids.size(); ++k) out[k] = glm::dvec3(field[ids[k]]);
    };
    const ProbeFn probe = [&](const std::vector<std::uint32_t>& ids, std::vector<glm::dvec3>& out, std::vector<double>& error) {
        out.resize(ids.size());
        error.assign(ids.size(), 0.0);
        for (std::size_t k = 0; k < ids.size(); ++k) out[k] = glm::dvec3((*probeSees)[ids[k]]);
    };
    const ProbeFn noProbe;
    Placed p;
    std::vector<std::uint8_t> invalid;
    placeGathers(t, settings, f.texelSizeM, rays, gather, probeSees ? probe : noProbe, {}, p.stats, p.value, invalid,
                 [&](std::size_t n) { p.advanced += n; });
    EXPECT_EQ(std::count(invalid.begin(), invalid.end(), 1), 0);
    return p;
}

// Texels further from the field than interpolation may take them. Interpolation between equal values is exact, but a
// cubic through a lattice point on the dark line may overshoot the bright floor within the tolerance (1.05 for 1).
std::size_t wrongTexels(const Placed& p, const std::vector<double>& field) {
    const double tolerance = LightmapSettings{}.interpolationTolerance;
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < field.size(); ++i) wrong += std::abs(p.value[i].x - field[i]) > tolerance * field[i] + 1e-12;
    return wrong;
}

}  // namespace

// Uniform light: without a probe every texel between the last lattice column (or row) and the chart's edge lacks a
// neighbour and is gathered; with one, the chart's ends on the lattice rows and columns are gathered and the texels
// between them interpolated along their rows and columns.
TEST(AdaptivePlacement, TexelsBesideAChartsEdgeAreInterpolatedToItsEnds) {
    const Floor f = makeFloor();
    ASSERT_EQ(f.texels.size(), 1u);
    const std::size_t n = f.texels[0].count();
    ASSERT_GT(n, 1000u);
    const std::vector<double> field(n, 1.0);
    const Placed without = place(f, field, nullptr);
    const Placed with = place(f, field, &field);
    std::printf("texels %zu; without probes: rendered %zu (unsupported %zu); with: rendered %zu (chart ends %zu, unsupported %zu), "
                "%zu probed, %zu interpolated beside the edges\n",
                n, without.stats.rendered, without.stats.renderedUnsupported, with.stats.rendered, with.stats.renderedChartEnds,
                with.stats.renderedUnsupported, with.stats.probedBesideChartEdges, with.stats.interpolatedBesideChartEdges);
    for (const Placed* p : {&without, &with}) {
        EXPECT_EQ(wrongTexels(*p, field), 0u);
        EXPECT_EQ(p->advanced, n);
        EXPECT_EQ(p->stats.rendered + p->stats.interpolated, n);
        EXPECT_EQ(p->stats.renderedLattice + p->stats.renderedChartEnds + p->stats.renderedUnsupported +
                      p->stats.renderedDisagreeing,
                  p->stats.rendered);
        EXPECT_EQ(p->stats.renderedDisagreeing, 0u);  // nothing varies
    }
    EXPECT_EQ(without.stats.renderedChartEnds, 0u);  // placement as it was: they are of use only with probes
    EXPECT_EQ(without.stats.probedBesideChartEdges, 0u);
    // The chart ends and what is still unsupported are fewer than the texels they stand in for.
    EXPECT_GT(without.stats.renderedUnsupported, with.stats.renderedChartEnds + with.stats.renderedUnsupported);
    // With probes: the chart's ends on its lattice rows and columns, and its corners; no texel lacks support.
    EXPECT_GT(with.stats.renderedChartEnds, 0u);
    EXPECT_EQ(with.stats.renderedUnsupported, 0u);
    EXPECT_EQ(with.stats.interpolatedBesideChartEdges, with.stats.probedBesideChartEdges);
    EXPECT_LT(with.stats.rendered, without.stats.rendered);
}

// A dark line one texel in from the chart's edge, between the chart's end and the first lattice column: the two
// agree, and only the texels' own probes see the dark between them. A probe that saw only the bright floor would let
// the line be interpolated away.
TEST(AdaptivePlacement, AProbeKeepsADarkLineTheLatticeCannotSee) {
    const Floor f = makeFloor();
    const AtlasTexels& t = f.texels[0];
    const int x0 = *std::min_element(t.x.begin(), t.x.end()), x1 = *std::max_element(t.x.begin(), t.x.end());
    // The columns strictly between the chart's first (or last) column and the nearest lattice column.
    const int firstLattice = (x0 + kLatticeStep - 1) / kLatticeStep * kLatticeStep, lastLattice = x1 / kLatticeStep * kLatticeStep;
    std::vector<double> field(t.count(), 1.0), blind(t.count(), 1.0);
    std::size_t dark = 0;
    for (std::size_t i = 0; i < t.count(); ++i) {
        const int x = t.x[i];
        if ((x > x0 && x < firstLattice) || (x > lastLattice && x < x1)) field[i] = 0.2, ++dark;
    }
    ASSERT_GT(dark, 0u) << "the chart's first and last columns are both lattice columns: no band to darken";
    const Placed seen = place(f, field, &field);
    const Placed missed = place(f, field, &blind);
    std::printf("dark texels %zu; probes that see them: %zu wrong, %zu probed, %zu rejected; blind probes: %zu wrong\n", dark,
                wrongTexels(seen, field), seen.stats.probedBesideChartEdges,
                seen.stats.probedBesideChartEdges - seen.stats.interpolatedBesideChartEdges, wrongTexels(missed, field));
    EXPECT_EQ(wrongTexels(seen, field), 0u);
    EXPECT_GT(seen.stats.probedBesideChartEdges, seen.stats.interpolatedBesideChartEdges);  // some were turned back
    EXPECT_GT(wrongTexels(missed, field), 0u);
}
