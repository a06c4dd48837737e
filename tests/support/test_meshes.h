#pragma once
// Closed test surfaces (UV sphere, torus, solid boxes) and single-mesh scenes, shared by the mesh and baker tests.
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mesh/scene_builder.h"

namespace hemibake::test {

using Tri = std::array<int, 3>;

// One instance, grey ρ = 0.5, named "mesh".
inline Scene singleMesh(const std::vector<glm::dvec3>& p, const std::vector<Tri>& t) {
    SceneBuilder b;
    const int m = b.addMaterial(glm::vec3(0.5f));
    b.addTriangles(p, t, m, "mesh");
    return b.build();
}

// A closed, outward-facing axis-aligned box as one instance with 8 shared corners: a solid (mesh/solid_cuts.h), where
// SceneBuilder::addBox makes six open quads. withTop = false leaves the +y face out (an open box, no solid).
inline void addSolidBox(SceneBuilder& b, const glm::dvec3& lo, const glm::dvec3& hi, int material, const std::string& name,
                        bool withTop = true) {
    std::vector<glm::dvec3> c;
    for (int i = 0; i < 8; ++i) c.emplace_back(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    std::vector<Tri> tris;
    for (int f = 0; f < 6; ++f) {
        if (!withTop && f == 3) continue;
        tris.push_back({quads[f][0], quads[f][1], quads[f][2]});
        tris.push_back({quads[f][0], quads[f][2], quads[f][3]});
    }
    b.addTriangles(c, tris, material, name);
}

// UV sphere of radius r at c (nu segments, nv rings, single poles), outward facing.
inline void addSphere(SceneBuilder& b, int material, int nu, int nv, double r, glm::dvec3 c, const std::string& name = "sphere") {
    std::vector<glm::dvec3> p{c + glm::dvec3(0, r, 0)};
    for (int j = 1; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            const double th = M_PI * j / nv, ph = 2 * M_PI * i / nu;
            p.push_back(c + r * glm::dvec3(std::sin(th) * std::cos(ph), std::cos(th), -std::sin(th) * std::sin(ph)));
        }
    p.push_back(c - glm::dvec3(0, r, 0));
    const int south = int(p.size()) - 1;
    auto id = [&](int j, int i) { return 1 + (j - 1) * nu + (i % nu); };
    std::vector<Tri> t;
    for (int i = 0; i < nu; ++i) t.push_back({0, id(1, i), id(1, i + 1)});
    for (int j = 1; j < nv - 1; ++j)
        for (int i = 0; i < nu; ++i) {
            t.push_back({id(j, i), id(j + 1, i), id(j + 1, i + 1)});
            t.push_back({id(j, i), id(j + 1, i + 1), id(j, i + 1)});
        }
    for (int i = 0; i < nu; ++i) t.push_back({id(nv - 1, i), south, id(nv - 1, i + 1)});
    b.addTriangles(p, t, material, name);
}

// Torus about the y axis (major radius R, minor r), outward facing.
inline void addTorus(SceneBuilder& b, int material, int nu, int nv, double R, double r, const std::string& name = "torus") {
    std::vector<glm::dvec3> p;
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            const double u = 2 * M_PI * i / nu, v = 2 * M_PI * j / nv;
            p.push_back({(R + r * std::cos(v)) * std::cos(u), r * std::sin(v), -(R + r * std::cos(v)) * std::sin(u)});
        }
    auto id = [&](int j, int i) { return (j % nv) * nu + (i % nu); };
    std::vector<Tri> t;
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            t.push_back({id(j, i), id(j, i + 1), id(j + 1, i + 1)});
            t.push_back({id(j, i), id(j + 1, i + 1), id(j + 1, i)});
        }
    b.addTriangles(p, t, material, name);
}

// The unit sphere / a torus as a single-mesh scene (as singleMesh).
inline Scene uvSphere(int nu, int nv) {
    SceneBuilder b;
    addSphere(b, b.addMaterial(glm::vec3(0.5f)), nu, nv, 1.0, glm::dvec3(0.0), "mesh");
    return b.build();
}
inline Scene torus(int nu, int nv, double R, double r) {
    SceneBuilder b;
    addTorus(b, b.addMaterial(glm::vec3(0.5f)), nu, nv, R, r, "mesh");
    return b.build();
}

}  // namespace hemibake::test
