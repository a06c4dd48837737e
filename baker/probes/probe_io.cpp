#include "baker/probes/probe_io.h"

#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "baker/util/atomic_output.h"
#include "mesh/errors.h"

namespace hemibake {

static_assert(std::endian::native == std::endian::little, "volume files are written as native little-endian");

namespace {

namespace fs = std::filesystem;

const char* kShOrder[kShCoefficients] = {"l00", "l1-1", "l10", "l11", "l2-2", "l2-1", "l20", "l21", "l22"};

nlohmann::json vec3(const glm::dvec3& v) { return {v.x, v.y, v.z}; }

nlohmann::json shJson(const ShRgb& sh) {
    nlohmann::json a = nlohmann::json::array();
    for (const glm::dvec3& c : sh.c) a.push_back({float(c.x), float(c.y), float(c.z)});
    return a;
}

nlohmann::json shDescription(const ProbeBakeSettings& s) {
    const glm::dvec3 w = shWindowWeights(s.window);
    return {{"order", kShOrder},
            {"quantity", "incident radiance, W m^-2 sr^-1 (not convolved); E(n) = sum_lm A_l L_lm Y_lm(n), "
                         "A = pi, 2pi/3, pi/4"},
            {"window", shWindowName(s.window)},
            {"windowWeights", {w.x, w.y, w.z}},
            {"cubeResolution", s.resolution}};
}

std::string readText(const fs::path& path, const std::string& what) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path.string(), "cannot open " + what);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

nlohmann::json parseJson(const fs::path& path, const std::string& what) {
    const std::string text = readText(path, what);
    try {
        return nlohmann::json::parse(text);
    } catch (const nlohmann::json::parse_error& e) {
        // nlohmann's message carries the byte position; keep it on one line.
        std::string message = e.what();
        for (char& c : message)
            if (c == '\n') c = ' ';
        throw InputError(path.string(), "not valid JSON (" + message + ")");
    }
}

glm::dvec3 readVec3(const nlohmann::json& j, const fs::path& path, const std::string& where) {
    if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number())
        throw InputError(path.string(), where + " must be an array of 3 numbers");
    const glm::dvec3 v(j[0].get<double>(), j[1].get<double>(), j[2].get<double>());
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
        throw InputError(path.string(), where + " is not finite");
    return v;
}

template <class T>
void append(std::string& out, const T& value) {
    out.append(reinterpret_cast<const char*>(&value), sizeof value);
}

}  // namespace

std::vector<glm::dvec3> readProbePositions(const fs::path& path) {
    const nlohmann::json j = parseJson(path, "the probe positions file");
    if (!j.is_object() || !j.contains("positions"))
        throw InputError(path.string(), "expected an object {\"positions\": [[x, y, z], ...]}");
    const nlohmann::json& list = j["positions"];
    if (!list.is_array()) throw InputError(path.string(), "\"positions\" must be an array of [x, y, z]");
    std::vector<glm::dvec3> out;
    for (std::size_t k = 0; k < list.size(); ++k)
        out.push_back(readVec3(list[k], path, "positions[" + std::to_string(k) + "]"));
    return out;
}

nlohmann::json probesToJson(std::span<const BakedProbe> probes, const ProbeBakeSettings& settings) {
    nlohmann::json list = nlohmann::json::array();
    for (const BakedProbe& p : probes)
        list.push_back({{"position", vec3(p.position)},
                        {"sh", shJson(p.sh)},
                        {"valid", p.valid},
                        {"backfaceFraction", p.backfaceFraction},
                        {"skyFraction", p.skyFraction}});
    return {{"format", kProbesFormat}, {"sh", shDescription(settings)}, {"probes", list}};
}

void writeProbesJson(const fs::path& path, std::span<const BakedProbe> probes, const ProbeBakeSettings& settings) {
    writeTextAtomically(path, probesToJson(probes, settings).dump(1) + "\n");
}

std::vector<std::string> writeIrradianceVolume(const fs::path& dir, const IrradianceVolumeData& volume,
                                               const ProbeBakeSettings& settings, const VolumeBakeStats& stats) {
    volume.validate();
    const std::size_t n = volume.probeCount();
    std::string data;
    data.reserve(n * kVolumeRecordBytes);
    for (std::size_t i = 0; i < n; ++i) {
        for (const glm::dvec3& c : volume.sh[i].c) {
            append(data, float(c.x));
            append(data, float(c.y));
            append(data, float(c.z));
        }
        append(data, std::uint32_t(volume.valid[i] ? 1 : 0));
    }
    const int d = volume.depthResolution;
    std::string visibility;
    if (d > 0) {
        visibility.reserve(n * (3 + 2 * std::size_t(d) * std::size_t(d)) * 4);
        for (std::size_t i = 0; i < n; ++i) {
            append(visibility, volume.probeOffsets[i]);
            for (std::size_t t = 0; t < std::size_t(d) * std::size_t(d); ++t)
                append(visibility, volume.depthMoments[i * std::size_t(d) * std::size_t(d) + t]);
        }
    }
    nlohmann::json j = {{"format", kVolumeFormat},
                        {"min", vec3(volume.boxMin)},
                        {"max", vec3(volume.boxMax)},
                        {"resolution", {volume.resolution.x, volume.resolution.y, volume.resolution.z}},
                        {"spacing", vec3(volume.spacing())},
                        {"probeCount", n},
                        {"invalidProbes", stats.invalid},
                        {"relocatedProbes", stats.relocated},
                        {"sh", shDescription(settings)},
                        {"data", {{"file", kVolumeBinName},
                                  {"recordBytes", kVolumeRecordBytes},
                                  {"layout", "per probe, x fastest then y then z, probe (i,j,k) at min + (i,j,k)*spacing: "
                                             "27 float32 (coefficient-major: l00 r g b, l1-1 r g b, ..., l22 r g b), then "
                                             "uint32 validity (1 valid, 0 inside geometry); little-endian"}}}};
    if (d > 0)
        j["visibility"] = {{"file", kVolumeVisibilityName},
                           {"octahedralResolution", d},
                           {"recordBytes", (3 + 2 * d * d) * 4},
                           {"layout", "per probe, same order: 3 float32 offset (m) from the grid corner to where the probe "
                                      "was rendered, then D*D texels (row v, column u at v*D+u) of 2 float32: mean distance "
                                      "(m) and mean squared distance (m^2) to the nearest surface; octahedral encoding "
                                      "per docs/probes.md; little-endian"}};
    writeAtomically(dir / kVolumeBinName, [&](const fs::path& temp) {
        std::ofstream out(temp, std::ios::binary);
        out.write(data.data(), std::streamsize(data.size()));
        if (!out.flush()) throw std::runtime_error(temp.string() + ": write failed");
    });
    std::vector<std::string> files = {kVolumeJsonName, kVolumeBinName};
    if (d > 0) {
        writeAtomically(dir / kVolumeVisibilityName, [&](const fs::path& temp) {
            std::ofstream out(temp, std::ios::binary);
            out.write(visibility.data(), std::streamsize(visibility.size()));
            if (!out.flush()) throw std::runtime_error(temp.string() + ": write failed");
        });
        files.push_back(kVolumeVisibilityName);
    }
    // The JSON last: a reader that finds it finds the data it describes.
    writeTextAtomically(dir / kVolumeJsonName, j.dump(2) + "\n");
    return files;
}

IrradianceVolumeData readIrradianceVolume(const fs::path& dir) {
    const fs::path jsonPath = dir / kVolumeJsonName;
    const nlohmann::json j = parseJson(jsonPath, "the volume description (is this a bake with --volume-spacing?)");
    const std::string where = jsonPath.string();
    if (!j.is_object() || j.value("format", "") != kVolumeFormat)
        throw InputError(where, std::string("not a \"") + kVolumeFormat + "\" file");
    IrradianceVolumeData v;
    try {
        v.boxMin = readVec3(j.at("min"), jsonPath, "min");
        v.boxMax = readVec3(j.at("max"), jsonPath, "max");
        const auto& r = j.at("resolution");
        if (!r.is_array() || r.size() != 3) throw InputError(where, "resolution must be [nx, ny, nz]");
        v.resolution = glm::ivec3(r[0].get<int>(), r[1].get<int>(), r[2].get<int>());
    } catch (const nlohmann::json::exception& e) {
        throw InputError(where, std::string("malformed (") + e.what() + ")");
    }
    if (v.resolution.x < 2 || v.resolution.y < 2 || v.resolution.z < 2 ||
        double(v.resolution.x) * v.resolution.y * v.resolution.z > 1e8)
        throw InputError(where, "resolution out of range");
    const std::size_t n = v.probeCount();

    const std::string data = readText(dir / kVolumeBinName, "the volume data");
    if (data.size() != n * kVolumeRecordBytes)
        throw InputError((dir / kVolumeBinName).string(), "expected " + std::to_string(n * kVolumeRecordBytes) +
                                                              " bytes for " + std::to_string(n) + " probes, found " +
                                                              std::to_string(data.size()));
    v.sh.resize(n);
    v.valid.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const char* record = data.data() + i * kVolumeRecordBytes;
        float f[27];
        std::memcpy(f, record, sizeof f);
        for (int k = 0; k < kShCoefficients; ++k) v.sh[i].c[std::size_t(k)] = glm::dvec3(f[3 * k], f[3 * k + 1], f[3 * k + 2]);
        std::uint32_t flag = 0;
        std::memcpy(&flag, record + sizeof f, sizeof flag);
        v.valid[i] = flag != 0;
    }
    if (j.contains("visibility")) {
        const nlohmann::json& vis = j["visibility"];
        const int d = vis.value("octahedralResolution", 0);
        if (d < 1 || d > 256) throw InputError(where, "visibility.octahedralResolution out of range");
        const fs::path visPath = dir / vis.value("file", std::string(kVolumeVisibilityName));
        const std::string bytes = readText(visPath, "the volume visibility data");
        const std::size_t recordFloats = 3 + 2 * std::size_t(d) * std::size_t(d);
        if (bytes.size() != n * recordFloats * 4)
            throw InputError(visPath.string(), "expected " + std::to_string(n * recordFloats * 4) + " bytes, found " +
                                                   std::to_string(bytes.size()));
        v.depthResolution = d;
        v.probeOffsets.resize(n);
        v.depthMoments.resize(n * std::size_t(d) * std::size_t(d));
        for (std::size_t i = 0; i < n; ++i) {
            const char* record = bytes.data() + i * recordFloats * 4;
            std::memcpy(&v.probeOffsets[i], record, 12);
            std::memcpy(&v.depthMoments[i * std::size_t(d) * std::size_t(d)], record + 12, 8 * std::size_t(d) * std::size_t(d));
        }
    }
    try {
        v.validate();
    } catch (const std::invalid_argument& e) {
        throw InputError(where, e.what());
    }
    return v;
}

}  // namespace hemibake
