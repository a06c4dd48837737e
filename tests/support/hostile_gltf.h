#pragma once
// glTF files that pass tinygltf's parser but stress what comes after it (issue 17): hierarchies deep enough to
// overflow a recursive walk, singular node transforms, sparse accessors, embedded data that does not decode.
// Shared by the loader tests (mesh_gltf_loader_test) and the end-to-end ones (cli_bake_test).
#include <cstdint>
#include <string>
#include <vector>

#include "support/gltf_fixture.h"

namespace hemibake::test {

// The unit quad (XZ plane, facing +Y) on the last of `depth` nested nodes, each moving its subtree 1 mm along +X:
// the quad lands at x = depth mm. Nodes are listed deepest first, so children come before parents in the file.
inline GltfFixture deepHierarchyFixture(int depth) {
    GltfFixture g = unitQuadFixture();
    nlohmann::json nodes = nlohmann::json::array();
    for (int i = 0; i < depth; ++i) {
        nlohmann::json node = {{"translation", {0.001, 0.0, 0.0}}};
        if (i == 0) {
            node["mesh"] = 0;
            node["name"] = "leaf";
        } else {
            node["children"] = {i - 1};
        }
        nodes.push_back(node);
    }
    g.json()["nodes"] = nodes;
    g.json()["scenes"][0]["nodes"] = {depth - 1};
    return g;
}

// Node 0 'flat' places the unit quad through an all-zero matrix; node 1 'floor' places it normally, unless
// `withGoodNode` is false.
inline GltfFixture singularNodeFixture(bool withGoodNode) {
    GltfFixture g = unitQuadFixture();
    g.json()["nodes"][0]["name"] = "flat";
    g.json()["nodes"][0]["matrix"] = std::vector<double>(16, 0.0);
    if (withGoodNode) g.addNode({{"name", "floor"}, {"mesh", 0}, {"translation", {0.0, 0.0, 2.0}}});
    return g;
}

// The unit quad whose POSITION accessor is sparse: the base view holds a wrong third corner (5, 5, 5) and no
// fourth (zeros), the sparse part substitutes corners 2 and 3 with (1, 0, 1) and (1, 0, 0). Loaded correctly, it
// is the unit quad. `sparseIndex3` replaces the index of the second substitution (to make it out of range).
inline GltfFixture sparseQuadFixture(std::uint16_t sparseIndex3 = 3) {
    GltfFixture g;
    const int pos = g.addPositions({0, 0, 0, 0, 0, 1, 5, 5, 5, 0, 0, 0});
    const std::vector<std::uint16_t> which = {2, sparseIndex3};
    const std::vector<float> values = {1, 0, 1, 1, 0, 0};
    const int whichView = g.addView(which.data(), which.size() * sizeof(std::uint16_t));
    const int valuesView = g.addView(values.data(), values.size() * sizeof(float));
    g.json()["accessors"][std::size_t(pos)]["sparse"] = {{"count", 2},
                                                         {"indices", {{"bufferView", whichView}, {"componentType", 5123}}},
                                                         {"values", {{"bufferView", valuesView}}}};
    g.json()["accessors"][std::size_t(pos)]["min"] = {0, 0, 0};
    g.json()["accessors"][std::size_t(pos)]["max"] = {1, 0, 1};
    g.addNode({{"name", "sparse"}, {"mesh", g.addMesh(pos, g.addIndicesU16({0, 1, 2, 0, 2, 3}))}});
    return g;
}

// The unit quad with a baseColor texture whose embedded PNG (a data URI) has a valid signature and garbage after.
inline GltfFixture corruptTextureFixture() {
    GltfFixture g;
    const int pos = g.addPositions({0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0});
    const std::vector<float> uv = {0, 0, 0, 1, 1, 1, 1, 0};
    const int uvAccessor = g.addAccessor(g.addView(uv.data(), uv.size() * sizeof(float)), 5126, "VEC2", 4);
    const int material = g.addMaterial({{"name", "painted"},
                                        {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicFactor", 0.0}}}});
    g.json()["textures"] = {{{"source", 0}}};
    // "\x89PNG\r\n\x1a\n" followed by "garbage" × 4, which is no PNG chunk.
    g.json()["images"] = {{{"uri", "data:image/png;base64,iVBORw0KGgpnYXJiYWdlZ2FyYmFnZWdhcmJhZ2VnYXJiYWdl"}}};
    g.addNode({{"name", "painted"}, {"mesh", g.addMesh(pos, g.addIndicesU16({0, 1, 2, 0, 2, 3}), material, 4,
                                                       {{"TEXCOORD_0", uvAccessor}})}});
    return g;
}

}  // namespace hemibake::test
