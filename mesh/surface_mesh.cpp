#include "mesh/surface_mesh.h"

namespace hemibake {

double SurfaceMesh::faceArea(FaceHandle f) const {
    auto fv = cfv_iter(f);
    const Point a = point(*fv);
    const Point b = point(*++fv);
    const Point c = point(*++fv);
    return 0.5 * OpenMesh::cross(b - a, c - a).norm();
}

}  // namespace hemibake
