// baker/spherical_harmonics, baker/cube_map_solid_angle, measureCubeMap and the octahedral map: the SH maths
// against GROUND_TRUTH §6, on synthetic cube maps (no GL).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

#include "baker/probes/cube_map_solid_angle.h"
#include "baker/probes/light_probes.h"
#include "baker/probes/spherical_harmonics.h"
#include "baker/probes/volume_lookup.h"

namespace hemibake {
namespace {


CubeMapImage synthetic(int r, const std::function<glm::vec4(const glm::dvec3&)>& f) {
    CubeMapImage image;
    image.resolution = r;
    image.pixels.resize(std::size_t(6 * r * r));
    for (int face = 0; face < 6; ++face)
        for (int j = 0; j < r; ++j)
            for (int i = 0; i < r; ++i)
                const_cast<glm::vec4&>(image.at(face, i, j)) = f(glm::normalize(image.direction(face, i, j)));
    return image;
}

ShRgb project(int r, const std::function<glm::vec4(const glm::dvec3&)>& f) {
    const auto omega = cubeFaceSolidAngles(r);
    return measureCubeMap(synthetic(r, f), omega, 0, 1.0).sh;
}

TEST(CubeMapSolidAngle, TexelsSumToFourPi) {
    for (int r : {1, 2, 7, 32, 128}) {
        double sum = 0.0;
        for (double w : cubeFaceSolidAngles(r)) sum += w;
        EXPECT_NEAR(6.0 * sum, 4.0 * std::numbers::pi, 1e-12) << "R " << r;
    }
    // A corner texel is smaller than a centre texel by about (1 + 2)^{3/2} = 5.2 at fine resolution.
    const auto w = cubeFaceSolidAngles(64);
    EXPECT_NEAR(w[31 * 64 + 31] / w[0], std::pow(3.0, 1.5), 0.2);
}

TEST(SphericalHarmonics, BasisConstantsAndOrder) {
    const auto y = shBasis(glm::dvec3(0, 1, 0));
    EXPECT_NEAR(y[0], 0.282095, 1e-6);
    EXPECT_NEAR(y[1], 0.488603, 1e-6);  // Y1-1 ∝ y
    EXPECT_NEAR(y[6], -0.315392, 1e-6);
    EXPECT_NEAR(y[8], -0.546274, 1e-6);
    const glm::dvec3 d = glm::normalize(glm::dvec3(1, 2, 3));
    const auto v = shBasis(d);
    EXPECT_NEAR(v[2], 0.488603 * d.z, 1e-6);  // Y10 ∝ z
    EXPECT_NEAR(v[3], 0.488603 * d.x, 1e-6);  // Y11 ∝ x
    EXPECT_NEAR(v[4], 1.092548 * d.x * d.y, 1e-6);
    EXPECT_NEAR(v[5], 1.092548 * d.y * d.z, 1e-6);
    EXPECT_NEAR(v[7], 1.092548 * d.x * d.z, 1e-6);
}

TEST(SphericalHarmonics, ConstantRadianceProjectsToL00Only) {
    const ShRgb sh = project(16, [](const glm::dvec3&) { return glm::vec4(2.0f, 1.0f, 0.5f, 1.0f); });
    EXPECT_NEAR(sh.c[0].x, 2.0 * 2.0 * std::sqrt(std::numbers::pi), 1e-12);
    for (int k = 1; k < kShCoefficients; ++k) EXPECT_NEAR(glm::length(sh.c[std::size_t(k)]), 0.0, 1e-12) << k;
    EXPECT_NEAR(sh.irradianceOverPi(glm::normalize(glm::dvec3(-1, 3, 2))).y, 1.0, 1e-12);
}

// §6 test 1 with y up: L = 1 above the horizon. L00 = √π, L1-1 = √(3π)/2, E/π = (1 + cos θ)/2 exactly.
TEST(SphericalHarmonics, UniformSkyIsExact) {
    const ShRgb sh = project(64, [](const glm::dvec3& d) { return glm::vec4(d.y > 0.0 ? 1.0f : 0.0f); });
    EXPECT_NEAR(sh.c[0].x, std::sqrt(std::numbers::pi), 1e-12);
    EXPECT_NEAR(sh.c[1].x, std::sqrt(3.0 * std::numbers::pi) / 2.0, 2e-4);  // the horizon row's texel quadrature
    for (int k : {2, 3, 4, 5, 6, 7, 8}) EXPECT_NEAR(sh.c[std::size_t(k)].x, 0.0, 1e-12) << k;
    for (double deg : {0.0, 30.0, 45.0, 60.0, 90.0, 120.0, 150.0, 180.0}) {
        const double t = deg * std::numbers::pi / 180.0;
        EXPECT_NEAR(sh.irradiance({std::sin(t), std::cos(t), 0.0}).x, std::numbers::pi * (1.0 + std::cos(t)) / 2.0, 5e-4) << deg;
    }
}

// §6 test 2, band scaling: coefficients L_lm = Y_lm(d) are a unit directional light; the reconstructed
// irradiance is (3 + 16c + 15c²)/32.
TEST(SphericalHarmonics, DirectionalLightBandScaling) {
    const glm::dvec3 d = glm::normalize(glm::dvec3(0.3, 0.8, -0.5));
    ShRgb sh;
    const auto y = shBasis(d);
    for (int k = 0; k < kShCoefficients; ++k) sh.c[std::size_t(k)] = glm::dvec3(y[std::size_t(k)]);
    for (double deg : {0.0, 30.0, 60.0, 90.0, 122.2, 180.0}) {
        const double c = std::cos(deg * std::numbers::pi / 180.0);
        // A normal at angle deg from d.
        const glm::dvec3 side = glm::normalize(glm::cross(d, glm::dvec3(1, 0, 0)));
        const glm::dvec3 n = c * d + std::sqrt(std::max(0.0, 1.0 - c * c)) * side;
        EXPECT_NEAR(sh.irradiance(n).x, (3.0 + 16.0 * c + 15.0 * c * c) / 32.0, 1e-12) << deg;
    }
    EXPECT_NEAR(sh.irradiance(d).x, 1.0625, 1e-12);
    // Gaussian window: (1, 0.830, 0.572) and no negative lobe (table in §6: E(0) 0.844, E(90) 0.161, min 0).
    const glm::dvec3 w = shWindowWeights(ShWindow::Gaussian);
    EXPECT_NEAR(w.y, 0.830, 1e-3);
    EXPECT_NEAR(w.z, 0.572, 1e-3);
    ShRgb windowed = sh;
    windowed.scaleBands(w);
    EXPECT_NEAR(windowed.irradiance(d).x, 0.844, 1e-3);
    double minimum = 1e9;
    for (int k = 0; k <= 180; ++k) {
        const double c = std::cos(k * std::numbers::pi / 180.0);
        const glm::dvec3 side = glm::normalize(glm::cross(d, glm::dvec3(1, 0, 0)));
        minimum = std::min(minimum, windowed.irradiance(c * d + std::sqrt(std::max(0.0, 1.0 - c * c)) * side).x);
    }
    EXPECT_GT(minimum, -1e-4);
    EXPECT_EQ(parseShWindow("gaussian"), ShWindow::Gaussian);
    EXPECT_THROW(parseShWindow("hann"), std::invalid_argument);
}

// The documented bias of the window on the uniform sky: E(up) = (w0 + w1)/2 · π.
TEST(SphericalHarmonics, WindowBiasOnUniformSky) {
    ShRgb sh = project(64, [](const glm::dvec3& d) { return glm::vec4(d.y > 0.0 ? 1.0f : 0.0f); });
    const glm::dvec3 w = shWindowWeights(ShWindow::Gaussian);
    sh.scaleBands(w);
    EXPECT_NEAR(sh.irradiance({0, 1, 0}).x, (w.x + w.y) / 2.0 * std::numbers::pi, 5e-4);
}

TEST(CubeMapMeasurement, FractionsAndDepthMoments) {
    const auto omega = cubeFaceSolidAngles(32);
    // Back faces at 2 m below the horizon, sky above.
    const CubeMapImage image = synthetic(32, [](const glm::dvec3& d) {
        return d.y < 0.0 ? glm::vec4(0.0f, 0.0f, 0.0f, -2.0f) : glm::vec4(1.0f, 1.0f, 1.0f, 0.0f);
    });
    const CubeMapMeasurement m = measureCubeMap(image, omega, 8, 10.0);
    EXPECT_NEAR(m.backfaceFraction, 0.5, 1e-12);
    EXPECT_NEAR(m.skyFraction, 0.5, 1e-12);
    EXPECT_TRUE(m.sawBackface);
    EXPECT_NEAR(m.nearestBackfaceDistanceM, 2.0, 0.0);
    EXPECT_LT(m.nearestBackfaceDirection.y, 0.0);
    ASSERT_EQ(m.depthMoments.size(), 64u);
    IrradianceVolumeData v;
    v.depthResolution = 8;
    v.depthMoments = m.depthMoments;
    const glm::dvec2 down = v.depthMomentsAt(0, glm::normalize(glm::dvec3(0.1, -1, 0.2)));
    EXPECT_NEAR(down.x, 2.0, 1e-6);
    EXPECT_NEAR(down.y, 4.0, 1e-5);
    const glm::dvec2 up = v.depthMomentsAt(0, glm::normalize(glm::dvec3(0.1, 1, 0.2)));
    EXPECT_NEAR(up.x, 10.0, 1e-5);
}

TEST(OctahedralMap, RoundTrip) {
    for (const glm::dvec3& d : {glm::dvec3(0, 0, 1), glm::dvec3(0, 0, -1), glm::dvec3(1, 2, -3), glm::dvec3(-0.2, -0.9, 0.1),
                                glm::dvec3(0, 1, 0)}) {
        const glm::dvec3 n = glm::normalize(d);
        const glm::dvec2 uv = octahedralEncode(n);
        EXPECT_GE(uv.x, 0.0);
        EXPECT_LE(uv.y, 1.0);
        EXPECT_NEAR(glm::length(octahedralDecode(uv) - n), 0.0, 1e-12);
    }
}

// Trilinear interpolation of probes whose E/π is linear in x reproduces it, and invalid probes are excluded.
TEST(VolumeLookup, TrilinearAndValidity) {
    IrradianceVolumeData v;
    v.boxMin = {0, 0, 0};
    v.boxMax = {2, 1, 1};
    v.resolution = {3, 2, 2};
    v.sh.resize(12);
    v.valid.assign(12, 1);
    for (int z = 0; z < 2; ++z)
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 3; ++x)  // constant radiance x + 1: E/π = x + 1 for every normal
                v.sh[v.index(x, y, z)].c[0] = glm::dvec3(2.0 * std::sqrt(std::numbers::pi) * (x + 1.0));
    VolumeLookupOptions tri;
    tri.weighting = VolumeWeighting::Trilinear;
    EXPECT_NEAR(sampleIrradianceVolume(v, {0.25, 0.3, 0.9}, {0, 1, 0}, tri).irradianceOverPi.x, 1.25, 1e-12);
    EXPECT_NEAR(sampleIrradianceVolume(v, {1.5, 0.5, 0.5}, {0, 1, 0}, tri).irradianceOverPi.x, 2.5, 1e-12);
    for (int z = 0; z < 2; ++z)
        for (int y = 0; y < 2; ++y) v.valid[v.index(2, y, z)] = 0;
    EXPECT_NEAR(sampleIrradianceVolume(v, {1.5, 0.5, 0.5}, {0, 1, 0}, tri).irradianceOverPi.x, 2.0, 1e-12);
    VolumeLookupOptions naive;
    naive.weighting = VolumeWeighting::Naive;
    EXPECT_NEAR(sampleIrradianceVolume(v, {1.5, 0.5, 0.5}, {0, 1, 0}, naive).irradianceOverPi.x, 2.5, 1e-12);
    // Without depth data the visibility weighting still renormalises over valid probes.
    EXPECT_NEAR(sampleIrradianceVolume(v, {1.5, 0.5, 0.5}, {0, 1, 0}).irradianceOverPi.x, 2.0, 1e-12);
}

}  // namespace
}  // namespace hemibake
