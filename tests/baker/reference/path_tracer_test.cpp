// PathTracer, the independent reference: furnace (GROUND_TRUTH §2.A), point → rectangle form factors (§1(d)),
// Cornell box direct light (§5), punctual lights, one-sided emission, and reproducibility across thread counts.
#include <numbers>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>

#include <tbb/global_control.h>

#include "baker/reference/path_tracer.h"
#include "mesh/gltf_loader.h"
#include "mesh/scene_builder.h"

using namespace hemibake;

namespace {


// |mean − expected| within `sigmas` combined standard errors, per channel.
void expectWithinSigmas(const Estimate& e, const glm::dvec3& expected, const glm::dvec3& expectedSigma, double sigmas,
                        const std::string& what) {
    for (int c = 0; c < 3; ++c) {
        const double sigma = std::hypot(e.standardError[c], expectedSigma[c]);
        EXPECT_LE(std::abs(e.mean[c] - expected[c]), sigmas * sigma)
            << what << " channel " << c << ": " << e.mean[c] << " ± " << e.standardError[c] << " vs " << expected[c];
    }
}

// GROUND_TRUTH §1(d), parallel: dA on the normal through a corner of an a × b rectangle at distance c.
double cornerParallelFormFactor(double a, double b, double c) {
    const double x = a / c, y = b / c;
    const double sx = std::sqrt(1 + x * x), sy = std::sqrt(1 + y * y);
    return (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy)) / (2 * std::numbers::pi);
}

// GROUND_TRUTH §1(d), perpendicular: rectangle in y = c, x ∈ [0, a], z ∈ [0, b]; dA at the origin facing +z.
double cornerPerpendicularFormFactor(double a, double b, double c) {
    const double r = std::sqrt(b * b + c * c);
    return (std::atan(a / c) - c / r * std::atan(a / r)) / (2 * std::numbers::pi);
}

Scene furnace(glm::vec3 emitted, bool textured) {
    SceneBuilder b("furnace");
    const int m = b.addMaterial(textured ? glm::vec3(0.999f) : glm::vec3(0.8f), emitted);
    b.addBox({0, 0, 0}, {1, 2, 3}, m, true);
    Scene scene = b.build();
    if (textured) {
        // Factor × texture = 0.999 × 0.8008 ≈ 0.8: the texture must be read for the furnace answer to hold.
        scene.textures.push_back({2, 2, std::vector<float>(12, 0.8f / 0.999f)});
        scene.materials[std::size_t(m)].reflectanceTexture = 0;
    }
    return scene;
}

}  // namespace

TEST(PathTracer, FurnaceIncidentRadianceIsEmissionOverOneMinusReflectance) {
    const glm::vec3 emitted(1.0f, 0.5f, 2.0f);
    for (const bool textured : {false, true}) {
        const Scene scene = furnace(emitted, textured);
        const EmbreeScene rays(scene);
        const PathTracer tracer(scene, rays, {});
        const double rho = textured ? double(0.999f * (0.8f / 0.999f)) : double(0.8f);
        const glm::dvec3 expected = glm::dvec3(emitted) / (1.0 - rho);  // B = E/(1-ρ) everywhere ⇒ H/π = L_e/(1-ρ)
        const std::vector<SurfacePoint> points = {
            {{0.5, 0.0, 1.5}, {0, 1, 0}}, {{0.2, 2.0, 2.7}, {0, -1, 0}}, {{0.0, 1.0, 0.5}, {1, 0, 0}}, {{0.9, 1.9, 3.0}, {0, 0, -1}},
            // 10 µm from two walls, closer than the ray epsilon (15 µm here): no light may leak past them.
            {{0.99999, 1.99999, 3.0}, {0, 0, -1}}};
        const std::vector<Estimate> estimates = tracer.irradianceOverPi(points, 4096);
        for (std::size_t i = 0; i < points.size(); ++i) {
            expectWithinSigmas(estimates[i], expected, glm::dvec3(0.0), 3.0, "furnace point " + std::to_string(i));
            EXPECT_LT(estimates[i].standardError.x, 0.03 * expected.x);
            EXPECT_EQ(estimates[i].samples, 4096u);
        }
    }
}

TEST(PathTracer, FurnaceSeenByTheCamera) {
    const glm::vec3 emitted(1.0f, 0.5f, 2.0f);
    const Scene scene = furnace(emitted, false);
    const EmbreeScene rays(scene);
    const PathTracer tracer(scene, rays, {});
    Camera camera;
    camera.position = {0.5, 1.0, 1.0};
    camera.forward = {0.3f, 0.2f, 1.0f};
    camera.yfovRadians = 1.2f;
    const CameraRender image = tracer.renderCamera(camera, 12, 8, 64);
    ASSERT_EQ(image.radiance.pixels.size(), 12u * 8u);
    ASSERT_EQ(image.varianceOfMean.pixels.size(), 12u * 8u);
    // Outgoing radiance = L_e + ρ·L_e/(1-ρ) = L_e/(1-ρ) on every wall.
    Estimate mean;
    const double pixels = 12.0 * 8.0;
    for (std::size_t p = 0; p < image.radiance.pixels.size(); ++p) {
        mean.mean += glm::dvec3(image.radiance.pixels[p]) / pixels;
        mean.standardError += glm::dvec3(image.varianceOfMean.pixels[p]) / (pixels * pixels);
    }
    mean.standardError = glm::sqrt(mean.standardError);
    expectWithinSigmas(mean, glm::dvec3(emitted) / (1.0 - double(0.8f)), glm::dvec3(0.0), 3.0, "camera furnace");
    EXPECT_GT(image.rays, 12u * 8u * 64u);
}

TEST(PathTracer, TexturedReflectanceFollowsTheTexcoords) {
    SceneBuilder b;
    const int floorMaterial = b.addMaterial(glm::vec3(0.999f));
    b.addQuad({0, 0, 1}, {1, 0, 1}, {1, 0, 0}, {0, 0, 0}, floorMaterial, "floor");  // faces +y
    PunctualLight sun;
    sun.type = LightType::Directional;
    sun.intensity = glm::vec3(3.0f);
    sun.direction = {0, -1, 0};
    b.addLight(sun);
    Scene scene = b.build();
    // Two texels, 0.2 (left) and 0.6 (right), bilinear with REPEAT; u = x on the floor.
    scene.textures.push_back({2, 1, {0.2f, 0.2f, 0.2f, 0.6f, 0.6f, 0.6f}});
    scene.materials[std::size_t(floorMaterial)].reflectanceTexture = 0;
    SurfaceMesh& mesh = scene.instances[0].mesh;
    for (auto v : mesh.vertices()) mesh.set_texcoord2D(v, {float(mesh.point(v)[0]), float(mesh.point(v)[2])});
    const EmbreeScene rays(scene);
    PathTracerSettings settings;
    settings.maxDepth = 1;
    const PathTracer tracer(scene, rays, settings);

    // Looking straight down from 1 m, tan(fov/2) = 0.5: the 4 × 4 image spans the floor exactly, x to the right.
    Camera camera;
    camera.position = {0.5, 1.0, 0.5};
    camera.forward = {0, -1, 0};
    camera.up = {0, 0, -1};
    camera.yfovRadians = float(2.0 * std::atan(0.5));
    const CameraRender image = tracer.renderCamera(camera, 4, 4, 256);
    // Texel centres sit at u = 0.25 and 0.75 and ρ is linear over each pixel's footprint (the pixel → floor map
    // is affine), so a pixel's mean is ρ at its centre u = 0.125, 0.375, 0.625, 0.875 (the first wraps around).
    const double expectedRho[4] = {0.6 - 0.4 * 0.75, 0.2 + 0.4 * 0.25, 0.2 + 0.4 * 0.75, 0.6 - 0.4 * 0.25};
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
            const double expected = expectedRho[x] * 3.0 / std::numbers::pi;
            const double sigma = std::sqrt(double(image.varianceOfMean.at(x, y).x));
            EXPECT_NEAR(image.radiance.at(x, y).x, expected, 3.0 * sigma + 1e-5 * expected) << "pixel " << x << "," << y;
        }
}

TEST(PathTracer, EmissiveRectangleMatchesCornerFormFactors) {
    const glm::vec3 emitted(2.0f, 1.0f, 0.5f);
    struct Case { bool parallel; double a, b, c, table; };
    const Case cases[] = {
        {true, 1, 1, 1, 0.138532},  {true, 1, 2, 1, 0.167375},  {true, 2, 2, 1, 0.207757},
        {true, 1, 1, 0.1, 0.247971}, {true, 1, 1, 10, 0.003141}, {true, 0.5, 2, 0.5, 0.175270},
        {false, 1, 1, 1, 0.055734}, {false, 1, 2, 1, 0.095068}, {false, 2, 1, 1, 0.068697},
        {false, 1, 1, 0.1, 0.221739}, {false, 1, 1, 10, 0.000157}, {false, 2, 2, 0.5, 0.181278},
    };
    for (const Case& k : cases) {
        const double f = k.parallel ? cornerParallelFormFactor(k.a, k.b, k.c) : cornerPerpendicularFormFactor(k.a, k.b, k.c);
        ASSERT_NEAR(f, k.table, 5e-7) << "the closed form as typed here";
        SceneBuilder b;
        const int lamp = b.addMaterial(glm::vec3(0.0f), emitted);
        if (k.parallel)  // z = c, facing −z (towards the point)
            b.addQuad({0, 0, k.c}, {0, k.b, k.c}, {k.a, k.b, k.c}, {k.a, 0, k.c}, lamp);
        else  // y = c, facing −y
            b.addQuad({0, k.c, 0}, {k.a, k.c, 0}, {k.a, k.c, k.b}, {0, k.c, k.b}, lamp);
        const Scene scene = b.build();
        const EmbreeScene rays(scene);
        const PathTracer tracer(scene, rays, {});
        const Estimate e = tracer.irradianceOverPi({0, 0, 0}, {0, 0, 1}, 65536, 0);
        const std::string what = std::string(k.parallel ? "parallel " : "perpendicular ") + std::to_string(k.a) + " " +
                                 std::to_string(k.b) + " " + std::to_string(k.c);
        expectWithinSigmas(e, glm::dvec3(emitted) * f, glm::dvec3(0.0), 3.0, what);
        EXPECT_LT(e.standardError.x, 0.01 * emitted.x * f) << what;
    }
}

TEST(PathTracer, OnlyDoubleSidedEmittersShineFromTheBack) {
    const glm::vec3 emitted(3.0f);
    for (const bool doubleSided : {false, true}) {
        SceneBuilder b;
        const int lamp = b.addMaterial(glm::vec3(0.0f), emitted, doubleSided);
        b.addQuad({0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, lamp);  // faces +z, away from the point below
        const Scene scene = b.build();
        const EmbreeScene rays(scene);
        const PathTracer tracer(scene, rays, {});
        const Estimate e = tracer.irradianceOverPi({0, 0, 0}, {0, 0, 1}, 8192, 0);
        if (doubleSided)
            expectWithinSigmas(e, glm::dvec3(emitted) * cornerParallelFormFactor(1, 1, 1), glm::dvec3(0.0), 3.0, "double-sided");
        else
            EXPECT_EQ(e.mean, glm::dvec3(0.0));
    }
}

TEST(PathTracer, PunctualLightsAreExactAndShadowed) {
    SceneBuilder b;
    const int grey = b.addMaterial(glm::vec3(0.5f));
    b.addQuad({-10, 0, 10}, {10, 0, 10}, {10, 0, -10}, {-10, 0, -10}, grey, "floor");
    b.addQuad({4.5, 1, 0.5}, {5.5, 1, 0.5}, {5.5, 1, -0.5}, {4.5, 1, -0.5}, grey, "blocker");
    PunctualLight point;
    point.position = {0, 2, 0};
    point.intensity = {10.0f, 20.0f, 5.0f};
    b.addLight(point);
    PunctualLight spot = point;
    spot.type = LightType::Spot;
    spot.position = {5, 2, 0};
    spot.direction = {0, -1, 0};
    spot.innerConeAngle = 0.1f;
    spot.outerConeAngle = 0.3f;
    b.addLight(spot);
    const Scene scene = b.build();
    const EmbreeScene rays(scene);
    PathTracerSettings settings;
    settings.maxDepth = 1;
    const PathTracer tracer(scene, rays, settings);

    const glm::dvec3 p(1.0, 0.0, -0.5);  // lit by the point light only (the spot's cone ends at x ≈ 4.4)
    const double d = glm::length(point.position - p);
    const Estimate e = tracer.irradianceOverPi(p, {0, 1, 0}, 16, 0);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(e.mean[c], point.intensity[c] * (2.0 / d) / (std::numbers::pi * d * d), 1e-9 * e.mean[c]);
    EXPECT_EQ(e.standardError, glm::dvec3(0.0));
    // Under the blocker, the spot's light is shadowed: only the point light's remains.
    const glm::dvec3 q(5.0, 0.0, 0.0);
    const double dq = glm::length(point.position - q);
    EXPECT_NEAR(tracer.irradianceOverPi(q, {0, 1, 0}, 16, 0).mean.x, point.intensity.x * (2.0 / dq) / (std::numbers::pi * dq * dq), 1e-12);
}

TEST(PathTracer, CornellBoxDirectLightMatchesGroundTruth) {
    const Scene scene = loadGltf(std::string(HEMIBAKE_SHARED_DIR) + "/scenes/cornell_box.gltf");
    const EmbreeScene rays(scene);
    PathTracerSettings settings;
    settings.maxDepth = 1;  // direct light only
    const PathTracer tracer(scene, rays, settings);
    const glm::dvec3 emitted(17.0, 12.0, 4.0);

    // GROUND_TRUTH §5 (mm): F "with blocks" and its Monte Carlo 1σ (0 where the point sees the whole light).
    struct Row { glm::dvec3 pointMm; glm::vec3 normal; double f, sigmaF; };
    const Row rows[] = {
        {{278, 0, 279.5}, {0, 1, 0}, 0.01046, 0.00016},
        {{278, 274.4, 559.2}, {0, 0, -1}, 0.01372, 0.00018},
        {{278, 0, 50}, {0, 1, 0}, 0.00352, 0.00009},
        {{185.5, 165, 169}, {0, 1, 0}, 0.022258, 0.0},
        {{368.5, 330, 351.25}, {0, 1, 0}, 0.054098, 0.0},
    };
    std::vector<SurfacePoint> points;
    for (const Row& r : rows) points.push_back({r.pointMm * 1e-3, r.normal});
    const std::vector<Estimate> estimates = tracer.irradianceOverPi(points, 16384);
    for (std::size_t i = 0; i < points.size(); ++i) {
        std::printf("cornell point %zu: E/pi = %.5f %.5f %.5f +- %.5f %.5f %.5f, expected %.5f %.5f %.5f +- %.5f\n", i,
                    estimates[i].mean.x, estimates[i].mean.y, estimates[i].mean.z, estimates[i].standardError.x,
                    estimates[i].standardError.y, estimates[i].standardError.z, emitted.x * rows[i].f,
                    emitted.y * rows[i].f, emitted.z * rows[i].f, emitted.x * rows[i].sigmaF);
        expectWithinSigmas(estimates[i], emitted * rows[i].f, emitted * rows[i].sigmaF, 3.0, "cornell point " + std::to_string(i));
        EXPECT_LT(estimates[i].standardError.x, 0.02 * emitted.x * rows[i].f);
    }
}

TEST(PathTracer, ResultsDoNotDependOnThreadCountAndThroughputIsReported) {
    const Scene scene = loadGltf(std::string(HEMIBAKE_SHARED_DIR) + "/scenes/cornell_box.gltf");
    const EmbreeScene rays(scene);
    const PathTracer tracer(scene, rays, {});  // full global illumination
    std::vector<SurfacePoint> points;  // on the back wall, which no block touches
    for (int i = 0; i < 64; ++i) points.push_back({{0.05 + 0.45 * (i % 8) / 7.0, 0.05 + 0.45 * (i / 8) / 7.0, 0.5592}, {0, 0, -1}});
    constexpr std::uint32_t kSpp = 4096;

    std::vector<Estimate> byThreads[2];
    for (int threads = 1; threads <= 2; ++threads) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        const auto start = std::chrono::steady_clock::now();
        byThreads[threads - 1] = tracer.irradianceOverPi(points, kSpp);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::uint64_t rayCount = 0;
        for (const Estimate& e : byThreads[threads - 1]) rayCount += e.rays;
        std::printf("cornell, full GI, %d thread(s): %.0f samples/s, %.2f Mrays/s (%.1f rays/sample)\n", threads,
                    double(points.size() * kSpp) / seconds, double(rayCount) / seconds * 1e-6,
                    double(rayCount) / double(points.size() * kSpp));
    }
    for (std::size_t i = 0; i < points.size(); ++i) {
        EXPECT_EQ(byThreads[0][i].mean, byThreads[1][i].mean) << i;
        EXPECT_EQ(byThreads[0][i].standardError, byThreads[1][i].standardError) << i;
        EXPECT_GT(byThreads[0][i].mean.x, 0.0) << i;
    }
    // A different seed gives different (but statistically compatible) numbers.
    PathTracerSettings other;
    other.seed = 2;
    const Estimate e = PathTracer(scene, rays, other).irradianceOverPi(points[0].position, points[0].normal, kSpp, 0);
    EXPECT_NE(e.mean, byThreads[0][0].mean);
    EXPECT_LE(std::abs(e.mean.x - byThreads[0][0].mean.x), 4.0 * std::hypot(e.standardError.x, byThreads[0][0].standardError.x));
}
