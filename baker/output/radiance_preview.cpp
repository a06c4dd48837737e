#include "baker/output/radiance_preview.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "baker/output/png_preview.h"

namespace hemibake {

float radianceExposure(const std::vector<glm::vec3>& pixels) {
    double sumLog = 0.0, peak = 0.0;
    std::size_t count = 0;
    for (const glm::vec3& p : pixels) {
        const double v = std::max({p.x, p.y, p.z});
        if (std::isfinite(v)) peak = std::max(peak, v);
    }
    const double delta = 1e-4 * peak;  // keeps black pixels from sending the log-average to 0
    for (const glm::vec3& p : pixels) {
        const double v = std::max({p.x, p.y, p.z});
        if (!std::isfinite(v) || v < 0.0) continue;
        sumLog += std::log(delta + v);
        ++count;
    }
    const double k = count && peak > 0.0 ? std::exp(sumLog / double(count)) / 0.18 : 1.0;
    return std::isfinite(k) && k > 0.0 ? float(k) : 1.0f;
}

float writeRadiancePreviewPng(const std::filesystem::path& path, const RgbImage& image) {
    const float exposure = radianceExposure(image.pixels);
    std::vector<std::uint8_t> srgb(image.pixels.size() * 3);
    for (std::size_t p = 0; p < image.pixels.size(); ++p)
        for (int c = 0; c < 3; ++c) srgb[3 * p + std::size_t(c)] = linearToSrgb8(image.pixels[p][c] / exposure);
    writeBytesAtomically(path, encodePng(srgb.data(), image.width, image.height, 3));
    return exposure;
}

}  // namespace hemibake
