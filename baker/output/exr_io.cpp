#include "baker/output/exr_io.h"

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "baker/util/atomic_output.h"
#include "baker/util/oiio_error.h"
#include "mesh/errors.h"

namespace hemibake {

void writeLightmapExr(const std::filesystem::path& path, const LightmapImage& image) {
    const std::size_t texels = std::size_t(image.size) * std::size_t(image.size);
    if (image.size <= 0 || image.irradianceOverPi.size() != texels)
        throw std::invalid_argument(path.string() + ": lightmap has no texels or its size does not match its data");
    const bool haveState = image.state.size() == texels;
    std::vector<float> pixels(texels * 3);
    for (std::size_t t = 0; t < texels; ++t) {
        const bool empty = haveState && image.state[t] == TexelState::Empty;
        for (int c = 0; c < 3; ++c) pixels[3 * t + std::size_t(c)] = empty ? 0.0f : image.irradianceOverPi[t][c];
    }
    writeAtomically(path, [&](const std::filesystem::path& temp) {
        auto out = OIIO::ImageOutput::create(temp.string());
        if (!out) throw std::runtime_error(path.string() + ": cannot create an EXR writer: " + oiioError(""));
        OIIO::ImageSpec spec(image.size, image.size, 3, OIIO::TypeDesc::FLOAT);
        spec.channelnames = {"R", "G", "B"};
        spec.attribute("compression", "zip");
        spec.attribute("oiio:ColorSpace", "Linear");
        spec.attribute("Software", "hemibake");
        if (!out->open(temp.string(), spec))
            throw std::runtime_error(path.string() + ": cannot open for writing: " + oiioError(out->geterror()));
        if (!out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()))
            throw std::runtime_error(path.string() + ": cannot write: " + oiioError(out->geterror()));
        if (!out->close()) throw std::runtime_error(path.string() + ": cannot finish writing: " + oiioError(out->geterror()));
    });
}

LightmapImage readLightmapExr(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw InputError(path.string(), "file not found");
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) throw InputError(path.string(), "cannot be read as an image: " + oiioError(""));
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.width != spec.height)
        throw InputError(path.string(), "lightmap is " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                                            " texels; atlases are square");
    if (spec.nchannels < 1) throw InputError(path.string(), "image has no channels");
    const int channels = spec.nchannels;
    std::vector<float> pixels(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(channels));
    if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data()))
        throw InputError(path.string(), "cannot read pixels: " + oiioError(in->geterror()));
    in->close();

    LightmapImage image;
    image.resize(spec.width);
    const std::size_t texels = std::size_t(spec.width) * std::size_t(spec.height);
    for (std::size_t t = 0; t < texels; ++t) {
        glm::vec3 v;
        for (int c = 0; c < 3; ++c) v[c] = pixels[t * std::size_t(channels) + std::size_t(channels >= 3 ? c : 0)];
        image.irradianceOverPi[t] = v;
        image.state[t] = (v.x != 0.0f || v.y != 0.0f || v.z != 0.0f) ? TexelState::Covered : TexelState::Empty;
    }
    return image;
}

}  // namespace hemibake
