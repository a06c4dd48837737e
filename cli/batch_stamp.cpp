#include "cli/batch_stamp.h"

#include <array>
#include <cstdio>
#include <cctype>
#include <cstring>
#include <fstream>

#include "baker/util/atomic_output.h"

namespace hemibake::cli {

namespace {

namespace fs = std::filesystem;

// Two independent 64-bit FNV-1a streams (different offset bases) give a 128-bit digest: plenty to tell edited
// inputs apart, with no dependency beyond the standard library. Not a defence against deliberate collisions.
class Digest {
public:
    void add(const void* data, std::size_t n) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < n; ++i) {
            a_ = (a_ ^ p[i]) * kPrime;
            b_ = (b_ ^ p[i]) * kPrime;
        }
    }
    void add(const std::string& s) {
        const std::uint64_t n = s.size();
        add(&n, sizeof n);
        add(s.data(), s.size());
    }
    std::string hex() const {
        char buf[40];
        std::snprintf(buf, sizeof buf, "%016llx%016llx", static_cast<unsigned long long>(a_), static_cast<unsigned long long>(b_));
        return buf;
    }

private:
    static constexpr std::uint64_t kPrime = 0x100000001b3ULL;
    std::uint64_t a_ = 0xcbf29ce484222325ULL;
    std::uint64_t b_ = 0x84222325cbf29ce4ULL;
};

std::string readAll(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

// The JSON part of a .gltf, or the JSON chunk of a .glb; empty when it is neither.
std::string gltfJsonText(const std::string& bytes) {
    if (bytes.size() >= 20 && std::memcmp(bytes.data(), "glTF", 4) == 0) {
        std::uint32_t chunkLength = 0, chunkType = 0;
        std::memcpy(&chunkLength, bytes.data() + 12, 4);
        std::memcpy(&chunkType, bytes.data() + 16, 4);
        if (chunkType != 0x4E4F534Au || chunkLength > bytes.size() - 20) return {};
        return bytes.substr(20, chunkLength);
    }
    return bytes;
}

std::string percentDecoded(const std::string& uri) {
    std::string out;
    for (std::size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[i + 1])) && std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
            out += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

}  // namespace

std::vector<fs::path> sceneInputFiles(const fs::path& scene) {
    std::vector<fs::path> files{scene};
    const nlohmann::json j = nlohmann::json::parse(gltfJsonText(readAll(scene)), nullptr, false);
    if (!j.is_object()) return files;
    for (const char* list : {"buffers", "images"}) {
        if (!j.contains(list) || !j[list].is_array()) continue;
        for (const auto& item : j[list]) {
            if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
            const std::string uri = item["uri"].get<std::string>();
            if (uri.rfind("data:", 0) == 0) continue;
            files.push_back((scene.parent_path() / percentDecoded(uri)).lexically_normal());
        }
    }
    return files;
}

std::string inputHash(const fs::path& scene) {
    Digest d;
    for (const fs::path& f : sceneInputFiles(scene)) {
        d.add(f.lexically_relative(scene.parent_path()).generic_string());
        std::error_code ec;
        if (!fs::is_regular_file(f, ec)) {
            d.add(std::string("<missing>"));
            continue;
        }
        const std::string bytes = readAll(f);
        d.add(bytes);
    }
    return d.hex();
}

std::string settingsHash(const nlohmann::json& settings, const std::string& version) {
    Digest d;
    d.add(settings.dump());  // nlohmann::json objects keep keys sorted, so this is canonical
    d.add(version);
    return d.hex();
}

std::uintmax_t inputBytes(const fs::path& scene) {
    std::uintmax_t total = 0;
    for (const fs::path& f : sceneInputFiles(scene)) {
        std::error_code ec;
        const std::uintmax_t n = fs::file_size(f, ec);
        if (!ec) total += n;
    }
    return total;
}

bool bakeIsUpToDate(const fs::path& out, const fs::path& scene, const BatchStamp& expected) {
    std::error_code ec;
    const nlohmann::json stamp = nlohmann::json::parse(readAll(out / kBatchStampFile), nullptr, false);
    if (!stamp.is_object() || stamp.value("inputHash", "") != expected.inputHash ||
        stamp.value("settingsHash", "") != expected.settingsHash)
        return false;
    const nlohmann::json report = nlohmann::json::parse(readAll(out / "bake.json"), nullptr, false);
    if (!report.is_object()) return false;
    if (!fs::is_regular_file(out / (scene.stem().string() + ".glb"), ec)) return false;
    if (report.contains("lightmap") && report["lightmap"].contains("files"))
        for (const auto& f : report["lightmap"]["files"])
            if (!f.is_string() || !fs::is_regular_file(out / f.get<std::string>(), ec)) return false;
    return true;
}

void writeBatchStamp(const fs::path& out, const fs::path& scene, const nlohmann::json& settings, const BatchStamp& stamp) {
    const nlohmann::json j = {{"format", "hemibake-batch-stamp/1"},
                              {"scene", fs::absolute(scene).lexically_normal().string()},
                              {"settings", settings},
                              {"inputHash", stamp.inputHash},
                              {"settingsHash", stamp.settingsHash}};
    writeTextAtomically(out / kBatchStampFile, j.dump(2) + "\n");
}

}  // namespace hemibake::cli
