// The solver against closed-form answers (GROUND_TRUTH §2): furnaces, one emitting face, energy balance.
#include <chrono>

#include <gtest/gtest.h>

#include "baker/solve/form_factor_cache.h"
#include "mesh/scene_builder.h"
#include "support/solver_fixture.h"

using namespace hemibake;
using hemibake::test::meanIrradianceOverPi;
using hemibake::test::furnace;
using hemibake::test::openSceneWithLamp;
using hemibake::test::shootOnly;
using hemibake::test::solveTestScene;

namespace {

PunctualLight pointLight(const glm::dvec3& position, float intensity) {
    PunctualLight point;
    point.type = LightType::Point;
    point.position = position;
    point.intensity = glm::vec3(intensity);
    return point;
}

// Power in (emitters + direct light) equals power out (absorbed + escaped + absorbed on back faces + unshot) in
// every channel, within `relative` of what came in. Returns the ratio out/in − 1 of the first channel.
double expectLedgerBalances(const SolveReport& r, double relative) {
    const glm::dvec3 in = r.emitterPowerW + r.directPowerW;
    const glm::dvec3 out = r.absorbedPowerW + r.escapedPowerW + r.backfacePowerW + r.unshotPowerW;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(out[c], in[c], relative * in[c]) << "channel " << c;
    std::printf("  ledger out/in - 1: %.3g\n", out.x / in.x - 1.0);
    return out.x / in.x - 1.0;
}

}  // namespace

// §2.A: B = E/(1−ρ) and H = B everywhere, whatever the meshing, when weights sum to exactly 1.
class Furnace : public ::testing::TestWithParam<std::pair<float, double>> {};

TEST_P(Furnace, UniformEmissionGivesLeOverOneMinusRho) {
    const auto [rho, tolerance] = GetParam();
    const float le = 2.0f;
    // §2.A holds for any meshing; 24 patches keep ρ = 0.99 (≈ 344 sweeps of shots, §2.D) quick.
    SolveSettings s = shootOnly(1.0, 32);
    const auto solved = solveTestScene(furnace(rho, le, false), s);
    const glm::dvec3 mean = meanIrradianceOverPi(*solved);
    const double expected = le / (1.0 - double(rho));
    std::printf("furnace rho %.3f: mean E/pi %.6f, exact %.6f, rel err %+.2e, %llu shots\n", rho, mean.x, expected,
                mean.x / expected - 1.0, static_cast<unsigned long long>(solved->report.shots));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean[c], expected, tolerance * expected) << "rho " << rho;
    EXPECT_EQ(solved->report.stopReason, "converged");
    EXPECT_LE(solved->report.unshotFraction, s.solver.epsilon);
}

INSTANTIATE_TEST_SUITE_P(GroundTruth2A, Furnace,
                         // The local bound at epsilon 1e-3 (with the ambient term off) leaves about 0.1 %.
                         ::testing::Values(std::make_pair(0.5f, 0.002), std::make_pair(0.9f, 0.002),
                                           std::make_pair(0.99f, 0.002)));

TEST(FurnaceExtreme, Rho0999ConvergesWithAmbientCorrection) {
    SolveSettings s = shootOnly(1.0, 32);
    s.solver.ambientCorrection = true;
    s.solver.maxShots = 3000;  // ~3450 sweeps would be needed to reach 1e-3 (§2.D); the ambient term covers the rest
    const auto solved = solveTestScene(furnace(0.999f, 1.0f, false), s);
    const glm::dvec3 mean = meanIrradianceOverPi(*solved);
    for (std::size_t e = 0; e < solved->mesh.elements.size(); ++e)
        ASSERT_TRUE(std::isfinite(solved->solution.displayIrradiance(e).x)) << "element " << e;
    std::printf("furnace rho 0.999, 3000 shots + ambient: mean E/pi %.3f, exact 1000, rel err %+.2e\n", mean.x,
                mean.x / 1000.0 - 1.0);
    EXPECT_NEAR(mean.x, 1000.0, 0.05 * 1000.0);
    EXPECT_LT(solved->report.unshotFraction, 1.0);  // it made progress, it did not diverge
}

// §2.C: one emitting face; the area-mean radiosity is (1/6)·E/(1−ρ) exactly (energy balance).
TEST(OneEmittingFace, AreaMeanRadiosity) {
    for (float rho : {0.5f, 0.8f}) {
        const double exitance = 1.0;
        const auto solved = solveTestScene(furnace(rho, float(exitance / M_PI), true), shootOnly(0.5, 64));
        double sumBA = 0.0, area = 0.0;
        for (std::size_t e = 0; e < solved->mesh.elements.size(); ++e) {
            sumBA += solved->solution.displayRadiosity(solved->mesh, e).x * solved->mesh.elements.areaM2[e];
            area += solved->mesh.elements.areaM2[e];
        }
        const double expected = (1.0 / 6.0) * exitance / (1.0 - rho);
        std::printf("one emitting face rho %.2f: area-mean B %.6f, exact %.6f, rel err %+.2e\n", rho, sumBA / area, expected,
                    sumBA / area / expected - 1.0);
        EXPECT_NEAR(sumBA / area, expected, 0.01 * expected) << "rho " << rho;
    }
}

// Open scene: every watt emitted is absorbed, escapes, or is still unshot.
TEST(EnergyBalance, OpenSceneConservesPower) {
    SceneBuilder b = openSceneWithLamp();
    b.addLight(pointLight({0.5, 0.8, 0.5}, 2.0f));
    SolveSettings s = shootOnly(0.25, 64);
    s.solver.epsilon = 1e-4;
    const auto solved = solveTestScene(b.build(), s);
    const SolveReport& r = solved->report;
    const glm::dvec3 in = r.emitterPowerW + r.directPowerW;
    const double balance = expectLedgerBalances(r, 1e-3);
    std::printf("energy balance: in %.6f W (out/in %+.2e), escaped %.1f%%\n", in.x, balance, 100.0 * r.escapedPowerW.x / in.x);
    for (int c = 0; c < 3; ++c) EXPECT_GT(r.escapedPowerW[c], 0.1 * in[c]);
}

// Issue 14: a row that did not fit the form-factor cache was moved into it all the same, so the shot delivered
// nothing while the patch's unshot power was already zeroed. With a budget of a few rows most shots overflow it:
// the ledger must still balance and the furnace still reach L_e/(1−ρ) (GROUND_TRUTH §2.A).
TEST(FormFactorCacheBudget, TinyCacheBalancesTheLedgerAndMatchesTheFurnace) {
    SolveSettings s = shootOnly(0.5, 32);
    s.solver.formFactorCacheMiB = 4096.0 / 1048576.0;  // 4 KiB: a couple of rows
    const float rho = 0.5f, le = 1.0f;
    const auto solved = solveTestScene(furnace(rho, le, false), s);
    const SolveReport& r = solved->report;
    ASSERT_GT(r.formFactorCacheBytes, 0u);
    ASSERT_LE(r.formFactorCacheBytes, 4096u);
    ASSERT_GT(r.hemicubes, solved->mesh.patches.size());  // rows that did not fit were rendered again
    // Patches whose rows did not fit bound what they can still give (ΔB_p ≤ per element): the local phase ends.
    EXPECT_EQ(r.stopReason, "converged");
    EXPECT_LT(r.shots, 2000u);
    expectLedgerBalances(r, 1e-9);
    const double expected = le / (1.0 - double(rho));
    EXPECT_NEAR(meanIrradianceOverPi(*solved).x, expected, 0.005 * expected);
}

// A patch's last uneven row is replaced at every uneven shot: the budget counts only the row kept, and a row that
// does not fit leaves the slot empty (the shot uses its own copy) instead of keeping a stale one.
TEST(FormFactorCacheBudget, ReplaceKeepsTheBudgetExact) {
    auto rowOf = [](std::size_t n) {
        std::vector<std::uint32_t> ids(n);
        for (std::uint32_t i = 0; i < n; ++i) ids[i] = i;
        FormFactorRow row;
        row.assign(ids, std::vector<double>(n, 1.0 / double(n)));
        return row;
    };
    FormFactorCache cache(2, 4096);
    FormFactorRow small = rowOf(10), medium = rowOf(100), huge = rowOf(2000);
    ASSERT_TRUE(cache.store(0, small));
    ASSERT_TRUE(cache.store(1, medium));
    const std::size_t mediumBytes = cache.find(1)->bytes();
    const std::size_t before = cache.bytesUsed();
    FormFactorRow other = rowOf(20);
    ASSERT_TRUE(cache.replace(0, other));
    EXPECT_EQ(cache.find(0)->size(), 20u);
    EXPECT_EQ(cache.bytesUsed(), mediumBytes + cache.find(0)->bytes());
    EXPECT_GT(cache.bytesUsed(), before);  // 20 entries cost more than 10
    EXPECT_FALSE(cache.replace(0, huge));   // 6 KB (3 bytes an entry) does not fit 4 KiB
    EXPECT_EQ(cache.find(0), nullptr);
    EXPECT_EQ(cache.bytesUsed(), mediumBytes);
    EXPECT_EQ(huge.size(), 2000u);  // left to the caller
}

// A point lamp 0.15 m over one side of a 2 m floor patch lights a hot spot on a few of its elements: the patch's
// light lies unevenly, so it is shot from the elements it lies on (ProgressiveShooter, unevenShotSpread), through
// those elements' own cached rows weighted by the light each holds at that shot. The power ledger balances either way and the bound closes (reading the even
// row for an uneven patch kept the local bound from ever closing). HangingPanel.* checks what it is for.
TEST(UnevenShots, HotSpotIsShotFromWhereItLiesAndTheLedgerBalances) {
    auto solve = [](double spread) {
        SceneBuilder b("hot spot");
        const int grey = b.addMaterial(glm::vec3(0.6f));
        b.addQuad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, grey, "floor");
        b.addBox({0.45, 0.0, -0.3}, {0.65, 0.3, 0.3}, grey, false, "block");
        b.addLight(pointLight({0.85, 0.15, 0.0}, 1.0f));
        SolveSettings s = shootOnly(2.0, 64);
        s.subdivision.elementSizeM = 0.125;
        s.solver.epsilon = 1e-4;
        s.solver.unevenShotSpread = spread;
        return solveTestScene(b.build(), s);
    };
    const auto uneven = solve(SolverSettings{}.unevenShotSpread);
    const auto even = solve(1.0);
    for (const auto* solved : {uneven.get(), even.get()}) {
        expectLedgerBalances(solved->report, 1e-9);
        EXPECT_EQ(solved->report.stopReason, "converged");
    }
    std::printf("uneven shots %llu of %llu; element rows rendered %llu for %zu elements, hemicubes %llu\n",
                static_cast<unsigned long long>(uneven->report.unevenShots),
                static_cast<unsigned long long>(uneven->report.shots),
                static_cast<unsigned long long>(uneven->report.elementRows), uneven->mesh.elements.size(),
                static_cast<unsigned long long>(uneven->report.hemicubes));
    EXPECT_GT(uneven->report.unevenShots, 0u);
    EXPECT_EQ(even->report.unevenShots, 0u);
    EXPECT_EQ(uneven->report.elementRows, uneven->report.cachedElementRows);  // each once (ElementRows.* below)
}

// A needle triangle across a furnace's floor (1 m long, 10 µm wide: a sliver as cutting and unwrapping leave them
// beside walls). A shooter's hemicube pixel that lands on it hands it all of that pixel, F_ji = F_ij·A_i/A_j in the
// hundreds, where no receiver can see more than all of one patch: level_clean had such elements at 1e7 W/m², and whole
// rooms came out +120 … +390 % per object through the texels that see them. A 4 KiB form-factor cache makes every
// shot render its hemicube again, so some pixel does land on the needle. After shooting, the elements so hit show the
// shot light around them: no element is brighter than the furnace's L_e/(1−ρ) allows (GROUND_TRUTH §2.A), and the
// power ledger, the shooting's, still balances. (A needle element no pixel ever lands on stays dark: left alone.)
TEST(ImplausibleReceivers, NeedleInAFurnaceFloorShowsTheLightAroundIt) {
    const float rho = 0.8f, le = 1.0f;
    const double width = 1e-5;
    SolveSettings s = shootOnly(0.5, 32);
    s.solver.epsilon = 1e-4;
    s.solver.formFactorCacheMiB = 4096.0 / 1048576.0;
    const auto solved = solveTestScene(hemibake::test::needleFurnace(rho, le, width), s);
    const PatchMesh& mesh = solved->mesh;
    const double expected = le / (1.0 - double(rho));
    double needleArea = 0.0, brightest = 0.0;
    std::size_t needleElements = 0, needleNear = 0;
    for (std::size_t e = 0; e < mesh.elements.size(); ++e) {
        const double value = solved->solution.displayIrradiance(e).x / M_PI;
        brightest = std::max(brightest, value / expected);
        if (mesh.elements.areaM2[e] < 1e-4) {
            needleArea += mesh.elements.areaM2[e];
            ++needleElements;
            needleNear += std::abs(value / expected - 1.0) <= 0.03;
        }
    }
    std::printf("needle furnace: %zu needle elements (%.2e m²), %zu within 3 %%, %zu implausible receivers, brightest "
                "element %.3f × L_e/(1-rho), %llu shots\n",
                needleElements, needleArea, needleNear, solved->report.implausibleReceivers, brightest,
                static_cast<unsigned long long>(solved->report.shots));
    ASSERT_GT(needleElements, 0u);
    EXPECT_NEAR(needleArea, 0.5 * width, 1e-3 * 0.5 * width);  // the needle is all there, as elements of its own
    EXPECT_GT(solved->report.implausibleReceivers, 0u);         // pixels did land on it
    EXPECT_GE(needleNear, solved->report.implausibleReceivers);  // those show the light around them
    EXPECT_LE(brightest, 1.5);  // ordinary elements keep their shots' noise (±5 %, up to 31 % on small corner ones)
    expectLedgerBalances(solved->report, 1e-9);
    EXPECT_NEAR(meanIrradianceOverPi(*solved).x, expected, 0.002 * expected);
}

// A closed room lit by two point lamps near its walls: every patch is near another wall (proximity: its row merges
// its elements' rows) and the lamps' hot spots are shot from where they lie (uneven: the same element rows). Each
// element's row is rendered once however many shots of either kind use it, and each patch renders at most one probe
// hemicube for its even row: hemicubes ≤ patches + elements while the cache holds everything. Before session 18 near
// patches rendered their own per-element hemicubes apart from the cached ones, so uneven shots rendered them again.
TEST(ElementRows, RenderedOnceForProximityAndUnevenShots) {
    SceneBuilder b("lit corners");
    const int wall = b.addMaterial(glm::vec3(0.6f));
    hemibake::test::addFurnaceFaces(b, wall, wall);
    b.addLight(pointLight({0.1, 0.1, 0.1}, 1.0f));
    b.addLight(pointLight({0.9, 0.85, 0.5}, 0.5f));
    SolveSettings s = shootOnly(0.34, 32);
    s.subdivision.elementSizeM = 0.34 / 4;
    s.solver.epsilon = 1e-4;
    const auto solved = solveTestScene(b.build(), s);
    const SolveReport& r = solved->report;
    const std::size_t patches = solved->mesh.patches.size(), elements = solved->mesh.elements.size();
    std::printf("  %zu patches, %zu elements: %llu shots (%llu uneven), %llu element rows, %llu hemicubes\n", patches,
                elements, static_cast<unsigned long long>(r.shots), static_cast<unsigned long long>(r.unevenShots),
                static_cast<unsigned long long>(r.elementRows), static_cast<unsigned long long>(r.hemicubes));
    EXPECT_EQ(r.stopReason, "converged");
    EXPECT_GT(r.unevenShots, 50u);
    EXPECT_GT(r.elementRows, elements / 2);  // near patches' rows are merged element rows
    EXPECT_EQ(r.elementRows, r.cachedElementRows);  // none rendered twice: each is the one the cache holds
    EXPECT_LE(r.hemicubes, patches + elements);
    expectLedgerBalances(r, 1e-9);
}
