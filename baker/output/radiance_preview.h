#pragma once
// 8-bit pictures of radiance images (camera renders, reference or lightmapped): for people to look at, never
// for measuring. Exposure follows Reinhard et al.'s key rule: the log-average of max(R, G, B) maps to middle
// grey 0.18, so a small bright emitter clips instead of darkening the whole picture.
#include <filesystem>
#include <vector>

#include <glm/glm.hpp>

#include "baker/util/rgb_image.h"

namespace hemibake {

// The exposure k (pixels shown as sRGB(value / k)); 1 for an all-black or non-finite image.
float radianceExposure(const std::vector<glm::vec3>& pixels);

// Writes the sRGB PNG atomically and returns the exposure used.
float writeRadiancePreviewPng(const std::filesystem::path& path, const RgbImage& image);

}  // namespace hemibake
