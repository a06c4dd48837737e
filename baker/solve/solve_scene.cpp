#include "baker/solve/solve_scene.h"

#include "baker/direct/emissive_area_lights.h"

#include "baker/rays/element_ray_scene.h"
#include "baker/solve/adaptive_refinement.h"
#include "baker/solve/direct_steps.h"
#include "baker/util/stopwatch.h"
#include "raster/hemicube_pool.h"

namespace hemibake {

SolvedScene::SolvedScene() = default;
SolvedScene::~SolvedScene() = default;

namespace {

// Whether rays carry the emitters' light, decided once for every stage: not when more emitter input triangles than
// LightingSettings::maxRayTracedEmitters lie near one receiver (each near one costs a contour per point), which falls
// back to shooting them (the bake warns; the report says why). Emitter patches are a quarter of the patch size so
// that emitters shooting their light through hemicubes do it from close enough (GROUND_TRUTH §3.4); when rays carry
// their light, an emitter patch shoots only what it reflects, like any patch: the finer size would multiply patches
// and shots for nothing (a closed cube emitting on every face: 15k patches instead of 1k).
SolveSettings withEmitterLighting(const Scene& scene, SolveSettings settings, std::size_t& nearOneReceiver) {
    nearOneReceiver = 0;
    if (settings.lighting.emitters != EmitterLighting::Rays) return settings;
    nearOneReceiver = emitterTrianglesNearOneReceiver(scene, settings.subdivision.elementSizeM);
    if (nearOneReceiver > std::size_t(std::max(settings.lighting.maxRayTracedEmitters, 0))) {
        settings.lighting.emitters = EmitterLighting::Hemicube;
        return settings;
    }
    if (nearOneReceiver > 0 && settings.subdivision.emitterPatchSizeM <= 0.0)
        settings.subdivision.emitterPatchSizeM = settings.subdivision.patchSizeM;
    return settings;
}

}  // namespace

std::unique_ptr<SolvedScene> solveScene(const Scene& scene, const SolveSettings& requested, const EmbreeScene& rays,
                                        const SolveProgress& progress) {
    std::size_t emittersNearOneReceiver = 0;
    const SolveSettings settings = withEmitterLighting(scene, requested, emittersNearOneReceiver);
    auto owned = std::make_unique<SolvedScene>();
    SolvedScene& solved = *owned;
    const Stopwatch clock;
    double prepareSeconds = 0.0, prepareStart = 0.0;
    const auto preparing = [&](const std::string& what) {
        if (progress) progress("preparing: " + what, ConvergenceRecord{});
    };
    // Subdivides (with `request`'s refinement regions), trims to exposed areas and solves from scratch.
    auto subdivideAndSolve = [&](const RefinementRequest* request) {
        solved.pool.reset();
        solved.elementRays.reset();
        preparing("patches and elements");
        solved.mesh = subdivideApart(scene, rays, settings.subdivision, request, settings.sides, &solved.sides);
        preparing("exposed area of " + std::to_string(solved.mesh.elements.size()) + " elements");
        solved.exposedArea = applyExposedAreas(scene, rays, solved.mesh, settings.exposure);
        solved.pool = std::make_unique<HemicubePool>(solved.mesh, settings.solver.hemicubeResolution);
        if (settings.solver.rowSampling == RowSampling::Rays)
            solved.elementRays = std::make_unique<ElementRayScene>(solved.mesh, rays);
        prepareSeconds += clock.seconds() - prepareStart;
        solved.report = solveRadiosity(scene, solved.mesh, settings, *solved.pool, rays, solved.solution, progress,
                                       solved.elementRays.get());
        prepareStart = clock.seconds();
    };
    // Regions accumulate (room scale, then each adaptive level): each re-subdivision starts from the unrefined mesh.
    preparing("room scale");
    RefinementRequest request = findRoomScaleRegions(scene, rays, settings, &solved.roomScale);
    const RefinementRequest steps = findDirectLightSteps(scene, rays, settings, request, &solved.directSteps);
    request.regions.insert(request.regions.end(), steps.regions.begin(), steps.regions.end());
    subdivideAndSolve(request.regions.empty() ? nullptr : &request);
    solved.elementsBeforeRefinement = solved.mesh.elements.size();
    for (int level = 1; level <= settings.adaptive.levels; ++level) {
        const double target = settings.subdivision.elementSizeM / double(1 << level);
        const RefinementRequest found =
            findRadiosityDiscontinuities(solved.mesh, solved.solution, settings.adaptive.threshold, target);
        if (found.regions.empty()) break;
        request.regions.insert(request.regions.end(), found.regions.begin(), found.regions.end());
        solved.refinementRegions = request.regions.size() - solved.roomScale.regions - solved.directSteps.regions;
        subdivideAndSolve(&request);
    }
    solved.report.prepareSeconds = prepareSeconds;
    solved.report.emitterTrianglesNearOneReceiver = emittersNearOneReceiver;
    return owned;
}

}  // namespace hemibake
