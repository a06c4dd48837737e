#pragma once
// The solve, start to finish: direct light from punctual lights and sky (Embree shadow rays), progressive
// shooting to the bound, ambient correction, then gathering sweeps at the receivers.
#include <functional>
#include <string>

#include "baker/solve/convergence.h"
#include "baker/solve/radiosity_solution.h"
#include "baker/solve/solve_settings.h"
#include "mesh/patches.h"
#include "mesh/scene.h"

namespace hemibake {

class EmbreeScene;
class ElementRayScene;
class HemicubePool;

struct SolveReport {
    std::string stopReason;        // converged | max-shots | max-time | sweeps
    std::uint64_t shots = 0;
    std::uint64_t hemicubes = 0;   // shooting hemicubes (or ray-sampled rows) + gathering hemicubes (rendered)
    bool rowsByRays = false;       // shooting rows were sampled by rays (SolverSettings::rowSampling)
    std::uint64_t cachedShots = 0; // shots that reused a cached form-factor row (no hemicube rendered)
    std::uint64_t unevenShots = 0; // shots from elements picked by the patch's uneven light
    std::uint64_t rowRaysTraced = 0;  // rows by rays: rays traced in all (tight-gap re-traces included)
    std::uint64_t elementRows = 0; // element rows rendered (near patches' rows, uneven shots): each once while cached
    std::size_t cachedElementRows = 0; // of those, held in the form-factor cache at the end
    std::uint64_t localRounds = 0; // local-bound evaluations that picked what to shoot after the bulk
    double localBoundSeconds = 0.0; // spent in them (part of shootSeconds)
    std::size_t formFactorCacheBytes = 0;
    int gatherSweeps = 0;
    // Elements a shot handed F_ji > 1 through one or two hemicube pixels (a sliver given a whole pixel): after
    // shooting they show the shot light of the elements around them (radiosity_solver.cpp).
    std::size_t implausibleReceivers = 0;
    double directSeconds = 0.0, shootSeconds = 0.0, gatherSeconds = 0.0;
    // Before the solve (solveScene): room scale, subdivision, exposed areas, the element ray scene, over every
    // adaptive level.
    double prepareSeconds = 0.0;
    // Power ledger, W per channel.
    glm::dvec3 emitterPowerW{0.0};   // π·L_e·A over emitting elements
    glm::dvec3 directPowerW{0.0};    // arriving straight from punctual lights and the sky
    glm::dvec3 escapedPowerW{0.0};   // shot into the sky
    glm::dvec3 backfacePowerW{0.0};  // shot onto backs of single-sided surfaces (absorbed)
    glm::dvec3 absorbedPowerW{0.0};  // Σ (1−ρ)·H·A over elements
    glm::dvec3 unshotPowerW{0.0};    // still unshot when shooting stopped
    double unshotFraction = 0.0;     // unshot / injected, summed over channels
    double errorBound = 0.0;         // see ConvergenceRecord::errorBound
    // The local bound (ProgressiveShooter::LocalBound) when shooting stopped: area-weighted over elements.
    double localBoundMax = 0.0, localBoundP95 = 0.0, localBoundMedian = 0.0;
    glm::dvec3 ambientIrradianceMeanW{0.0};  // area-weighted over all elements
    std::size_t ambientElements = 0;         // elements the unshot light reaches (the others get no ambient)
    std::size_t ambientUnknownPatches = 0;   // unshot patches without a row: their light is in no ambient
    bool emittersByRays = false;     // emitters' direct light came from EmissiveAreaLights, not from shooting
    // Emitter input triangles near one receiver, what LightingSettings::maxRayTracedEmitters limits (solveScene;
    // 0 when emitters shoot by setting).
    std::size_t emitterTrianglesNearOneReceiver = 0;
    ConvergenceHistory history;
};

// `stage` is "shoot" or "gather" with the record of that moment, or "preparing: …" (what the solve is about to do;
// the record is empty) before each step that comes before the first shot.
using SolveProgress = std::function<void(const std::string& stage, const ConvergenceRecord&)>;

// Solves `mesh` (subdivided from `scene`, with `pool` and `rays` built on them) into `solution`. Shooting rows are
// sampled by rays into `rowRays` (built on `mesh`) when settings.solver.rowSampling is Rays; given null, the solve
// builds its own. Uses every core; throws std::invalid_argument on bad settings.
SolveReport solveRadiosity(const Scene& scene, const PatchMesh& mesh, const SolveSettings& settings, HemicubePool& pool,
                           const EmbreeScene& rays, RadiositySolution& solution, const SolveProgress& progress = {},
                           const ElementRayScene* rowRays = nullptr);

}  // namespace hemibake
