// libFuzzer target for what comes after the loader: small random meshes, loaded as a user's file would be (so every
// scene satisfies the loader's guarantees: finite, no zero-area triangles, non-manifold faces as separate sheets),
// then subdivided into patches and elements (mesh/subdivision) and unwrapped into lightmap atlases (charts,
// parameterize, pack, uv_atlas) with texels placed on them (mesh/texels). Any crash, ASan/UBSan report, hang
// (-timeout) or broken promise of those headers (checked below, __builtin_trap) is a finding; an InputError (the
// loader's, or an instance whose charts cannot share one atlas) is the expected way to refuse.
//
// Input layout (FuzzedDataProvider): a few choices (scale, offset, sizes, settings), then per instance a vertex
// count and coordinates on a small integer grid (so corners coincide, edges are shared and slivers occur), then
// triangles as vertex indices, optionally TEXCOORD_1 for --uv keep.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

#include <fuzzer/FuzzedDataProvider.h>
#include <nlohmann/json.hpp>

#include "fuzz_scratch_dir.h"
#include "mesh/errors.h"
#include "mesh/gltf_loader.h"
#include "mesh/subdivision.h"
#include "mesh/texels.h"
#include "mesh/uv_atlas.h"

namespace {

void check(bool promise) {
    if (!promise) __builtin_trap();
}

// One .gltf + .bin pair per process, rewritten for every input.
class SceneFile {
public:
    std::string write(nlohmann::json gltf, const std::vector<std::uint8_t>& bin) {
        gltf["buffers"][0]["uri"] = "mesh.bin";
        std::ofstream(dir_.path() / "mesh.bin", std::ios::binary | std::ios::trunc)
            .write(reinterpret_cast<const char*>(bin.data()), std::streamsize(bin.size()));
        const std::filesystem::path path = dir_.path() / "mesh.gltf";
        std::ofstream(path, std::ios::trunc) << gltf.dump();
        return path.string();
    }

private:
    hemibake::fuzz::ScratchDir dir_{"hemibake-fuzz-unwrap"};
};

// Appends `bytes` to the buffer as a view; returns its index.
int addView(nlohmann::json& gltf, std::vector<std::uint8_t>& bin, const void* data, std::size_t bytes) {
    while (bin.size() % 4) bin.push_back(0);
    gltf["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes}});
    const auto* p = static_cast<const std::uint8_t*>(data);
    bin.insert(bin.end(), p, p + bytes);
    return int(gltf["bufferViews"].size()) - 1;
}

int addAccessor(nlohmann::json& gltf, int view, int componentType, const char* type, std::size_t count) {
    gltf["accessors"].push_back({{"bufferView", view}, {"componentType", componentType}, {"type", type}, {"count", count}});
    return int(gltf["accessors"].size()) - 1;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static SceneFile file;
    FuzzedDataProvider in(data, size);
    // Metres per grid step: millimetre parts to a 100 km level; optionally far from the origin.
    const double scale = in.PickValueInArray({1e-3, 0.05, 0.37, 1.0, 25.0, 1e3});
    const double offset = in.PickValueInArray({0.0, 0.0, 1e5, -3.3e4});
    const int instances = in.ConsumeIntegralInRange(1, 3);
    const bool withUv1 = in.ConsumeBool();

    nlohmann::json gltf = {{"asset", {{"version", "2.0"}}},
                           {"scene", 0},
                           {"scenes", {{{"nodes", nlohmann::json::array()}}}},
                           {"nodes", nlohmann::json::array()},
                           {"meshes", nlohmann::json::array()},
                           {"materials", {{{"doubleSided", false}}, {{"doubleSided", true}, {"emissiveFactor", {1.0, 1.0, 1.0}}}}},
                           {"accessors", nlohmann::json::array()},
                           {"bufferViews", nlohmann::json::array()},
                           {"buffers", {{{"byteLength", 0}}}}};
    std::vector<std::uint8_t> bin;
    for (int m = 0; m < instances; ++m) {
        const int vertices = in.ConsumeIntegralInRange(3, 24);
        std::vector<float> pos, uv;
        for (int v = 0; v < vertices; ++v) {
            for (int c = 0; c < 3; ++c) pos.push_back(float(offset + scale * double(in.ConsumeIntegralInRange(-8, 8))));
            uv.push_back(float(in.ConsumeIntegralInRange(0, 16)) / 16.0f);
            uv.push_back(float(in.ConsumeIntegralInRange(0, 16)) / 16.0f);
        }
        const int triangles = in.ConsumeIntegralInRange(1, 32);
        std::vector<std::uint16_t> idx;
        for (int t = 0; t < 3 * triangles; ++t) idx.push_back(std::uint16_t(in.ConsumeIntegralInRange(0, vertices - 1)));
        nlohmann::json attributes = {
            {"POSITION", addAccessor(gltf, addView(gltf, bin, pos.data(), pos.size() * 4), 5126, "VEC3", std::size_t(vertices))}};
        if (withUv1)
            attributes["TEXCOORD_1"] = addAccessor(gltf, addView(gltf, bin, uv.data(), uv.size() * 4), 5126, "VEC2", std::size_t(vertices));
        const int indices = addAccessor(gltf, addView(gltf, bin, idx.data(), idx.size() * 2), 5123, "SCALAR", idx.size());
        const nlohmann::json primitive = {{"attributes", attributes}, {"indices", indices}, {"material", in.ConsumeIntegralInRange(0, 1)}};
        gltf["meshes"].push_back({{"primitives", nlohmann::json::array({primitive})}});
        gltf["nodes"].push_back({{"mesh", m}});
        gltf["scenes"][0]["nodes"].push_back(m);
    }
    gltf["buffers"][0]["byteLength"] = bin.size();

    hemibake::Scene scene;
    try {
        scene = hemibake::loadGltf(file.write(gltf, bin));
    } catch (const hemibake::InputError&) {
        return 0;  // e.g. every triangle degenerate: nothing to bake
    }
    const double diagonal = scene.bounds().diagonal();
    check(std::isfinite(diagonal) && diagonal > 0.0);

    // Subdivision: patch size a fraction of the scene, elements finer still (at most a few thousand elements).
    hemibake::SubdivisionSettings sub;
    sub.patchSizeM = diagonal / double(in.ConsumeIntegralInRange(1, 6));
    sub.elementSizeM = sub.patchSizeM / double(in.ConsumeIntegralInRange(1, 3));
    const hemibake::PatchMesh pm = hemibake::subdivide(scene, sub);
    check(pm.elements.size() >= scene.triangleCount());
    double elementArea = 0.0;
    for (std::size_t e = 0; e < pm.elements.size(); ++e) {
        check(pm.elements.patch[e] < pm.patches.size());
        check(std::isfinite(pm.elements.areaM2[e]) && pm.elements.areaM2[e] >= 0.0);
        // Unit normals, elements without area included: rays leave every element along its normal.
        check(std::abs(glm::length(glm::dvec3(pm.elements.normal[e])) - 1.0) < 1e-5);
        if (!pm.elements.backSide[e]) elementArea += pm.elements.areaM2[e];
        for (std::uint32_t k : pm.elements.triangles[e]) check(k < pm.elements.vertices.size());
    }
    const double area = scene.surfaceAreaM2();
    // Pieces inside a closed solid are dropped (mesh/solid_cuts.h) and counted: what is baked plus what was dropped
    // is the input's surface. Bisection and cuts keep the surface to rounding; mending T-junctions
    // (mesh/subdivision.cpp, conformBoundaries) splits a boundary edge at a vertex up to its tolerance (1e-7 of the
    // diagonal) off the edge, which moves each face by at most half its edge times that: nothing on a room, a few %
    // of a scene made only of slivers that thin.
    double perimeterM = 0.0;
    for (const hemibake::MeshInstance& instance : scene.instances)
        for (auto h : instance.mesh.halfedges())
            if (!instance.mesh.is_boundary(h)) perimeterM += instance.mesh.calc_edge_length(h);
    const double conformSlackM2 = 0.5 * 1e-7 * diagonal * perimeterM;  // front elements only, as elementArea
    const double droppedM2 = pm.solidCuts.areaDroppedM2;
    check(std::isfinite(droppedM2) && droppedM2 >= 0.0 && droppedM2 <= area * (1.0 + 1e-6));
    check(std::abs(elementArea + droppedM2 - area) <= 1e-6 * area + conformSlackM2);
    for (std::size_t p = 0; p < pm.patches.size(); ++p) {
        const std::uint32_t first = pm.patches.firstElement[p], count = pm.patches.elementCount[p];
        check(count > 0 && std::size_t(first) + count <= pm.elements.size());
        for (std::uint32_t e = first; e < first + count; ++e) check(pm.elements.patch[e] == p);
    }

    // Unwrapping at a density that keeps atlases small, with the settings users can change.
    hemibake::UnwrapSettings uw;
    uw.texelsPerUnit = double(in.ConsumeIntegralInRange(2, 64)) / diagonal;
    uw.maxAtlasSize = in.PickValueInArray({16, 32, 64, 256});
    uw.paddingTexels = in.ConsumeIntegralInRange(0, 4);
    uw.allowRotation = in.ConsumeBool();
    uw.powerOfTwo = in.ConsumeBool();
    uw.keepExistingUv = withUv1 && in.ConsumeBool();
    hemibake::UvAtlas atlas;
    try {
        atlas = hemibake::unwrapScene(scene, uw);
    } catch (const hemibake::InputError&) {
        return 0;  // more charts than one atlas of this size holds with this padding: a message, not a crash
    }
    check(atlas.instances.size() == scene.instances.size());
    for (const hemibake::AtlasPage& page : atlas.atlases) check(page.size > 0 && page.size <= uw.maxAtlasSize);
    for (const hemibake::UnwrappedInstance& ui : atlas.instances) {
        check(ui.atlas >= -1 && ui.atlas < std::int32_t(atlas.atlases.size()));
        check(ui.vertexSource.size() == ui.uv.size() && ui.faceSource.size() == ui.triangles.size());
        for (const glm::vec2& t : ui.uv) check(t.x >= 0.0f && t.x <= 1.0f && t.y >= 0.0f && t.y <= 1.0f);
        for (const auto& tri : ui.triangles)
            for (std::uint32_t k : tri) check(k < ui.uv.size());
    }
    const std::vector<hemibake::AtlasTexels> texels = hemibake::computeTexels(scene, atlas);
    check(texels.size() == atlas.atlases.size());
    for (const hemibake::AtlasTexels& t : texels)
        for (std::size_t i = 0; i < t.count(); ++i) {
            check(t.x[i] < t.size && t.y[i] < t.size);
            check(std::isfinite(t.position[i].x + t.position[i].y + t.position[i].z));
            check(t.instance[i] >= 0 && std::size_t(t.instance[i]) < scene.instances.size());
        }
    return 0;
}
