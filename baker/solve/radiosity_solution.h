#pragma once
// The solver's state, flat per element and per patch, all in double: at ρ = 0.999 float accumulation loses
// the tail of the geometric series (GROUND_TRUTH §2.E: −3.4e-3 at 384 patches, growing with N).
#include <cmath>
#include <vector>

#include <glm/glm.hpp>

#include "mesh/patches.h"

namespace hemibake {

struct RadiositySolution {
    // Per element.
    std::vector<glm::dvec3> radiosity;           // B, W·m⁻², including emission π·L_e
    std::vector<glm::dvec3> irradiance;          // H, W·m⁻², incident (excludes own emission); texel = H/π
    // The part of H that came by rays from punctual lights and ray-traced emitters (DirectLight): lightmaps
    // evaluate it again at every texel instead of interpolating it from elements.
    std::vector<glm::dvec3> rayTracedIrradiance;
    // Per patch: radiosity received but not yet shot, W·m⁻² (area-weighted over its elements).
    std::vector<glm::dvec3> unshotRadiosity;

    // Ambient term, per element (empty: none): the irradiance the still-unshot power will add, estimated from
    // where it goes next (its first bounce through the shooters' form-factor rows) with the bounces after it at
    // the mean reflectance of what it reaches. Cohen et al. 1988 spread it uniformly; here a room the unshot
    // light cannot see gets none.
    std::vector<glm::dvec3> ambientIrradiance;

    void resize(const PatchMesh& mesh);
    glm::dvec3 ambient(std::size_t element) const {
        return ambientIrradiance.empty() ? glm::dvec3(0.0) : ambientIrradiance[element];
    }
    // Irradiance including the ambient estimate: what the lightmap stores (as H/π) mid-solve.
    glm::dvec3 displayIrradiance(std::size_t element) const { return irradiance[element] + ambient(element); }
    glm::dvec3 displayRadiosity(const PatchMesh& mesh, std::size_t element) const {
        return radiosity[element] + glm::dvec3(mesh.elements.reflectance[element]) * ambient(element);
    }
    // Outgoing radiance (B/π, W·m⁻²·sr⁻¹) a gathering hemicube shows for the element. Without emission when the
    // emitters' direct light reaches receivers by rays (EmissiveAreaLights): the gather must not count it twice.
    glm::vec3 gatherRadiance(const PatchMesh& mesh, std::size_t element, bool withoutEmission) const {
        glm::dvec3 b = displayRadiosity(mesh, element);
        if (withoutEmission) b -= M_PI * glm::dvec3(mesh.elements.emittedRadiance[element]);
        return glm::vec3(glm::max(b, glm::dvec3(0.0)) / M_PI);
    }
};

}  // namespace hemibake
