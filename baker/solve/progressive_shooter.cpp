#include "baker/solve/progressive_shooter.h"

#include <algorithm>
#include <cmath>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "baker/util/colour.h"
#include "baker/util/stopwatch.h"
#include "raster/hemicube.h"
#include "raster/hemicube_pool.h"

namespace hemibake {

namespace {

// Enough sample points to integrate the form factor over a patch near a receiver (GROUND_TRUTH §3.4: 4×4
// points take hinged squares from −4.8 % to ≈ 0.1 %), few enough that one shot stays cheap.
constexpr std::uint32_t kMaxSamplesPerPatch = 16;

}  // namespace

// One patch's shot: the radiosity it shoots and its row of area-averaged form factors to every element it sees
// (the cache's, or its own when the cache is full).
struct ProgressiveShooter::Shot {
    std::uint32_t patch = 0;
    glm::dvec3 deltaRadiosity{0.0};
    FormFactorRow own;
    const FormFactorRow* row = nullptr;
    std::uint32_t hemicubesRendered = 0;
    std::uint64_t seed = 0;
};

// Per-thread scratch for merging several hemicubes' form factors: a dense accumulator and the ids it touched.
struct ProgressiveShooter::MergeScratch {
    FormFactorList list;
    std::vector<double> dense;
    std::vector<std::uint32_t> touched;
};

ProgressiveShooter::ProgressiveShooter(const PatchMesh& mesh, RadiositySolution& solution, HemicubePool& pool,
                                       const SolverSettings& settings)
    : mesh_(mesh), solution_(solution), pool_(pool), settings_(settings), queue_(mesh.patches.size()),
      scratch_(std::make_unique<tbb::enumerable_thread_specific<MergeScratch>>()),
      cache_(std::make_unique<FormFactorCache>(mesh.patches.size(), std::size_t(settings.formFactorCacheMiB * 1048576.0))) {
    for (const glm::vec3& rho : mesh.elements.reflectance)
        maxReflectance_ = std::max({maxReflectance_, double(rho.x), double(rho.y), double(rho.z)});
}

ProgressiveShooter::~ProgressiveShooter() = default;

void ProgressiveShooter::addUnshot(std::uint32_t patch, const glm::dvec3& radiosity) {
    solution_.unshotRadiosity[patch] += radiosity;
    queue_.set(patch, channelSum(solution_.unshotRadiosity[patch]) * mesh_.patches.areaM2[patch]);
}

void ProgressiveShooter::injectEmission(bool shoot) {
    const ElementArrays& el = mesh_.elements;
    for (std::size_t e = 0; e < el.size(); ++e) {
        const glm::dvec3 exitance = M_PI * glm::dvec3(el.emittedRadiance[e]);
        if (channelSum(exitance) <= 0.0) continue;
        solution_.radiosity[e] += exitance;
        exitanceW_ += channelSum(exitance) * el.areaM2[e];
        if (!shoot) continue;
        ledger_.injectedW += exitance * el.areaM2[e];
        addUnshot(el.patch[e], exitance * (el.areaM2[e] / mesh_.patches.areaM2[el.patch[e]]));
    }
}

void ProgressiveShooter::injectIrradiance(const std::vector<glm::dvec3>& irradiance) {
    const ElementArrays& el = mesh_.elements;
    for (std::size_t e = 0; e < el.size(); ++e) {
        if (channelSum(irradiance[e]) <= 0.0) continue;
        const glm::dvec3 reflected = glm::dvec3(el.reflectance[e]) * irradiance[e];
        solution_.irradiance[e] += irradiance[e];
        solution_.radiosity[e] += reflected;
        exitanceW_ += channelSum(reflected) * el.areaM2[e];
        ledger_.injectedW += irradiance[e] * el.areaM2[e];
        addUnshot(el.patch[e], reflected * (el.areaM2[e] / mesh_.patches.areaM2[el.patch[e]]));
    }
}

void ProgressiveShooter::renderShot(std::uint32_t patch, Shot& shot) const {
    if (const FormFactorRow* cached = cache_->find(patch)) {
        shot.row = cached;
        shot.hemicubesRendered = 0;
        cache_->countHit();
        return;
    }
    renderRow(patch, shot.seed, shot.own);
    shot.hemicubesRendered = shot.own.hemicubes;
    shot.row = cache_->store(patch, std::move(shot.own)) ? cache_->find(patch) : &shot.own;
}

void ProgressiveShooter::renderRow(std::uint32_t patch, std::uint64_t seed, FormFactorRow& row) const {
    HemicubeRenderer& renderer = pool_.local();
    MergeScratch& scratch = scratch_->local();
    const PatchArrays& pa = mesh_.patches;
    const ElementArrays& el = mesh_.elements;

    HemicubeFrame frame = HemicubeFrame::randomlyRotated(pa.centroid[patch], glm::dvec3(pa.normal[patch]), seed);
    renderer.renderFormFactors(frame, scratch.list);
    row.hemicubes = 1;
    const double patchSizeM = std::sqrt(2.0 * pa.areaM2[patch]);
    const std::uint32_t count = pa.elementCount[patch];
    if (count <= 1 || !(scratch.list.minDepthM < settings_.proximityFactor * patchSizeM)) {
        row.elements.assign(scratch.list.elements.begin(), scratch.list.elements.end());
        row.formFactors.assign(scratch.list.formFactors.begin(), scratch.list.formFactors.end());
        row.skyFraction = scratch.list.skyFraction;
        row.backfaceFraction = scratch.list.backfaceFraction;
        return;
    }

    // Proximity: something is close relative to the patch, so one centred hemicube misrepresents the patch.
    // Integrate over the patch with one hemicube per (a spread subset of) its elements, area-weighted.
    if (scratch.dense.size() != el.size()) scratch.dense.assign(el.size(), 0.0);
    scratch.touched.clear();
    const std::uint32_t samples = std::min(count, kMaxSamplesPerPatch);
    const std::uint32_t first = pa.firstElement[patch];
    double sampledArea = 0.0;
    for (std::uint32_t s = 0; s < samples; ++s) sampledArea += el.areaM2[first + std::uint64_t(s) * count / samples];
    row.skyFraction = row.backfaceFraction = 0.0;
    row.hemicubes = 0;
    for (std::uint32_t s = 0; s < samples; ++s) {
        const std::uint32_t e = first + std::uint32_t(std::uint64_t(s) * count / samples);
        const double w = el.areaM2[e] / sampledArea;
        frame = HemicubeFrame::randomlyRotated(el.centroid[e], glm::dvec3(el.normal[e]), seed * 1315423911u + s);
        renderer.renderFormFactors(frame, scratch.list);
        ++row.hemicubes;
        for (std::size_t k = 0; k < scratch.list.size(); ++k) {
            const std::uint32_t j = scratch.list.elements[k];
            if (scratch.dense[j] == 0.0) scratch.touched.push_back(j);
            scratch.dense[j] += w * scratch.list.formFactors[k];
        }
        row.skyFraction += w * scratch.list.skyFraction;
        row.backfaceFraction += w * scratch.list.backfaceFraction;
    }
    row.elements.clear();
    row.formFactors.clear();
    for (std::uint32_t j : scratch.touched) {
        row.elements.push_back(j);
        row.formFactors.push_back(float(scratch.dense[j]));
        scratch.dense[j] = 0.0;
    }
}

void ProgressiveShooter::applyShot(const Shot& shot) {
    const ElementArrays& el = mesh_.elements;
    const double shooterArea = mesh_.patches.areaM2[shot.patch];
    const glm::dvec3 powerW = shot.deltaRadiosity * shooterArea;
    const FormFactorRow& row = *shot.row;
    for (std::size_t k = 0; k < row.elements.size(); ++k) {
        const std::uint32_t j = row.elements[k];
        // Reciprocity: F_ji = F_ij·A_i/A_j, so the irradiance j gains is ΔB_i·F_ij·A_i/A_j.
        const glm::dvec3 deltaIrradiance = shot.deltaRadiosity * (double(row.formFactors[k]) * shooterArea / el.areaM2[j]);
        const glm::dvec3 reflected = glm::dvec3(el.reflectance[j]) * deltaIrradiance;
        solution_.irradiance[j] += deltaIrradiance;
        solution_.radiosity[j] += reflected;
        exitanceW_ += channelSum(reflected) * el.areaM2[j];
        const std::uint32_t p = el.patch[j];
        solution_.unshotRadiosity[p] += reflected * (el.areaM2[j] / mesh_.patches.areaM2[p]);
    }
    // Queue updates after the loop: a patch with many receiving elements is updated once per element otherwise.
    for (std::size_t k = 0; k < row.elements.size(); ++k) {
        const std::uint32_t p = el.patch[row.elements[k]];
        queue_.set(p, channelSum(solution_.unshotRadiosity[p]) * mesh_.patches.areaM2[p]);
    }
    ledger_.escapedW += powerW * row.skyFraction;
    ledger_.backfaceW += powerW * row.backfaceFraction;
    ++ledger_.shots;
    ledger_.hemicubes += shot.hemicubesRendered;
    ledger_.cachedShots += shot.hemicubesRendered == 0 ? 1 : 0;
}

glm::dvec3 ProgressiveShooter::unshotPowerPerChannelW() const {
    glm::dvec3 sum(0.0);
    for (std::size_t p = 0; p < mesh_.patches.size(); ++p) sum += solution_.unshotRadiosity[p] * mesh_.patches.areaM2[p];
    return sum;
}

std::string ProgressiveShooter::run(ConvergenceHistory& history, const Progress& progress, double startSeconds) {
    const Stopwatch clock;
    const double injected = channelSum(ledger_.injectedW);
    const std::size_t batch = std::max<std::size_t>(1, tbb::this_task_arena::max_concurrency());
    std::vector<Shot> shots(batch);
    std::uint64_t shotSeed = settings_.seed * 0x9E3779B97F4A7C15ull;
    std::string reason;

    auto record = [&](bool force) {
        const double seconds = startSeconds + clock.seconds();
        if (!force && !history.wants(ledger_.shots, seconds)) return;
        ConvergenceRecord r;
        r.shots = ledger_.shots;
        r.seconds = seconds;
        r.unshotFraction = injected > 0.0 ? queue_.totalPower() / injected : 0.0;
        r.errorBound = exitanceErrorBound(queue_.totalPower(), exitanceW_, maxReflectance_);
        history.add(r);
        if (progress) progress(r);
    };
    record(true);

    while (true) {
        if (!(injected > 0.0) || queue_.totalPower() <= settings_.epsilon * injected) { reason = "converged"; break; }
        if (settings_.maxShots && ledger_.shots >= settings_.maxShots) { reason = "max-shots"; break; }
        if (settings_.maxTimeSeconds > 0.0 && startSeconds + clock.seconds() >= settings_.maxTimeSeconds) { reason = "max-time"; break; }

        // Pick the top patches; each shoots what it holds now (later gains stay unshot for a later turn).
        std::size_t picked = 0;
        for (; picked < batch; ++picked) {
            if (queue_.maxPower() <= 0.0) break;
            if (settings_.maxShots && ledger_.shots + picked >= settings_.maxShots) break;
            const auto p = std::uint32_t(queue_.argmax());
            shots[picked].patch = p;
            shots[picked].deltaRadiosity = solution_.unshotRadiosity[p];
            shots[picked].seed = ++shotSeed;
            solution_.unshotRadiosity[p] = glm::dvec3(0.0);
            queue_.set(p, 0.0);
        }
        if (picked == 0) { reason = "converged"; break; }
        tbb::parallel_for(std::size_t(0), picked, [&](std::size_t i) { renderShot(shots[i].patch, shots[i]); },
                          tbb::simple_partitioner());
        for (std::size_t i = 0; i < picked; ++i) applyShot(shots[i]);
        record(false);
    }
    record(true);
    return reason;
}

}  // namespace hemibake
