#pragma once
// The output stage's knobs: how the lightmapped glb carries the lightmaps, and the preview picture.
#include "baker/output/gltf_writer.h"

namespace hemibake {

struct OutputSettings {
    GltfWriteOptions gltf;       // lightmap (MOZ_lightmap) or emissive; lightmap folder name
    bool preview = true;         // render OUT/preview.exr/.png from the scene's first camera
    int previewWidthPixels = 640;  // height from the camera's aspect ratio
};

}  // namespace hemibake
