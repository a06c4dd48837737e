#pragma once
// Every knob of a bake, in one struct: printed into bake.json, so a bake is reproducible from its report.
#include <cstdint>
#include <string>

#include <glm/glm.hpp>

#include "mesh/patches.h"

namespace hemibake {

enum class SolverKind {
    Shoot,   // progressive refinement shooting only
    Gather,  // Jacobi gathering sweeps only
    Hybrid,  // shoot to the bound, then gather sweeps at the receivers (default)
};

struct SolverSettings {
    SolverKind kind = SolverKind::Hybrid;
    int hemicubeResolution = 128;       // R: front face R×R pixels, four R×R/2 side faces
    double epsilon = 1e-3;              // stop when unshot power ≤ epsilon × injected power
    double maxTimeSeconds = 0.0;        // 0 = no limit
    std::uint64_t maxShots = 0;         // 0 = no limit
    int gatherSweeps = 1;               // Hybrid: gathering sweeps after shooting
    int maxGatherSweeps = 200;          // Gather: sweeps at most (it stops earlier at the epsilon bound)
    bool ambientCorrection = true;      // add Cohen et al. 1988's ambient term for what is still unshot
    // A patch re-shoots from one hemicube per element when something is nearer than this × the patch's size
    // (GROUND_TRUTH §3.4: one centred hemicube is 4.8 % low for hinged squares, 16 points 0.01 %).
    double proximityFactor = 2.0;
    // Form-factor rows kept for patches that shoot again (0 = render every shot). Rows cost ≈ 8 bytes per
    // element a patch sees.
    double formFactorCacheMiB = 1024.0;
    int threads = 0;                    // 0 = all cores
    std::uint64_t seed = 1;             // hemicube rotations and sampling
};

// Model only what the scene requires: after a first solve, elements whose radiosity differs from an edge
// neighbour's by more than `threshold` (relative) are bisected down to elementSize / 2^levels, and the scene is
// solved again. Smooth regions stay coarse; unlit ones never shoot.
struct AdaptiveSettings {
    int levels = 0;           // 0 = off
    double threshold = 0.2;   // |B_a − B_b| > threshold × max(B_a, B_b) (+ a small floor relative to the mean)
};

enum class TexelMode {
    Interpolate,  // texels interpolate the element solution (fast)
    Gather,       // texels gather from a final hemicube each, placed adaptively (quality)
};

struct LightmapSettings {
    double texelsPerUnit = 0.0;     // texels per metre; 0 = from the preset and scene size
    int maxAtlasSize = 1024;
    int paddingTexels = 2;
    TexelMode mode = TexelMode::Gather;
    int latticeStep = 4;            // Elias-style placement: hemicubes on every 4th texel first (power of two)
    double interpolationTolerance = 0.05;  // interpolate a texel when its lattice neighbours agree within this
    double invalidBackfaceFraction = 0.1;  // a texel whose hemicube sees more back faces is inside geometry
    int dilationTexels = 2;         // padding texels filled from their chart's edge
    bool stitchSeams = true;
    bool keepExistingUv = false;    // use TEXCOORD_1 from the input where present
};

enum class EmitterLighting {
    Hemicube,  // emitters shoot their power through item-buffer hemicubes like every other patch
    Rays,      // direct light from emitters by Lambert's formula and shadow rays (EmissiveAreaLights); bounces shoot
};

struct LightingSettings {
    EmitterLighting emitters = EmitterLighting::Hemicube;
    int emitterSamples = 16;            // shadow rays per point towards emissive surfaces (Rays)
    int maxRayTracedEmitters = 4096;    // more emitting elements than this: fall back to Hemicube (cost per point)
    glm::vec3 skyRadiance{0.0f};        // uniform sky, W·m⁻²·sr⁻¹, seen where rays and hemicube pixels escape
    int skySamplesPerElement = 64;      // cosine-weighted visibility rays for direct sky light
    float sunAngularDiameterRad = 0.0f; // > 0: directional lights become soft-shadowed discs
    int lightSamplesPerElement = 16;    // stratified points per element for punctual light shadows
};

struct BakeSettings {
    std::string preset = "medium";
    SubdivisionSettings subdivision;
    SolverSettings solver;
    AdaptiveSettings adaptive;
    LightmapSettings lightmap;
    LightingSettings lighting;
};

const char* solverKindName(SolverKind kind);
const char* emitterLightingName(EmitterLighting mode);
EmitterLighting parseEmitterLighting(const std::string& name);  // throws std::invalid_argument
SolverKind parseSolverKind(const std::string& name);  // throws std::invalid_argument

}  // namespace hemibake
