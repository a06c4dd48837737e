#pragma once
// The one image type: width × height pixels, rows top to bottom (as glTF UVs and image files address them).
#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

namespace hemibake {

template <class Pixel>
struct Image {
    int width = 0;
    int height = 0;
    std::vector<Pixel> pixels;  // width × height

    Image() = default;
    Image(int w, int h, Pixel fill = Pixel(0)) : width(w), height(h), pixels(std::size_t(w) * std::size_t(h), fill) {}
    std::size_t index(int x, int y) const { return std::size_t(y) * std::size_t(width) + std::size_t(x); }
    Pixel& at(int x, int y) { return pixels[index(x, y)]; }
    const Pixel& at(int x, int y) const { return pixels[index(x, y)]; }
};

using RgbImage = Image<glm::vec3>;      // linear float RGB (radiance, E/π, errors)
using Rgb8Image = Image<glm::u8vec3>;   // 8-bit sRGB, for PNG previews and maps

}  // namespace hemibake
