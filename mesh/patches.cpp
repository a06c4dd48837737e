#include "mesh/patches.h"

namespace hemibake {

void recomputePatchSums(PatchMesh& mesh, std::size_t p) {
    const ElementArrays& el = mesh.elements;
    PatchArrays& pa = mesh.patches;
    double patchArea = 0.0;
    glm::dvec3 areaCentroid(0.0), areaNormal(0.0), areaRho(0.0), areaLe(0.0);
    const std::size_t first = pa.firstElement[p], end = first + pa.elementCount[p];
    for (std::size_t e = first; e < end; ++e) {
        const double area = el.areaM2[e];
        patchArea += area;
        areaCentroid += area * el.centroid[e];
        areaNormal += area * glm::dvec3(el.normal[e]);
        areaRho += area * glm::dvec3(el.reflectance[e]);
        areaLe += area * glm::dvec3(el.emittedRadiance[e]);
    }
    const double nLen = glm::length(areaNormal);
    pa.areaM2[p] = patchArea;
    if (patchArea > 0.0) {
        pa.centroid[p] = areaCentroid / patchArea;
        pa.reflectance[p] = glm::vec3(areaRho / patchArea);
        pa.emittedRadiance[p] = glm::vec3(areaLe / patchArea);
    }
    if (nLen > 0.0) pa.normal[p] = glm::vec3(areaNormal / nLen);
}

}  // namespace hemibake
