#pragma once
// Lightmap atlases as OpenEXR files (CONVENTIONS.md "Bake output layout": OUT/lightmaps/<atlas>.exr).
// Written as 32-bit float RGB (not half: E/π spans many decades — 1e-6 and 1e6 must survive exactly, and the
// reference/compare commands diff bakes texel for texel), ZIP-compressed, rows top to bottom as glTF UVs
// address them. Texels whose TexelState is Empty are written as 0 whatever the image holds.
#include <filesystem>

#include "baker/lightmap/lightmap.h"

namespace hemibake {

// Writes atomically (a temp file with the same extension beside `path`, then rename); creates the folder.
// Throws std::runtime_error naming the file when OpenImageIO fails; `path` is then untouched.
void writeLightmapExr(const std::filesystem::path& path, const LightmapImage& image);

// Reads an EXR (or any float image OpenImageIO reads) back as a lightmap: RGB as float (a grey image fills all
// three channels, extra channels are ignored). The file does not record texel states, so texels with any
// non-zero channel are marked Covered and the others Empty. Throws InputError for a missing, unreadable or
// non-square image.
LightmapImage readLightmapExr(const std::filesystem::path& path);

// Where a path-traced estimate keeps its standard error per pixel: IMG.exr → IMG.stderr.exr (`reference` writes
// it for camera images and texel atlases; `compare` reads it for B). Pure; thread-safe.
inline constexpr const char* kStandardErrorExtension = ".stderr.exr";
inline std::filesystem::path standardErrorPath(const std::filesystem::path& values) {
    return std::filesystem::path(values).replace_extension(kStandardErrorExtension);
}

}  // namespace hemibake
