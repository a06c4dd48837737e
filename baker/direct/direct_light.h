#pragma once
// Direct light from KHR_lights_punctual lights with shadow rays, as E/π (W·m⁻²·sr⁻¹): what a lightmap texel
// stores, restricted to the light that arrives straight from punctual lights and, when given, from emissive
// surfaces lit by rays (EmissiveAreaLights; otherwise they are the radiosity shooter's job). The sky is not
// handled here.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "baker/direct/emissive_area_lights.h"
#include "baker/rays/embree_scene.h"
#include "mesh/patches.h"
#include "mesh/scene.h"

namespace hemibake {

struct DirectLightSettings {
    // Full angle of the disk a directional light subtends (the real sun: ≈ 0.0093 rad). 0 = hard shadows.
    // Only visibility is averaged over the disk, so an unoccluded point receives exactly intensity·cosθ.
    float sunAngularDiameterRad = 0.0f;
    int sunSamples = 16;    // stratified shadow rays over the sun disk (when its diameter is > 0)
    bool useRange = false;  // honour PunctualLight::range with the KHR_lights_punctual window
    bool punctualLights = true;  // false: only the area lights (the solver's power ledger keeps them apart)
};

class DirectLight {
public:
    // `scene`, `rays` and `areaLights` (optional: emissive surfaces lit by rays) must outlive this object.
    // Throws std::invalid_argument on bad settings.
    DirectLight(const Scene& scene, const EmbreeScene& rays, DirectLightSettings settings,
                const EmissiveAreaLights* areaLights = nullptr);

    // E/π at surface point p with unit normal n (the receiving side). `seed` decorrelates the sun-disk jitter
    // between points; with a hard sun the result does not depend on it.
    glm::dvec3 irradianceOverPiAt(const glm::dvec3& p, const glm::vec3& n, std::uint32_t seed) const;

    // Mean E/π over k² stratified points of the element's triangle (the centroids of its k × k regular
    // sub-triangles), k = ceil(sqrt(samplesPerElement)): exact for a field linear over the element.
    glm::dvec3 elementIrradianceOverPi(const PatchMesh& patches, std::size_t element, int samplesPerElement) const;

    const DirectLightSettings& settings() const { return settings_; }

private:
    // irradianceOverPiAt with the area lights seen from `view` (a receiver holding p) when given.
    glm::dvec3 irradianceOverPiAt(const glm::dvec3& p, const glm::dvec3& n, std::uint32_t seed,
                                  const EmissiveAreaLights::ReceiverView* view) const;
    glm::dvec3 fromLight(const PunctualLight& light, const glm::dvec3& p, const glm::dvec3& n, std::uint32_t seed) const;
    double sunVisibility(const glm::dvec3& origin, const glm::dvec3& n, const glm::dvec3& toSun, std::uint32_t seed) const;

    const Scene& scene_;
    const EmbreeScene& rays_;
    DirectLightSettings settings_;
    const EmissiveAreaLights* areaLights_;
};

// elementIrradianceOverPi for every element, in parallel (oneTBB); index = element index.
std::vector<glm::dvec3> elementsIrradianceOverPi(const DirectLight& light, const PatchMesh& patches, int samplesPerElement);

}  // namespace hemibake
