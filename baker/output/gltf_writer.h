#pragma once
// OUT/<scene>.glb (CONVENTIONS.md "Bake output layout" and "Lightmaps in glTF"): the input scene re-read with
// tinygltf, every baked primitive instance given its unwrapped vertex set with TEXCOORD_1, and the lightmaps
// attached as 8-bit PNG textures stored in buffer views.
//
// What changes in the file:
// - Geometry. Each baked primitive (one per MeshInstance) gets the unwrapped vertices of its UnwrappedInstance:
//   every input attribute (POSITION, NORMAL, TANGENT, TEXCOORD_n, COLOR_n, JOINTS_n, WEIGHTS_n, custom ones, and
//   morph target attributes) is gathered from the input accessors through the glTF vertex each unwrapped vertex
//   copies (SurfaceMesh::sourceVertex), so values stay in the node's local space, bit for bit, in their input
//   component types; TEXCOORD_1 (float) is the atlas UV (and TEXCOORD_0 too when the input has none, since
//   glTF wants texture coordinate sets numbered from 0). Triangles keep the input's order and winding (strips
//   and fans become plain triangle lists); triangles the loader dropped as degenerate are gone.
// - Instancing. A glTF mesh placed by several nodes needs one lightmap per node: the first node keeps the mesh,
//   every other node gets its own copy of it (appended to `meshes`).
// - Materials. A baked material is cloned per lightmap atlas when primitives on different atlases use it (or when
//   primitives that are not baked use it too); a primitive without a material gets hemibake's default one
//   (diffuse 0.8 grey, metallic 0, as it was baked).
//   Mode Lightmap: the material keeps its PBR data and gets `MOZ_lightmap { index, texCoord: 1, intensity: k }`;
//     the texture holds sRGB(texel / k), k = the atlas's 99.9th-percentile brightness (png_preview.h), and
//     MOZ_lightmap is listed in extensionsUsed only.
//   Mode Emissive: baseColorFactor.rgb = 0 (alpha kept), metallic 1, roughness 1, every other material extension
//     removed, emissiveFactor 1, emissiveTexture { texCoord: 1 } holding sRGB((ρ × texel + L_e) / k) and
//     KHR_materials_emissive_strength = k. ρ is evaluated per texel (base colour factor × base colour texture at
//     the texel's TEXCOORD_0, via Scene::reflectance), so there is one emissive texture per atlas.
// - Images. Every image, including the input's own (external files and data URIs), is stored in a buffer view;
//   everything lives in the GLB's single BIN buffer. Accessors and buffer views nothing refers to any more are
//   dropped (unless the file uses an extension the writer does not know, in which case all are kept).
// - Unnamed baked nodes are named "node<index>" so that bake.json can name them. asset.generator = "hemibake".
//
// The Scene and UvAtlas must come from loadGltf(inputPath) and unwrapScene of that scene. Lightmaps are indexed
// by atlas (UnwrappedInstance::atlas) and must have the atlas's size. The EXR files are not written here (see
// exr_io.h); the returned entries name them as `<lightmapDir>/<atlas>.exr`.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "baker/lightmap/lightmap.h"
#include "mesh/scene.h"
#include "mesh/uv_atlas.h"

namespace hemibake {

// One bake.json "primitives" entry (CONVENTIONS.md "Bake output layout").
struct BakedPrimitive {
    std::string node;       // glTF node name in the output glb
    int mesh = -1;          // mesh index in the output glb
    int primitive = -1;     // primitive index within that mesh
    std::string lightmap;   // EXR path relative to OUT
    int rect[4] = {0, 0, 0, 0};  // x, y, width, height in texels
};

struct GltfWriteOptions {
    enum class Mode { Lightmap, Emissive };
    Mode mode = Mode::Lightmap;
    std::string lightmapDir = "lightmaps";  // EXR folder relative to OUT (for the report entries)
};

// "lightmap" / "emissive" → mode; throws std::invalid_argument otherwise.
GltfWriteOptions::Mode parseGltfMode(const std::string& name);
const char* gltfModeName(GltfWriteOptions::Mode mode);

// "<lightmapDir>/<atlas>.exr", with forward slashes (as bake.json stores it).
std::string lightmapRelativePath(const GltfWriteOptions& options, int atlas);

// Writes `outGlb` atomically (creating its folder) and returns one bake.json entry per baked primitive (an
// instance with unwrapped triangles), in Scene::instances order; a node the loader reached twice (an invalid
// hierarchy) is written, and listed, once. Throws InputError when the input cannot be re-read or uses what the writer cannot carry
// (EXT_meshopt_compression, KHR_draco_mesh_compression), std::invalid_argument when scene/atlas/lightmaps do not
// match, std::runtime_error when writing fails; `outGlb` is then untouched.
std::vector<BakedPrimitive> writeLightmappedGlb(const std::string& inputPath, const Scene& scene, const UvAtlas& atlas,
                                                const std::vector<LightmapImage>& lightmaps,
                                                const std::filesystem::path& outGlb,
                                                const GltfWriteOptions& options = {});

}  // namespace hemibake
