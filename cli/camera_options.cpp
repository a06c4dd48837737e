#include "cli/camera_options.h"

#include <algorithm>
#include <cmath>

#include "mesh/errors.h"

namespace hemibake::cli {

namespace {

glm::dvec3 toVec(const std::vector<double>& v) { return {v[0], v[1], v[2]}; }

}  // namespace

std::vector<CLI::Option*> addCameraOptions(CLI::App& cmd, CameraOptions& o) {
    auto* name = cmd.add_option("--camera", o.name, "A camera of the scene, by glTF name");
    auto* pos = cmd.add_option("--camera-pos", o.position, "Camera position X,Y,Z in metres")->delimiter(',')->expected(3);
    auto* dir = cmd.add_option("--camera-dir", o.direction, "Viewing direction X,Y,Z")->delimiter(',')->expected(3);
    auto* up = cmd.add_option("--camera-up", o.up, "Up direction X,Y,Z")->capture_default_str()->delimiter(',')->expected(3);
    auto* fov = cmd.add_option("--fov-deg", o.fovDeg, "Vertical field of view in degrees (default: the camera's, or 45)")
                    ->check(CLI::Range(0.1, 179.0));
    auto* width = cmd.add_option("--width", o.width, "Image width in pixels")->capture_default_str()->check(CLI::Range(1, 16384));
    auto* height = cmd.add_option("--height", o.height, "Image height in pixels (default: from the camera's aspect ratio, "
                                                        "else square)")->check(CLI::Range(1, 16384));
    name->excludes(pos)->excludes(dir);
    pos->needs(dir);
    dir->needs(pos);
    return {name, pos, dir, up, fov, width, height};
}

void validateCameraOptions(const CameraOptions& o) {
    if (!o.given()) throw CLI::ValidationError("--camera", "give --camera NAME or --camera-pos X,Y,Z --camera-dir X,Y,Z");
    if (!o.position.empty()) {
        const glm::dvec3 dir = toVec(o.direction), up = toVec(o.up);
        if (!(glm::length(dir) > 0.0)) throw CLI::ValidationError("--camera-dir", "must not be zero");
        if (!(glm::length(glm::cross(glm::normalize(dir), up)) > 1e-6))
            throw CLI::ValidationError("--camera-up", "must not be zero or parallel to --camera-dir");
    }
}

Camera chooseCamera(const Scene& scene, const std::string& scenePath, const CameraOptions& o) {
    Camera camera;
    if (!o.name.empty()) {
        std::string names;
        for (const Camera& c : scene.cameras) {
            if (c.name == o.name) camera = c;
            names += (names.empty() ? "" : ", ") + c.name;
        }
        if (camera.name != o.name)
            throw InputError(scenePath, "has no camera named \"" + o.name + "\" (cameras: " + (names.empty() ? "none" : names) + ")");
    } else {
        camera.name = "command line";
        camera.position = toVec(o.position);
        camera.forward = glm::vec3(glm::normalize(toVec(o.direction)));
        camera.up = glm::vec3(glm::normalize(toVec(o.up)));
        camera.yfovRadians = float(45.0 * M_PI / 180.0);
    }
    if (o.fovDeg) camera.yfovRadians = float(*o.fovDeg * M_PI / 180.0);
    return camera;
}

int imageHeight(const CameraOptions& o, const Camera& camera) {
    if (o.height) return *o.height;
    return camera.aspectRatio > 0.0f ? std::max(1, int(std::lround(o.width / camera.aspectRatio))) : o.width;
}

}  // namespace hemibake::cli
