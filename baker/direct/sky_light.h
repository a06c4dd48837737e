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

// E/π from the sky for every element (at its centroid), in parallel.
std::vector<glm::dvec3> elementsSkyIrradianceOverPi(const EmbreeScene& rays, const PatchMesh& mesh, glm::vec3 skyRadiance,
                                                    int samplesPerElement, std::uint64_t seed);

}  // namespace hemibake
