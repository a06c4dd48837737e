#pragma once
// The camera a view command looks through (`reference SCENE --camera`, `render OUT/ --camera`): a glTF camera
// by name or a pose from the command line, with an optional field of view and image size. One definition, so
// a reference render and a lightmapped render of the same options frame exactly the same picture.
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "mesh/scene.h"

namespace hemibake::cli {

struct CameraOptions {
    std::string name;
    std::vector<double> position, direction, up{0.0, 1.0, 0.0};
    std::optional<double> fovDeg;
    int width = 512;
    std::optional<int> height;

    bool given() const { return !name.empty() || !position.empty(); }
};

// Registers --camera, --camera-pos, --camera-dir, --camera-up, --fov-deg, --width, --height; returns them (for
// `excludes` with options of other modes).
std::vector<CLI::Option*> addCameraOptions(CLI::App& command, CameraOptions& options);

// Consistency CLI11 cannot express (throws CLI::ValidationError, exit 2): a camera is given; a pose's direction is
// non-zero and not parallel to up.
void validateCameraOptions(const CameraOptions& options);

// The named camera of `scene` (InputError naming `scenePath` and listing the cameras when there is none by that
// name) or the command-line pose (45° vertical field of view unless --fov-deg).
Camera chooseCamera(const Scene& scene, const std::string& scenePath, const CameraOptions& options);

// --height, else from the camera's aspect ratio, else square.
int imageHeight(const CameraOptions& options, const Camera& camera);

}  // namespace hemibake::cli
