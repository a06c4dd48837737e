#include "baker/output/exr_io.h"

#include <stdexcept>
#include <string>

#include "baker/util/rgb_image.h"
#include "mesh/errors.h"

namespace hemibake {

void writeLightmapExr(const std::filesystem::path& path, const LightmapImage& image) {
    const std::size_t texels = std::size_t(image.size) * std::size_t(image.size);
    if (image.size <= 0 || image.irradianceOverPi.size() != texels)
        throw std::invalid_argument(path.string() + ": lightmap has no texels or its size does not match its data");
    const bool haveState = image.state.size() == texels;
    RgbImage rgb(image.size, image.size);
    for (std::size_t t = 0; t < texels; ++t)
        if (!haveState || image.state[t] != TexelState::Empty) rgb.pixels[t] = image.irradianceOverPi[t];
    writeRgbExr(path, rgb);
}

LightmapImage readLightmapExr(const std::filesystem::path& path) {
    const RgbImage rgb = readRgbImage(path);
    if (rgb.width != rgb.height)
        throw InputError(path.string(), "lightmap is " + std::to_string(rgb.width) + "x" + std::to_string(rgb.height) +
                                            " texels; atlases are square");
    LightmapImage image;
    image.resize(rgb.width);
    for (std::size_t t = 0; t < rgb.pixels.size(); ++t) {
        const glm::vec3 v = rgb.pixels[t];
        image.irradianceOverPi[t] = v;
        image.state[t] = (v.x != 0.0f || v.y != 0.0f || v.z != 0.0f) ? TexelState::Covered : TexelState::Empty;
    }
    return image;
}

}  // namespace hemibake
