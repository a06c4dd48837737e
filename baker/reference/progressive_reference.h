#pragma once
// Progressive reference estimates: the path tracer runs in passes until the target sample count or the time
// limit is reached, whichever comes first, and the passes are merged into one estimate per pixel or texel.
//
// Passes double the samples so far (2, 2, 4, 8, … spp: after pass k the total is 2^k), the last one cut to the
// target. With a time limit, a pass is also cut to the samples the remaining time affords at the rate measured
// so far, and no pass starts when not even one sample per point fits; the first pass always runs, so there is
// always an estimate. Each pass draws from its own seed (derived from the base seed and the pass index), so
// passes are independent and their means and sample variances merge exactly (Chan et al.'s pairwise formula);
// the standard error written out is that of the merged mean. Without a time limit the result depends on the
// arguments only (spp, seed, settings), never on timing or thread count.
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "baker/reference/path_tracer.h"

namespace hemibake {

struct ProgressiveSettings {
    std::uint32_t spp = 64;         // target samples per point (pixel or texel)
    double timeLimitSeconds = 0.0;  // 0 = no limit
};

struct ProgressiveStatus {
    std::uint32_t spp = 0;     // samples per point so far
    std::uint32_t passes = 0;
    double seconds = 0.0;      // wall time of the passes so far
    std::uint64_t rays = 0;
    bool timeLimited = false;  // stopped short of the target spp by the time limit
};

struct ProgressiveEstimate {
    std::vector<glm::dvec3> mean;           // per point
    std::vector<glm::dvec3> standardError;  // per point: of the mean (0 where fewer than 2 samples)
    ProgressiveStatus status;
};

// One pass: `spp` new samples per point with the given seed; fills one Estimate per point.
using PassFunction = std::function<void(std::uint64_t seed, std::uint32_t spp, std::vector<Estimate>& out)>;
using PassCallback = std::function<void(const ProgressiveStatus&)>;

// The pass seeds derived from a base seed: pass 0 uses the base seed itself.
std::uint64_t passSeed(std::uint64_t baseSeed, std::uint32_t pass);

ProgressiveEstimate estimateProgressively(std::size_t points, const ProgressiveSettings& settings, std::uint64_t baseSeed,
                                          const PassFunction& pass, const PassCallback& onPass = {});

// E/π at surface points (texel mode), point i using random stream i.
ProgressiveEstimate irradianceOverPiProgressively(const Scene& scene, const EmbreeScene& rays,
                                                  const PathTracerSettings& tracer, std::span<const SurfacePoint> points,
                                                  const ProgressiveSettings& settings, const PassCallback& onPass = {});

// Radiance per pixel of a pinhole camera (rows top to bottom), as PathTracer::renderCamera.
ProgressiveEstimate renderCameraProgressively(const Scene& scene, const EmbreeScene& rays, const PathTracerSettings& tracer,
                                              const Camera& camera, int width, int height,
                                              const ProgressiveSettings& settings, const PassCallback& onPass = {});

}  // namespace hemibake
