#pragma once
// Leak-aware lookup in an irradiance volume: E/π at any point and normal from the grid of SH probes
// (CONVENTIONS.md "Irradiance volume", docs/probes.md). Depends on nothing but GLM and the SH helpers, so an
// engine can port it line by line.
//
// Naive trilinear interpolation leaks light through walls thinner than the probe spacing (GROUND_TRUTH §7).
// The visibility-aware weights follow DDGI (Majercik et al. 2019) and RTXGI:
//  - each probe stores, over a small octahedral map of directions, the mean distance μ and mean squared
//    distance to the nearest surface it sees; a shading point farther from the probe than μ in that
//    direction is probably behind a surface, and is weighted by the one-sided Chebyshev bound
//    σ²/(σ² + (d − μ)²), cubed, floored at 0.05;
//  - a "wrap" back-face weight ((dot(dirToProbe, n) + 1)/2)² + 0.2 favours probes in front of the surface;
//  - weights below 0.2 are crushed (w³/0.04), multiplied by the trilinear weights and renormalised over the
//    valid probes (invalid probes, inside geometry, get weight 0).
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "baker/probes/spherical_harmonics.h"

namespace hemibake {

// Octahedral map of directions (Cigolle et al. 2014) on [0, 1]²; z is the folded axis.
glm::dvec2 octahedralEncode(const glm::dvec3& unitDirection);
glm::dvec3 octahedralDecode(const glm::dvec2& uv);  // unit vector

struct IrradianceVolumeData {
    glm::dvec3 boxMin{0.0}, boxMax{0.0};  // world space, metres; probes sit on the box's cell corners
    glm::ivec3 resolution{0};             // probes per axis (≥ 2 each), x fastest, then y, then z
    std::vector<ShRgb> sh;                // incident radiance per probe
    std::vector<std::uint8_t> valid;      // 0 = inside geometry, excluded from interpolation

    // Visibility (optional: depthResolution 0 means none, and the lookup falls back to trilinear over valid
    // probes). Per probe: its offset from the grid corner where it was relocated out of geometry, and a
    // D×D octahedral map of (mean distance, mean squared distance), metres and m², row-major, texel (u, v) at
    // index v·D + u.
    int depthResolution = 0;
    std::vector<glm::vec3> probeOffsets;
    std::vector<glm::vec2> depthMoments;

    std::size_t probeCount() const { return std::size_t(resolution.x) * std::size_t(resolution.y) * std::size_t(resolution.z); }
    std::size_t index(int x, int y, int z) const {
        return (std::size_t(z) * std::size_t(resolution.y) + std::size_t(y)) * std::size_t(resolution.x) + std::size_t(x);
    }
    glm::dvec3 spacing() const { return (boxMax - boxMin) / glm::dvec3(glm::max(resolution - 1, glm::ivec3(1))); }
    glm::dvec3 gridPosition(int x, int y, int z) const { return boxMin + glm::dvec3(x, y, z) * spacing(); }
    // Where the probe was actually rendered: grid position + offset.
    glm::dvec3 probePosition(int x, int y, int z) const;
    // Bilinear lookup of probe `probe`'s depth moments in unit direction d.
    glm::dvec2 depthMomentsAt(std::size_t probe, const glm::dvec3& unitDirection) const;
    // Throws std::invalid_argument when array sizes disagree with the resolution.
    void validate() const;
};

enum class VolumeWeighting {
    Naive,       // trilinear over all eight probes, validity ignored: the leaking baseline
    Trilinear,   // trilinear, renormalised over valid probes
    Visibility,  // trilinear × back-face wrap × Chebyshev depth test, renormalised over valid probes (default)
};

struct VolumeLookupOptions {
    VolumeWeighting weighting = VolumeWeighting::Visibility;
    // The depth test uses the point moved this far (× the smallest probe spacing) along the normal, so a
    // point on a surface a probe sees is not judged "behind" that surface by the texel-averaged depth.
    double normalBiasPerSpacing = 0.05;
};

struct VolumeSample {
    glm::dvec3 irradianceOverPi{0.0};  // E/π, W·m⁻²·sr⁻¹, clamped at 0 per channel
    double weightSum = 0.0;            // before renormalisation; 0 when no probe could be used
    int probesUsed = 0;                // probes with non-zero weight
};

// E/π at world point p for unit normal n. Points outside the box are clamped onto it.
VolumeSample sampleIrradianceVolume(const IrradianceVolumeData& volume, const glm::dvec3& p, const glm::dvec3& n,
                                    const VolumeLookupOptions& options = {});

}  // namespace hemibake
