#pragma once
// Direct light from a uniform sky: E/π = L_sky × (cosine-weighted fraction of the hemisphere that escapes),
// by stratified cosine-weighted visibility rays. The shooter needs it as injected irradiance; a final gather
// sees the sky itself through its hemicube pixels.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "baker/rays/embree_scene.h"
#include "mesh/patches.h"

namespace hemibake {

// Cosine-weighted fraction of escaping directions at p (normal n), from `samples` stratified rays.
double skyVisibility(const EmbreeScene& rays, const glm::dvec3& p, const glm::dvec3& n, int samples, std::uint64_t seed);

// E/π from the sky for every element, in parallel: the mean over the element's whole triangle, at the k² points
// DirectLight::elementIrradianceOverPi uses (k = ceil(sqrt(pointsPerElement))), samplesPerElement rays shared
// among them. Sampling at the centroid alone missed how a window's light falls off across a metre-sized element
// (rooms lit through windows came out 1.6–3.8 % bright on a generated level). An element trimmed to its exposed part
// (ElementArrays::areaM2 below its triangle's area) averages only its points that are not covered (half their rays
// on back faces): dividing a whole-triangle mean by the exposed fraction would add the mismatch between the
// exposure samples and these points (up to 19 % measured), and its exposed centroid alone can sit millimetres
// from the cover's edge (5 % dark beside a 2 mm slab).
std::vector<glm::dvec3> elementsSkyIrradianceOverPi(const EmbreeScene& rays, const PatchMesh& mesh, glm::vec3 skyRadiance,
                                                    int samplesPerElement, int pointsPerElement, std::uint64_t seed);

}  // namespace hemibake
