#pragma once
// Probe and volume files (CONVENTIONS.md "Spherical harmonics", "Irradiance volume"; docs/probes.md):
//   probes.json              "hemibake-probes/1": [{position, sh: [[r,g,b] × 9]}, ...] (+ valid, backfaceFraction)
//   volume.json + volume.bin "hemibake-volume/1": box, resolution, per probe 27 float32 SH + uint32 validity
//   volume_visibility.bin    per probe: 3 float32 offset, D×D × (mean, mean²) float32 depth moments
// All written through atomic_output (temp file, then rename); binary data little-endian.
#include <filesystem>
#include <span>
#include <vector>

#include <nlohmann/json.hpp>

#include "baker/probes/irradiance_volume.h"
#include "baker/probes/light_probes.h"

namespace hemibake {

inline constexpr const char* kProbesFormat = "hemibake-probes/1";
inline constexpr const char* kVolumeFormat = "hemibake-volume/1";
inline constexpr const char* kVolumeJsonName = "volume.json";
inline constexpr const char* kVolumeBinName = "volume.bin";
inline constexpr const char* kVolumeVisibilityName = "volume_visibility.bin";
inline constexpr std::size_t kVolumeRecordBytes = 27 * 4 + 4;

// `{"positions": [[x, y, z], ...]}`; throws InputError("<path>: <problem>").
std::vector<glm::dvec3> readProbePositions(const std::filesystem::path& path);

nlohmann::json probesToJson(std::span<const BakedProbe> probes, const ProbeBakeSettings& settings);
void writeProbesJson(const std::filesystem::path& path, std::span<const BakedProbe> probes, const ProbeBakeSettings& settings);

// Writes volume.json, volume.bin, volume_visibility.bin into `dir`; returns the file names written.
std::vector<std::string> writeIrradianceVolume(const std::filesystem::path& dir, const IrradianceVolumeData& volume,
                                               const ProbeBakeSettings& settings, const VolumeBakeStats& stats);
// Reads them back (the visibility file only when volume.json lists it); throws InputError.
IrradianceVolumeData readIrradianceVolume(const std::filesystem::path& dir);

}  // namespace hemibake
