#include "baker/lightmap/ray_gatherer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "baker/util/colour.h"
#include "mesh/frame_math.h"
#include "mesh/z_curve.h"

namespace hemibake {

RayGatherer::RayGatherer(const PatchMesh& mesh, int raysPerPoint, std::uint64_t seed)
    : strata_(strataForRays(raysPerPoint)), seed_(seed), ownScene_(std::make_unique<ElementRayScene>(mesh)),
      scene_(ownScene_.get()) {}

RayGatherer::RayGatherer(const ElementRayScene& scene, int raysPerPoint, std::uint64_t seed)
    : strata_(strataForRays(raysPerPoint)), seed_(seed), scene_(&scene) {}

RayGatherer::~RayGatherer() = default;

void RayGatherer::setElementRadiance(std::vector<glm::vec3> radiance) { radiance_ = std::move(radiance); }

void RayGatherer::setTexelLight(std::shared_ptr<const TexelLight> light) { texelLight_ = std::move(light); }

glm::dvec3 RayGatherer::texelLightAt(std::uint32_t e, double b1, double b2) const {
    const TexelLight& light = *texelLight_;
    if (light.atlasSize <= 0 || e >= light.cornerUvLayer.size()) return glm::dvec3(0.0);
    const auto& corner = light.cornerUvLayer[e];
    if (!(corner[0].z >= 0.0f)) return glm::dvec3(0.0);
    const std::size_t layer = std::size_t(corner[0].z);
    if (layer >= light.layers.size()) return glm::dvec3(0.0);
    const double b0 = 1.0 - b1 - b2;
    const glm::dvec2 uv = b0 * glm::dvec2(corner[0]) + b1 * glm::dvec2(corner[1]) + b2 * glm::dvec2(corner[2]);
    // GL_LINEAR with GL_CLAMP_TO_EDGE, as the radiance hemicube samples it.
    const int size = light.atlasSize;
    const double x = uv.x * size - 0.5, y = uv.y * size - 0.5;
    const double fx0 = std::floor(x), fy0 = std::floor(y);
    const double fx = x - fx0, fy = y - fy0;
    const auto clampIndex = [&](double i) { return std::size_t(std::clamp(i, 0.0, double(size - 1))); };
    const std::size_t x0 = clampIndex(fx0), x1 = clampIndex(fx0 + 1.0), y0 = clampIndex(fy0), y1 = clampIndex(fy0 + 1.0);
    const std::vector<glm::vec3>& texels = light.layers[layer];
    const auto at = [&](std::size_t xi, std::size_t yi) { return glm::dvec3(texels[yi * std::size_t(size) + xi]); };
    const glm::dvec3 value = (1.0 - fy) * ((1.0 - fx) * at(x0, y0) + fx * at(x1, y0)) + fy * ((1.0 - fx) * at(x0, y1) + fx * at(x1, y1));
    return glm::dvec3(light.scale[e]) * value;
}

RayGatherer::RayCounts RayGatherer::gather(const std::vector<GatherPoint>& points, glm::vec3 skyRadiance, std::uint64_t sweep,
                                  std::vector<glm::dvec3>& irradianceOverPi, std::vector<float>* backfaceFraction,
                                  std::span<const std::uint32_t> keys) const {
    return trace(points, skyRadiance, sweep, keys, false, irradianceOverPi, backfaceFraction, nullptr);
}

RayGatherer::RayCounts RayGatherer::probe(const std::vector<GatherPoint>& points, glm::vec3 skyRadiance, std::uint64_t sweep,
                                          std::vector<glm::dvec3>& irradianceOverPi, std::vector<double>& standardError,
                                          std::span<const std::uint32_t> keys) const {
    if (!canProbe())
        throw std::logic_error("RayGatherer::probe: " + std::to_string(strata_) + " strata a side, fewer than " +
                               std::to_string(2 * kProbeStrataPerSide));
    return trace(points, skyRadiance, sweep, keys, true, irradianceOverPi, nullptr, &standardError);
}

RayGatherer::RayCounts RayGatherer::trace(const std::vector<GatherPoint>& points, glm::vec3 skyRadiance, std::uint64_t sweep,
                                          std::span<const std::uint32_t> keys, bool probeOnly,
                                          std::vector<glm::dvec3>& irradianceOverPi, std::vector<float>* backfaceFraction,
                                          std::vector<double>* standardError) const {
    if (!keys.empty() && keys.size() != points.size())
        throw std::invalid_argument("RayGatherer::gather: " + std::to_string(keys.size()) + " keys for " +
                                    std::to_string(points.size()) + " points");
    irradianceOverPi.assign(points.size(), glm::dvec3(0.0));
    if (backfaceFraction) backfaceFraction->assign(points.size(), 0.0f);
    if (standardError) standardError->assign(points.size(), 0.0);
    const std::uint64_t base = splitMix64(seed_ ^ splitMix64(sweep));
    const bool texelLightOn = texelLight_ && texelLight_->atlasSize > 0;
    // The probe: every stride-th stratum each way, traced first when back faces are asked for.
    const bool probed = probeOnly || (backfaceFraction && canProbe() && insideBackFraction_ <= kProbeMaxInsideBackFraction);
    const int stride = probed ? strata_ / kProbeStrataPerSide : 0;
    std::vector<std::uint32_t> probe, rest;
    for (int sy = 0; sy < strata_ && stride; ++sy)
        for (int sx = 0; sx < strata_; ++sx)
            (sx % stride == 0 && sy % stride == 0 ? probe : rest).push_back(std::uint32_t(sy * strata_ + sx));
    struct Scratch {
        std::vector<glm::dvec3> dirs, subsetDirs;
        std::vector<ElementHit> hits, subsetHits;
        RayCounts counts;
    };
    // Traces the rays `subset` of `dirs` into their places in `hits`.
    const auto traceSubset = [this](Scratch& s, const glm::dvec3& origin, const std::vector<std::uint32_t>& subset) {
        s.subsetDirs.resize(subset.size());
        s.subsetHits.resize(subset.size());
        for (std::size_t k = 0; k < subset.size(); ++k) s.subsetDirs[k] = s.dirs[subset[k]];
        scene_->trace(origin, s.subsetDirs, s.subsetHits);
        for (std::size_t k = 0; k < subset.size(); ++k) s.hits[subset[k]] = s.subsetHits[k];
    };
    tbb::enumerable_thread_specific<Scratch> scratch;
    // Points along a Z-curve: a batch's texels come in atlas order, where neighbours lie anywhere in the level, and
    // on a large level each point's rays would start from a part of the BVH long out of the cache (10 copies of a
    // level: the final gather 144.4 → 133.3 s). A point's rays depend on its key, not on when it is traced, so the
    // order changes no value.
    std::vector<glm::dvec3> positions(points.size());
    for (std::size_t k = 0; k < points.size(); ++k) positions[k] = points[k].position;
    const std::vector<std::uint32_t> order = zCurveOrder(positions);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 8), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t k = r.begin(); k != r.end(); ++k) {
            const std::size_t i = order[k];
            const glm::dvec3 n = glm::normalize(glm::dvec3(points[i].normal));
            if (!std::isfinite(n.x + n.y + n.z)) continue;  // a degenerate receiver sees nothing
            std::uint64_t state = splitMix64(base + (keys.empty() ? std::uint64_t(i) : std::uint64_t(keys[i])));
            const auto uniform = [&state] {
                state = splitMix64(state);
                return double(state >> 11) * 0x1.0p-53;
            };
            // A random rotation about the normal per point: the strata's pattern does not repeat from texel to texel.
            glm::dvec3 t0, b0;
            orthonormalBasis(n, t0, b0);
            const double angle = 2.0 * M_PI * uniform();
            const glm::dvec3 t = std::cos(angle) * t0 + std::sin(angle) * b0, b = glm::cross(n, t);
            const glm::dvec3 origin = scene_->lift(points[i].position, n);
            Scratch& local = scratch.local();
            local.dirs.clear();
            appendStratifiedCosineDirections(t, b, n, strata_, uniform, local.dirs);
            local.hits.resize(local.dirs.size());
            // What the rays saw, summed in stratum order.
            glm::dvec3 sum(0.0);
            double sumSquares = 0.0;  // of each ray's channel sum (the probe's standard error)
            std::uint64_t backs = 0, skies = 0, seen = 0;
            const auto add = [&](const ElementHit& hit) {
                ++seen;
                glm::dvec3 ray(0.0);  // added to sum term by term, in the order every gather has summed them
                if (hit.kind == ElementHit::Kind::Sky) {
                    ray = glm::dvec3(skyRadiance);
                    sum += ray;
                    ++skies;
                } else if (hit.kind == ElementHit::Kind::Back) {
                    ++backs;
                } else {
                    if (hit.element < radiance_.size()) {
                        ray = glm::dvec3(radiance_[hit.element]);
                        sum += ray;
                    }
                    if (texelLightOn) {
                        const glm::dvec3 light = texelLightAt(hit.element, hit.b1, hit.b2);
                        sum += light;
                        ray += light;
                    }
                }
                sumSquares += channelSum(ray) * channelSum(ray);
            };
            bool inside = false;
            if (stride) {
                traceSubset(local, origin, probe);
                const auto probeBacks = std::count_if(probe.begin(), probe.end(), [&](std::uint32_t stratum) {
                    return local.hits[stratum].kind == ElementHit::Kind::Back;
                });
                inside = double(probeBacks) > kInsideProbeBackFraction * double(probe.size());
                if (!inside && !probeOnly) traceSubset(local, origin, rest);
            } else {
                scene_->trace(origin, local.dirs, local.hits);
            }
            if (inside || probeOnly) {
                for (const std::uint32_t stratum : probe) add(local.hits[stratum]);
            } else {
                for (const ElementHit& hit : local.hits) add(hit);
            }
            local.counts.traced += seen;
            local.counts.stoppedInside += inside && !probeOnly;
            irradianceOverPi[i] = sum / double(seen);
            if (standardError && seen > 1) {
                const double mean = channelSum(sum) / double(seen);
                const double variance = std::max(0.0, (sumSquares - double(seen) * mean * mean) / double(seen - 1));
                (*standardError)[i] = std::sqrt(variance / double(seen));
            }
            if (backfaceFraction) (*backfaceFraction)[i] = float(double(backs) / double(seen));
            local.counts.escaped += skies;
        }
    });
    RayCounts counts;
    for (const Scratch& s : scratch) {
        counts.traced += s.counts.traced;
        counts.escaped += s.counts.escaped;
        counts.stoppedInside += s.counts.stoppedInside;
    }
    return counts;
}

}  // namespace hemibake
