#include "baker/util/rgb_image.h"

#include <fstream>
#include <stdexcept>
#include <string>

#include <OpenImageIO/imageio.h>

#include "baker/util/atomic_output.h"
#include "baker/util/oiio_error.h"
#include "mesh/errors.h"

namespace hemibake {

RgbImage readRgbImage(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path.string(), "file not found");
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) throw InputError(path.string(), "cannot be read as an image: " + oiioError(""));
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels < 1) throw InputError(path.string(), "image has no pixels");
    const int channels = spec.nchannels;
    std::vector<float> raw(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(channels));
    if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, raw.data()))
        throw InputError(path.string(), "cannot read pixels: " + oiioError(in->geterror()));
    in->close();
    RgbImage image(spec.width, spec.height);
    for (std::size_t p = 0; p < image.pixels.size(); ++p)
        for (int c = 0; c < 3; ++c)
            image.pixels[p][c] = raw[p * std::size_t(channels) + std::size_t(channels >= 3 ? c : 0)];
    return image;
}

void writeRgbExr(const std::filesystem::path& path, const RgbImage& image) {
    if (image.width <= 0 || image.height <= 0 || image.pixels.size() != std::size_t(image.width) * std::size_t(image.height))
        throw std::invalid_argument(path.string() + ": image has no pixels or its size does not match its data");
    writeAtomically(path, [&](const std::filesystem::path& temp) {
        auto out = OIIO::ImageOutput::create(temp.string());
        if (!out) throw std::runtime_error(path.string() + ": cannot create an EXR writer: " + oiioError(""));
        OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::FLOAT);
        spec.channelnames = {"R", "G", "B"};
        spec.attribute("compression", "zip");
        spec.attribute("oiio:ColorSpace", "Linear");
        spec.attribute("Software", "hemibake");
        if (!out->open(temp.string(), spec))
            throw std::runtime_error(path.string() + ": cannot open for writing: " + oiioError(out->geterror()));
        if (!out->write_image(OIIO::TypeDesc::FLOAT, image.pixels.data()))
            throw std::runtime_error(path.string() + ": cannot write: " + oiioError(out->geterror()));
        if (!out->close()) throw std::runtime_error(path.string() + ": cannot finish writing: " + oiioError(out->geterror()));
    });
}

void writeBytesAtomically(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes) {
    writeAtomically(path, [&](const std::filesystem::path& temp) {
        std::ofstream out(temp, std::ios::binary);
        out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
        out.close();
        if (!out) throw std::runtime_error(path.string() + ": cannot write");
    });
}

}  // namespace hemibake
