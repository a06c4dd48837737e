#include "baker/output/png_preview.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "baker/util/atomic_output.h"
#include "baker/util/oiio_error.h"

namespace hemibake {

namespace {

std::vector<std::uint8_t> nonEmptyMask(const LightmapImage& image) {
    std::vector<std::uint8_t> mask;
    if (image.state.size() != image.irradianceOverPi.size()) return mask;
    mask.resize(image.state.size());
    bool any = false;
    for (std::size_t t = 0; t < mask.size(); ++t) {
        mask[t] = image.state[t] != TexelState::Empty;
        any = any || mask[t];
    }
    if (!any) mask.clear();  // nothing marked: use every texel
    return mask;
}

}  // namespace

float brightnessPercentile(const std::vector<glm::vec3>& texels, const std::vector<std::uint8_t>& selected,
                           double fraction) {
    std::vector<float> values;
    values.reserve(texels.size());
    for (std::size_t t = 0; t < texels.size(); ++t) {
        if (!selected.empty() && (t >= selected.size() || !selected[t])) continue;
        const float v = std::max({texels[t].x, texels[t].y, texels[t].z});
        if (std::isfinite(v)) values.push_back(v);
    }
    if (values.empty()) return 0.0f;
    fraction = std::clamp(fraction, 0.0, 1.0);
    std::size_t rank = std::size_t(std::ceil(fraction * double(values.size())));
    rank = std::clamp<std::size_t>(rank, 1, values.size());
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(rank - 1), values.end());
    return values[rank - 1];
}

float lightmapExposureScale(const LightmapImage& image) {
    const float p = brightnessPercentile(image.irradianceOverPi, nonEmptyMask(image), 0.999);
    return (p > 0.0f && std::isfinite(p)) ? p : 1.0f;
}

std::uint8_t linearToSrgb8(float linear) {
    if (!(linear > 0.0f)) return 0;  // also NaN
    if (linear >= 1.0f) return 255;
    const double c = linear <= 0.0031308 ? 12.92 * double(linear) : 1.055 * std::pow(double(linear), 1.0 / 2.4) - 0.055;
    return std::uint8_t(std::clamp(std::lround(c * 255.0), 0L, 255L));
}

float srgb8ToLinear(std::uint8_t value) {
    const double c = double(value) / 255.0;
    return float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}

std::vector<std::uint8_t> lightmapToSrgb8(const LightmapImage& image, float scale) {
    const std::size_t texels = image.irradianceOverPi.size();
    const bool haveState = image.state.size() == texels;
    const float inv = scale > 0.0f && std::isfinite(scale) ? 1.0f / scale : 1.0f;
    std::vector<std::uint8_t> rgb(texels * 3, 0);
    for (std::size_t t = 0; t < texels; ++t) {
        if (haveState && image.state[t] == TexelState::Empty) continue;
        for (int c = 0; c < 3; ++c) rgb[3 * t + std::size_t(c)] = linearToSrgb8(image.irradianceOverPi[t][c] * inv);
    }
    return rgb;
}

std::vector<std::uint8_t> encodePng(const std::uint8_t* pixels, int width, int height, int channels) {
    if (width <= 0 || height <= 0 || channels < 1 || channels > 4 || !pixels)
        throw std::invalid_argument("encodePng: bad image dimensions");
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput proxy(bytes);
    auto out = OIIO::ImageOutput::create("png");
    if (!out) throw std::runtime_error("cannot create a PNG encoder: " + oiioError(""));
    if (!out->supports("ioproxy") || !out->set_ioproxy(&proxy))
        throw std::runtime_error("the PNG encoder cannot write to memory");
    OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", "sRGB");
    if (!out->open("memory.png", spec)) throw std::runtime_error("cannot encode PNG: " + oiioError(out->geterror()));
    if (!out->write_image(OIIO::TypeDesc::UINT8, pixels))
        throw std::runtime_error("cannot encode PNG: " + oiioError(out->geterror()));
    if (!out->close()) throw std::runtime_error("cannot encode PNG: " + oiioError(out->geterror()));
    out.reset();
    return std::vector<std::uint8_t>(bytes.begin(), bytes.end());
}

float writeLightmapPreviewPng(const std::filesystem::path& path, const LightmapImage& image) {
    const std::size_t texels = std::size_t(image.size) * std::size_t(image.size);
    if (image.size <= 0 || image.irradianceOverPi.size() != texels)
        throw std::invalid_argument(path.string() + ": lightmap has no texels or its size does not match its data");
    const float k = lightmapExposureScale(image);
    const std::vector<std::uint8_t> rgb = lightmapToSrgb8(image, k);
    writeAtomically(path, [&](const std::filesystem::path& temp) {
        auto out = OIIO::ImageOutput::create(temp.string());
        if (!out) throw std::runtime_error(path.string() + ": cannot create a PNG writer: " + oiioError(""));
        OIIO::ImageSpec spec(image.size, image.size, 3, OIIO::TypeDesc::UINT8);
        spec.attribute("oiio:ColorSpace", "sRGB");
        spec.attribute("Software", "hemibake");
        spec.attribute("hemibake:exposureScale", k);
        if (!out->open(temp.string(), spec))
            throw std::runtime_error(path.string() + ": cannot open for writing: " + oiioError(out->geterror()));
        if (!out->write_image(OIIO::TypeDesc::UINT8, rgb.data()))
            throw std::runtime_error(path.string() + ": cannot write: " + oiioError(out->geterror()));
        if (!out->close()) throw std::runtime_error(path.string() + ": cannot finish writing: " + oiioError(out->geterror()));
    });
    return k;
}

}  // namespace hemibake
