#pragma once
// glTF 2.0 (.gltf / .glb) → Scene. Every malformed input becomes an InputError naming the file and the problem.
#include <string>

#include "mesh/scene.h"

namespace tinygltf {
class Model;
class TinyGLTF;
}  // namespace tinygltf

namespace hemibake {

Scene loadGltf(const std::string& path);

// Reads `path` with the given (configured) tinygltf loader as .gltf or .glb, chosen by its magic bytes; a missing,
// non-glTF or unparsable file is an InputError naming it. For callers that need the raw model (the glTF writer).
void readTinyGltf(const std::string& path, tinygltf::TinyGLTF& loader, tinygltf::Model& model);

}  // namespace hemibake
