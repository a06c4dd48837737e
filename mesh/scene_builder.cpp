#include "mesh/scene_builder.h"

#include <stdexcept>

namespace hemibake {

SceneBuilder::SceneBuilder(std::string name) { scene_.path = std::move(name); }

int SceneBuilder::addMaterial(const Material& material) {
    scene_.materials.push_back(material);
    return int(scene_.materials.size()) - 1;
}

int SceneBuilder::addMaterial(glm::vec3 reflectance, glm::vec3 emittedRadiance, bool doubleSided, const std::string& name) {
    Material m;
    m.name = name.empty() ? "material" + std::to_string(scene_.materials.size()) : name;
    m.reflectanceFactor = glm::clamp(reflectance, glm::vec3(0.0f), glm::vec3(0.999f));
    m.emittedRadiance = emittedRadiance;
    m.doubleSided = doubleSided;
    return addMaterial(m);
}

void SceneBuilder::addQuad(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2, const glm::dvec3& p3,
                           int material, const std::string& name) {
    addTriangles({p0, p1, p2, p3}, {{0, 1, 2}, {0, 2, 3}}, material, name);
}

void SceneBuilder::addTriangles(const std::vector<glm::dvec3>& positions, const std::vector<std::array<int, 3>>& triangles,
                                int material, const std::string& name) {
    if (material < 0 || std::size_t(material) >= scene_.materials.size())
        throw std::invalid_argument("SceneBuilder: material " + std::to_string(material) + " does not exist");
    MeshInstance inst;
    const int index = int(scene_.instances.size());
    inst.source = {index, index, 0, name};
    inst.material = material;
    std::vector<SurfaceMesh::VertexHandle> vh;
    for (const auto& p : positions) vh.push_back(inst.mesh.add_vertex({p.x, p.y, p.z}));
    int t = 0;
    for (const auto& tri : triangles) {
        auto f = inst.mesh.add_face(vh.at(std::size_t(tri[0])), vh.at(std::size_t(tri[1])), vh.at(std::size_t(tri[2])));
        if (!f.is_valid()) throw std::invalid_argument("SceneBuilder: non-manifold triangle in '" + name + "'");
        inst.mesh.material(f) = material;
        inst.mesh.instance(f) = index;
        inst.mesh.sourceFace(f) = t++;
    }
    inst.mesh.update_face_normals();
    inst.mesh.update_vertex_normals();
    scene_.instances.push_back(std::move(inst));
    ++scene_.report.primitives;
    ++scene_.report.meshNodes;
    ++scene_.report.nodes;
}

void SceneBuilder::addBox(const glm::dvec3& lo, const glm::dvec3& hi, int material, bool facesInward,
                          const std::string& name) {
    // Corners indexed by bits (x, y, z); each face listed counter-clockwise seen from outside.
    auto c = [&](int i) { return glm::dvec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z); };
    const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    const char* names[6] = {"-x", "+x", "-y", "+y", "-z", "+z"};
    for (int f = 0; f < 6; ++f) {
        const auto& q = faces[f];
        if (facesInward)
            addQuad(c(q[3]), c(q[2]), c(q[1]), c(q[0]), material, name + names[f]);
        else
            addQuad(c(q[0]), c(q[1]), c(q[2]), c(q[3]), material, name + names[f]);
    }
}

void SceneBuilder::addLight(const PunctualLight& light) { scene_.lights.push_back(light); }
void SceneBuilder::addCamera(const Camera& camera) { scene_.cameras.push_back(camera); }

Scene SceneBuilder::build() { return std::move(scene_); }

}  // namespace hemibake
