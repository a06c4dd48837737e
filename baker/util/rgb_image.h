#pragma once
// Linear float RGB images of any size (camera renders, error maps of two renders) and their files. Lightmap
// atlases are square and go through baker/exr_io.h; this is the general case, for what the reference and
// compare commands read and write outside the bake layout.
#include <cstdint>
#include <filesystem>
#include <vector>

#include "baker/util/image.h"

namespace hemibake {

// Reads any image OpenImageIO reads as linear float RGB (a grey image fills all three channels, extra channels
// are ignored; 8-bit files are taken as they are stored, without sRGB decoding). Throws InputError naming the file.
RgbImage readRgbImage(const std::filesystem::path& path);

// 32-bit float RGB EXR, ZIP-compressed, written atomically. Throws std::runtime_error naming the file.
void writeRgbExr(const std::filesystem::path& path, const RgbImage& image);

// Writes bytes (e.g. from encodePng) to `path` atomically. Throws std::runtime_error naming the file.
void writeBytesAtomically(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes);

}  // namespace hemibake
