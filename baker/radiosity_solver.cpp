#include "baker/radiosity_solver.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "baker/direct_light.h"
#include "baker/embree_scene.h"
#include "baker/emissive_area_lights.h"
#include "baker/gatherer.h"
#include "baker/progressive_shooter.h"
#include "baker/sky_light.h"
#include "mesh/triangle_sampling.h"
#include "raster/hemicube_pool.h"

namespace hemibake {

namespace {

double channelSum(const glm::dvec3& v) { return v.x + v.y + v.z; }

class Stopwatch {
public:
    double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count(); }
private:
    std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};

// Jacobi gathering sweeps from the current solution. Stops after `maxSweeps`, or earlier once the a-posteriori
// bound ρ_max/(1−ρ_max)·|B_k − B_{k−1}| (area-weighted L1; ρF contracts by ρ_max there thanks to reciprocity)
// falls below `epsilon` (pass epsilon = 0 for exactly maxSweeps).
void gatherSweeps(const PatchMesh& mesh, const BakeSettings& settings, HemicubePool& pool,
                  const std::vector<glm::dvec3>& rayTracedIrradiance, bool emittersByRays, RadiositySolution& solution, int maxSweeps,
                  double epsilon, double startSeconds, SolveReport& report, const SolveProgress& progress) {
    const ElementArrays& el = mesh.elements;
    Gatherer gatherer(pool, settings.solver.seed);
    const std::vector<GatherPoint> points = elementGatherPoints(mesh);
    std::vector<glm::vec3> radiance(el.size());
    std::vector<glm::dvec3> eOverPi;
    double maxRho = 0.0;
    for (const glm::vec3& r : el.reflectance) maxRho = std::max({maxRho, double(r.x), double(r.y), double(r.z)});
    Stopwatch clock;
    for (int sweep = 0; sweep < maxSweeps; ++sweep) {
        for (std::size_t e = 0; e < el.size(); ++e) radiance[e] = solution.gatherRadiance(mesh, e, emittersByRays);
        gatherer.setElementRadiance(radiance);
        gatherer.gather(points, settings.lighting.skyRadiance, std::uint64_t(sweep) + 1, eOverPi);
        double change = 0.0, total = 0.0;
        for (std::size_t e = 0; e < el.size(); ++e) {
            const glm::dvec3 irradiance = M_PI * eOverPi[e] + rayTracedIrradiance[e];
            const glm::dvec3 b = M_PI * glm::dvec3(el.emittedRadiance[e]) + glm::dvec3(el.reflectance[e]) * irradiance;
            change += channelSum(glm::abs(b - solution.displayRadiosity(mesh, e))) * el.areaM2[e];
            total += channelSum(b) * el.areaM2[e];
            solution.irradiance[e] = irradiance;
            solution.radiosity[e] = b;
        }
        solution.ambientRadiosity = glm::dvec3(0.0);  // the gather has taken it in
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

SolveReport solveRadiosity(const Scene& scene, const PatchMesh& mesh, const BakeSettings& settings, HemicubePool& pool,
                           const EmbreeScene& rays, RadiositySolution& solution, const SolveProgress& progress) {
    SolveReport report;
    solution.resize(mesh);
    const ElementArrays& el = mesh.elements;
    Stopwatch total;

    // Direct light by rays from punctual lights and (EmitterLighting::Rays) emissive surfaces, kept apart (the
    // gather cannot see punctual lights, and must not see ray-traced emitters twice), and from the sky.
    // An element averages lightSamplesPerElement points, so each needs only its share of the emitter rays.
    const int pointsPerElement = std::max(settings.lighting.lightSamplesPerElement, 1);
    const std::unique_ptr<EmissiveAreaLights> areaLights = makeEmissiveAreaLights(
        mesh, rays, settings.lighting, std::max(4, (settings.lighting.emitterSamples + pointsPerElement - 1) / pointsPerElement));
    report.emittersByRays = areaLights != nullptr;
    std::vector<glm::dvec3> rayTraced(el.size(), glm::dvec3(0.0)), fromEmitters(el.size(), glm::dvec3(0.0));
    DirectLightSettings ds;
    ds.sunAngularDiameterRad = settings.lighting.sunAngularDiameterRad;
    auto directIrradiance = [&](const DirectLight& direct, std::vector<glm::dvec3>& out) {
        out = elementsIrradianceOverPi(direct, mesh, settings.lighting.lightSamplesPerElement);
        for (glm::dvec3& h : out) h *= M_PI;
    };
    if (!scene.lights.empty()) directIrradiance(DirectLight(scene, rays, ds), rayTraced);
    if (areaLights) {
        DirectLightSettings emittersOnly = ds;
        emittersOnly.punctualLights = false;
        directIrradiance(DirectLight(scene, rays, emittersOnly, areaLights.get()), fromEmitters);
        for (std::size_t e = 0; e < el.size(); ++e) rayTraced[e] += fromEmitters[e];
    }
    std::vector<glm::dvec3> sky = elementsSkyIrradianceOverPi(rays, mesh, settings.lighting.skyRadiance,
                                                              settings.lighting.skySamplesPerElement,
                                                              settings.solver.seed);
    // Ray-traced averages run over the whole triangle, and its covered points (under a block) see nothing; an
    // element trimmed to its exposed part (baker/exposed_area.h) wants the mean over that part. Elements almost
    // wholly covered are left alone: nobody sees them, and 1/fraction would amplify any stray ray.
    for (std::size_t e = 0; e < el.size(); ++e) {
        const double whole = triangleArea(el, e);
        const double fraction = whole > 0.0 ? el.areaM2[e] / whole : 1.0;
        if (!(fraction < 1.0) || fraction < 0.01) continue;
        rayTraced[e] /= fraction;
        fromEmitters[e] /= fraction;
        sky[e] /= fraction;
    }
    solution.rayTracedIrradiance = rayTraced;
    std::vector<glm::dvec3> injected(el.size(), glm::dvec3(0.0));
    glm::dvec3 emitterDirectW(0.0);
    for (std::size_t e = 0; e < el.size(); ++e) {
        injected[e] = rayTraced[e] + M_PI * sky[e];
        emitterDirectW += fromEmitters[e] * el.areaM2[e];
        report.directPowerW += (injected[e] - fromEmitters[e]) * el.areaM2[e];
        report.emitterPowerW += M_PI * glm::dvec3(el.emittedRadiance[e]) * el.areaM2[e];
    }
    report.directSeconds = total.seconds();

    const SolverKind kind = settings.solver.kind;
    if (kind == SolverKind::Shoot || kind == SolverKind::Hybrid) {
        ProgressiveShooter shooter(mesh, solution, pool, settings.solver);
        shooter.injectEmission(!areaLights);
        shooter.injectIrradiance(injected);
        const double t0 = total.seconds();
        report.stopReason = shooter.run(
            report.history, [&](const ConvergenceRecord& r) { if (progress) progress("shoot", r); }, t0);
        report.shootSeconds = total.seconds() - t0;
        const ShootingLedger& ledger = shooter.ledger();
        report.shots = ledger.shots;
        report.hemicubes = ledger.hemicubes;
        report.cachedShots = ledger.cachedShots;
        report.formFactorCacheBytes = shooter.formFactorCacheBytes();
        report.escapedPowerW = ledger.escapedW;
        // Ray-traced emitters did not shoot: what they emitted and no front face received went to the sky or
        // onto back faces before its first bounce (not told apart here).
        if (areaLights) report.escapedPowerW += report.emitterPowerW - emitterDirectW;
        report.backfacePowerW = ledger.backfaceW;
        report.unshotPowerW = shooter.unshotPowerPerChannelW();
        const double injectedSum = channelSum(ledger.injectedW);
        report.unshotFraction = injectedSum > 0.0 ? shooter.unshotPowerW() / injectedSum : 0.0;
        report.errorBound = exitanceErrorBound(shooter.unshotPowerW(), shooter.exitancePowerW(), shooter.maxReflectance());
        if (settings.solver.ambientCorrection) {
            // Cohen et al. 1988: what is unshot will arrive, after bounces at the mean reflectance, spread evenly.
            glm::dvec3 areaRho(0.0);
            double area = 0.0;
            for (std::size_t e = 0; e < el.size(); ++e) {
                areaRho += glm::dvec3(el.reflectance[e]) * el.areaM2[e];
                area += el.areaM2[e];
            }
            if (area > 0.0) {
                const glm::dvec3 meanRho = areaRho / area;
                solution.ambientRadiosity = report.unshotPowerW / (area * glm::max(glm::dvec3(1.0) - meanRho, glm::dvec3(1e-12)));
            }
        }
    } else {
        for (std::size_t e = 0; e < el.size(); ++e) {
            solution.irradiance[e] = rayTraced[e];
            solution.radiosity[e] = M_PI * glm::dvec3(el.emittedRadiance[e]) + glm::dvec3(el.reflectance[e]) * rayTraced[e];
        }
    }
    report.ambientRadiosity = solution.ambientRadiosity;

    const double t1 = total.seconds();
    if (kind == SolverKind::Gather)
        gatherSweeps(mesh, settings, pool, rayTraced, areaLights != nullptr, solution, settings.solver.maxGatherSweeps, settings.solver.epsilon, t1,
                     report, progress);
    else if (kind == SolverKind::Hybrid && settings.solver.gatherSweeps > 0)
        gatherSweeps(mesh, settings, pool, rayTraced, areaLights != nullptr, solution, settings.solver.gatherSweeps, 0.0, t1, report, progress);
    report.gatherSeconds = total.seconds() - t1;
    if (kind == SolverKind::Gather)
        report.stopReason = report.errorBound <= settings.solver.epsilon ? "converged" : "max-sweeps";

    for (std::size_t e = 0; e < el.size(); ++e)
        report.absorbedPowerW += (glm::dvec3(1.0) - glm::dvec3(el.reflectance[e])) * solution.irradiance[e] * el.areaM2[e];
    return report;
}

}  // namespace hemibake
