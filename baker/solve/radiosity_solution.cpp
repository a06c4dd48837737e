#include "baker/solve/radiosity_solution.h"

namespace hemibake {

void RadiositySolution::resize(const PatchMesh& mesh) {
    radiosity.assign(mesh.elements.size(), glm::dvec3(0.0));
    irradiance.assign(mesh.elements.size(), glm::dvec3(0.0));
    rayTracedIrradiance.assign(mesh.elements.size(), glm::dvec3(0.0));
    unshotRadiosity.assign(mesh.patches.size(), glm::dvec3(0.0));
    ambientIrradiance.clear();
}

}  // namespace hemibake
