// raster/cube_map_renderer: face layout, distances, back-face tagging and sky, by real OSMesa rendering.
#include <gtest/gtest.h>

#include "raster/cube_map_renderer.h"
#include "support/raster_fixtures.h"

namespace hemibake {
namespace {

TEST(CubeMapRenderer, FacesDistancesBackFacesAndSky) {
    test::TriangleSoup soup;
    // A square facing the probe (front towards −x) at x = 2, and one at y = −1 facing away (front −y).
    soup.addQuad({2, -1, -1}, {2, -1, 1}, {2, 1, 1}, {2, 1, -1});
    soup.addQuad({-1, -1, -1}, {1, -1, -1}, {1, -1, 1}, {-1, -1, 1});
    PatchMesh mesh = soup.build();
    GlContext context;
    SceneBuffers buffers(context, mesh);
    std::vector<glm::vec3> radiance(mesh.elements.size(), glm::vec3(5.0f, 4.0f, 3.0f));
    buffers.setElementRadiance(radiance);
    CubeMapRenderer renderer(buffers, 16);
    CubeMapImage image;
    renderer.render({0, 0, 0}, glm::vec3(0.5f, 0.25f, 0.125f), image);
    ASSERT_EQ(image.pixels.size(), std::size_t(3 * 16 * 2 * 16));
    // +X face centre: the front of the first square, at distance |texel direction| × 2.
    const glm::vec4 front = image.at(0, 8, 8);
    EXPECT_EQ(front.x, 5.0f);
    EXPECT_NEAR(front.w, 2.0 * glm::length(image.direction(0, 8, 8)), 1e-4);
    // −Y face centre: the back of the second square, black, negative distance.
    const glm::vec4 back = image.at(3, 8, 8);
    EXPECT_EQ(back.x, 0.0f);
    EXPECT_NEAR(back.w, -1.0 * glm::length(image.direction(3, 8, 8)), 1e-4);
    // +Y face and −X face: sky.
    EXPECT_EQ(image.at(2, 8, 8), glm::vec4(0.5f, 0.25f, 0.125f, 0.0f));
    EXPECT_EQ(image.at(1, 3, 12), glm::vec4(0.5f, 0.25f, 0.125f, 0.0f));
    // Orientation: on the +X face (right = +z, up = +y), the square covers |s|,|t| ≤ 1/2: texel 2 (s = −0.69) is sky.
    EXPECT_EQ(image.at(0, 2, 8).w, 0.0f);
    EXPECT_GT(image.at(0, 5, 8).w, 0.0f);
}

}  // namespace
}  // namespace hemibake
