#include "baker/probes/volume_lookup.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hemibake {

namespace {
constexpr double kChebyshevFloor = 0.05;
constexpr double kCrushThreshold = 0.2;
constexpr double kWrapFloor = 0.2;

double signNotZero(double v) { return v >= 0.0 ? 1.0 : -1.0; }
}  // namespace

glm::dvec2 octahedralEncode(const glm::dvec3& d) {
    const double l1 = std::abs(d.x) + std::abs(d.y) + std::abs(d.z);
    glm::dvec2 p(d.x / l1, d.y / l1);
    if (d.z < 0.0) p = glm::dvec2((1.0 - std::abs(p.y)) * signNotZero(p.x), (1.0 - std::abs(p.x)) * signNotZero(p.y));
    return 0.5 * p + 0.5;
}

glm::dvec3 octahedralDecode(const glm::dvec2& uv) {
    const glm::dvec2 p = 2.0 * uv - 1.0;
    glm::dvec3 d(p.x, p.y, 1.0 - std::abs(p.x) - std::abs(p.y));
    if (d.z < 0.0) {
        const double x = d.x;
        d.x = (1.0 - std::abs(d.y)) * signNotZero(x);
        d.y = (1.0 - std::abs(x)) * signNotZero(d.y);
    }
    return glm::normalize(d);
}

glm::dvec3 IrradianceVolumeData::probePosition(int x, int y, int z) const {
    const glm::dvec3 grid = gridPosition(x, y, z);
    return probeOffsets.empty() ? grid : grid + glm::dvec3(probeOffsets[index(x, y, z)]);
}

glm::dvec2 IrradianceVolumeData::depthMomentsAt(std::size_t probe, const glm::dvec3& d) const {
    const int n = depthResolution;
    // Texel centres at (k + 0.5)/n; clamp at the map's edge (the octahedral fold makes the true neighbour
    // across an edge a mirrored texel; clamping is a slight blur there, not a discontinuity).
    const glm::dvec2 t = octahedralEncode(d) * double(n) - 0.5;
    const int u0 = std::clamp(int(std::floor(t.x)), 0, n - 1), v0 = std::clamp(int(std::floor(t.y)), 0, n - 1);
    const int u1 = std::min(u0 + 1, n - 1), v1 = std::min(v0 + 1, n - 1);
    const double fu = std::clamp(t.x - u0, 0.0, 1.0), fv = std::clamp(t.y - v0, 0.0, 1.0);
    const glm::vec2* map = depthMoments.data() + probe * std::size_t(n) * std::size_t(n);
    auto at = [&](int u, int v) { return glm::dvec2(map[std::size_t(v) * std::size_t(n) + std::size_t(u)]); };
    return (1.0 - fv) * ((1.0 - fu) * at(u0, v0) + fu * at(u1, v0)) + fv * ((1.0 - fu) * at(u0, v1) + fu * at(u1, v1));
}

void IrradianceVolumeData::validate() const {
    if (resolution.x < 2 || resolution.y < 2 || resolution.z < 2)
        throw std::invalid_argument("irradiance volume: resolution must be at least 2 per axis");
    if (!(boxMin.x < boxMax.x && boxMin.y < boxMax.y && boxMin.z < boxMax.z))
        throw std::invalid_argument("irradiance volume: box min must be below max on every axis");
    const std::size_t n = probeCount();
    if (sh.size() != n || valid.size() != n)
        throw std::invalid_argument("irradiance volume: " + std::to_string(n) + " probes but " + std::to_string(sh.size()) +
                                    " SH sets and " + std::to_string(valid.size()) + " validity flags");
    if (depthResolution < 0) throw std::invalid_argument("irradiance volume: negative depth map resolution");
    if (depthResolution > 0 &&
        (probeOffsets.size() != n || depthMoments.size() != n * std::size_t(depthResolution) * std::size_t(depthResolution)))
        throw std::invalid_argument("irradiance volume: visibility data does not match the probe count");
}

VolumeSample sampleIrradianceVolume(const IrradianceVolumeData& volume, const glm::dvec3& p, const glm::dvec3& n,
                                    const VolumeLookupOptions& options) {
    const glm::dvec3 spacing = volume.spacing();
    const glm::dvec3 point = glm::clamp(p, volume.boxMin, volume.boxMax);
    // Cell and position inside it.
    const glm::dvec3 g = (point - volume.boxMin) / spacing;
    const glm::ivec3 base = glm::clamp(glm::ivec3(glm::floor(g)), glm::ivec3(0), volume.resolution - 2);
    const glm::dvec3 f = glm::clamp(g - glm::dvec3(base), 0.0, 1.0);
    const bool visibility = options.weighting == VolumeWeighting::Visibility;
    const bool haveDepth = visibility && volume.depthResolution > 0;
    const double minSpacing = std::min({spacing.x, spacing.y, spacing.z});
    const glm::dvec3 biased = point + options.normalBiasPerSpacing * minSpacing * n;

    VolumeSample out;
    glm::dvec3 sum(0.0);
    for (int corner = 0; corner < 8; ++corner) {
        const glm::ivec3 o(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
        const glm::ivec3 c = base + o;
        const std::size_t i = volume.index(c.x, c.y, c.z);
        const glm::dvec3 tri = glm::mix(1.0 - f, f, glm::dvec3(o));
        const double trilinear = tri.x * tri.y * tri.z;
        if (options.weighting != VolumeWeighting::Naive && !volume.valid[i]) continue;
        double w = 1.0;
        if (visibility) {
            const glm::dvec3 probe = volume.probePosition(c.x, c.y, c.z);
            const glm::dvec3 toProbe = probe - point;
            const double toProbeLength = glm::length(toProbe);
            if (toProbeLength > 0.0) {
                const double wrap = 0.5 * (glm::dot(toProbe / toProbeLength, n) + 1.0);
                w *= wrap * wrap + kWrapFloor;
            }
            if (haveDepth) {
                const glm::dvec3 fromProbe = biased - probe;
                const double d = glm::length(fromProbe);
                if (d > 0.0) {
                    const glm::dvec2 m = volume.depthMomentsAt(i, fromProbe / d);
                    if (d > m.x) {
                        const double variance = std::abs(m.x * m.x - m.y);
                        const double excess = d - m.x;
                        const double chebyshev = variance / (variance + excess * excess);
                        w *= std::max(kChebyshevFloor, chebyshev * chebyshev * chebyshev);
                    }
                }
            }
            w = std::max(w, 1e-6);
            if (w < kCrushThreshold) w *= w * w / (kCrushThreshold * kCrushThreshold);
        }
        w *= trilinear;
        if (w <= 0.0) continue;
        sum += w * volume.sh[i].irradianceOverPi(n);
        out.weightSum += w;
        ++out.probesUsed;
    }
    if (out.weightSum > 0.0) out.irradianceOverPi = glm::max(sum / out.weightSum, glm::dvec3(0.0));
    return out;
}

}  // namespace hemibake
