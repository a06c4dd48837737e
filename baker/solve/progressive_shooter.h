#pragma once
// Progressive refinement by shooting (Cohen, Chen, Wallace & Greenberg 1988): the patch with the most unshot
// power renders an item-buffer hemicube and hands ρ_j·ΔB_i·F_ij·A_i/A_j to every element j it sees; what the
// receivers reflect becomes their patches' unshot radiosity. Patches are shot in batches of one per worker thread,
// rendered in parallel and applied in order (each shoots what it holds when its batch is picked).
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <tbb/enumerable_thread_specific.h>

#include "baker/solve/convergence.h"
#include "baker/solve/form_factor_cache.h"
#include "baker/solve/radiosity_solution.h"
#include "baker/solve/solve_settings.h"
#include "baker/solve/unshot_queue.h"
#include "mesh/patches.h"

namespace hemibake {

class ElementRayScene;

// A receiver cannot see more than its whole hemisphere of one patch (F_ji ≤ 1). A shot that hands element j
// F_ji = F_ij·A_i/A_j above this through one or two hemicube pixels or rays (ProgressiveShooter::
// singlePixelFormFactor) drew an element much smaller than a pixel into all of it: level_clean has slivers of
// 1e-13 m² beside walls handed F_ji = 8e7, radiosity 1e7 W/m², and the few texels whose gathers see them made rooms
// +120 … +390 % per object. Such an element's own shot light is replaced after the solve (RadiositySolver) and does
// not hold the local bound open. Elements that fill many pixels are left alone even above 1: 5 cm under a light
// panel the near-field rows overshoot (up to F_ji = 32 in the HangingPanel room) but are right on average:
// replacing those above 2 took the ceiling over the panel from +0.8 % to −17 %.
constexpr double kImplausibleReceivedFormFactor = 1.0;
class HemicubePool;
struct HemicubeFrame;

// Power in W per channel, accumulated over the whole solve (for the energy balance check).
struct ShootingLedger {
    glm::dvec3 injectedW{0.0};       // emitted by surfaces + arriving directly from punctual lights and sky
    glm::dvec3 escapedW{0.0};        // shot into hemicube pixels that saw nothing (lost to the sky)
    glm::dvec3 backfaceW{0.0};       // shot onto the backs of single-sided surfaces (absorbed there)
    std::uint64_t shots = 0;
    std::uint64_t hemicubes = 0;     // rendered; > shots when proximity asked for several sample points
    std::uint64_t cachedShots = 0;   // shots that reused their patch's cached form-factor row
    std::uint64_t unevenShots = 0;   // shots from elements picked by the patch's uneven light (unevenShotSpread)
    std::uint64_t elementRows = 0;   // element rows rendered (proximity and uneven shots): each once while it is kept
    std::uint64_t rowRays = 0;       // rows by rays: rays traced (tight-gap re-traces included)
    std::uint64_t localRounds = 0;   // local-bound evaluations after the bulk (each picks the next patches to shoot)
    double localBoundSeconds = 0.0;  // spent evaluating them (serial; the rest of the shoot time renders and applies)
    std::size_t cacheBytes = 0;      // form-factor rows kept
};

class ProgressiveShooter {
public:
    // Rows are sampled by `pool`'s item-buffer hemicubes, or by rays into `rowRays` (built on `mesh`) when given
    // (SolverSettings::rowSampling). Both must outlive the shooter.
    ProgressiveShooter(const PatchMesh& mesh, RadiositySolution& solution, HemicubePool& pool,
                       const SolverSettings& settings, const ElementRayScene* rowRays = nullptr);
    ~ProgressiveShooter();

    // Emission: B = π·L_e on every emitting element, and (if `shoot`) its patch's unshot radiosity. Without
    // `shoot` the emitters' direct light must arrive through injectIrradiance (EmissiveAreaLights).
    void injectEmission(bool shoot = true);
    // Irradiance arriving from outside the surface set (punctual lights, sky), W·m⁻² per element.
    void injectIrradiance(const std::vector<glm::dvec3>& irradiance);

    // The local error bound: per element e, the irradiance still to arrive at it, H_pending(e) = Σ_p ΔB_p·F_pe·A_p/A_e
    // over the unshot patches (first bounce, through their cached form-factor rows), over (1 − ρ_max)·H(e), its
    // irradiance so far. A patch that has never shot could reach anything: it must shoot; one that has shot but whose
    // row did not fit the cache bounds each lit element's gain by its ΔB (F_ep ≤ 1). Implausible receivers
    // (singlePixelFormFactor() > kImplausibleReceivedFormFactor) are left out: their own value is replaced.
    struct LocalBound {
        double max = 0.0, p95 = 0.0, median = 0.0;  // over elements, area-weighted
        std::size_t unknownPatches = 0;              // unshot patches without a row
        std::size_t neverShotPatches = 0;            // unshot patches that have never shot (each holds max at ∞)
        std::vector<std::uint32_t> worstPatches;     // what to shoot next: its own share of the worst bound first
    };
    // `quantiles` false: median and p95 stay 0 unless max ≤ epsilon (they need a sort of every element; the
    // rounds before the last only use max and worstPatches). Not thread-safe against a running shoot.
    LocalBound localBound(double epsilon, bool quantiles = true) const;

    using Progress = std::function<void(const ConvergenceRecord&)>;
    // Shoots the largest unshot powers (in sweeps: every patch with at least half the largest, along a Z-curve
    // through their centroids) until the total is ≤ epsilon × injected power, then the patches that decide the
    // local bound until every element's is ≤ epsilon (a sunlit exterior does not decide when a dark corridor
    // stops), or a time/shot limit. Returns the stop reason.
    std::string run(ConvergenceHistory& history, const Progress& progress, double startSeconds);
    // Per element, the irradiance the unshot patches with a cached row will deliver when they next shoot, W·m⁻²
    // (no rendering). `unknownPatches` counts unshot patches without a row (their light is not in it).
    std::vector<glm::dvec3> pendingIrradiance(std::size_t* unknownPatches = nullptr) const;
    const LocalBound& finalLocalBound() const { return finalBound_; }
    // Per element, the largest F_ji = F_ij·A_i/A_j a shot handed it through at most two pixels' worth of F_ij (a
    // receiver much smaller than the pixel it was drawn into, given all of it: a sliver beside a wall). Above 1 that
    // element's own value is noise (no receiver sees more than all of one patch). Elements that fill many pixels
    // (5 cm under a light panel) are not counted: their near-field rows overshoot 1 too, but right on average.
    const std::vector<float>& singlePixelFormFactor() const { return singlePixelFormFactor_; }

    const ShootingLedger& ledger() const { return ledger_; }
    std::size_t formFactorCacheBytes() const { return cache_->bytesUsed(); }
    std::size_t cachedElementRows() const;  // element rows held in the cache now
    double unshotPowerW() const { return queue_.totalPower(); }  // sum over channels
    glm::dvec3 unshotPowerPerChannelW() const;
    double exitancePowerW() const { return exitanceW_; }  // Σ B·A over elements, summed over channels
    double maxReflectance() const { return maxReflectance_; }

private:
    struct Shot;
    struct MergeScratch;
    void addUnshot(std::uint32_t patch, const glm::dvec3& radiosity);
    void renderShot(std::uint32_t patch, Shot& shot) const;
    // `patch`'s row into shot.own: one hemicube at its centroid, or, something being near (proximity) or a tight
    // gap in front of it, its elements' own rows merged by area. Returns the hemicubes rendered.
    std::uint32_t renderRow(std::uint32_t patch, std::uint64_t seed, Shot& shot) const;
    // Whether `patch`'s unshot light lies unevenly over it: more than settings_.unevenShotSpread of it away from
    // an even spread over its area (total-variation distance between the two distributions over its elements).
    bool unevenLight(std::uint32_t patch) const;
    // The share of everything `patch` has given off (its elements' radiosity × area) that its unshot light is: 1 on
    // its first shot, small once it has shot most of what it will receive.
    double lightShareOfShot(std::uint32_t patch) const;
    double unshotW(std::uint32_t patch) const;  // Σ unshotW_ over the patch's elements
    // Up to kMaxSamplesPerPatch of `patch`'s elements spread over it, weighted by area (weights sum to 1).
    std::vector<std::pair<std::uint32_t, double>> areaPicks(std::uint32_t patch) const;
    // Up to kMaxSamplesPerPatch elements picked by systematic sampling of `patch`'s unshot light, each with the
    // share it shoots from its centroid (weights sum to 1).
    std::vector<std::pair<std::uint32_t, double>> lightPicks(std::uint32_t patch) const;
    // Every element of `patch` weighted by the unshot light it holds, W: where an uneven row by rays leaves from
    // (tracePickedRow; an uneven patch holds some, unevenLight).
    std::vector<std::pair<std::uint32_t, double>> lightSources(std::uint32_t patch) const;
    // Every element of `patch` weighted 1/4 by area, 3/4 by the light put into it before shooting (by area alone if
    // none was): where an even row by rays leaves from, the same whatever the order of the shots.
    std::vector<std::pair<std::uint32_t, double>> evenSources(std::uint32_t patch) const;
    // The rows of `picks` (element, weight) merged into shot.own, weights normalised: each element's own row from
    // the cache, or rendered (in parallel) and, if `keep`, stored there, so proximity and uneven shots of a patch
    // share them; rows not stored stay in shot.elementRows. Returns the hemicubes rendered.
    std::uint32_t mergeElementRows(const std::vector<std::pair<std::uint32_t, double>>& picks, Shot& shot,
                                   bool keep = true) const;
    // One element's row: a hemicube at its centroid rotated by `rotation`, or, facing a tight gap, the mean of
    // kTightSamplesPerSide² hemicubes over it. Uses this thread's renderer and scratch; thread-safe across threads.
    void renderElementRow(std::uint32_t element, std::uint64_t rotation, FormFactorRow& row) const;
    // One row sample at `frame` into scratch.list: an item-buffer hemicube of this thread's renderer. Thread-safe
    // across threads.
    void sampleRow(const HemicubeFrame& frame, MergeScratch& scratch) const;
    // Rows by rays: the row of light leaving `sources` (element, weight; normalised here) into `row`, in one pass of
    // N = s² ≤ `rayCount` rays (s² the largest such square): each source gets its weight's share of them to within
    // one ray, each ray leaves from a uniform point of its element's triangle in a stratified cosine direction and
    // carries 1/N of the row. So the row is the sources' area-averaged form factors, the near field where surfaces
    // meet included, with N rays in all however many sources. Trimmed elements leave from their centroid, elements
    // facing a gap (gapFacing) from their centroid or inset points (see the .cpp). Seeded by `seed` alone. Returns
    // the rays traced (gapFacing's first tests included), 0 if the weights are all zero. Thread-safe across threads.
    std::uint64_t tracePickedRow(const std::vector<std::pair<std::uint32_t, double>>& sources, std::uint64_t seed,
                                 double rayCount, FormFactorRow& row) const;
    // How an element's rays by rays leave it: Open (from uniform points), Wide (a gap within kCoveredFraction of
    // its size in front of it: from its centroid), Tight (within kTightFraction: from inset points).
    enum class GapFacing : std::uint8_t { Unknown, Open, Wide, Tight };
    // `element`'s GapFacing, found once from rays of its own (added to `raysTraced`) and kept. Thread-safe.
    GapFacing gapFacing(std::uint32_t element, std::uint64_t& raysTraced) const;
    // Whether the last sampleRow into `scratch`, from an element or patch of this size, faced a tight gap.
    bool facesTightGap(const MergeScratch& scratch, double sizeM) const;
    // The cached row that predicts `patch`'s next shot: its row, or, its light lying unevenly, the row of its last
    // uneven shot (the next one re-weights the same elements by the light they hold then); null if none.
    const FormFactorRow* nextRow(std::uint32_t patch) const;
    // `rows` (row, weight) averaged into `merged`, weights normalised to sum 1. Uses this thread's merge scratch.
    void mergeRows(const std::vector<std::pair<const FormFactorRow*, double>>& rows, FormFactorRow& merged) const;
    // Cache slot of one element's own row (uneven shots), after the patches' rows.
    std::uint32_t elementSlot(std::uint32_t element) const { return std::uint32_t(mesh_.patches.size()) + element; }
    // Cache slot of a patch's last uneven row, after the elements' rows.
    std::uint32_t unevenSlot(std::uint32_t patch) const {
        return std::uint32_t(mesh_.patches.size() + mesh_.elements.size()) + patch;
    }
    // Hands `deltaRadiosity` of `patch` through `row` to the elements it sees (queue updates left to the caller).
    void applyRow(std::uint32_t patch, const FormFactorRow& row, const glm::dvec3& deltaRadiosity);
    void applyShot(const Shot& shot);
    // Renders (in parallel) and applies the shots of `patches`, each with what it holds now, a batch of
    // shots.size() at a time; after each batch `afterBatch` reports progress and returns false to stop there (a
    // local round can hold thousands of patches: minutes without it). Patches not reached keep their unshot light.
    void shoot(const std::vector<std::uint32_t>& patches, std::vector<Shot>& shots, std::uint64_t& shotSeed,
               const std::function<bool()>& afterBatch);

    const PatchMesh& mesh_;
    RadiositySolution& solution_;
    HemicubePool& pool_;
    const ElementRayScene* rowRays_ = nullptr;  // rows by rays when set
    double rowRayCount_ = 0.0;                  // rows by rays: N, the rays a row traces (a little more, rounded up)
    SolverSettings settings_;
    UnshotQueue queue_;
    ShootingLedger ledger_;
    double maxReflectance_ = 0.0;
    double exitanceW_ = 0.0;  // kept up to date by every injection and shot
    LocalBound finalBound_;
    std::vector<bool> shotOnce_;  // per patch: has shot (its row may not be cached)
    std::vector<std::uint32_t> shotsOfPatch_;  // per patch: shots so far (rows by rays are seeded by it)
    // Per patch: the last shot (ledger_.shots + 1) whose receivers updated its queue entry, so a shot updates each
    // receiving patch once, not once per element (in a furnace every shot reaches thousands of elements).
    std::vector<std::uint64_t> queuedAtShot_;
    std::vector<std::pair<std::uint32_t, double>> queueUpdates_;  // applyShot's, for UnshotQueue::setMany
    // Unshot power per element, W (channel sum): where on its patch the light to shoot lies.
    std::vector<double> unshotW_;
    std::unique_ptr<std::atomic<std::uint8_t>[]> gapFacing_;  // per element: its GapFacing once known (rows by rays)
    std::vector<double> injectedW_;  // per element: the light put into it before shooting (direct, emission), W
    std::vector<float> singlePixelFormFactor_;  // per element, see singlePixelFormFactor()
    std::vector<std::uint32_t> zCurveRank_;      // per patch: its place on a Z-curve through the centroids (run())
    double largestPixelFormFactor_ = 0.0;        // the hemicube's largest delta form factor (its centre pixel)
    std::unique_ptr<tbb::enumerable_thread_specific<MergeScratch>> scratch_;
    std::unique_ptr<FormFactorCache> cache_;
};

}  // namespace hemibake
