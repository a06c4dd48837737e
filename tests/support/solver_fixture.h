#pragma once
// Runs the full solver on a scene made in code: real OSMesa hemicubes, real Embree rays.
#include <memory>

#include "baker/rays/embree_scene.h"
#include "baker/solve/radiosity_solver.h"
#include "mesh/scene_builder.h"
#include "mesh/subdivision.h"
#include "raster/hemicube_pool.h"

namespace hemibake::test {

struct SolvedTestScene {
    Scene scene;
    PatchMesh mesh;
    RadiositySolution solution;
    SolveReport report;
};

// The faces of a closed unit cube, facing inwards; +y (top) in `top` so it can emit alone; the floor (−y) unless
// the caller brings its own.
inline void addFurnaceFaces(SceneBuilder& b, int wall, int top, bool floor = true) {
    auto c = [](int i) { return glm::dvec3(i & 1, (i >> 1) & 1, (i >> 2) & 1); };
    b.addQuad(c(2), c(6), c(4), c(0), wall, "-x");
    b.addQuad(c(1), c(5), c(7), c(3), wall, "+x");
    if (floor) b.addQuad(c(0), c(4), c(5), c(1), wall, "-y");
    b.addQuad(c(2), c(3), c(7), c(6), top, "+y");
    b.addQuad(c(0), c(1), c(3), c(2), wall, "-z");
    b.addQuad(c(4), c(6), c(7), c(5), wall, "+z");
}

// A closed unit cube seen from inside; every face emits L_e (or only the top one) with reflectance rho.
inline Scene furnace(float rho, float emitted, bool onlyTopEmits) {
    SceneBuilder b("furnace");
    const int wall = b.addMaterial(glm::vec3(rho), onlyTopEmits ? glm::vec3(0.0f) : glm::vec3(emitted));
    const int lamp = b.addMaterial(glm::vec3(rho), glm::vec3(emitted));
    addFurnaceFaces(b, wall, lamp);
    return b.build();
}

// A closed unit cube, every face emitting L_e with reflectance rho, whose floor has a needle triangle across it
// (1 m long, `widthM` wide at its apex, in the floor's plane): a sliver as cutting and unwrapping leave them beside
// walls, which a shot's pixel or ray can hand all of itself (F_ji ≫ 1).
inline Scene needleFurnace(float rho, float emitted, double widthM) {
    SceneBuilder b("needle furnace");
    const int wall = b.addMaterial(glm::vec3(rho), glm::vec3(emitted));
    addFurnaceFaces(b, wall, wall, false);
    b.addTriangles({{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}, {0, 0, 0.5}, {1, 0, 0.5}, {0.5, 0, 0.5 + widthM}},
                   {{0, 4, 1}, {1, 4, 5}, {4, 6, 5}, {4, 3, 6}, {6, 3, 2}, {6, 2, 5}}, wall, "floor with a needle");
    return b.build();
}

// An open scene for power-ledger checks: a floor, a block standing on it and a square lamp above, open to the sky
// on every side (callers may add lights before building).
inline SceneBuilder openSceneWithLamp() {
    SceneBuilder b("open");
    const int grey = b.addMaterial(glm::vec3(0.6f, 0.4f, 0.2f));
    const int lamp = b.addMaterial(glm::vec3(0.3f), glm::vec3(5.0f, 4.0f, 3.0f));
    b.addQuad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, grey, "floor");
    b.addBox({-0.3, 0.0, -0.3}, {0.2, 0.6, 0.1}, grey, false, "block");
    b.addQuad({-0.2, 1.0, -0.2}, {0.2, 1.0, -0.2}, {0.2, 1.0, 0.2}, {-0.2, 1.0, 0.2}, lamp, "lamp");
    return b;
}

// Shooting alone, no ambient term: what the closed forms of GROUND_TRUTH §2 describe. Rows as `rows` samples them.
inline SolveSettings shootOnly(double patchSize, int resolution, RowSampling rows = RowSampling::Hemicube) {
    SolveSettings s;
    s.subdivision = {patchSize, patchSize / 2, patchSize};
    s.solver.kind = SolverKind::Shoot;
    s.solver.hemicubeResolution = resolution;
    s.solver.ambientCorrection = false;
    s.solver.rowSampling = rows;
    return s;
}

inline std::unique_ptr<SolvedTestScene> solveTestScene(Scene scene, const SolveSettings& settings) {
    auto s = std::make_unique<SolvedTestScene>();
    s->scene = std::move(scene);
    s->mesh = subdivide(s->scene, settings.subdivision);
    HemicubePool pool(s->mesh, settings.solver.hemicubeResolution);
    EmbreeScene rays(s->scene);
    s->report = solveRadiosity(s->scene, s->mesh, settings, pool, rays, s->solution);
    return s;
}

// Area-weighted mean of the displayed E/π (texel value) over the elements of one instance, or all if -1.
inline glm::dvec3 meanIrradianceOverPi(const SolvedTestScene& s, int instance = -1) {
    glm::dvec3 sum(0.0);
    double area = 0.0;
    for (std::size_t e = 0; e < s.mesh.elements.size(); ++e) {
        if (instance >= 0 && s.mesh.elements.instance[e] != std::uint32_t(instance)) continue;
        sum += s.solution.displayIrradiance(e) * s.mesh.elements.areaM2[e];
        area += s.mesh.elements.areaM2[e];
    }
    return sum / area / M_PI;
}

}  // namespace hemibake::test
