// raster/lightmapped_renderer: the pinhole framing matches the path tracer's camera model, radiance passes through
// unchanged, lightmap UVs address texels as glTF does, back faces of single-sided batches are black, and a
// scene 1e5 m from the origin renders like one at it.
#include <gtest/gtest.h>

#include <cmath>

#include "raster/lightmapped_renderer.h"

namespace hemibake {
namespace {

// A square of side `side` facing +z (counter-clockwise seen from +z), centred at `centre`, UVs covering [0,1]².
LightmappedBatch square(const glm::dvec3& centre, double side, const std::vector<glm::vec3>* radiance, int atlasSize) {
    LightmappedBatch b;
    const double h = 0.5 * side;
    const glm::dvec3 p00 = centre + glm::dvec3(-h, -h, 0), p10 = centre + glm::dvec3(h, -h, 0),
                     p11 = centre + glm::dvec3(h, h, 0), p01 = centre + glm::dvec3(-h, h, 0);
    // v down in glTF: the top edge (y = +h) has v = 0.
    const glm::vec2 t00(0, 1), t10(1, 1), t11(1, 0), t01(0, 0);
    b.positions = {p00, p10, p11, p00, p11, p01};
    b.uvs = {t00, t10, t11, t00, t11, t01};
    b.atlasSize = atlasSize;
    b.radiance = radiance;
    return b;
}

PinholeView lookingDownMinusZ(const glm::dvec3& eye, int size) {
    PinholeView view;
    view.position = eye;
    view.forward = {0, 0, -1};
    view.up = {0, 1, 0};
    view.yfovRadians = 2.0 * std::atan(0.5);  // tan(half fov) = 0.5
    view.width = view.height = size;
    view.nearM = 1e-3;
    return view;
}

class LightmappedRendererTest : public ::testing::Test {
protected:
    GlContext context;
};

TEST_F(LightmappedRendererTest, FramesLikeThePinholeModelAndKeepsRadiance) {
    // Square of side 1 at distance 2 with tan(half fov) = 0.5: it spans exactly half the image width. With 64
    // pixels, pixels 16..47 are fully inside, the rest fully outside (edges fall on pixel boundaries).
    const std::vector<glm::vec3> atlas(4 * 4, glm::vec3(2.5f, 0.5f, 1e-3f));
    const std::vector<LightmappedBatch> batches{square({0, 0, 0}, 1.0, &atlas, 4)};
    const glm::vec3 sky(0.1f, 0.2f, 0.3f);
    const int size = 64;
    const std::vector<glm::vec3> image = renderLightmapped(context, batches, lookingDownMinusZ({0, 0, 2}, size), sky, 4);
    ASSERT_EQ(image.size(), std::size_t(size * size));
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const bool inside = x >= 16 && x < 48 && y >= 16 && y < 48;
            const glm::vec3 expected = inside ? atlas[0] : sky;
            const glm::vec3 got = image[std::size_t(y * size + x)];
            for (int c = 0; c < 3; ++c)
                ASSERT_NEAR(got[c], expected[c], 1e-6f * std::abs(expected[c]) + 1e-9f) << "pixel " << x << "," << y;
        }
}

TEST_F(LightmappedRendererTest, UvsAddressTexelsTopDownAndBackFacesAreBlack) {
    // 2×2 atlas: top row (v < 0.5) red, bottom row blue. The square's top half must show red.
    const std::vector<glm::vec3> atlas{{1, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 0, 1}};
    std::vector<LightmappedBatch> batches{square({0, 0, 0}, 1.0, &atlas, 2)};
    const int size = 64;
    const std::vector<glm::vec3> front = renderLightmapped(context, batches, lookingDownMinusZ({0, 0, 2}, size), {}, 1);
    // The square spans pixels 16..47. Row 24's centre is at v = 8.5/32: bilinear between the texel centres at
    // v = 0.25 (red) and 0.75 (blue) gives 1/32 blue. Row 40 (v = 24.5/32) lies past the blue centre: pure blue.
    // GL filters with 8-bit sub-texel weights, hence 1/256.
    const glm::vec3 top = front[std::size_t(24 * size + 32)], bottom = front[std::size_t(40 * size + 32)];
    EXPECT_NEAR(top.x, 31.0f / 32.0f, 1.0f / 256.0f);
    EXPECT_NEAR(top.z, 1.0f / 32.0f, 1.0f / 256.0f);
    EXPECT_NEAR(bottom.z, 1.0f, 1.0f / 256.0f);
    EXPECT_NEAR(bottom.x, 0.0f, 1.0f / 256.0f);

    // From behind (eye at z = -2 looking +z): single-sided → black, double-sided → the lightmap.
    PinholeView behind = lookingDownMinusZ({0, 0, -2}, size);
    behind.forward = {0, 0, 1};
    const glm::vec3 sky(0.5f);
    const std::vector<glm::vec3> back = renderLightmapped(context, batches, behind, sky, 1);
    EXPECT_EQ(back[std::size_t(32 * size + 32)], glm::vec3(0.0f));
    EXPECT_EQ(back[std::size_t(2 * size + 2)], sky);
    batches[0].doubleSided = true;
    const std::vector<glm::vec3> twoSided = renderLightmapped(context, batches, behind, sky, 1);
    // Seen from behind the image is mirrored left-right, not top-bottom: row 24 still shows the top half.
    EXPECT_NEAR(twoSided[std::size_t(24 * size + 32)].x, 31.0f / 32.0f, 1.0f / 256.0f);
}

TEST_F(LightmappedRendererTest, FarFromTheOriginRendersTheSamePicture) {
    const std::vector<glm::vec3> atlas(16, glm::vec3(1.0f));
    const int size = 64;
    const glm::dvec3 offset(1e5, -2e5, 3e5);
    const std::vector<glm::vec3> near = renderLightmapped(
        context, {square({0, 0, 0}, 1.0, &atlas, 4)}, lookingDownMinusZ({0.01, 0.02, 2}, size), {}, 2);
    const std::vector<glm::vec3> far = renderLightmapped(
        context, {square(offset, 1.0, &atlas, 4)}, lookingDownMinusZ(offset + glm::dvec3(0.01, 0.02, 2), size), {}, 2);
    // Float positions relative to the eye: ~1e5 m × 2^-24 ≈ 6 mm of vertex jitter would move edges by a
    // fifth of a pixel; relative to the eye they are exact to ~1e-7 m.
    std::size_t differing = 0;
    for (std::size_t i = 0; i < near.size(); ++i) differing += std::abs(near[i].x - far[i].x) > 1e-6f;
    EXPECT_EQ(differing, 0u);
}

TEST_F(LightmappedRendererTest, RejectsMismatchedBatches) {
    const std::vector<glm::vec3> atlas(4, glm::vec3(1.0f));
    LightmappedBatch bad = square({0, 0, 0}, 1.0, &atlas, 4);  // 4 texels for a 4×4 atlas
    EXPECT_THROW(renderLightmapped(context, {bad}, lookingDownMinusZ({0, 0, 2}, 8), {}), std::invalid_argument);
}

}  // namespace
}  // namespace hemibake
