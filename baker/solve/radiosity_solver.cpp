#include "baker/solve/radiosity_solver.h"

#include <algorithm>
#include <cmath>

#include "baker/direct/direct_light.h"
#include "baker/direct/emissive_area_lights.h"
#include "baker/direct/sky_light.h"
#include "baker/rays/embree_scene.h"
#include "baker/solve/gatherer.h"
#include "baker/solve/progressive_shooter.h"
#include "baker/util/colour.h"
#include "baker/util/stopwatch.h"
#include "mesh/triangle_sampling.h"
#include "raster/hemicube_pool.h"

namespace hemibake {

namespace {

// Light that reaches the elements straight from its source, by rays, per element (irradiance H, W/m²).
struct InjectedLight {
    std::unique_ptr<EmissiveAreaLights> areaLights;  // set when emitters light by rays
    std::vector<glm::dvec3> rayTraced;     // punctual lights + ray-traced emitters: what the gather cannot see
    std::vector<glm::dvec3> fromEmitters;  // the emitters' part of rayTraced
    std::vector<glm::dvec3> injected;      // rayTraced + sky: what the shooter starts from
};

// Direct light by rays from punctual lights and (EmitterLighting::Rays) emissive surfaces, kept apart (the gather
// cannot see punctual lights, and must not see ray-traced emitters twice), and from the sky. Fills the report's
// direct and emitter power.
InjectedLight injectDirectLight(const Scene& scene, const PatchMesh& mesh, const SolveSettings& settings,
                                const EmbreeScene& rays, SolveReport& report) {
    const ElementArrays& el = mesh.elements;
    const LightingSettings& lighting = settings.lighting;
    InjectedLight light;
    // An element averages lightSamplesPerElement points, so each needs only its share of the emitter rays.
    const int pointsPerElement = std::max(lighting.lightSamplesPerElement, 1);
    light.areaLights = makeEmissiveAreaLights(mesh, rays, lighting,
                                              std::max(4, (lighting.emitterSamples + pointsPerElement - 1) / pointsPerElement));
    light.rayTraced.assign(el.size(), glm::dvec3(0.0));
    light.fromEmitters.assign(el.size(), glm::dvec3(0.0));
    DirectLightSettings ds;
    ds.sunAngularDiameterRad = lighting.sunAngularDiameterRad;
    auto directIrradiance = [&](const DirectLight& direct, std::vector<glm::dvec3>& out) {
        out = elementsIrradianceOverPi(direct, mesh, lighting.lightSamplesPerElement);
        for (glm::dvec3& h : out) h *= M_PI;
    };
    if (!scene.lights.empty()) directIrradiance(DirectLight(scene, rays, ds), light.rayTraced);
    if (light.areaLights) {
        DirectLightSettings emittersOnly = ds;
        emittersOnly.punctualLights = false;
        directIrradiance(DirectLight(scene, rays, emittersOnly, light.areaLights.get()), light.fromEmitters);
        for (std::size_t e = 0; e < el.size(); ++e) light.rayTraced[e] += light.fromEmitters[e];
    }
    std::vector<glm::dvec3> sky = elementsSkyIrradianceOverPi(rays, mesh, lighting.skyRadiance, lighting.skySamplesPerElement,
                                                              pointsPerElement, settings.solver.seed);
    // Ray-traced averages of lights and emitters run over the whole triangle, and its covered points (under a
    // block) see nothing; an element trimmed to its exposed part (baker/solve/exposed_area.h) wants the mean over
    // that part. The sky of a trimmed element is sampled at its exposed centroid alone, so it already is that mean.
    // Elements almost wholly covered are left alone: nobody sees them, and 1/fraction would amplify any stray ray.
    for (std::size_t e = 0; e < el.size(); ++e) {
        const double whole = triangleArea(el, e);
        const double fraction = whole > 0.0 ? el.areaM2[e] / whole : 1.0;
        if (!(fraction < 1.0) || fraction < 0.01) continue;
        light.rayTraced[e] /= fraction;
        light.fromEmitters[e] /= fraction;
    }
    light.injected.assign(el.size(), glm::dvec3(0.0));
    for (std::size_t e = 0; e < el.size(); ++e) {
        light.injected[e] = light.rayTraced[e] + M_PI * sky[e];
        report.directPowerW += (light.injected[e] - light.fromEmitters[e]) * el.areaM2[e];
        report.emitterPowerW += M_PI * glm::dvec3(el.emittedRadiance[e]) * el.areaM2[e];
    }
    report.emittersByRays = light.areaLights != nullptr;
    return light;
}

// The ambient term where the unshot light goes (Cohen et al. 1988 spread it over every surface): its next bounce
// exactly, through the shooters' cached rows, and the bounces after it at the mean reflectance of the elements it
// reaches. An element the unshot light cannot see (a sealed room) gets none; unshot patches without a row are
// left out (where their light would go is not known).
std::vector<glm::dvec3> ambientIrradiance(const PatchMesh& mesh, std::vector<glm::dvec3> pending, SolveReport& report) {
    const ElementArrays& el = mesh.elements;
    glm::dvec3 areaRho(0.0);
    double area = 0.0, totalArea = 0.0;
    for (std::size_t e = 0; e < el.size(); ++e) {
        totalArea += el.areaM2[e];
        if (!(channelSum(pending[e]) > 0.0)) continue;
        areaRho += glm::dvec3(el.reflectance[e]) * el.areaM2[e];
        area += el.areaM2[e];
        ++report.ambientElements;
    }
    if (!(area > 0.0)) return {};
    const glm::dvec3 bounces = 1.0 / glm::max(glm::dvec3(1.0) - areaRho / area, glm::dvec3(1e-12));
    for (std::size_t e = 0; e < el.size(); ++e) {
        pending[e] *= bounces;
        report.ambientIrradianceMeanW += pending[e] * (el.areaM2[e] / totalArea);
    }
    return pending;
}

// Progressive shooting to the bound; fills the report's shooting figures and power ledger.
void shootToBound(const PatchMesh& mesh, const SolveSettings& settings, HemicubePool& pool, const InjectedLight& light,
                  double startSeconds, RadiositySolution& solution, SolveReport& report, const SolveProgress& progress) {
    ProgressiveShooter shooter(mesh, solution, pool, settings.solver);
    shooter.injectEmission(!light.areaLights);
    shooter.injectIrradiance(light.injected);
    report.stopReason = shooter.run(
        report.history, [&](const ConvergenceRecord& r) { if (progress) progress("shoot", r); }, startSeconds);
    const ShootingLedger& ledger = shooter.ledger();
    report.shots = ledger.shots;
    report.hemicubes = ledger.hemicubes;
    report.cachedShots = ledger.cachedShots;
    report.unevenShots = ledger.unevenShots;
    report.formFactorCacheBytes = shooter.formFactorCacheBytes();
    report.escapedPowerW = ledger.escapedW;
    // Ray-traced emitters did not shoot: what they emitted and no front face received went to the sky or onto
    // back faces before its first bounce (not told apart here).
    if (light.areaLights) {
        glm::dvec3 emitterDirectW(0.0);
        for (std::size_t e = 0; e < mesh.elements.size(); ++e) emitterDirectW += light.fromEmitters[e] * mesh.elements.areaM2[e];
        report.escapedPowerW += report.emitterPowerW - emitterDirectW;
    }
    report.backfacePowerW = ledger.backfaceW;
    report.unshotPowerW = shooter.unshotPowerPerChannelW();
    const double injectedSum = channelSum(ledger.injectedW);
    report.unshotFraction = injectedSum > 0.0 ? shooter.unshotPowerW() / injectedSum : 0.0;
    report.errorBound = exitanceErrorBound(shooter.unshotPowerW(), shooter.exitancePowerW(), shooter.maxReflectance());
    const ProgressiveShooter::LocalBound& bound = shooter.finalLocalBound();
    report.localBoundMax = bound.max;
    report.localBoundP95 = bound.p95;
    report.localBoundMedian = bound.median;
    if (settings.solver.ambientCorrection) {
        std::size_t unknown = 0;
        std::vector<glm::dvec3> pending = shooter.pendingIrradiance(&unknown);
        report.ambientUnknownPatches = unknown;
        solution.ambientIrradiance = ambientIrradiance(mesh, std::move(pending), report);
    }
}

// Jacobi gathering sweeps from the current solution. Stops after `maxSweeps`, or earlier once the a-posteriori
// bound ρ_max/(1−ρ_max)·|B_k − B_{k−1}| (area-weighted L1; ρF contracts by ρ_max there thanks to reciprocity)
// falls below `epsilon` (pass epsilon = 0 for exactly maxSweeps).
void gatherSweeps(const PatchMesh& mesh, const SolveSettings& settings, HemicubePool& pool, const InjectedLight& light,
                  int maxSweeps, double epsilon, double startSeconds, RadiositySolution& solution, SolveReport& report,
                  const SolveProgress& progress) {
    const ElementArrays& el = mesh.elements;
    const bool emittersByRays = light.areaLights != nullptr;
    Gatherer gatherer(pool, settings.solver.seed);
    const std::vector<GatherPoint> points = elementGatherPoints(mesh);
    std::vector<glm::vec3> radiance(el.size());
    std::vector<glm::dvec3> eOverPi;
    double maxRho = 0.0;
    for (const glm::vec3& r : el.reflectance) maxRho = std::max({maxRho, double(r.x), double(r.y), double(r.z)});
    const Stopwatch clock;
    for (int sweep = 0; sweep < maxSweeps; ++sweep) {
        for (std::size_t e = 0; e < el.size(); ++e) radiance[e] = solution.gatherRadiance(mesh, e, emittersByRays);
        gatherer.setElementRadiance(radiance);
        gatherer.gather(points, settings.lighting.skyRadiance, std::uint64_t(sweep) + 1, eOverPi);
        double change = 0.0, total = 0.0;
        for (std::size_t e = 0; e < el.size(); ++e) {
            const glm::dvec3 irradiance = M_PI * eOverPi[e] + light.rayTraced[e];
            const glm::dvec3 b = M_PI * glm::dvec3(el.emittedRadiance[e]) + glm::dvec3(el.reflectance[e]) * irradiance;
            change += channelSum(glm::abs(b - solution.displayRadiosity(mesh, e))) * el.areaM2[e];
            total += channelSum(b) * el.areaM2[e];
            solution.irradiance[e] = irradiance;
            solution.radiosity[e] = b;
        }
        solution.ambientIrradiance.clear();  // the gather has taken it in
        report.hemicubes += points.size();
        ++report.gatherSweeps;
        ConvergenceRecord r;
        r.shots = report.shots + std::uint64_t(sweep + 1) * points.size();
        r.seconds = startSeconds + clock.seconds();
        r.errorBound = total > 0.0 ? maxRho / std::max(1.0 - maxRho, 1e-12) * change / total : 0.0;
        report.history.add(r);
        report.errorBound = r.errorBound;
        if (progress) progress("gather", r);
        if (epsilon > 0.0 && r.errorBound <= epsilon) break;
    }
}

}  // namespace

SolveReport solveRadiosity(const Scene& scene, const PatchMesh& mesh, const SolveSettings& settings, HemicubePool& pool,
                           const EmbreeScene& rays, RadiositySolution& solution, const SolveProgress& progress) {
    SolveReport report;
    solution.resize(mesh);
    const ElementArrays& el = mesh.elements;
    const Stopwatch clock;

    const InjectedLight light = injectDirectLight(scene, mesh, settings, rays, report);
    solution.rayTracedIrradiance = light.rayTraced;
    report.directSeconds = clock.seconds();

    const SolverKind kind = settings.solver.kind;
    if (kind == SolverKind::Shoot || kind == SolverKind::Hybrid) {
        const double t0 = clock.seconds();
        shootToBound(mesh, settings, pool, light, t0, solution, report, progress);
        report.shootSeconds = clock.seconds() - t0;
    } else {
        for (std::size_t e = 0; e < el.size(); ++e) {
            solution.irradiance[e] = light.rayTraced[e];
            solution.radiosity[e] = M_PI * glm::dvec3(el.emittedRadiance[e]) + glm::dvec3(el.reflectance[e]) * light.rayTraced[e];
        }
    }

    const double t1 = clock.seconds();
    if (kind == SolverKind::Gather)
        gatherSweeps(mesh, settings, pool, light, settings.solver.maxGatherSweeps, settings.solver.epsilon, t1, solution, report,
                     progress);
    else if (kind == SolverKind::Hybrid && settings.solver.gatherSweeps > 0)
        gatherSweeps(mesh, settings, pool, light, settings.solver.gatherSweeps, 0.0, t1, solution, report, progress);
    report.gatherSeconds = clock.seconds() - t1;
    if (kind == SolverKind::Gather)
        report.stopReason = report.errorBound <= settings.solver.epsilon ? "converged" : "max-sweeps";

    for (std::size_t e = 0; e < el.size(); ++e)
        report.absorbedPowerW += (glm::dvec3(1.0) - glm::dvec3(el.reflectance[e])) * solution.irradiance[e] * el.areaM2[e];
    return report;
}

}  // namespace hemibake
