// raster/hemicube_reduction: 2×2 sum pyramids of weighted radiance keep the hemicube total at every level.
#include <gtest/gtest.h>

#include <random>

#include "raster/hemicube.h"
#include "support/raster_fixtures.h"

namespace hemibake {
namespace {

TEST(HemicubeReduction, EveryLevelKeepsTheTotalOfARenderedHemicube) {
    // A box with a different radiance on every element and a bright sky through a missing wall, so the image
    // has structure at every scale.
    test::TriangleSoup soup;
    soup.addGrid({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 6);
    soup.addGrid({0, 0, 1}, {0, 1, 0}, {1, 0, 0}, 6);
    soup.addGrid({0, 0, 0}, {0, 1, 0}, {0, 0, 1}, 6);
    const PatchMesh mesh = soup.build();
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 10.0f);
    std::vector<glm::vec3> radiance(mesh.elements.size());
    for (glm::vec3& l : radiance) l = {u(rng), u(rng), u(rng)};

    GlContext context;
    SceneBuffers buffers(context, mesh);
    buffers.setElementRadiance(radiance);
    HemicubeRenderer renderer(buffers, 64);
    const HemicubeFrame frame = HemicubeFrame::randomlyRotated({0.4, 0.5, 0.3}, glm::normalize(glm::dvec3(-0.3, 0.1, 1)), 1);
    const glm::vec3 sky(3.0f, 2.0f, 1.0f);

    WeightedRadianceImage image;
    renderer.renderWeightedRadiance(frame, sky, image);
    ASSERT_EQ(image.width, 3 * 64);
    ASSERT_EQ(image.height, 64);
    const RadianceGather gather = renderer.gatherRadiance(frame, sky);
    EXPECT_GT(gather.skyFraction, 0.05);  // the open sides are really seen
    const glm::dvec3 total = image.total();
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(total[ch], gather.irradianceOverPi[ch], 1e-13 * total[ch]);

    const std::vector<WeightedRadianceImage> levels = reductionPyramid(image);
    // 192×64 → 96×32 → … → 3×1 → 2×1 → 1×1
    ASSERT_EQ(levels.size(), 9u);
    EXPECT_EQ(levels[1].width, 96);
    EXPECT_EQ(levels[6].width, 3);
    EXPECT_EQ(levels[7].width, 2);  // odd width: the last column folds into a half-covered pixel
    EXPECT_EQ(levels.back().width, 1);
    EXPECT_EQ(levels.back().height, 1);
    for (std::size_t level = 1; level < levels.size(); ++level)
        for (int ch = 0; ch < 3; ++ch)
            EXPECT_NEAR(levels[level].total()[ch], total[ch], 1e-14 * total[ch]) << "level " << level;
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(levels.back().pixels[0][ch], total[ch], 1e-14 * total[ch]);
}

TEST(HemicubeReduction, OddSizesAreSummedNotDropped) {
    WeightedRadianceImage image{3, 3, {}};
    for (int k = 0; k < 9; ++k) image.pixels.push_back(glm::dvec3(k + 1));
    const WeightedRadianceImage half = reduce2x2(image);
    ASSERT_EQ(half.width, 2);
    ASSERT_EQ(half.height, 2);
    EXPECT_EQ(half.pixels[0].x, 1 + 2 + 4 + 5);
    EXPECT_EQ(half.pixels[1].x, 3 + 6);
    EXPECT_EQ(half.pixels[2].x, 7 + 8);
    EXPECT_EQ(half.pixels[3].x, 9);
    EXPECT_EQ(half.total().x, 45);
}

}  // namespace
}  // namespace hemibake
