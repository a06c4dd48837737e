#include "baker/solve/radiosity_solver.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <unordered_map>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "baker/direct/direct_light.h"
#include "baker/direct/emissive_area_lights.h"
#include "baker/direct/sky_light.h"
#include "baker/rays/embree_scene.h"
#include "baker/rays/element_ray_scene.h"
#include "baker/solve/gatherer.h"
#include "baker/solve/progressive_shooter.h"
#include "baker/util/colour.h"
#include "baker/util/stopwatch.h"
#include "mesh/cell_key.h"
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

// What element e reflects and emits under irradiance H (W·m⁻²): B = π·L_e + ρ·H.
glm::dvec3 radiosityUnder(const ElementArrays& el, std::size_t e, const glm::dvec3& irradiance) {
    return M_PI * glm::dvec3(el.emittedRadiance[e]) + glm::dvec3(el.reflectance[e]) * irradiance;
}

// Replaces the shot light of the elements a shot handed an implausible F_ji (kImplausibleReceivedFormFactor) by
// that of the measured elements around them. The power those shots moved is right on average (the receiver's patch
// shoots it on), so the solve and its ledger keep it; only what the element itself shows is noise. Not gathered
// again: a hemicube at a sliver in a corner has its near plane reaching through the wall.
void replaceImplausibleReceivers(const PatchMesh& mesh, const SolveSettings& settings, const InjectedLight& light,
                                 const std::vector<float>& singlePixelFormFactor, RadiositySolution& solution,
                                 SolveReport& report) {
    const ElementArrays& el = mesh.elements;
    const PatchArrays& pa = mesh.patches;
    std::vector<std::uint8_t> implausible(el.size(), 0);
    std::vector<std::uint32_t> replacedElements;
    for (std::size_t e = 0; e < el.size() && e < singlePixelFormFactor.size(); ++e)
        if (singlePixelFormFactor[e] > kImplausibleReceivedFormFactor) {
            implausible[e] = 1;
            replacedElements.push_back(std::uint32_t(e));
        }
    report.implausibleReceivers = replacedElements.size();
    if (replacedElements.empty()) return;

    // Shot light (all but the ray-traced part): the area-weighted mean over the measured elements nearest around
    // each replaced one, on the same instance and facing the same way: within twice its longest edge, or twice
    // that, … up to an element size (refined elements keep their detail; a needle in a corner is often a face and
    // a patch of its own); the mean over the patch's measured elements where there are none; else none.
    auto shotLight = [&](std::size_t e) { return solution.displayIrradiance(e) - light.rayTraced[e]; };
    const double cellM = std::max(settings.subdivision.elementSizeM, 1e-12);
    auto cellOf = [&](const glm::dvec3& p) { return glm::i64vec3(glm::floor(p / cellM)); };
    auto longestEdgeM = [&](std::size_t e) {
        const auto& t = el.triangles[e];
        const glm::dvec3 &a = el.vertices[t[0]], &b = el.vertices[t[1]], &c = el.vertices[t[2]];
        return std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
    };
    // The measured elements by cell: (cell key, element) sorted, so each cell's are one run in ascending order (the
    // order the sums below take them in), found through one map entry per cell. A map of vectors cost a small heap
    // block per cell, and the search ran on one thread: 1.3 CPU s a copy on 10 copies of a level, 0.9 s on one.
    std::vector<std::pair<std::uint64_t, std::uint32_t>> measured;
    measured.reserve(el.size() - report.implausibleReceivers);
    std::vector<glm::dvec3> patchSum(pa.size(), glm::dvec3(0.0));
    std::vector<double> patchArea(pa.size(), 0.0);
    for (std::size_t e = 0; e < el.size(); ++e) {
        if (implausible[e]) continue;
        patchSum[el.patch[e]] += shotLight(e) * el.areaM2[e];
        patchArea[el.patch[e]] += el.areaM2[e];
        const glm::i64vec3 c = cellOf(el.centroid[e]);
        measured.emplace_back(cellKey(c.x, c.y, c.z), std::uint32_t(e));
    }
    std::sort(measured.begin(), measured.end());
    std::unordered_map<std::uint64_t, std::pair<std::size_t, std::size_t>> runOfCell;  // key → [first, last)
    for (std::size_t first = 0, last = 0; first < measured.size(); first = last) {
        while (last < measured.size() && measured[last].first == measured[first].first) ++last;
        runOfCell.emplace(measured[first].first, std::make_pair(first, last));
    }
    std::vector<glm::dvec3> replacedShot(replacedElements.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, replacedElements.size(), 64), [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<std::pair<double, std::uint32_t>> around;  // (distance, element)
        for (std::size_t k = r.begin(); k != r.end(); ++k) {
            const std::size_t e = replacedElements[k];
            around.clear();
            const glm::i64vec3 c = cellOf(el.centroid[e]);
            for (std::int64_t z = c.z - 1; z <= c.z + 1; ++z)
                for (std::int64_t y = c.y - 1; y <= c.y + 1; ++y)
                    for (std::int64_t x = c.x - 1; x <= c.x + 1; ++x) {
                        const auto it = runOfCell.find(cellKey(x, y, z));
                        if (it == runOfCell.end()) continue;
                        for (std::size_t i = it->second.first; i < it->second.second; ++i) {
                            const std::uint32_t m = measured[i].second;
                            const double d = glm::length(el.centroid[m] - el.centroid[e]);
                            if (el.instance[m] == el.instance[e] && glm::dot(el.normal[m], el.normal[e]) >= 0.9f && d <= cellM)
                                around.emplace_back(d, m);
                        }
                    }
            glm::dvec3 sum(0.0);
            double area = 0.0;
            if (!around.empty()) {
                const double nearest = std::min_element(around.begin(), around.end())->first;
                double radius = std::max(2.0 * longestEdgeM(e), 1e-12);
                while (radius < nearest) radius *= 2.0;
                for (const auto& [d, m] : around)
                    if (d <= radius) {
                        sum += shotLight(m) * el.areaM2[m];
                        area += el.areaM2[m];
                    }
            }
            const std::uint32_t p = el.patch[e];
            replacedShot[k] = area > 0.0             ? sum / area
                              : patchArea[p] > 0.0 ? patchSum[p] / patchArea[p]
                                                   : glm::dvec3(0.0);
        }
    });
    for (std::size_t k = 0; k < replacedElements.size(); ++k) {
        const std::uint32_t e = replacedElements[k];
        const glm::dvec3& shot = replacedShot[k];
        solution.irradiance[e] = light.rayTraced[e] + glm::max(shot, glm::dvec3(0.0));
        solution.radiosity[e] = radiosityUnder(el, e, solution.irradiance[e]);
        if (!solution.ambientIrradiance.empty()) solution.ambientIrradiance[e] = glm::dvec3(0.0);
    }
}

// Progressive shooting to the bound; fills the report's shooting figures and power ledger.
// `singlePixelFormFactor` receives ProgressiveShooter::singlePixelFormFactor().
void shootToBound(const PatchMesh& mesh, const SolveSettings& settings, HemicubePool& pool, const ElementRayScene* rowRays,
                  const InjectedLight& light, double startSeconds, RadiositySolution& solution, SolveReport& report,
                  const SolveProgress& progress, std::vector<float>& singlePixelFormFactor) {
    ProgressiveShooter shooter(mesh, solution, pool, settings.solver, rowRays);
    shooter.injectEmission(!light.areaLights);
    shooter.injectIrradiance(light.injected);
    report.stopReason = shooter.run(
        report.history, [&](const ConvergenceRecord& r) { if (progress) progress("shoot", r); }, startSeconds);
    const ShootingLedger& ledger = shooter.ledger();
    report.shots = ledger.shots;
    report.hemicubes = ledger.hemicubes;
    report.cachedShots = ledger.cachedShots;
    report.unevenShots = ledger.unevenShots;
    report.rowRaysTraced = ledger.rowRays;
    report.elementRows = ledger.elementRows;
    report.cachedElementRows = shooter.cachedElementRows();
    report.localRounds = ledger.localRounds;
    report.localBoundSeconds = ledger.localBoundSeconds;
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
    singlePixelFormFactor = shooter.singlePixelFormFactor();
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
            const glm::dvec3 b = radiosityUnder(el, e, irradiance);
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
                           const EmbreeScene& rays, RadiositySolution& solution, const SolveProgress& progress,
                           const ElementRayScene* rowRays) {
    std::unique_ptr<ElementRayScene> ownRowRays;
    const bool byRays = settings.solver.rowSampling == RowSampling::Rays;
    if (byRays && !rowRays) {
        ownRowRays = std::make_unique<ElementRayScene>(mesh);
        rowRays = ownRowRays.get();
    }
    if (!byRays) rowRays = nullptr;
    SolveReport report;
    report.rowsByRays = byRays;
    solution.resize(mesh);
    const ElementArrays& el = mesh.elements;
    const Stopwatch clock;

    if (progress) progress("preparing: direct light at " + std::to_string(el.size()) + " elements", ConvergenceRecord{});
    const InjectedLight light = injectDirectLight(scene, mesh, settings, rays, report);
    solution.rayTracedIrradiance = light.rayTraced;
    report.directSeconds = clock.seconds();

    const SolverKind kind = settings.solver.kind;
    std::vector<float> singlePixelFormFactor;
    if (kind == SolverKind::Shoot || kind == SolverKind::Hybrid) {
        const double t0 = clock.seconds();
        shootToBound(mesh, settings, pool, rowRays, light, t0, solution, report, progress, singlePixelFormFactor);
        report.shootSeconds = clock.seconds() - t0;
    } else {
        for (std::size_t e = 0; e < el.size(); ++e) {
            solution.irradiance[e] = light.rayTraced[e];
            solution.radiosity[e] = radiosityUnder(el, e, light.rayTraced[e]);
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
    // After the ledger: it is the power the solve moved; the replaced values are what those elements show.
    if (!singlePixelFormFactor.empty() && report.gatherSweeps == 0) {
        const double t2 = clock.seconds();
        replaceImplausibleReceivers(mesh, settings, light, singlePixelFormFactor, solution, report);
        report.gatherSeconds += clock.seconds() - t2;
    }
    return report;
}

}  // namespace hemibake
