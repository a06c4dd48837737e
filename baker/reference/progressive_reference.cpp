#include "baker/reference/progressive_reference.h"
#include "mesh/frame_math.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace hemibake {

namespace {

// Sample count, mean and sum of squared deviations of every point: the merged state of all passes so far.
struct MergedSamples {
    double count = 0.0;  // the same for every point: each pass adds the same spp everywhere
    std::vector<glm::dvec3> mean, m2;

    explicit MergedSamples(std::size_t points) : mean(points, glm::dvec3(0.0)), m2(points, glm::dvec3(0.0)) {}

    void merge(const std::vector<Estimate>& pass, std::uint32_t spp) {
        const double n = double(spp), total = count + n;
        for (std::size_t i = 0; i < mean.size(); ++i) {
            const Estimate& e = pass[i];
            // Sum of squared deviations of the pass, recovered from its standard error of the mean.
            const glm::dvec3 passM2 = e.standardError * e.standardError * n * std::max(n - 1.0, 0.0);
            const glm::dvec3 delta = e.mean - mean[i];
            mean[i] += delta * (n / total);
            m2[i] += passM2 + delta * delta * (count * n / total);
        }
        count = total;
    }

    std::vector<glm::dvec3> standardError() const {
        std::vector<glm::dvec3> se(mean.size(), glm::dvec3(0.0));
        if (count < 2.0) return se;
        for (std::size_t i = 0; i < se.size(); ++i) se[i] = glm::sqrt(m2[i] / (count - 1.0) / count);
        return se;
    }
};

}  // namespace

std::uint64_t passSeed(std::uint64_t baseSeed, std::uint32_t pass) {
    return pass == 0 ? baseSeed : splitMix64(baseSeed ^ splitMix64(pass));
}

ProgressiveEstimate estimateProgressively(std::size_t points, const ProgressiveSettings& settings, std::uint64_t baseSeed,
                                          const PassFunction& pass, const PassCallback& onPass) {
    if (settings.spp < 1) throw std::invalid_argument("progressive estimate: spp must be at least 1");
    if (!(settings.timeLimitSeconds >= 0.0)) throw std::invalid_argument("progressive estimate: time limit must be >= 0");
    using Clock = std::chrono::steady_clock;
    const Clock::time_point start = Clock::now();
    MergedSamples merged(points);
    ProgressiveStatus status;
    std::vector<Estimate> estimates(points);
    double secondsPerSample = 0.0;  // per sample per point, measured over all passes so far

    while (status.spp < settings.spp) {
        std::uint32_t spp = status.spp == 0 ? 2u : status.spp;  // doubling the total
        spp = std::min(spp, settings.spp - status.spp);
        if (settings.timeLimitSeconds > 0.0 && status.passes > 0) {
            const double remaining = settings.timeLimitSeconds - status.seconds;
            const double affordable = secondsPerSample > 0.0 ? std::floor(remaining / secondsPerSample) : double(spp);
            if (affordable < 1.0) {
                status.timeLimited = true;
                break;
            }
            spp = std::uint32_t(std::min(double(spp), affordable));
        }
        estimates.assign(points, Estimate{});
        pass(passSeed(baseSeed, status.passes), spp, estimates);
        if (estimates.size() != points) throw std::logic_error("progressive estimate: a pass returned the wrong count");
        merged.merge(estimates, spp);
        for (const Estimate& e : estimates) status.rays += e.rays;
        status.spp += spp;
        status.passes += 1;
        status.seconds = std::chrono::duration<double>(Clock::now() - start).count();
        secondsPerSample = status.seconds / double(status.spp);
        if (onPass) onPass(status);
    }
    ProgressiveEstimate result;
    result.standardError = merged.standardError();
    result.mean = std::move(merged.mean);
    result.status = status;
    return result;
}

ProgressiveEstimate irradianceOverPiProgressively(const Scene& scene, const EmbreeScene& rays,
                                                  const PathTracerSettings& tracer, std::span<const SurfacePoint> points,
                                                  const ProgressiveSettings& settings, const PassCallback& onPass) {
    return estimateProgressively(
        points.size(), settings, tracer.seed,
        [&](std::uint64_t seed, std::uint32_t spp, std::vector<Estimate>& out) {
            PathTracerSettings s = tracer;
            s.seed = seed;
            out = PathTracer(scene, rays, s).irradianceOverPi(points, spp);
        },
        onPass);
}

ProgressiveEstimate renderCameraProgressively(const Scene& scene, const EmbreeScene& rays, const PathTracerSettings& tracer,
                                              const Camera& camera, int width, int height,
                                              const ProgressiveSettings& settings, const PassCallback& onPass) {
    if (width < 1 || height < 1) throw std::invalid_argument("reference render: image size must be positive");
    const std::size_t pixels = std::size_t(width) * std::size_t(height);
    return estimateProgressively(
        pixels, settings, tracer.seed,
        [&](std::uint64_t seed, std::uint32_t spp, std::vector<Estimate>& out) {
            PathTracerSettings s = tracer;
            s.seed = seed;
            const CameraRender image = PathTracer(scene, rays, s).renderCamera(camera, width, height, spp);
            for (std::size_t p = 0; p < pixels; ++p) {
                Estimate& e = out[p];
                e.mean = glm::dvec3(image.radiance.pixels[p]);
                e.standardError = glm::sqrt(glm::dvec3(image.varianceOfMean.pixels[p]));
                e.samples = spp;
            }
            // A render reports rays for the whole frame; book them on the first pixel so the sum is right.
            out[0].rays = image.rays;
        },
        onPass);
}

}  // namespace hemibake
