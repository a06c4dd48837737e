#pragma once
// Bounds-checked reads of glTF accessors. tinygltf parses the JSON but does not check that an accessor's
// range fits its buffer view and buffer; these functions do, so hostile files fail with a message, not a crash.
// Sparse accessors are read: the base view (or zeros) with the sparse values substituted.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace tinygltf {
class Model;
}

namespace hemibake {

// Reads `accessorIndex` as `components` doubles per element (normalized integers are mapped to [0,1] / [-1,1]).
// `what` names the accessor in error messages, e.g. "mesh 2 primitive 0 POSITION".
std::vector<double> readAccessorFloats(const tinygltf::Model& model, int accessorIndex, int components,
                                       const std::string& path, const std::string& what);

// Reads an index accessor (u8/u16/u32 scalars).
std::vector<std::uint32_t> readAccessorIndices(const tinygltf::Model& model, int accessorIndex, const std::string& path,
                                               const std::string& what);

// A primitive's triangles from its indices and glTF mode (triangles, strip, fan; other modes give none). Every
// other strip triangle is reversed to keep one winding. SurfaceMesh::sourceFace indexes this list.
std::vector<std::array<std::uint32_t, 3>> assembleTriangles(int mode, const std::vector<std::uint32_t>& indices);

}  // namespace hemibake
