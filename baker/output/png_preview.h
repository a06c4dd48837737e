#pragma once
// 8-bit sRGB views of lightmaps: the PNG preview of an atlas, and the shared pieces the glTF writer uses for
// its 8-bit lightmap textures (CONVENTIONS.md "Lightmaps in glTF").
//
// Exposure: a texel's brightness is max(R, G, B). The scale k is the 99.9th percentile of that over the
// atlas's non-Empty texels (nearest rank: the value at position ceil(0.999·n) in ascending order; all texels
// when none is marked non-Empty). A texel is shown as sRGB(clamp(value / k, 0, 1)), so the brightest 0.1 % clip
// and everything else keeps its ratio. An all-black (or non-finite) atlas gets k = 1. Empty texels show as 0.
#include <cstdint>
#include <filesystem>
#include <vector>

#include <glm/glm.hpp>

#include "baker/lightmap/lightmap.h"

namespace hemibake {

// Nearest-rank percentile (fraction in (0, 1]) of max(R, G, B) over the selected texels; 0 when there are none.
// `selected` may be empty (all texels) or hold one flag per texel. Non-finite values are ignored.
float brightnessPercentile(const std::vector<glm::vec3>& texels, const std::vector<std::uint8_t>& selected,
                           double fraction = 0.999);

// The exposure scale k of the header comment for a lightmap (k > 0 always).
float lightmapExposureScale(const LightmapImage& image);

// Linear [0,1] → 8-bit sRGB (IEC 61966-2-1), clamped, rounded to nearest; NaN → 0.
std::uint8_t linearToSrgb8(float linear);
// Inverse of the sRGB transfer function (for tests and readers).
float srgb8ToLinear(std::uint8_t value);

// Row-major RGB bytes (rows top to bottom) of sRGB(texel / scale); Empty texels are 0.
std::vector<std::uint8_t> lightmapToSrgb8(const LightmapImage& image, float scale);

// Encodes 8-bit pixels (1–4 channels, rows top to bottom) as PNG bytes in memory (OpenImageIO).
// Throws std::runtime_error on failure.
std::vector<std::uint8_t> encodePng(const std::uint8_t* pixels, int width, int height, int channels);

// Writes OUT/…/<atlas>.png atomically: the 8-bit sRGB preview with the exposure above. Returns the k used.
float writeLightmapPreviewPng(const std::filesystem::path& path, const LightmapImage& image);

}  // namespace hemibake
