#include "mesh/scene.h"

#include <algorithm>
#include <cmath>

namespace hemibake {

namespace {
float wrapRepeat(float t) { return t - std::floor(t); }

glm::vec3 clampReflectance(glm::vec3 rho) { return glm::clamp(rho, glm::vec3(0.0f), glm::vec3(0.999f)); }
}  // namespace

glm::vec3 Texture::sample(glm::vec2 uv) const {
    if (width <= 0 || height <= 0) return glm::vec3(1.0f);
    // Texel centres sit at half-integers; bilinear with REPEAT, the glTF default sampler.
    const float x = wrapRepeat(uv.x) * float(width) - 0.5f;
    const float y = wrapRepeat(uv.y) * float(height) - 0.5f;
    const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
    const float fx = x - float(x0), fy = y - float(y0);
    auto at = [&](int xi, int yi) {
        xi = ((xi % width) + width) % width;
        yi = ((yi % height) + height) % height;
        const float* p = &linearRgb[(std::size_t(yi) * std::size_t(width) + std::size_t(xi)) * 3];
        return glm::vec3(p[0], p[1], p[2]);
    };
    return glm::mix(glm::mix(at(x0, y0), at(x0 + 1, y0), fx), glm::mix(at(x0, y0 + 1), at(x0 + 1, y0 + 1), fx), fy);
}

glm::vec3 Texture::average() const {
    glm::dvec3 sum(0.0);
    const std::size_t n = std::size_t(width) * std::size_t(height);
    for (std::size_t i = 0; i < n; ++i) sum += glm::dvec3(linearRgb[3 * i], linearRgb[3 * i + 1], linearRgb[3 * i + 2]);
    return n ? glm::vec3(sum / double(n)) : glm::vec3(1.0f);
}

Bounds Scene::bounds() const {
    Bounds b;
    for (const MeshInstance& inst : instances)
        for (auto v : inst.mesh.vertices()) {
            const auto& p = inst.mesh.point(v);
            b.extend(glm::dvec3(p[0], p[1], p[2]));
        }
    return b;
}

std::size_t Scene::triangleCount() const {
    std::size_t n = 0;
    for (const MeshInstance& inst : instances) n += inst.mesh.n_faces();
    return n;
}

double Scene::surfaceAreaM2() const {
    double area = 0.0;
    for (const MeshInstance& inst : instances)
        for (auto f : inst.mesh.faces()) area += inst.mesh.faceArea(f);
    return area;
}

glm::dvec3 Scene::emittedPowerWatts() const {
    glm::dvec3 power(0.0);
    for (const MeshInstance& inst : instances) {
        const Material& m = materials[std::size_t(inst.material)];
        if (!m.isEmissive()) continue;
        double area = 0.0;
        for (auto f : inst.mesh.faces()) area += inst.mesh.faceArea(f);
        power += M_PI * area * glm::dvec3(m.emittedRadiance);
    }
    return power;
}

glm::vec3 Scene::reflectance(int material, glm::vec2 uv) const {
    const Material& m = materials[std::size_t(material)];
    glm::vec3 rho = m.reflectanceFactor;
    if (m.reflectanceTexture >= 0) rho *= textures[std::size_t(m.reflectanceTexture)].sample(uv);
    return clampReflectance(rho);
}

glm::vec3 Scene::averageReflectance(int material, glm::vec2 uvA, glm::vec2 uvB, glm::vec2 uvC) const {
    const Material& m = materials[std::size_t(material)];
    if (m.reflectanceTexture < 0) return clampReflectance(m.reflectanceFactor);
    // A barycentric lattice of 10 points: textures vary inside a triangle; the triangle keeps their mean.
    glm::dvec3 sum(0.0);
    int n = 0;
    constexpr int kSteps = 4;
    for (int i = 0; i < kSteps; ++i)
        for (int j = 0; j < kSteps - i; ++j) {
            const float a = (float(i) + 1.0f / 3.0f) / kSteps, b = (float(j) + 1.0f / 3.0f) / kSteps;
            sum += glm::dvec3(reflectance(material, a * uvA + b * uvB + (1.0f - a - b) * uvC));
            ++n;
        }
    return glm::vec3(sum / double(n));
}

}  // namespace hemibake
