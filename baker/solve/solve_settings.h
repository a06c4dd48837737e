#pragma once
// The solve stage's knobs: subdivision into patches and elements, exposed-area trimming, the solver itself,
// adaptive refinement, and the lighting it injects. Gathered in SolveSettings, which is all solveScene needs.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "baker/direct/lighting_settings.h"
#include "mesh/patches.h"

namespace hemibake {

enum class SolverKind {
    Shoot,   // progressive refinement shooting only
    Gather,  // Jacobi gathering sweeps only
    Hybrid,  // shoot to the bound, then gather sweeps at the receivers (default)
};
const char* solverKindName(SolverKind kind);
SolverKind parseSolverKind(const std::string& name);  // throws std::invalid_argument

// How a shooting row (the form factors from a point to every element it sees) is sampled.
enum class RowSampling {
    Hemicube,  // an item-buffer hemicube through OSMesa per point: exact delta form factors per pixel
    Rays,      // stratified cosine rays through Embree into the elements, R² a row split over its points (every preset)
};
const char* rowSamplingName(RowSampling sampling);
RowSampling parseRowSampling(const std::string& name);  // throws std::invalid_argument

struct SolverSettings {
    SolverKind kind = SolverKind::Hybrid;
    int hemicubeResolution = 128;       // R: front face R×R pixels, four R×R/2 side faces (presets 32–256)
    // Rays on every preset: a culled hemicube costs what it draws, which grows with the level, and a shot from 16
    // points costs 16 of them; R² rays cost the log of the level and the same for 1 or 16 points. Measured at medium
    // (docs/performance.md, session 24): solve 84 → 23 s on the clean 10k level, 181 → 45 s on the overlapping one,
    // capped at 1,200 s → converged in 565 s at 100k, the Cornell box 3.5 → 1.3 s; per object as good or better.
    RowSampling rowSampling = RowSampling::Rays;
    // Rays per row with RowSampling::Rays, split over the shot's picks; 0 = R² (as many as a texel's final gather).
    // 3R² (the hemicube's pixel count) took the 100k level's solve from 565 to 1,191 s for the same error per object.
    int rowRays = 0;
    // Rows by rays, uneven shots (always traced, never cached): a shot whose light is a share s of what its patch
    // has given off so far (1 on its first shot, 1e-3 late in the local rounds) traces min(1, this × s) of the
    // row's rays, at least 1/16. Its noise adds variance ∝ s²/rays, so rays ∝ s keeps all later shots' noise
    // together at about 1/this of the first shot's, for a fraction of the rays. 0 = every uneven shot all rays.
    double unevenRaysPerLightShare = 4.0;
    // Stop when, at every element, the irradiance still to arrive (the unshot light's next bounce, with the
    // bounces after it) is ≤ epsilon × what it has (presets 1e-2–1e-4); the bulk is shot first by power, down to
    // epsilon × injected power.
    double epsilon = 1e-3;
    double maxTimeSeconds = 0.0;        // 0 = no limit
    std::uint64_t maxShots = 0;         // 0 = no limit
    int gatherSweeps = 1;               // Hybrid: gathering sweeps after shooting (presets: 0, the texel gather is final)
    int maxGatherSweeps = 200;          // Gather: sweeps at most (it stops earlier at the epsilon bound)
    bool ambientCorrection = true;      // add the ambient term for what is still unshot, where it will arrive
    // A patch re-shoots from one hemicube per element when something is nearer than this × the patch's size
    // (GROUND_TRUTH §3.4: one centred hemicube is 4.8 % low for hinged squares, 16 points 0.01 %).
    double proximityFactor = 2.0;
    // A patch whose unshot light lies unevenly over it (more than this fraction of it away from an even spread over
    // its area) shoots from up to 16 elements picked in proportion to that light: a ceiling patch lit only above a
    // hanging panel sends that light back into the panel's gap, not into the room. 1 = never (every shot from the
    // patch's centre or area-weighted points). Presets 0.1.
    double unevenShotSpread = 0.1;
    // Form-factor rows kept for patches that shoot again (0 = render every shot). Rows cost ≈ 3 bytes per
    // element a patch sees (FormFactorRow); the 30k-triangle level at 4 texels/m holds all of its rows in ≈ 500 MiB.
    double formFactorCacheMiB = 1024.0;
    int threads = 0;                    // 0 = all cores
    std::uint64_t seed = 1;             // hemicube rotations and sampling
};



// Model only what the scene requires: after a first solve, elements whose radiosity differs from an edge
// neighbour's by more than `threshold` (relative) are bisected down to elementSize / 2^levels, and the scene is
// solved again. Smooth regions stay coarse; unlit ones never shoot.
struct AdaptiveSettings {
    int levels = 0;           // 0 = off (ultra: 1)
    double threshold = 0.2;   // |B_a − B_b| > threshold × max(B_a, B_b) (+ a small floor relative to the mean)
};

// Elements partly under other geometry keep only their exposed part (baker/solve/exposed_area.h).
struct ExposedAreaSettings {
    // k: k² points per element; a straight cut through the element misassigns at most (2k − 1)/k² of its area
    // (the sub-triangles it crosses), and much less on average as their errors take both signs.
    int samplesPerSide = 16;
    // Screening (0 = off): an element is sampled with the k² points only when one of its screenSamplesPerSide²
    // points, or of a neighbour's (sharing a vertex), sees any back face at all; the rest (most elements) are
    // open. A cover that falls between the screening points of an element and all its neighbours (smaller than
    // about 1/screenSamplesPerSide of an element) is missed.
    int screenSamplesPerSide = 4;
    int rayStrata = 8;                     // cosine-weighted rays per point: rayStrata², as the texel criterion
    int screenRayStrata = 2;               // per screening point (it looks for any back face at all)
    double coveredBackfaceFraction = 0.9;  // see above
    int horizonRays = 16;                  // the ring just above the surface
    double horizonElevationRad = 10.0 * M_PI / 180.0;
    // An element with nothing exposed keeps this fraction of its triangle: a positive area, so that whatever
    // stray power reaches it (a hemicube pixel through a contact line) divides by something.
    double minFraction = 1e-3;
};

// Elements and patches never straddle a wall standing on their face (baker/solve/separate_sides.h).
struct SideSeparationSettings {
    // Off by default: on a 26 m level with 1.6 m elements it makes 6× the elements and still leaves some
    // straddling (measured, issue 15's note); on clean geometry it changes nothing.
    bool enabled = false;
    int samplesPerSide = 4;         // k: k² points per element tested for connectivity (4: 16 points, ≤ 120 segments)
    // Elements are bisected down to elementSize × this at the finest (1/8: 20 cm for 1.6 m elements): walls
    // thicker than about that separate cleanly; finer multiplies the elements along every wall (1/64 took a
    // 26 m level from 19k to over 260k elements).
    double minEdgeFraction = 1.0 / 8.0;
    // Points are lifted off the face by this × the element's longest edge (and at least the ray epsilon):
    // above float error, below any step that separates rooms.
    double liftFraction = 1e-3;
};

// Elements no larger than a fraction of the room they are in (baker/solve/room_scale.h). The presets size
// elements from the scene's diagonal, which makes a level's rooms a few elements across (1.6 m elements in 5 m
// rooms, more on bigger levels); this refines each element to roomFraction × its mean free path (the mean
// distance its cosine-weighted rays travel before they hit something, 4V/S in a closed convex room).
struct RoomScaleSettings {
    // 0 = off. Presets: 1 at draft and medium (a safety net: on a 26 m level it refines only corners and tight
    // spaces, on a 100 m one every room), 1/2 at high, 1/3 at ultra (0.8–0.9 m elements in 5 m rooms).
    double roomFraction = 0.0;
    int raysPerElement = 16;          // stratified cosine-weighted rays from each element's centroid
    // Never finer than elementSize × this (two bisections): tight gaps and buried elements stay bounded.
    double minSizeFraction = 0.25;
};

// Elements halved where direct light steps within them, before the solve (baker/solve/direct_steps.h).
struct DirectStepSettings {
    int levels = 0;                  // 0 = off (every preset: experimental, see docs/architecture.md)
    double contrast = 0.5;           // (max − min) over an element's points > contrast × max
    int samplesPerSide = 2;          // k: k² points per element (the centroids of its k × k sub-triangles)
    int emitterSamples = 16;         // shadow rays per point towards emitters (a step, not a precise value)
    double faintFraction = 0.01;     // steps whose peak is below this × the mean peak of lit elements are left
    double minSizeFraction = 0.125;  // never finer than elementSize × this
};

struct SolveSettings {
    SubdivisionSettings subdivision;
    RoomScaleSettings roomScale;
    DirectStepSettings directSteps;
    ExposedAreaSettings exposure;
    SideSeparationSettings sides;
    SolverSettings solver;
    AdaptiveSettings adaptive;
    LightingSettings lighting;
};

}  // namespace hemibake
