// Direct light in the Cornell box (GROUND_TRUTH §5): receiver-side radiance hemicubes with only the light
// lit give E/π = L_e·F at the table's points. This is the gather the lightmap texels use.
#include <gtest/gtest.h>

#include "baker/rays/embree_scene.h"
#include "baker/solve/gatherer.h"
#include "mesh/gltf_loader.h"
#include "mesh/subdivision.h"
#include "raster/hemicube_pool.h"
#include "support/gltf_fixture.h"

using namespace hemibake;

namespace {

struct TablePoint {
    const char* name;
    glm::dvec3 positionMm;
    glm::vec3 normal;
    double formFactor;       // GROUND_TRUTH §5, "with blocks" (exact Lambert value where unoccluded)
    double formFactorSigma;  // the table's 1σ Monte Carlo uncertainty (0 where exact)
};

const TablePoint kPoints[] = {
    {"floor under light centre", {278, 0, 279.5}, {0, 1, 0}, 0.01046, 0.00016},
    {"back wall centre", {278, 274.4, 559.2}, {0, 0, -1}, 0.013895, 0.0},
    {"floor near front", {278, 0, 50}, {0, 1, 0}, 0.00352, 0.00009},
    {"top of short block", {185.5, 165, 169}, {0, 1, 0}, 0.022258, 0.0},
    {"top of tall block", {368.5, 330, 351.25}, {0, 1, 0}, 0.054098, 0.0},
};

// F(dA → light) with occlusion by midpoint quadrature over an n×n grid on the light (130 × 105 mm at
// y = 548.8 mm, facing down) and Embree shadow rays: independent of any hemicube.
double occludedFormFactor(const EmbreeScene& rays, const glm::dvec3& p, const glm::dvec3& n, int grid) {
    const glm::dvec3 corner(0.213, 0.5488, 0.227);
    const double a = 0.130, b = 0.105, dA = a * b / (double(grid) * grid);
    double f = 0.0;
    for (int i = 0; i < grid; ++i)
        for (int j = 0; j < grid; ++j) {
            const glm::dvec3 q = corner + glm::dvec3((i + 0.5) * a / grid, 0.0, (j + 0.5) * b / grid);
            const glm::dvec3 d = q - p;
            const double r2 = glm::dot(d, d);
            const double cosR = glm::dot(n, d) / std::sqrt(r2);
            const double cosL = d.y / std::sqrt(r2);  // light faces -y
            if (cosR <= 0.0 || cosL <= 0.0) continue;
            if (rays.occluded(rays.offsetFromSurface(p, n), q - glm::dvec3(0, 1e-6, 0))) continue;
            f += cosR * cosL / (M_PI * r2) * dA;
        }
    return f;
}

}  // namespace

TEST(CornellDirect, QuadratureOracleAgreesWithTable) {
    const Scene scene = loadGltf(hemibake::test::sharedScene("cornell_box.gltf"));
    const EmbreeScene rays(scene);
    for (const TablePoint& t : kPoints) {
        const double f = occludedFormFactor(rays, t.positionMm / 1000.0, glm::dvec3(t.normal), 400);
        // Exact table values to 1e-4 (midpoint rule on 160 000 cells); MC values within 3 of their σ.
        const double tolerance = t.formFactorSigma > 0.0 ? 3.0 * t.formFactorSigma : 1e-4 * t.formFactor;
        EXPECT_NEAR(f, t.formFactor, tolerance) << t.name;
    }
}

TEST(CornellDirect, ReceiverHemicubesMatchTable) {
    const Scene scene = loadGltf(hemibake::test::sharedScene("cornell_box.gltf"));
    const PatchMesh mesh = subdivide(scene, {0.1, 0.05, 0.0});
    std::vector<glm::vec3> radiance(mesh.elements.size());
    for (std::size_t e = 0; e < radiance.size(); ++e) radiance[e] = mesh.elements.emittedRadiance[e];
    std::vector<GatherPoint> points;
    const EmbreeScene rays(scene);
    std::vector<double> oracle;
    for (const TablePoint& p : kPoints) {
        points.push_back({p.positionMm / 1000.0, p.normal});
        oracle.push_back(occludedFormFactor(rays, p.positionMm / 1000.0, glm::dvec3(p.normal), 400));
    }
    for (int resolution : {256}) {
        HemicubePool pool(mesh, resolution);
        Gatherer gatherer(pool, 7);
        gatherer.setElementRadiance(radiance);
        std::vector<glm::dvec3> eOverPi;
        gatherer.gather(points, glm::vec3(0.0f), 1, eOverPi);
        for (std::size_t i = 0; i < points.size(); ++i) {
            const double expected = 17.0 * oracle[i];  // red channel: L_e = 17
            const double got = eOverPi[i].x;
            std::printf("R=%d %-26s E/pi %.6f expected %.6f (%+.2f%%; table F %.6f, oracle F %.6f)\n", resolution,
                        kPoints[i].name, got, expected, 100.0 * (got / expected - 1.0), kPoints[i].formFactor, oracle[i]);
            // §3.6 at N = 256: a source a few times farther than it is wide sits between the square d = 2 and
            // d = 10 rows (max 1e-2 … 0.12); measured ≤ 1.0 % at these points with this seed.
            EXPECT_NEAR(got, expected, 0.015 * expected) << kPoints[i].name;
            EXPECT_NEAR(eOverPi[i].y / eOverPi[i].x, 12.0 / 17.0, 1e-5);  // colour is the light's
        }
    }
}
