#pragma once
// Writes small glTF files from test code, valid or deliberately broken, so loader tests need no binary fixtures.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace hemibake::test {

// A fresh directory under the system temp dir, removed when the object dies.
class TempDir {
public:
    TempDir();
    ~TempDir();
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const std::filesystem::path& path() const { return path_; }
    std::string file(const std::string& name) const { return (path_ / name).string(); }

private:
    std::filesystem::path path_;
};

// Builds one buffer plus JSON; `write` emits .gltf + .bin or a .glb.
class GltfFixture {
public:
    GltfFixture();
    nlohmann::json& json() { return json_; }
    std::vector<std::uint8_t>& buffer() { return bin_; }

    // Appends raw bytes as a buffer view; returns the view index.
    int addView(const void* data, std::size_t bytes, std::size_t stride = 0);
    // Accessor over a view; returns the accessor index.
    int addAccessor(int view, int componentType, const std::string& type, std::size_t count, bool withMinMax = false,
                    std::size_t byteOffset = 0);
    int addPositions(const std::vector<float>& xyz);  // VEC3 float, with min/max
    int addIndicesU8(const std::vector<std::uint8_t>& idx);
    int addIndicesU16(const std::vector<std::uint16_t>& idx);
    int addIndicesU32(const std::vector<std::uint32_t>& idx);
    int addMaterial(const nlohmann::json& material);
    // A mesh with one primitive; returns the mesh index.
    int addMesh(int positions, int indices, int material = -1, int mode = 4, const nlohmann::json& extraAttributes = {});
    int addNode(const nlohmann::json& node);  // also appended to scene 0's roots unless child
    int addChildNode(const nlohmann::json& node);

    std::string writeGltf(const TempDir& dir, const std::string& name, bool embedBuffer = false) const;
    std::string writeGlb(const TempDir& dir, const std::string& name) const;
    std::vector<std::uint8_t> glbBytes() const;

private:
    void align4();
    nlohmann::json json_;
    std::vector<std::uint8_t> bin_;
};

// A unit quad in the XZ plane facing +Y (two triangles), ready to load.
GltfFixture unitQuadFixture();

// The closed furnace: a unit cube [0,1]³, every face inward, ρ = kFurnaceReflectance and L_e = kFurnaceEmitted
// everywhere, a camera "inside" (yfov 1.2, aspect 1.5) at the centre. Radiance everywhere: L_e/(1−ρ).
inline constexpr float kFurnaceReflectance = 0.8f;
inline constexpr double kFurnaceEmitted[3] = {1.0, 0.5, 2.0};
GltfFixture furnaceFixture();

// Runs the hemibake binary; captures exit code, stdout and stderr.
struct CommandResult {
    int exitCode = -1;
    std::string out;
    std::string err;
};
CommandResult runHemibake(const std::vector<std::string>& args);

std::string sharedScene(const std::string& name);  // path under ../shared/scenes

}  // namespace hemibake::test
