// raster/hemicube: form factors and gathered radiance against GROUND_TRUTH.md §1-3, by real OSMesa rendering.
//
// Tolerances come from the §3 tables for the resolution used (R = 128 unless stated) or from the
// aliasing bound derived next to the test; each is an a-priori bound, not a measured value plus margin.
#include <gtest/gtest.h>

#include <cmath>

#include "raster/hemicube.h"
#include "support/raster_cases.h"

namespace hemibake {
namespace {

using namespace hemibake::test;

constexpr int kResolution = 128;
// Jittered, randomly rotated hemicubes per point case. §3.6 used 48; 192 makes our RMS estimate stable to
// ~±10 % (measured over seeds), so a 1.3× margin covers our noise plus the table's own 48-sample noise.
constexpr int kSamples = 192;
constexpr double kTableNoise = 1.3;

// §3.6 RMS at N = 128 for the straight-edged "square d=1" target (F = 0.239).
constexpr double kStraightEdgeRms128 = 1.7e-3;

// A world-vertical edge (perpendicular to the receiving surface) projects onto a pixel column of a side face
// whatever the rotation about the normal, so its aliasing does not average along the edge: it is off by a
// uniformly distributed fraction of one column, RMS = column/√12. A column spans ≤ 2/R radians of azimuth;
// from the horizon to elevation β it holds F = dφ·sin²β/(2π). Edges given as (horizontal distance, height).
double verticalEdgeRms(int resolution, std::initializer_list<std::pair<double, double>> edges) {
    double variance = 0.0;
    for (auto [d, h] : edges) {
        const double column = (2.0 / resolution) * (h * h / (h * h + d * d)) / (2.0 * std::numbers::pi);
        variance += column * column / 12.0;
    }
    return std::sqrt(variance);
}

struct PointTolerance {
    std::string name;
    double rms;  // expected RMS relative error at R = 128 (from §3.6 or derived), before kTableNoise
};

// GoogleTest would otherwise print the struct's bytes, padding included (uninitialised: valgrind reports it).
void PrintTo(const PointTolerance& p, std::ostream* os) { *os << p.name << " (RMS " << p.rms << ")"; }

class PointCaseTest : public ::testing::TestWithParam<PointTolerance> {};

TEST_P(PointCaseTest, MatchesGroundTruthWithinTheHemicubeTables) {
    const auto cases = pointCases();
    const auto it = std::find_if(cases.begin(), cases.end(), [&](const PointCase& c) { return c.name == GetParam().name; });
    ASSERT_NE(it, cases.end());
    const PointCase& c = *it;
    // The fixture is the §1 configuration: exact Lambert value at the un-jittered point = closed form
    // (the 1024-gon's area deficit makes disks ~6e-6 low).
    EXPECT_NEAR(pointPolygonFormFactor(c.point, {0, 0, 1}, c.polygon), c.groundTruth, 1e-5 * c.groundTruth);

    GlContext context;
    const PatchMesh mesh = c.mesh();
    SceneBuffers buffers(context, mesh);
    HemicubeRenderer renderer(buffers, kResolution);
    const ErrorStats stats = pointCaseErrors(renderer, c, kSamples, 2024);
    EXPECT_LT(stats.rms, kTableNoise * GetParam().rms) << c.name;
    // The max over samples is a heavy-tailed statistic (rare near-coherent alignments; §3.6's 48-sample max
    // is exceeded by 192 samples), so single hemicubes are held to the a-priori aliasing bound instead.
    EXPECT_LE(stats.worstOverBound, 1.0) << c.name;
    // Unbiased: exact weights and random lattice placement leave zero-mean aliasing noise
    // (midpoint weights would add ~+0.5/R², a wrong eye offset O(offset/distance)).
    EXPECT_LT(std::abs(stats.mean), 4.0 * stats.rms / std::sqrt(double(kSamples))) << c.name;
}

INSTANTIATE_TEST_SUITE_P(
    GroundTruth1cd, PointCaseTest,
    ::testing::Values(
        // Disks: §3.6 RMS at N = 128.
        PointTolerance{"disk r=0.5 h=1", 9.3e-4},
        PointTolerance{"disk r=1 h=1", 2.1e-4},
        // Straight edges at unit distance, like §3.6's "square d=1".
        PointTolerance{"parallel corner 1x1 c=1", kStraightEdgeRms128},
        PointTolerance{"parallel corner 2x2 c=1", kStraightEdgeRms128},
        // Dominated by the two vertical edges (x = 0 at distance c, x = a at √(a²+c²)).
        PointTolerance{"perpendicular a=b=c=1",
                       verticalEdgeRms(kResolution, {{1.0, 1.0}, {std::sqrt(2.0), 1.0}}) / cornerPerpendicularFormFactor(1, 1, 1)},
        PointTolerance{"perpendicular a=1 b=2 c=1",
                       verticalEdgeRms(kResolution, {{1.0, 2.0}, {std::sqrt(2.0), 2.0}}) / cornerPerpendicularFormFactor(1, 2, 1)}),
    [](const auto& p) {
        std::string name = p.param.name;
        for (char& ch : name)
            if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
        return name;
    });

TEST(Hemicube, ErrorShrinksWithResolution) {
    // §3.6: RMS over orientations falls as R^-1.5 (boundary pixels of random sign), 7.5e-3 → 3.1e-4 for
    // R = 32 → 256 on this disk; demand a strictly falling RMS and at least R^-1 overall (8×).
    const PointCase c = pointCases()[0];
    ASSERT_EQ(c.name, "disk r=0.5 h=1");
    GlContext context;
    const PatchMesh mesh = c.mesh();
    SceneBuffers buffers(context, mesh);
    double previous = 1.0, first = 0.0, last = 0.0;
    for (int r : {32, 64, 128, 256}) {
        HemicubeRenderer renderer(buffers, r);
        const double rms = pointCaseErrors(renderer, c, kSamples, 5).rms;
        EXPECT_LT(rms, previous) << "R = " << r;
        previous = rms;
        (r == 32 ? first : last) = rms;
    }
    EXPECT_LT(last, first / 8.0);
}

struct AreaTolerance {
    std::string name;
    double hemicube;  // allowed |hemicube average / same-point exact quadrature − 1|
};

class AreaCaseTest : public ::testing::TestWithParam<AreaTolerance> {};

TEST_P(AreaCaseTest, AveragedHemicubesMatchTheAreaFormFactor) {
    const auto cases = areaCases();
    const auto it = std::find_if(cases.begin(), cases.end(), [&](const AreaCase& c) { return c.name == GetParam().name; });
    ASSERT_NE(it, cases.end());
    GlContext context;
    const PatchMesh mesh = areaCaseMesh(*it);
    SceneBuffers buffers(context, mesh);
    HemicubeRenderer renderer(buffers, kResolution);
    const AreaEstimate estimate = areaCaseEstimate(renderer, *it, 16, 77);
    EXPECT_EQ(estimate.sourceSeen, 0.0) << "a sample must never see its own surface";
    // Pure hemicube error: the same 16×16 points with exact point form factors.
    EXPECT_NEAR(estimate.hemicube / estimate.quadrature, 1.0, GetParam().hemicube) << it->name;
    // Against the exact area form factor, the 16×16 midpoint quadrature's own bias adds (it is what §3.3-ii's
    // +7e-4 … +3e-4 at N = 128 mostly are).
    const double quadratureBias = std::abs(estimate.quadrature / it->groundTruth - 1.0);
    EXPECT_NEAR(estimate.hemicube / it->groundTruth, 1.0, quadratureBias + GetParam().hemicube) << it->name;
}

// The average of 256 rotated hemicubes has error ≈ (per-hemicube RMS)/16; tolerance 4σ with the §3.6 RMS at
// N = 128 (square d=1: 1.7e-3, also used for d = 0.5; square d=2: 4.0e-3). The hinged squares add the
// vertical-edge column aliasing (edges at horizontal distance ≥ 1/32 … 1, height 1): RMS ≤ 4e-3 per hemicube.
INSTANTIATE_TEST_SUITE_P(GroundTruth1ab, AreaCaseTest,
                         ::testing::Values(AreaTolerance{"coaxial squares d=0.5", 4 * 1.7e-3 / 16},
                                           AreaTolerance{"coaxial squares d=1", 4 * 1.7e-3 / 16},
                                           AreaTolerance{"coaxial squares d=2", 4 * 4.0e-3 / 16},
                                           AreaTolerance{"perpendicular squares", 4 * 4.0e-3 / 16}),
                         [](const auto& p) {
                             std::string name = p.param.name;
                             for (char& ch : name)
                                 if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                             return name;
                         });

TEST(Hemicube, AreaGroundTruthFormulasMatchTheTables) {
    EXPECT_NEAR(parallelRectanglesFormFactor(1, 1, 0.5), 0.4152532836, 1e-9);
    EXPECT_NEAR(parallelRectanglesFormFactor(1, 1, 1), 0.1998248957, 1e-9);
    EXPECT_NEAR(parallelRectanglesFormFactor(1, 1, 2), 0.0685895888, 1e-9);
    EXPECT_NEAR(perpendicularRectanglesFormFactor(1, 1, 1), 0.2000437761, 1e-9);
}

// A closed box: every pixel must hit an inward-facing element. Uniform radiance L must come back exactly
// (weights sum to 1, no pixel leaks to the 7L sky or to a back face), from points anywhere inside,
// including near walls and corners where the near plane and face seams are stressed.
TEST(Hemicube, ClosedBoxFurnaceGathersExactlyTheUniformRadiance) {
    TriangleSoup soup;
    soup.addInwardBox({-1.0, -0.5, 0.0}, {2.0, 1.5, 1.25}, 4);
    const PatchMesh mesh = soup.build();
    for (std::size_t e = 0; e < mesh.elements.size(); ++e)  // the fixture really faces inwards
        ASSERT_GT(glm::dot(glm::dvec3(mesh.elements.normal[e]), glm::dvec3(0.5, 0.5, 0.625) - mesh.elements.centroid[e]), 0.0);

    GlContext context;
    SceneBuffers buffers(context, mesh);
    const glm::vec3 radiance(1.0f, 0.5f, 0.25f);
    buffers.setElementRadiance(std::vector<glm::vec3>(mesh.elements.size(), radiance));
    HemicubeRenderer renderer(buffers, 64);

    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<HemicubeFrame> frames;
    for (int k = 0; k < 24; ++k) {
        const glm::dvec3 p(-1.0 + 3.0 * u(rng), -0.5 + 2.0 * u(rng), 1.25 * u(rng));
        const glm::dvec3 n = glm::normalize(glm::dvec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5));
        frames.push_back(HemicubeFrame::randomlyRotated(p, n, rng()));
    }
    frames.push_back({{-1.0 + 1e-3, -0.5 + 1e-3, 1e-3}, glm::normalize(glm::dvec3(-1, -1, -1)), 0.3});  // into a corner
    frames.push_back({{0.5, 0.5, 0.0}, {0, 0, 1}, 0.0});                                              // on the floor
    frames.push_back({{2.0, 1.5, 0.7}, glm::normalize(glm::dvec3(-1, -1, 0)), 1.0});                  // on an edge
    // On a wall, 4 near planes above the floor seam. (Exactly on the seam the floor would pass through the
    // eye and half the hemicube would look outside: sample points must lie inside their element.)
    frames.push_back({{-1.0, 0.2, 4.0 * renderer.nearPlaneM()}, {1, 0, 0}, 0.1});

    FormFactorList list;
    for (const HemicubeFrame& frame : frames) {
        const RadianceGather gather = renderer.gatherRadiance(frame, 7.0f * radiance);
        for (int ch = 0; ch < 3; ++ch)
            EXPECT_NEAR(gather.irradianceOverPi[ch], radiance[ch], 1e-6 * radiance[ch]) << "at " << frame.position.x << ","
                                                                                          << frame.position.y << "," << frame.position.z;
        EXPECT_EQ(gather.skyFraction, 0.0);
        EXPECT_EQ(gather.backfaceFraction, 0.0);

        renderer.renderFormFactors(frame, list);
        EXPECT_NEAR(list.sum(), 1.0, 1e-6);
        EXPECT_LT(list.skyFraction, 1e-6);
        EXPECT_EQ(list.backfaceFraction, 0.0);
        EXPECT_GT(list.size(), 1u);
        for (std::uint32_t e : list.elements) ASSERT_LT(e, mesh.elements.size());
    }
}

// Two flat furnaces 3 km apart, 1 × 1 m and 4 mm tall (the gap between two parts), turned off the axes, each its own
// island (mesh/islands.h). A hemicube on the floor or a wall, up to 1 mm from the edges, must gather exactly the
// furnace's radiance: nothing of the 7× brighter sky, no back face. With the scene's eye offset (1e-5 of its 3 km
// diagonal: 30 mm) every eye stood above its furnace's ceiling; each now takes its island's, raised to
// kEyeOffsetFloatSteps float steps at 1.5 km (0.7 mm; floats step by 0.09-0.18 mm there).
TEST(Hemicube, FlatFurnacesKilometresApartGatherExactlyTheUniformRadiance) {
    const FlatFurnaces furnaces;
    const PatchMesh& mesh = furnaces.mesh;
    constexpr double kHalfHeightM = FlatFurnaces::kHalfHeightM;

    GlContext context;
    SceneBuffers buffers(context, mesh);
    ASSERT_EQ(buffers.islands().size(), 2u);
    const glm::vec3 radiance(1.0f, 0.5f, 0.25f);
    buffers.setElementRadiance(std::vector<glm::vec3>(mesh.elements.size(), radiance));
    HemicubeRenderer renderer(buffers, 64);
    EXPECT_GT(renderer.eyeOffsetM(), 4.0 * kHalfHeightM);  // the scene's: it would not fit
    for (const glm::dvec3& centre : furnaces.centres) EXPECT_LT(renderer.eyeOffsetAtM(centre), 0.5 * kHalfHeightM);

    std::mt19937_64 rng(12);
    std::vector<HemicubeFrame> frames;
    furnaces.samplePoints(rng, 16, 0.5, [&](const FlatFurnaces::SurfacePoint& p) {
        frames.push_back(HemicubeFrame::randomlyRotated(p.position, p.normal, rng()));
    });
    FormFactorList list;
    for (const HemicubeFrame& frame : frames) {
        SCOPED_TRACE(frame.position.x);
        const RadianceGather gather = renderer.gatherRadiance(frame, 7.0f * radiance);
        for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(gather.irradianceOverPi[ch], radiance[ch], 1e-6 * radiance[ch]);
        EXPECT_EQ(gather.skyFraction, 0.0);
        EXPECT_EQ(gather.backfaceFraction, 0.0);
        renderer.renderFormFactors(frame, list);
        EXPECT_NEAR(list.sum(), 1.0, 1e-6);
        EXPECT_EQ(list.backfaceFraction, 0.0);
    }
}

TEST(Hemicube, FarFromTheOriginGivesTheSameFormFactors) {
    // 1e5 m away, float world coordinates would quantise to 8 mm; positions relative to the scene centre keep
    // the disk exact. Same jittered samples as near the origin, so the two runs must agree closely.
    PointCase near = pointCases()[0];
    PointCase far = near;
    const glm::dvec3 offset(1e5, -1e5, 1e5);
    for (glm::dvec3& v : far.polygon) v += offset;
    far.point += offset;

    GlContext context;
    const PatchMesh nearMesh = near.mesh(), farMesh = far.mesh();
    ASSERT_GT(glm::length(farMesh.origin), 1e5);
    SceneBuffers nearBuffers(context, nearMesh), farBuffers(context, farMesh);
    HemicubeRenderer nearRenderer(nearBuffers, kResolution), farRenderer(farBuffers, kResolution);
    const ErrorStats nearStats = pointCaseErrors(nearRenderer, near, 16, 3);
    const ErrorStats farStats = pointCaseErrors(farRenderer, far, 16, 3);
    EXPECT_LT(farStats.max, 2.5e-3);  // §3.6 max, N = 128, as near the origin
    EXPECT_NEAR(farStats.meanFormFactor, nearStats.meanFormFactor, 1e-5 * nearStats.meanFormFactor);
    // The same scene rendered in world floats (origin 0) really does fail: floats step 7.8 mm at 1e5 m, 1.6 % of
    // the disk's radius, so what keeps the far case exact is rendering relative to PatchMesh::origin.
    PatchMesh naiveMesh = farMesh;
    naiveMesh.origin = glm::dvec3(0.0);
    SceneBuffers naiveBuffers(context, naiveMesh);
    HemicubeRenderer naiveRenderer(naiveBuffers, kResolution);
    const ErrorStats naiveStats = pointCaseErrors(naiveRenderer, far, 16, 3);
    std::printf("far from the origin: max error %.2e relative to the mesh origin, %.2e in world floats\n", farStats.max,
                naiveStats.max);
    EXPECT_GT(naiveStats.max, 4.0 * farStats.max);
}

TEST(Hemicube, BackFacesOccludeAndSeeNothing) {
    // Single-sided unit quad at z = 1 facing up (away from the hemicube): the hemicube sees its back.
    TriangleSoup soup;
    soup.addQuad({-0.5, -0.5, 1}, {0.5, -0.5, 1}, {0.5, 0.5, 1}, {-0.5, 0.5, 1});
    // A front-facing quad above it, hidden behind the back face.
    soup.addQuad({-0.25, -0.25, 2}, {-0.25, 0.25, 2}, {0.25, 0.25, 2}, {0.25, -0.25, 2});
    const PatchMesh mesh = soup.build();
    ASSERT_GT(mesh.elements.normal[0].z, 0.0f);
    ASSERT_LT(mesh.elements.normal[2].z, 0.0f);

    GlContext context;
    SceneBuffers buffers(context, mesh);
    buffers.setElementRadiance(std::vector<glm::vec3>(mesh.elements.size(), glm::vec3(100.0f)));
    HemicubeRenderer renderer(buffers, kResolution);
    const HemicubeFrame frame = HemicubeFrame::randomlyRotated({0, 0, 0}, {0, 0, 1}, 42);
    const double exact = 4.0 * cornerParallelFormFactor(0.5, 0.5, 1.0);

    FormFactorList list;
    renderer.renderFormFactors(frame, list);
    EXPECT_EQ(list.size(), 0u) << "neither the back face nor what it hides may receive energy";
    const double bound = aliasingBound(frame, {{-0.5, -0.5, 1}, {0.5, -0.5, 1}, {0.5, 0.5, 1}, {-0.5, 0.5, 1}}, kResolution);
    EXPECT_NEAR(list.backfaceFraction, exact, bound);
    EXPECT_NEAR(list.skyFraction, 1.0 - list.backfaceFraction, 1e-12);
    EXPECT_NEAR(list.minDepthM, 1.0, 0.01);

    const glm::vec3 sky(0.25f);
    const RadianceGather gather = renderer.gatherRadiance(frame, sky);
    EXPECT_NEAR(gather.backfaceFraction, list.backfaceFraction, 1e-12);
    EXPECT_NEAR(gather.irradianceOverPi.x, 0.25 * (1.0 - gather.backfaceFraction), 1e-7);
}

TEST(Hemicube, DoubleSidedPairsShowTheirFrontSideWhateverTheDrawOrder) {
    // The two sides of a double-sided surface are coincident elements with opposite winding; the side facing
    // the hemicube must win every pixel even though their depths tie.
    for (bool backFirst : {true, false}) {
        TriangleSoup soup;
        const glm::dvec3 a(-0.5, -0.5, 1), b(0.5, -0.5, 1), c(0.5, 0.5, 1), d(-0.5, 0.5, 1);
        if (backFirst) soup.addQuad(a, b, c, d);  // faces up: its back is towards the hemicube
        soup.addQuad(a, d, c, b);                 // faces down, towards the hemicube
        if (!backFirst) soup.addQuad(a, b, c, d);
        const PatchMesh mesh = soup.build();
        const std::uint32_t frontFirst = backFirst ? 2 : 0;
        GlContext context;
        SceneBuffers buffers(context, mesh);
        HemicubeRenderer renderer(buffers, 64);
        FormFactorList list;
        renderer.renderFormFactors(HemicubeFrame::randomlyRotated({0.1, 0, 0}, {0, 0, 1}, 9), list);
        EXPECT_EQ(list.backfaceFraction, 0.0) << "back first: " << backFirst;
        for (std::uint32_t e : list.elements) EXPECT_TRUE(e == frontFirst || e == frontFirst + 1) << e;
        const double exact = 4.0 * cornerParallelFormFactor(0.5, 0.5, 1.0);  // 0.2395: a centred unit square
        EXPECT_NEAR(list.sum(), exact, aliasingBound({{0.1, 0, 0}, {0, 0, 1}, 0.0}, {a, b, c, d}, 64) + 1e-3 * exact);
    }
}

TEST(Hemicube, ChunksOutsideTheHemicubeAreNotDrawn) {
    // 64 tiles of 128 triangles along +x (x from 0 to 128), facing down.
    TriangleSoup soup;
    for (int k = 0; k < 64; ++k) soup.addGrid({k * 2.0, 0, 1}, {0, 1, 0}, {1, 0, 0}, 8);
    const PatchMesh mesh = soup.build();
    GlContext context;
    SceneBuffers buffers(context, mesh, 128);
    const std::size_t chunkCount = buffers.chunks().size();
    EXPECT_GE(chunkCount, 64u);
    HemicubeRenderer renderer(buffers, 32);
    FormFactorList list;
    // Beyond the left end, looking away (−x): everything is behind the horizon, nothing may be drawn.
    renderer.renderFormFactors({{-5.0, 0.5, 0.5}, {-1, 0, 0}, 0.0}, list);
    EXPECT_EQ(renderer.lastChunksDrawn(), 0u);
    EXPECT_NEAR(list.skyFraction, 1.0, 1e-12);
    // Under the tiles three quarters along, looking +x: only the last quarter's chunks (each in at most the
    // front and one side face) pass, and everything seen lies there.
    renderer.renderFormFactors({{96.0, 0.5, 0.5}, {1, 0, 0}, 0.0}, list);
    EXPECT_GT(list.sum(), 0.1);
    for (std::uint32_t e : list.elements) ASSERT_GE(mesh.elements.centroid[e].x, 96.0 - 1.0);
    EXPECT_GT(renderer.lastChunksDrawn(), 0u);
    EXPECT_LE(renderer.lastChunksDrawn(), 2 * (chunkCount / 4 + 2));
    // The totals (bake.json hemicubeDraws) count both renders and, in triangles, exactly the chunks drawn: none by
    // the first, 128 per chunk by the second.
    EXPECT_EQ(renderer.drawTotals().hemicubes, 2u);
    EXPECT_EQ(renderer.drawTotals().triangles, 128u * renderer.lastChunksDrawn());
}

TEST(Hemicube, ItemIdsNameTheElementEachPixelSees) {
    // 16×16 quads (512 triangles, 16 chunks) overhead, facing down; every element's own form factor must
    // match its exact value, which only holds if ids map to the right elements through chunking and sorting.
    TriangleSoup soup;
    soup.addGrid({-1.0, -1.0, 1.0}, {0, 2, 0}, {2, 0, 0}, 16);
    const PatchMesh mesh = soup.build();
    GlContext context;
    SceneBuffers buffers(context, mesh);
    ASSERT_GE(buffers.chunks().size(), 16u);
    HemicubeRenderer renderer(buffers, 256);
    const HemicubeFrame frame = HemicubeFrame::randomlyRotated({0.03, -0.02, 0.0}, {0, 0, 1}, 5);
    FormFactorList list;
    renderer.renderFormFactors(frame, list);
    ASSERT_EQ(list.size(), mesh.elements.size());
    for (std::size_t k = 0; k < list.size(); ++k) {
        const std::uint32_t e = list.elements[k];
        const auto& t = mesh.elements.triangles[e];
        const std::vector<glm::dvec3> triangle = {mesh.elements.vertices[t[0]], mesh.elements.vertices[t[1]],
                                                  mesh.elements.vertices[t[2]]};
        const double exact = pointPolygonFormFactor(frame.position, {0, 0, 1}, triangle);
        EXPECT_NEAR(list.formFactors[k], exact, aliasingBound(frame, triangle, 256)) << "element " << e;
    }
    EXPECT_NEAR(list.minDepthM, 1.0, 0.01);
}

TEST(Hemicube, RandomRotationIsReproducible) {
    const HemicubeFrame a = HemicubeFrame::randomlyRotated({1, 2, 3}, {0, 1, 0}, 17);
    const HemicubeFrame b = HemicubeFrame::randomlyRotated({1, 2, 3}, {0, 1, 0}, 17);
    const HemicubeFrame c = HemicubeFrame::randomlyRotated({1, 2, 3}, {0, 1, 0}, 18);
    EXPECT_EQ(a.rotationRadians, b.rotationRadians);
    EXPECT_NE(a.rotationRadians, c.rotationRadians);
    EXPECT_GE(a.rotationRadians, 0.0);
    EXPECT_LT(a.rotationRadians, 2.0 * std::numbers::pi);
    glm::dvec3 t, bt;
    a.tangentFrame(t, bt);
    EXPECT_NEAR(glm::dot(glm::cross(t, bt), glm::dvec3(0, 1, 0)), 1.0, 1e-12);
    EXPECT_NEAR(glm::dot(t, glm::dvec3(0, 1, 0)), 0.0, 1e-12);
}

}  // namespace
}  // namespace hemibake
