#pragma once
// Buffer-level editing of a tinygltf model for the glb writer (output stage internal): reading an accessor densely,
// appending buffer views to one staging buffer, and packing exactly what is referenced into the single BIN buffer.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace tinygltf {
class Model;
}

namespace hemibake {

constexpr int kArrayBuffer = 34962;
constexpr int kElementArrayBuffer = 34963;

// An accessor's elements, densely packed (sparse substitutions applied).
struct RawElements {
    int componentType = 0;
    int type = 0;
    bool normalized = false;
    std::size_t elementSize = 0;
    std::size_t count = 0;
    std::vector<std::uint8_t> bytes;
};

// The glTF at `path` as tinygltf reads it, images kept encoded (PNG, JPEG, KTX2, ... bytes as in the file) so that
// they can be stored unchanged. Throws InputError naming the file.
tinygltf::Model loadModelKeepingImages(const std::string& path);

// Edits `model` in place; every error is an InputError naming `path`. Not thread-safe.
class GltfBufferEditor {
public:
    // Appends the staging buffer that addView writes into.
    GltfBufferEditor(tinygltf::Model& model, std::string path);

    // Accessor `accessor`'s elements; `what` names it in errors (bad indices, views past their buffer, matrices).
    RawElements readRaw(int accessor, const std::string& what) const;
    // Appends `bytes` as a new buffer view (4-byte aligned) and returns its index.
    int addView(const void* data, std::size_t bytes, int target, std::size_t stride = 0);
    // A vertex attribute accessor holding raw's elements at `order` (glTF vertex indices), in raw's types.
    int addGatheredAttribute(const RawElements& raw, const std::vector<std::uint32_t>& order, bool withMinMax);
    // Every image (external file, data URI) stored in a buffer view, with its MIME type.
    void moveImagesIntoBufferViews();
    // Moves the staged views in, then keeps exactly the accessors and buffer views something refers to (unless an
    // unknown extension might refer to others), all in one BIN buffer.
    void finish();

private:
    [[noreturn]] void fail(const std::string& problem) const;
    const std::uint8_t* viewBytes(int viewIndex, std::size_t offset, std::size_t needed, const std::string& what) const;
    void compactBuffers();

    tinygltf::Model& m_;
    std::string path_;
    int stagingBuffer_ = -1;
    std::vector<std::uint8_t> staging_;
};

}  // namespace hemibake
