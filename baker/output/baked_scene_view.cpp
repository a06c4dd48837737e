#include "baker/output/baked_scene_view.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "baker/output/exitant_radiance_atlas.h"
#include "raster/gl_context.h"
#include "raster/lightmapped_renderer.h"

namespace hemibake {

int imageHeightFor(const Camera& camera, int width) {
    return camera.aspectRatio > 0.0f ? std::max(1, int(std::lround(double(width) / double(camera.aspectRatio)))) : width;
}

RgbImage renderBakedScene(const Scene& scene, const UvAtlas& atlas, const std::vector<LightmapImage>& lightmaps,
                          const Camera& camera, int width, int height, glm::vec3 sky, int samplesPerAxis) {
    const std::vector<int> instances = bakedInstances(atlas);
    std::vector<std::vector<glm::vec3>> radiance(lightmaps.size());
    for (std::size_t a = 0; a < lightmaps.size(); ++a)
        radiance[a] = exitantRadianceAtlas(scene, atlas, lightmaps[a], int(a), instances).irradianceOverPi;

    // One batch per (atlas, sidedness): the shader needs to know whether a back face is black.
    std::map<std::pair<int, bool>, LightmappedBatch> batches;
    for (const int i : instances) {
        const UnwrappedInstance& ui = atlas.instances[std::size_t(i)];
        if (std::size_t(ui.atlas) >= lightmaps.size())
            throw std::invalid_argument("renderBakedScene: an instance is on atlas " + std::to_string(ui.atlas) +
                                        " but only " + std::to_string(lightmaps.size()) + " lightmaps were given");
        const MeshInstance& inst = scene.instances[std::size_t(i)];
        const bool doubleSided = inst.material >= 0 && std::size_t(inst.material) < scene.materials.size() &&
                                 scene.materials[std::size_t(inst.material)].doubleSided;
        LightmappedBatch& batch = batches[{ui.atlas, doubleSided}];
        batch.atlasSize = lightmaps[std::size_t(ui.atlas)].size;
        batch.radiance = &radiance[std::size_t(ui.atlas)];
        batch.doubleSided = doubleSided;
        for (const auto& tri : ui.triangles)
            for (const std::uint32_t k : tri) {
                const auto p = inst.mesh.point(SurfaceMesh::VertexHandle(ui.vertexSource[k]));
                batch.positions.emplace_back(p[0], p[1], p[2]);
                batch.uvs.push_back(ui.uv[k]);
            }
    }
    std::vector<LightmappedBatch> list;
    for (auto& [key, batch] : batches) list.push_back(std::move(batch));

    PinholeView view;
    view.position = camera.position;
    view.forward = glm::dvec3(camera.forward);
    view.up = glm::dvec3(camera.up);
    view.yfovRadians = double(camera.yfovRadians);
    // The glTF znear can be large; the path tracer has none, so only guard against the eye's own surface.
    const Bounds bounds = scene.bounds();
    // Relative to the scene (a 1 µm floor clipped a millimetre-sized scene's first 0.1 %); a point scene gets 1 µm.
    const double diagonalM = glm::length(bounds.max - bounds.min);
    view.nearM = diagonalM > 0.0 ? 1e-6 * diagonalM : 1e-6;
    view.width = width;
    view.height = height;

    const GlContext context;
    RgbImage image(width, height);
    image.pixels = renderLightmapped(context, list, view, sky, samplesPerAxis);
    return image;
}

}  // namespace hemibake
