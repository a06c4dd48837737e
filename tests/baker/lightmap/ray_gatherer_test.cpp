// The final gather by rays against known answers: GROUND_TRUTH §1(c) point → disk, the uniform furnace (§2), and
// what a ray must see where the hemicube has a rule (double-sided twins, back faces, texel light, sky).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "baker/lightmap/ray_gatherer.h"
#include "support/raster_cases.h"
#include "support/raster_fixtures.h"

using namespace hemibake;
using namespace hemibake::test;

namespace {

constexpr int kRays = 4096;  // 64 × 64 strata, the medium preset's count
constexpr int kStrata = 64;

// One standard deviation bound of a stratified estimate of a coaxial disk's form factor F (sky 0, radiance 1).
// Malley's method maps the concentric square of half-side ρ onto the disk of radius ρ = sin(half-angle) = √F, so
// the disk's preimage is an axis-aligned square of side √F in the unit square: only the strata its four edges cut
// can be wrong, at most 4 (√F·N + 2) of them, each an independent Bernoulli of variance ≤ 1/4, weighted 1/N².
double diskSigmaBound(double formFactor) {
    const double cut = 4.0 * (std::sqrt(formFactor) * kStrata + 2.0);
    return std::sqrt(0.25 * cut) / double(kStrata * kStrata);
}

// Every element of `mesh` gets a back copy (reversed winding, flipped normal, backSide 1, vertices of its own), as
// subdivision builds double-sided surfaces.
void addBackCopies(PatchMesh& mesh) {
    ElementArrays& e = mesh.elements;
    const std::size_t n = e.size();
    for (std::size_t k = 0; k < n; ++k) {
        const auto first = std::uint32_t(e.vertices.size());
        for (int c = 0; c < 3; ++c) {
            e.vertices.push_back(e.vertices[e.triangles[k][std::size_t(c)]]);
            e.vertexLightmapUv.push_back(glm::vec2(0.0f));
        }
        e.triangles.push_back({first, first + 2, first + 1});
        e.normal.push_back(-e.normal[k]);
        e.centroid.push_back(e.centroid[k]);
        e.areaM2.push_back(e.areaM2[k]);
        e.reflectance.push_back(e.reflectance[k]);
        e.emittedRadiance.push_back(e.emittedRadiance[k]);
        e.patch.push_back(e.patch[k]);
        e.instance.push_back(e.instance[k]);
        e.sourceFace.push_back(e.sourceFace[k]);
        e.backSide.push_back(1);
    }
}

PatchMesh diskMesh(double radius, double height) {
    const PointCase c{"disk", diskPolygon(radius, height, 1024), diskFormFactor(radius, height), {0, 0, 0}, height};
    return c.mesh();
}

glm::dvec3 gatherOne(RayGatherer& g, const glm::dvec3& p, const glm::vec3& n, std::uint64_t sweep, float* backface = nullptr,
                     glm::vec3 sky = glm::vec3(0.0f), std::uint64_t* escaped = nullptr) {
    std::vector<glm::dvec3> out;
    std::vector<float> back;
    const std::uint64_t skies = g.gather({GatherPoint{p, n}}, sky, sweep, out, &back).escaped;
    if (backface) *backface = back[0];
    if (escaped) *escaped = skies;
    return out[0];
}

// Inside a closed furnace every point sees exactly its radiance, under a bright sky: no ray escapes, none meets a
// back face (GROUND_TRUTH §2).
void expectFurnaceSeenFromEveryPoint(RayGatherer& g, const std::vector<GatherPoint>& points, const glm::vec3& radiance) {
    std::vector<glm::dvec3> out;
    std::vector<float> back;
    EXPECT_EQ(g.gather(points, glm::vec3(1e6f), 1, out, &back).escaped, 0u);  // not one ray escapes
    for (std::size_t k = 0; k < points.size(); ++k) {
        SCOPED_TRACE(k);
        EXPECT_NEAR(out[k].x, radiance.x, 1e-12);
        EXPECT_NEAR(out[k].y, radiance.y, 1e-12);
        EXPECT_NEAR(out[k].z, radiance.z, 1e-12);
        EXPECT_EQ(back[k], 0.0f);
    }
}

}  // namespace

TEST(RayGatherer, RaysPerPointAreTheLargestSquareAtMostTheRequest) {
    const PatchMesh mesh = diskMesh(1.0, 1.0);
    EXPECT_EQ(RayGatherer(mesh, 4096, 1).raysPerPoint(), 4096);
    EXPECT_EQ(RayGatherer(mesh, 4095, 1).raysPerPoint(), 63 * 63);
    EXPECT_EQ(RayGatherer(mesh, 1, 1).raysPerPoint(), 1);
    EXPECT_EQ(RayGatherer(mesh, 0, 1).raysPerPoint(), 1);
}

// GROUND_TRUTH §1(c): F = r²/(r² + h²), here of the 1,024-gon by Lambert's formula. Each gather lies within 5σ of
// the stratification bound above, and the mean of 64 independent gathers within 5σ/8 (no bias); the rays that
// escape are exactly those that missed the disk.
TEST(RayGatherer, PointToDiskIsLambertsFormFactorWithinTheStratificationBound) {
    for (const auto& [r, h] : {std::pair{1.0, 1.0}, std::pair{0.5, 1.0}, std::pair{0.25, 2.0}}) {
        SCOPED_TRACE("r=" + std::to_string(r) + " h=" + std::to_string(h));
        const PatchMesh mesh = diskMesh(r, h);
        const double exact = pointPolygonFormFactor({0, 0, 0}, {0, 0, 1}, diskPolygon(r, h, 1024));
        ASSERT_NEAR(exact, diskFormFactor(r, h), 1e-4 * exact);
        RayGatherer g(mesh, kRays, 7);
        g.setElementRadiance(std::vector<glm::vec3>(mesh.elements.size(), glm::vec3(1.0f)));
        const double sigma = diskSigmaBound(exact);
        constexpr int kGathers = 64;
        double sum = 0.0;
        for (int k = 0; k < kGathers; ++k) {
            float back = -1.0f;
            std::uint64_t escaped = 0;
            const glm::dvec3 e = gatherOne(g, {0, 0, 0}, {0, 0, 1}, std::uint64_t(k), &back, glm::vec3(0.0f), &escaped);
            EXPECT_NEAR(e.x, exact, 5.0 * sigma);
            EXPECT_EQ(e.x, e.y);
            EXPECT_EQ(back, 0.0f);
            // Radiance 1 on the disk, nothing elsewhere: every ray that missed it escaped, and E/π counts the rest.
            EXPECT_EQ(double(kRays - escaped), e.x * kRays);
            sum += e.x;
        }
        EXPECT_NEAR(sum / kGathers, exact, 5.0 * sigma / std::sqrt(double(kGathers)));
    }
}

// GROUND_TRUTH §2: inside a closed box of uniform radiance every point sees exactly that radiance in every direction,
// wherever it is (1 mm from a corner as well) and however it faces: no ray may escape to the (bright) sky through
// an edge between elements, none may see a back face.
TEST(RayGatherer, FurnaceSeesTheUniformRadianceFromEveryPoint) {
    TriangleSoup soup;
    soup.addInwardBox({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}, 5);
    soup.translate({1e5, -2e4, 3.0});  // far from the world origin: precision is relative to the scene
    const PatchMesh mesh = soup.build();
    const glm::vec3 radiance(1.0f, 0.5f, 2.0f);
    RayGatherer g(mesh, 1024, 3);
    g.setElementRadiance(std::vector<glm::vec3>(mesh.elements.size(), radiance));
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-0.499, 0.499);
    std::normal_distribution<double> gauss;
    std::vector<GatherPoint> points;
    const glm::dvec3 centre(1e5, -2e4, 3.0);
    for (int k = 0; k < 64; ++k) {  // anywhere inside, facing anywhere
        const glm::dvec3 n = glm::normalize(glm::dvec3(gauss(rng), gauss(rng), gauss(rng)));
        points.push_back({centre + glm::dvec3(u(rng), u(rng), u(rng)), glm::vec3(n)});
    }
    for (int k = 0; k < 64; ++k) {  // on the floor, up to its edges and corners (texels sit on surfaces)
        const double x = k % 8 == 0 ? -0.499 : u(rng), y = k % 8 == 1 ? 0.499 : u(rng);
        points.push_back({centre + glm::dvec3(x, y, -0.5), glm::vec3(0, 0, 1)});
    }
    expectFurnaceSeenFromEveryPoint(g, points, radiance);
}

// Two flat furnaces 3 km apart, 1 × 1 m and 4 mm tall (the gap between two parts), each its own island
// (mesh/islands.h), turned off the axes so no wall's coordinates are exact in float. Each keeps the ray offset of its
// own size, raised to EmbreeScene::kRayEpsilonFloatSteps float steps at 1.5 km from the frame's centre (0.7 mm;
// floats step by 0.12 mm there). Points on the floor and a wall, up to 1 mm from the edges, lifted by that offset,
// must see exactly the furnace's radiance: no ray re-hits its own surface (a back face), none slips out through an
// edge to the bright sky (GROUND_TRUTH §2). With the whole scene's offset (12 mm) instead, the points rose out of
// their furnaces (385 expectations failed); with 0.1 float step, 71 of the 256 re-hit their own surfaces.
TEST(RayGatherer, FlatFurnacesKilometresApartSeeTheirUniformRadiance) {
    const FlatFurnaces furnaces;
    const PatchMesh& mesh = furnaces.mesh;
    const glm::vec3 radiance(1.0f, 0.5f, 2.0f);
    RayGatherer g(mesh, 1024, 3);
    g.setElementRadiance(std::vector<glm::vec3>(mesh.elements.size(), radiance));
    std::mt19937_64 rng(12);
    std::vector<GatherPoint> points;
    furnaces.samplePoints(rng, 64, 0.75, [&](const FlatFurnaces::SurfacePoint& p) {
        points.push_back({p.position, glm::vec3(p.normal)});
    });
    expectFurnaceSeenFromEveryPoint(g, points, radiance);
}

// A double-sided surface is two coincident elements; a ray must take the one whose front it meets (the hemicube
// pushes the other back in depth). Seen from below the disk shows its front copy's radiance, from above its back
// copy's, and never a back face. A single-sided disk seen from behind is black and counted as back face.
TEST(RayGatherer, DoubleSidedSurfacesShowTheSideFacingTheRay) {
    PatchMesh mesh = diskMesh(1.0, 1.0);  // fronts face −z, towards the origin
    const std::size_t fronts = mesh.elements.size();
    addBackCopies(mesh);
    std::vector<glm::vec3> radiance(mesh.elements.size(), glm::vec3(1.0f));
    for (std::size_t e = fronts; e < radiance.size(); ++e) radiance[e] = glm::vec3(3.0f);
    RayGatherer g(mesh, kRays, 5);
    g.setElementRadiance(radiance);
    const double exact = pointPolygonFormFactor({0, 0, 0}, {0, 0, 1}, diskPolygon(1.0, 1.0, 1024));
    const double sigma = diskSigmaBound(exact);
    for (int k = 0; k < 8; ++k) {
        float back = -1.0f;
        EXPECT_NEAR(gatherOne(g, {0, 0, 0}, {0, 0, 1}, std::uint64_t(k), &back).x, 1.0 * exact, 5.0 * sigma);
        EXPECT_EQ(back, 0.0f);
        EXPECT_NEAR(gatherOne(g, {0, 0, 2}, {0, 0, -1}, std::uint64_t(k), &back).x, 3.0 * exact, 3.0 * 5.0 * sigma);
        EXPECT_EQ(back, 0.0f);
    }

    const PatchMesh single = diskMesh(1.0, 1.0);
    RayGatherer s(single, kRays, 5);
    s.setElementRadiance(std::vector<glm::vec3>(single.elements.size(), glm::vec3(1.0f)));
    float back = -1.0f;
    const glm::dvec3 behind = gatherOne(s, {0, 0, 2}, {0, 0, -1}, 0, &back, glm::vec3(0.25f));
    EXPECT_NEAR(behind.x, 0.25 * (1.0 - back), 1e-7);  // the sky where it is not the disk's black back
    EXPECT_NEAR(back, exact, 5.0 * sigma);
}

// Texel light is sampled as the hemicube's GL_LINEAR + GL_CLAMP_TO_EDGE sampler would, at the hit's lightmap UV,
// times the element's scale. A 2 × 2 m square 0.5 m above the point carries a 4 × 4 light layer varying along u and
// v (so both the bilinear weights and the clamped border count); the answer is the integral of that light over the
// square, by a 2,000² midpoint rule.
TEST(RayGatherer, TexelLightIsSampledBilinearlyAtTheHitUv) {
    TriangleSoup soup;
    const glm::dvec3 p0(-1, -1, 0.5), p1(1, -1, 0.5), p2(1, 1, 0.5), p3(-1, 1, 0.5);
    soup.addQuad(p0, p3, p2, p1);  // counter-clockwise from below: faces −z
    const PatchMesh mesh = soup.build();
    auto light = std::make_shared<TexelLight>();
    constexpr int kSize = 4;
    light->atlasSize = kSize;
    light->layers.assign(1, std::vector<glm::vec3>(kSize * kSize));
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) light->layers[0][std::size_t(y * kSize + x)] = glm::vec3(float(x), float(y * y), 1.0f);
    // The square's corners at UV (x + 1)/2, (y + 1)/2: element corners in their own order.
    light->cornerUvLayer.resize(mesh.elements.size());
    light->scale.assign(mesh.elements.size(), glm::vec3(0.5f, 2.0f, 1.0f));
    for (std::size_t e = 0; e < mesh.elements.size(); ++e)
        for (int c = 0; c < 3; ++c) {
            const glm::dvec3& q = mesh.elements.vertices[mesh.elements.triangles[e][std::size_t(c)]];
            light->cornerUvLayer[e][std::size_t(c)] = glm::vec3(float((q.x + 1) / 2), float((q.y + 1) / 2), 0.0f);
        }
    const auto sample = [&](double u, double v) {  // GL_LINEAR, GL_CLAMP_TO_EDGE
        const double x = u * kSize - 0.5, y = v * kSize - 0.5;
        const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
        const double fx = x - x0, fy = y - y0;
        const auto at = [&](int i, int j) {
            return glm::dvec3(light->layers[0][std::size_t(std::clamp(j, 0, kSize - 1) * kSize + std::clamp(i, 0, kSize - 1))]);
        };
        return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) + fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
    };
    glm::dvec3 exact(0.0);
    constexpr int kCells = 2000;
    const double h = 0.5, cell = 2.0 / kCells;
    for (int j = 0; j < kCells; ++j)
        for (int i = 0; i < kCells; ++i) {
            const double x = -1 + (i + 0.5) * cell, y = -1 + (j + 0.5) * cell;
            const double r2 = x * x + y * y + h * h;
            // E/π = ∫ L cosθ cosθ' / (π r²) dA, both cosines h/r.
            exact += sample((x + 1) / 2, (y + 1) / 2) * (h * h / (r2 * r2)) * (cell * cell / std::numbers::pi);
        }
    exact *= glm::dvec3(0.5, 2.0, 1.0);
    RayGatherer g(mesh, 256 * 256, 9);
    g.setElementRadiance(std::vector<glm::vec3>(mesh.elements.size(), glm::vec3(0.0f)));
    g.setTexelLight(light);
    const glm::dvec3 e = gatherOne(g, {0, 0, 0}, {0, 0, 1}, 0);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(e[c], exact[c], 2e-3 * exact[c]) << "channel " << c;
    // The same square without its texel light is black: the light above came only from the layer.
    g.setTexelLight(nullptr);
    EXPECT_EQ(gatherOne(g, {0, 0, 0}, {0, 0, 1}, 0).x, 0.0);
}

// A point's rays depend on its key and the sweep, not on its place in the batch: adaptive placement batches texels
// differently when one decision flips, and that must not re-draw every later texel's noise (it moved a 20-texel
// surface of the millimetre Cornell box by 0.18 %, BakeExtremes.MillimetreScale).
TEST(RayGatherer, APointsRaysDependOnItsKeyNotItsPlaceInTheBatch) {
    const PatchMesh mesh = diskMesh(1.0, 1.0);
    RayGatherer g(mesh, 256, 2);
    g.setElementRadiance(std::vector<glm::vec3>(mesh.elements.size(), glm::vec3(1.0f)));
    const GatherPoint a{{0.1, 0, 0}, {0, 0, 1}}, b{{0, 0.2, 0}, {0, 0, 1}};
    std::vector<glm::dvec3> alone, batch;
    const std::vector<std::uint32_t> keyB = {17}, keys = {5, 17};
    g.gather({b}, glm::vec3(0.0f), 3, alone, nullptr, keyB);
    g.gather({a, b}, glm::vec3(0.0f), 3, batch, nullptr, keys);
    EXPECT_EQ(alone[0], batch[1]);
    g.gather({a, b}, glm::vec3(0.0f), 4, batch, nullptr, keys);
    EXPECT_NE(alone[0], batch[1]) << "another sweep draws other rays";
    const std::vector<std::uint32_t> tooFew = {1};
    EXPECT_THROW(g.gather({a, b}, glm::vec3(0.0f), 3, batch, nullptr, tooFew), std::invalid_argument);
}

// A point inside geometry stops after its probe (an 8 × 8 sub-lattice of its strata): above a single-sided disk that
// faces down, a point looking down meets its back over F = r²/(r² + d²) of its cosine-weighted hemisphere (GROUND_TRUTH
// §1(c)). At d = r/2 that is 0.8: the probe's 64 rays see more than half back faces and the point stops there. At
// d = 2r (0.2, inside by the lightmap's tenth but not by the probe's half) and below the disk (no back at all) every
// ray is traced, and the values are exactly those of a gather with no probe (no back-face share asked for).
TEST(RayGatherer, PointsInsideGeometryStopAfterTheirProbe) {
    const PatchMesh mesh = diskMesh(1.0, 1.0);  // radius 1 at z = 1, facing the origin
    RayGatherer g(mesh, kRays, 11);
    g.setElementRadiance(std::vector<glm::vec3>(mesh.elements.size(), glm::vec3(2.0f)));
    g.setInsideBackFraction(0.1);  // the lightmap's default
    const glm::vec3 sky(0.5f);
    const std::vector<GatherPoint> points = {{{0, 0, 1.5}, {0, 0, -1}}, {{0, 0, 3}, {0, 0, -1}}, {{0, 0, 0}, {0, 0, 1}}};
    std::vector<glm::dvec3> probed, plain;
    std::vector<float> back;
    const RayGatherer::RayCounts counts = g.gather(points, sky, 1, probed, &back);
    const RayGatherer::RayCounts plainCounts = g.gather(points, sky, 1, plain, nullptr);
    constexpr int kProbeRays = RayGatherer::kProbeStrataPerSide * RayGatherer::kProbeStrataPerSide;
    EXPECT_EQ(counts.stoppedInside, 1u);
    EXPECT_EQ(counts.traced, std::uint64_t(kProbeRays + 2 * kRays));
    EXPECT_EQ(plainCounts.stoppedInside, 0u);
    EXPECT_EQ(plainCounts.traced, std::uint64_t(3 * kRays));
    // The stopped point: the probe's share of back faces, and the sky on the rest of its probe.
    EXPECT_GT(back[0], RayGatherer::kInsideProbeBackFraction);
    EXPECT_NEAR(back[0], 0.8, 0.1);
    EXPECT_NEAR(probed[0].x, sky.x * (1.0 - back[0]), 1e-12);
    // The others: every ray, the same sums.
    EXPECT_NEAR(back[1], 0.2, 5.0 * diskSigmaBound(0.2));
    EXPECT_EQ(back[2], 0.0f);
    EXPECT_EQ(probed[1], plain[1]);
    EXPECT_EQ(probed[2], plain[2]);
    EXPECT_NEAR(probed[2].x, 2.0 * 0.5 + 0.5 * 0.5, 5.0 * 1.5 * diskSigmaBound(0.5));  // F = 1/2 of L = 2, the rest sky

    // A caller whose inside share is close to the probe's half (or no share set: nothing is inside) probes nothing:
    // a point on the surface near that share could pass half of 64 rays by chance. Every ray is traced.
    for (const double inside : {0.25, 1.0}) {
        g.setInsideBackFraction(inside);
        std::vector<glm::dvec3> unprobed;
        const RayGatherer::RayCounts all = g.gather(points, sky, 1, unprobed, &back);
        EXPECT_EQ(all.stoppedInside, 0u);
        EXPECT_EQ(all.traced, std::uint64_t(3 * kRays));
        EXPECT_EQ(unprobed[0], plain[0]);
        EXPECT_NEAR(back[0], 0.8, 5.0 * diskSigmaBound(0.8));
    }
}

// The lightmap checks an interpolation beside a chart's edge against the texel's probe (adaptive_placement.h): the same
// 64 rays its gather traces first, with the standard error of their mean.
TEST(RayGatherer, AProbeIsItsGathersFirstRaysWithTheirStandardError) {
    const PatchMesh mesh = diskMesh(1.0, 1.0);  // radius 1 at z = 1, facing the origin
    RayGatherer g(mesh, kRays, 11);
    g.setElementRadiance(std::vector<glm::vec3>(mesh.elements.size(), glm::vec3(2.0f)));
    g.setInsideBackFraction(0.1);
    const glm::vec3 sky(0.5f);
    // Inside (the disk's back on 0.8 of its rays), half under the disk (F = 1/2), and facing away from it (sky only).
    const std::vector<GatherPoint> points = {{{0, 0, 1.5}, {0, 0, -1}}, {{0, 0, 0}, {0, 0, 1}}, {{0, 0, 0}, {0, 0, -1}}};
    std::vector<glm::dvec3> gathered, probed;
    std::vector<float> back;
    std::vector<double> standardError;
    g.gather(points, sky, 1, gathered, &back);
    const RayGatherer::RayCounts counts = g.probe(points, sky, 1, probed, standardError);
    constexpr int kProbeRays = RayGatherer::kProbeStrataPerSide * RayGatherer::kProbeStrataPerSide;
    EXPECT_EQ(counts.traced, std::uint64_t(3 * kProbeRays));
    EXPECT_EQ(counts.stoppedInside, 0u);  // a probe is not a gather stopped early
    // The point inside stopped after its probe: the same rays summed in the same order.
    EXPECT_EQ(probed[0], gathered[0]);
    // Under the disk: L = 2 on half the hemisphere's cosine-weighted measure, the sky on the rest: E/π = 1.25. Each ray
    // brings a channel sum of 6 or 1.5, on about half the rays each: a spread of 2.27 over 64 rays, 0.28 on the mean.
    EXPECT_NEAR(standardError[1], 0.2835, 0.01);
    EXPECT_NEAR(probed[1].x, 1.25, 4.0 * standardError[1] / 3.0);
    // Every ray meets the sky: the exact sky, and no spread at all.
    EXPECT_EQ(probed[2], glm::dvec3(sky));
    EXPECT_EQ(standardError[2], 0.0);
    // Fewer than 16 × 16 strata have no probe.
    const RayGatherer coarse(mesh, 64, 11);
    EXPECT_FALSE(coarse.canProbe());
    EXPECT_TRUE(g.canProbe());
    EXPECT_THROW(coarse.probe(points, sky, 1, probed, standardError), std::logic_error);
}
