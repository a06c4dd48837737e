#include "baker/output/exitant_radiance_atlas.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace hemibake {

LightmapImage exitantRadianceAtlas(const Scene& scene, const UvAtlas& atlas, const LightmapImage& lm, int atlasIndex,
                                   const std::vector<int>& instances) {
    const int size = lm.size;
    const std::size_t texels = std::size_t(size) * std::size_t(size);
    std::vector<glm::vec3> rho(texels, glm::vec3(0.0f));
    std::vector<std::int32_t> owner(texels, -1);    // instance whose material emits there
    std::vector<std::uint8_t> assigned(texels, 0);  // 1 raster, 2 spread
    std::vector<std::uint32_t> queue;               // breadth-first order; every texel enters at most once
    queue.reserve(texels);
    for (const int instance : instances) {
        const UnwrappedInstance& ui = atlas.instances[std::size_t(instance)];
        if (ui.atlas != atlasIndex) continue;
        const MeshInstance& inst = scene.instances[std::size_t(instance)];
        const int material = inst.material;
        const bool validMaterial = material >= 0 && std::size_t(material) < scene.materials.size();
        for (const auto& tri : ui.triangles) {
            glm::dvec2 p[3];
            glm::vec2 t0[3];
            for (int k = 0; k < 3; ++k) {
                p[k] = glm::dvec2(ui.uv[tri[std::size_t(k)]]) * double(size);
                const auto tc = inst.mesh.texcoord2D(SurfaceMesh::VertexHandle(ui.vertexSource[tri[std::size_t(k)]]));
                t0[k] = glm::vec2(tc[0], tc[1]);
            }
            const double area = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x);
            if (!(std::abs(area) > 1e-12)) continue;
            const int x0 = std::max(0, int(std::floor(std::min({p[0].x, p[1].x, p[2].x}) - 0.5)));
            const int x1 = std::min(size - 1, int(std::ceil(std::max({p[0].x, p[1].x, p[2].x}) - 0.5)));
            const int y0 = std::max(0, int(std::floor(std::min({p[0].y, p[1].y, p[2].y}) - 0.5)));
            const int y1 = std::min(size - 1, int(std::ceil(std::max({p[0].y, p[1].y, p[2].y}) - 0.5)));
            for (int y = y0; y <= y1; ++y)
                for (int x = x0; x <= x1; ++x) {
                    const glm::dvec2 c(x + 0.5, y + 0.5);
                    auto edge = [&](const glm::dvec2& a, const glm::dvec2& e) {
                        return ((e.x - a.x) * (c.y - a.y) - (e.y - a.y) * (c.x - a.x)) / area;
                    };
                    const double w0 = edge(p[1], p[2]), w1 = edge(p[2], p[0]), w2 = 1.0 - w0 - w1;
                    const double eps = -1e-9;
                    if (w0 < eps || w1 < eps || w2 < eps) continue;
                    const std::size_t at = std::size_t(y) * std::size_t(size) + std::size_t(x);
                    const glm::vec2 uv0 = float(w0) * t0[0] + float(w1) * t0[1] + float(w2) * t0[2];
                    rho[at] = validMaterial ? scene.reflectance(material, uv0) : glm::vec3(0.8f);
                    owner[at] = instance;
                    if (!assigned[at]) queue.push_back(std::uint32_t(at));
                    assigned[at] = 1;
                }
        }
    }
    for (std::size_t head = 0; head < queue.size(); ++head) {
        const std::size_t at = queue[head];
        const int x = int(at % std::size_t(size)), y = int(at / std::size_t(size));
        const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
        for (int n = 0; n < 4; ++n) {
            if (nx[n] < 0 || ny[n] < 0 || nx[n] >= size || ny[n] >= size) continue;
            const std::size_t to = std::size_t(ny[n]) * std::size_t(size) + std::size_t(nx[n]);
            if (assigned[to]) continue;
            assigned[to] = 2;
            rho[to] = rho[at];
            owner[to] = owner[at];
            queue.push_back(std::uint32_t(to));
        }
    }
    LightmapImage out;
    out.resize(size);
    const bool haveState = lm.state.size() == texels;
    for (std::size_t t = 0; t < texels; ++t) {
        const bool covered = assigned[t] == 1 || !haveState || lm.state[t] != TexelState::Empty;
        if (!covered) continue;
        glm::vec3 emitted(0.0f);
        if (owner[t] >= 0) {
            const int material = scene.instances[std::size_t(owner[t])].material;
            if (material >= 0 && std::size_t(material) < scene.materials.size())
                emitted = scene.materials[std::size_t(material)].emittedRadiance;
        }
        out.irradianceOverPi[t] = rho[t] * lm.irradianceOverPi[t] + emitted;
        out.state[t] = TexelState::Covered;
    }
    return out;
}


std::vector<int> bakedInstances(const UvAtlas& atlas) {
    std::vector<int> instances;
    for (std::size_t i = 0; i < atlas.instances.size(); ++i)
        if (atlas.instances[i].atlas >= 0 && !atlas.instances[i].triangles.empty()) instances.push_back(int(i));
    return instances;
}

}  // namespace hemibake
