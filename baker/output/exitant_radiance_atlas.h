#pragma once
// What a viewer sees of a baked surface, per lightmap texel: ρ × texel + L_e (W·m⁻²·sr⁻¹, CONVENTIONS.md "What
// a lightmap texel stores"). The glTF writer's emissive mode stores it; the preview renderer draws it.
#include <vector>

#include "baker/lightmap/lightmap.h"
#include "mesh/scene.h"
#include "mesh/uv_atlas.h"

namespace hemibake {

// ρ and L_e come from the material of the instance whose unwrapped triangle covers the texel centre (ρ per texel
// through Scene::reflectance at the texel's TEXCOORD_0, so base colour textures show at lightmap resolution);
// texels no triangle centre-covers take them from the nearest covered texel (4-neighbour breadth-first), so
// chart-edge and dilated texels get their chart's material. Empty texels stay 0. `instances`: the instances
// (indices into scene.instances / atlas.instances) that are drawn with this atlas.
LightmapImage exitantRadianceAtlas(const Scene& scene, const UvAtlas& atlas, const LightmapImage& lightmap, int atlasIndex,
                                   const std::vector<int>& instances);

// Every instance with unwrapped triangles on some atlas.
std::vector<int> bakedInstances(const UvAtlas& atlas);

}  // namespace hemibake
