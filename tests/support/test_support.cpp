#include "support/gltf_fixture.h"

#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <sys/wait.h>

namespace hemibake::test {

namespace fs = std::filesystem;

TempDir::TempDir() {
    std::random_device rd;
    for (int attempt = 0; attempt < 100; ++attempt) {
        fs::path p = fs::temp_directory_path() / ("hemibake-test-" + std::to_string(rd()));
        if (fs::create_directory(p)) {
            path_ = p;
            return;
        }
    }
    throw std::runtime_error("cannot create a temporary directory");
}

TempDir::~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
}

GltfFixture::GltfFixture() {
    json_ = {{"asset", {{"version", "2.0"}, {"generator", "hemibake tests"}}},
             {"scene", 0},
             {"scenes", nlohmann::json::array({{{"nodes", nlohmann::json::array()}}})},
             {"nodes", nlohmann::json::array()},
             {"meshes", nlohmann::json::array()},
             {"accessors", nlohmann::json::array()},
             {"bufferViews", nlohmann::json::array()},
             {"buffers", nlohmann::json::array({{{"byteLength", 0}}})}};
}

void GltfFixture::align4() {
    while (bin_.size() % 4) bin_.push_back(0);
}

int GltfFixture::addView(const void* data, std::size_t bytes, std::size_t stride) {
    align4();
    nlohmann::json view = {{"buffer", 0}, {"byteOffset", bin_.size()}, {"byteLength", bytes}};
    if (stride) view["byteStride"] = stride;
    const auto* p = static_cast<const std::uint8_t*>(data);
    bin_.insert(bin_.end(), p, p + bytes);
    json_["bufferViews"].push_back(view);
    json_["buffers"][0]["byteLength"] = bin_.size();
    return int(json_["bufferViews"].size()) - 1;
}

int GltfFixture::addAccessor(int view, int componentType, const std::string& type, std::size_t count, bool withMinMax,
                             std::size_t byteOffset) {
    nlohmann::json a = {{"bufferView", view}, {"componentType", componentType}, {"type", type}, {"count", count}};
    if (byteOffset) a["byteOffset"] = byteOffset;
    (void)withMinMax;
    json_["accessors"].push_back(a);
    return int(json_["accessors"].size()) - 1;
}

int GltfFixture::addPositions(const std::vector<float>& xyz) {
    const int view = addView(xyz.data(), xyz.size() * sizeof(float));
    const int acc = addAccessor(view, 5126, "VEC3", xyz.size() / 3);
    std::array<float, 3> lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
    for (std::size_t i = 0; i < xyz.size(); ++i) {
        lo[i % 3] = std::min(lo[i % 3], xyz[i]);
        hi[i % 3] = std::max(hi[i % 3], xyz[i]);
    }
    json_["accessors"][std::size_t(acc)]["min"] = lo;
    json_["accessors"][std::size_t(acc)]["max"] = hi;
    return acc;
}

int GltfFixture::addIndicesU8(const std::vector<std::uint8_t>& idx) {
    return addAccessor(addView(idx.data(), idx.size()), 5121, "SCALAR", idx.size());
}
int GltfFixture::addIndicesU16(const std::vector<std::uint16_t>& idx) {
    return addAccessor(addView(idx.data(), idx.size() * 2), 5123, "SCALAR", idx.size());
}
int GltfFixture::addIndicesU32(const std::vector<std::uint32_t>& idx) {
    return addAccessor(addView(idx.data(), idx.size() * 4), 5125, "SCALAR", idx.size());
}

int GltfFixture::addMaterial(const nlohmann::json& material) {
    if (!json_.contains("materials")) json_["materials"] = nlohmann::json::array();
    json_["materials"].push_back(material);
    return int(json_["materials"].size()) - 1;
}

int GltfFixture::addMesh(int positions, int indices, int material, int mode, const nlohmann::json& extraAttributes) {
    nlohmann::json attributes = {{"POSITION", positions}};
    if (extraAttributes.is_object()) attributes.update(extraAttributes);
    nlohmann::json prim = {{"attributes", attributes}, {"mode", mode}};
    if (indices >= 0) prim["indices"] = indices;
    if (material >= 0) prim["material"] = material;
    json_["meshes"].push_back({{"primitives", nlohmann::json::array({prim})}});
    return int(json_["meshes"].size()) - 1;
}

int GltfFixture::addNode(const nlohmann::json& node) {
    const int index = addChildNode(node);
    json_["scenes"][0]["nodes"].push_back(index);
    return index;
}

int GltfFixture::addChildNode(const nlohmann::json& node) {
    json_["nodes"].push_back(node);
    return int(json_["nodes"].size()) - 1;
}

std::string GltfFixture::writeGltf(const TempDir& dir, const std::string& name, bool embedBuffer) const {
    nlohmann::json j = json_;
    const std::string binName = name + ".bin";
    if (!j.contains("buffers")) {
        // No buffer at all (e.g. an empty scene): nothing to write beside the JSON.
    } else if (embedBuffer) {
        static const char* b64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        std::string s;
        for (std::size_t i = 0; i < bin_.size(); i += 3) {
            const std::uint32_t n = (std::uint32_t(bin_[i]) << 16) | (i + 1 < bin_.size() ? bin_[i + 1] << 8 : 0) |
                                    (i + 2 < bin_.size() ? bin_[i + 2] : 0);
            s += b64[(n >> 18) & 63];
            s += b64[(n >> 12) & 63];
            s += i + 1 < bin_.size() ? b64[(n >> 6) & 63] : '=';
            s += i + 2 < bin_.size() ? b64[n & 63] : '=';
        }
        j["buffers"][0]["uri"] = "data:application/octet-stream;base64," + s;
    } else {
        j["buffers"][0]["uri"] = binName;
        std::ofstream(dir.file(binName), std::ios::binary)
            .write(reinterpret_cast<const char*>(bin_.data()), std::streamsize(bin_.size()));
    }
    const std::string path = dir.file(name + ".gltf");
    std::ofstream(path) << j.dump(1);
    return path;
}

std::vector<std::uint8_t> GltfFixture::glbBytes() const {
    std::string text = json_.dump();
    while (text.size() % 4) text += ' ';
    std::vector<std::uint8_t> bin = bin_;
    while (bin.size() % 4) bin.push_back(0);
    std::vector<std::uint8_t> out;
    auto u32 = [&](std::uint32_t v) {
        for (int i = 0; i < 4; ++i) out.push_back(std::uint8_t(v >> (8 * i)));
    };
    out.insert(out.end(), {'g', 'l', 'T', 'F'});
    u32(2);
    u32(std::uint32_t(12 + 8 + text.size() + 8 + bin.size()));
    u32(std::uint32_t(text.size()));
    u32(0x4E4F534Au);  // JSON
    out.insert(out.end(), text.begin(), text.end());
    u32(std::uint32_t(bin.size()));
    u32(0x004E4942u);  // BIN
    out.insert(out.end(), bin.begin(), bin.end());
    return out;
}

std::string GltfFixture::writeGlb(const TempDir& dir, const std::string& name) const {
    const std::vector<std::uint8_t> bytes = glbBytes();
    const std::string path = dir.file(name + ".glb");
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    return path;
}

GltfFixture unitQuadFixture() {
    GltfFixture g;
    const int pos = g.addPositions({0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0});
    const int idx = g.addIndicesU16({0, 1, 2, 0, 2, 3});
    const int mesh = g.addMesh(pos, idx);
    g.addNode({{"name", "quad"}, {"mesh", mesh}});
    return g;
}

CommandResult runHemibake(const std::vector<std::string>& args) {
    TempDir dir;
    std::string cmd = std::string("'") + HEMIBAKE_BINARY + "'";
    for (const std::string& a : args) cmd += " '" + a + "'";
    cmd += " >'" + dir.file("out") + "' 2>'" + dir.file("err") + "' </dev/null";
    const int status = std::system(cmd.c_str());
    CommandResult r;
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    std::ostringstream out, err;
    out << std::ifstream(dir.file("out")).rdbuf();
    err << std::ifstream(dir.file("err")).rdbuf();
    r.out = out.str();
    r.err = err.str();
    return r;
}

std::string sharedScene(const std::string& name) { return std::string(HEMIBAKE_SHARED_DIR) + "/scenes/" + name; }

// A closed unit cube, every face inward, ρ = 0.8 and L_e = (1, 0.5, 2) everywhere; camera "inside" at the centre.
GltfFixture furnaceFixture() {
    GltfFixture g;
    const int material = g.addMaterial({{"pbrMetallicRoughness", {{"baseColorFactor", {kFurnaceReflectance, kFurnaceReflectance, kFurnaceReflectance, 1.0}},
                                                                  {"metallicFactor", 0.0}}},
                                        {"emissiveFactor", {1.0, 1.0, 1.0}},
                                        {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 1.0}}}}}});
    // Emission (1, 0.5, 2) needs a factor above 1 in one channel: strength 2 on factor (0.5, 0.25, 1).
    g.json()["materials"][0]["emissiveFactor"] = {0.5, 0.25, 1.0};
    g.json()["materials"][0]["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] = 2.0;
    g.json()["extensionsUsed"] = {"KHR_materials_emissive_strength"};
    std::vector<float> positions;
    for (int k = 0; k < 8; ++k) positions.insert(positions.end(), {float(k & 1), float((k >> 1) & 1), float((k >> 2) & 1)});
    // Faces as corner quads (bit 0 = x, bit 1 = y, bit 2 = z), each wound so that its normal points inwards.
    const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    std::vector<std::uint16_t> indices;
    for (const auto& q : quads) {
        auto p = [&](int c) { return std::array<float, 3>{positions[3 * q[c]], positions[3 * q[c] + 1], positions[3 * q[c] + 2]}; };
        const auto a = p(0), b = p(1), c = p(2);
        const float u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        const float n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        const bool inward = n[0] * (0.5f - a[0]) + n[1] * (0.5f - a[1]) + n[2] * (0.5f - a[2]) > 0.0f;
        const int order[6] = {0, 1, 2, 0, 2, 3}, reversed[6] = {0, 2, 1, 0, 3, 2};
        for (int k : inward ? order : reversed) indices.push_back(std::uint16_t(q[k]));
    }
    const int mesh = g.addMesh(g.addPositions(positions), g.addIndicesU16(indices), material);
    g.addNode({{"name", "furnace"}, {"mesh", mesh}});
    g.json()["cameras"] = {{{"name", "inside"}, {"type", "perspective"},
                            {"perspective", {{"yfov", 1.2}, {"znear", 0.01}, {"aspectRatio", 1.5}}}}};
    g.addNode({{"name", "inside"}, {"camera", 0}, {"translation", {0.5, 0.5, 0.5}}});
    return g;
}


}  // namespace hemibake::test
