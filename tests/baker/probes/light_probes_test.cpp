// baker/light_probes: probes rendered by real OSMesa cube maps against closed forms (GROUND_TRUTH §1, §2.A, §6).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "baker/probes/light_probes.h"
#include "mesh/scene_builder.h"
#include "support/raster_fixtures.h"
#include "support/solver_fixture.h"

namespace hemibake {
namespace {

using test::TriangleSoup;


glm::dvec3 tilted(double thetaDeg) {  // from +y (up) towards +x
    const double t = thetaDeg * std::numbers::pi / 180.0;
    return {std::sin(t), std::cos(t), 0.0};
}

// Solid angle of a planar polygon seen from p (fan of triangles; Van Oosterom & Strackee 1983).
double polygonSolidAngle(const glm::dvec3& p, const std::vector<glm::dvec3>& polygon) {
    double total = 0.0;
    for (std::size_t i = 1; i + 1 < polygon.size(); ++i) {
        const glm::dvec3 a = polygon[0] - p, b = polygon[i] - p, c = polygon[i + 1] - p;
        const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
        const double numerator = glm::dot(a, glm::cross(b, c));
        const double denominator = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
        total += 2.0 * std::atan2(std::abs(numerator), denominator);
    }
    return total;
}

// §2.A through a probe: a closed box, every face emitting L_e with reflectance ρ, solved by the real solver.
// Every direction sees B/π = L_e/(1 − ρ), so E/π is that for every normal and only l00 is non-zero.
TEST(LightProbe, FurnaceSeesLeOverOneMinusRhoInEveryDirection) {
    const float rho = 0.5f, le = 2.0f;
    SceneBuilder b("furnace");
    const int wall = b.addMaterial(glm::vec3(rho), glm::vec3(le));
    b.addBox({0, 0, 0}, {1, 1, 1}, wall, true);
    SolveSettings s;
    s.subdivision = {0.5, 0.25, 0.5};
    s.solver.kind = SolverKind::Shoot;
    s.solver.hemicubeResolution = 32;
    s.solver.ambientCorrection = false;
    const auto solved = test::solveTestScene(b.build(), s);

    ProbeBakeSettings ps;
    ps.resolution = 32;
    ProbeBaker baker(solved->mesh, elementOutgoingRadiance(solved->mesh, solved->solution), glm::vec3(0.0f), ps);
    const ProbeRequest requests[] = {{{0.5, 0.5, 0.5}}, {{0.2, 0.7, 0.3}}};
    const auto probes = baker.bake(requests);
    const double exact = le / (1.0 - rho);
    double worst = 0.0, worstCoefficient = 0.0;
    for (const BakedProbe& p : probes) {
        EXPECT_TRUE(p.valid);
        EXPECT_NEAR(p.backfaceFraction, 0.0, 1e-12);
        EXPECT_NEAR(p.skyFraction, 0.0, 1e-12);
        for (const glm::dvec3& n : {glm::dvec3(0, 1, 0), glm::dvec3(0, -1, 0), glm::dvec3(1, 0, 0), glm::dvec3(0, 0, -1),
                                    glm::normalize(glm::dvec3(1, -2, 3))}) {
            const glm::dvec3 e = p.sh.irradianceOverPi(n);
            for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(e[c] / exact - 1.0));
        }
        for (int k = 1; k < kShCoefficients; ++k)
            for (int c = 0; c < 3; ++c)
                worstCoefficient = std::max(worstCoefficient, std::abs(p.sh.c[std::size_t(k)][c]) / p.sh.c[0][c]);
    }
    std::printf("furnace probe: worst |E/pi / (Le/(1-rho)) - 1| = %.2e, worst |L_lm|/L00 (l>0) = %.2e\n", worst,
                worstCoefficient);
    EXPECT_LT(worst, 0.01);
    EXPECT_LT(worstCoefficient, 0.01);
}

// A probe 1 m above a black plane 2 km wide under a uniform sky (GROUND_TRUTH §6 test 1): E/π(θ) =
// L_sky (1 + cos θ)/2, reproduced exactly by L1/L2; what remains is the plane's finite size (it hides sky below
// −0.06° elevation) and the cube map's pixel quadrature.
TEST(LightProbe, SkyOverBlackGroundGivesOnePlusCosOverTwo) {
    TriangleSoup soup;
    soup.addQuad({-1000, 0, -1000}, {-1000, 0, 1000}, {1000, 0, 1000}, {1000, 0, -1000});  // front +y
    PatchMesh mesh = soup.build();
    for (auto& r : mesh.elements.reflectance) r = glm::vec3(0.0f);
    const std::vector<glm::vec3> black(mesh.elements.size(), glm::vec3(0.0f));
    const glm::vec3 sky(1.0f, 2.0f, 0.5f);
    ProbeBakeSettings ps;
    ps.resolution = 64;
    ProbeBaker baker(mesh, black, sky, ps);
    const BakedProbe p = baker.bakeOne({{3.0, 1.0, -2.0}});
    EXPECT_TRUE(p.valid);
    for (double theta : {0.0, 45.0, 90.0, 135.0}) {
        const glm::dvec3 e = p.sh.irradianceOverPi(tilted(theta));
        const double exact = (1.0 + std::cos(theta * std::numbers::pi / 180.0)) / 2.0;
        std::printf("sky plane theta %5.1f: E/pi / L_sky = %.5f, exact %.5f, rel err %+.2e\n", theta, e.x / sky.x, exact,
                    e.x / sky.x / exact - 1.0);
        // The sky over a plane is band-limited in E (L1 exact); only the cube map's texel integration is left
        // (measured ≤ 1.9e-4).
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(e[c], sky[c] * exact, 1e-3 * sky[c] * exact) << "theta " << theta;
    }
}

// A probe on the axis of a single emissive rectangle (no other geometry, no sky). The exact irradiance along
// the axis is L_e·F with Lambert's formula (GROUND_TRUTH §1); L2 misses it by at most 3/32 of ∫L dω = L_e·Ω
// (the directional-light worst case of §6, summed over the rectangle's directions).
TEST(LightProbe, EmissiveRectangleWithinTheL2ErrorBound) {
    const double a = 1.0, b = 0.6, c = 0.8;  // rectangle a×b centred on the probe's +z axis at distance c
    const glm::dvec3 p0(-a / 2, -b / 2, c), p1(a / 2, -b / 2, c), p2(a / 2, b / 2, c), p3(-a / 2, b / 2, c);
    // Front must face the probe (−z): u × v = −z for u along y, v along x.
    TriangleSoup facing;
    facing.addGrid(p0, {0, b, 0}, {a, 0, 0}, 4);
    const PatchMesh mesh = facing.build();
    const glm::vec3 le(3.0f, 1.0f, 0.5f);
    const std::vector<glm::vec3> radiance(mesh.elements.size(), le);
    ProbeBakeSettings ps;
    ps.resolution = 64;
    ProbeBaker baker(mesh, radiance, glm::vec3(0.0f), ps);
    const BakedProbe p = baker.bakeOne({{0.0, 0.0, 0.0}});
    const std::vector<glm::dvec3> polygon = {p0, p1, p2, p3};
    const glm::dvec3 n(0, 0, 1);
    const double f = test::pointPolygonFormFactor(glm::dvec3(0.0), n, polygon);
    const double omega = polygonSolidAngle(glm::dvec3(0.0), polygon);
    const double bound = 3.0 / 32.0 * omega / std::numbers::pi;  // per unit L_e, in E/π units
    // The L2 value itself, by quadrature of the L2 kernel k(c) = (3 + 16c + 15c²)/32 over the rectangle: what a
    // perfect projection would give, so the rendering's own error shows separately from L2's.
    double l2 = 0.0;
    const int q = 400;
    for (int j = 0; j < q; ++j)
        for (int i = 0; i < q; ++i) {
            const glm::dvec3 x(-a / 2 + a * (i + 0.5) / q, -b / 2 + b * (j + 0.5) / q, c);
            const double r2 = glm::dot(x, x), cosine = c / std::sqrt(r2);
            const double dOmega = (a / q) * (b / q) * cosine / r2;
            l2 += (3.0 + 16.0 * cosine + 15.0 * cosine * cosine) / 32.0 * dOmega / std::numbers::pi;
        }
    for (int ch = 0; ch < 3; ++ch) {
        const double e = p.sh.irradianceOverPi(n)[ch] / le[ch];
        if (ch == 0)
            std::printf("rectangle: E/pi per L_e = %.6f, exact F = %.6f, error %+.2e (%.2f%%), bound 3/32*Omega/pi = %.4f, "
                        "ideal L2 %.6f (probe vs ideal %+.2e)\n",
                        e, f, e - f, 100.0 * (e / f - 1.0), bound, l2, e / l2 - 1.0);
        EXPECT_LE(std::abs(e - f), bound);
        EXPECT_NEAR(e, l2, 0.005 * l2);  // the cube map's quadrature at R = 64
    }
}

// A probe inside a closed solid sees only back faces: flagged, or moved out through the nearest face.
TEST(LightProbe, InsideGeometryIsDetectedAndRelocated) {
    SceneBuilder b("block");
    const int grey = b.addMaterial(glm::vec3(0.5f));
    b.addBox({0, 0, 0}, {1, 1, 1}, grey, false);  // a solid block, faces outwards
    Scene scene = b.build();
    const PatchMesh mesh = subdivide(scene, SubdivisionSettings{0.5, 0.5, 0.5});
    const std::vector<glm::vec3> radiance(mesh.elements.size(), glm::vec3(1.0f));
    ProbeBaker baker(mesh, radiance, glm::vec3(0.25f), ProbeBakeSettings{});
    const BakedProbe flagged = baker.bakeOne({{0.5, 0.5, 0.9}});
    EXPECT_FALSE(flagged.valid);
    EXPECT_GT(flagged.backfaceFraction, 0.99);
    const BakedProbe moved = baker.bakeOne({{0.5, 0.5, 0.9}, 0.3, 0.05});
    EXPECT_TRUE(moved.valid);
    EXPECT_TRUE(moved.relocated);
    EXPECT_NEAR(moved.position.z, 1.05, 1e-3);  // out through the nearest face (+z, 0.1 away) plus the margin
    EXPECT_NEAR(moved.position.x, 0.5, 0.05);
    const BakedProbe tooDeep = baker.bakeOne({{0.5, 0.5, 0.5}, 0.3, 0.05});  // 0.5 from every face
    EXPECT_FALSE(tooDeep.valid);
    const BakedProbe outside = baker.bakeOne({{0.5, 0.5, 1.5}});
    EXPECT_TRUE(outside.valid);
    EXPECT_NEAR(outside.backfaceFraction, 0.0, 1e-12);
}

}  // namespace
}  // namespace hemibake
