#pragma once
// glTF 2.0 (.gltf / .glb) → Scene. Every malformed input becomes an InputError naming the file and the problem.
#include <string>

#include "mesh/scene.h"

namespace hemibake {

Scene loadGltf(const std::string& path);

}  // namespace hemibake
