#pragma once
// Builds scenes in code: test fixtures, the example generator, and analytic set-ups (boxes, opposed squares).
#include <string>
#include <vector>

#include "mesh/scene.h"

namespace hemibake {

class SceneBuilder {
public:
    explicit SceneBuilder(std::string name = "generated");

    int addMaterial(const Material& material);
    int addMaterial(glm::vec3 reflectance, glm::vec3 emittedRadiance = glm::vec3(0.0f), bool doubleSided = false,
                    const std::string& name = "");
    // A planar quad p0 p1 p2 p3 (counter-clockwise seen from its front) as two triangles.
    void addQuad(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2, const glm::dvec3& p3,
                 int material, const std::string& name = "quad");
    void addTriangles(const std::vector<glm::dvec3>& positions, const std::vector<std::array<int, 3>>& triangles,
                      int material, const std::string& name = "mesh");
    // An axis-aligned box with faces pointing inwards (a closed room) or outwards (a solid block).
    void addBox(const glm::dvec3& min, const glm::dvec3& max, int material, bool facesInward,
                const std::string& name = "box");
    void addLight(const PunctualLight& light);
    void addCamera(const Camera& camera);

    Scene build();

private:
    Scene scene_;
};

}  // namespace hemibake
