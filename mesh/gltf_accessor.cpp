#include "mesh/gltf_accessor.h"

#include <cstring>

#include <tiny_gltf.h>

#include "mesh/errors.h"

namespace hemibake {

namespace {

int componentBytes(int componentType) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
        case TINYGLTF_COMPONENT_TYPE_SHORT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
        case TINYGLTF_COMPONENT_TYPE_INT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
        case TINYGLTF_COMPONENT_TYPE_DOUBLE: return 8;
        default: return 0;
    }
}

int typeComponents(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR: return 1;
        case TINYGLTF_TYPE_VEC2: return 2;
        case TINYGLTF_TYPE_VEC3: return 3;
        case TINYGLTF_TYPE_VEC4: return 4;
        case TINYGLTF_TYPE_MAT2: return 4;
        case TINYGLTF_TYPE_MAT3: return 9;
        case TINYGLTF_TYPE_MAT4: return 16;
        default: return 0;
    }
}

double readComponent(const unsigned char* p, int componentType, bool normalized) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: { float v; std::memcpy(&v, p, 4); return v; }
        case TINYGLTF_COMPONENT_TYPE_DOUBLE: { double v; std::memcpy(&v, p, 8); return v; }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: { const double v = *p; return normalized ? v / 255.0 : v; }
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
            std::int8_t v; std::memcpy(&v, p, 1);
            return normalized ? std::max(double(v) / 127.0, -1.0) : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            std::uint16_t v; std::memcpy(&v, p, 2);
            return normalized ? double(v) / 65535.0 : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
            std::int16_t v; std::memcpy(&v, p, 2);
            return normalized ? std::max(double(v) / 32767.0, -1.0) : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { std::uint32_t v; std::memcpy(&v, p, 4); return double(v); }
        case TINYGLTF_COMPONENT_TYPE_INT: { std::int32_t v; std::memcpy(&v, p, 4); return double(v); }
        default: return 0.0;
    }
}

struct CheckedView {
    const unsigned char* base = nullptr;  // first element; null for an accessor without buffer view (all zeros)
    std::size_t stride = 0;
    std::size_t count = 0;
    int componentType = 0;
    int components = 0;
    bool normalized = false;
    // Sparse substitutions (glTF 3.6.2.3): element sparseIndex(k) takes the k-th of the tightly packed values.
    std::size_t sparseCount = 0;
    const unsigned char* sparseIndices = nullptr;
    int sparseIndexType = 0;
    const unsigned char* sparseValues = nullptr;
};

// `bytes` bytes from `byteOffset` into buffer view `viewIndex`, bounds-checked against the view and its buffer.
const unsigned char* checkedViewBytes(const tinygltf::Model& model, int viewIndex, long long byteOffset, std::size_t bytes,
                                      const std::string& path, const std::string& what) {
    if (viewIndex < 0 || std::size_t(viewIndex) >= model.bufferViews.size())
        throw InputError(path, what + " refers to buffer view " + std::to_string(viewIndex) + ", which does not exist");
    const tinygltf::BufferView& bv = model.bufferViews[std::size_t(viewIndex)];
    if (bv.buffer < 0 || std::size_t(bv.buffer) >= model.buffers.size())
        throw InputError(path, what + " uses a buffer view whose buffer does not exist");
    const tinygltf::Buffer& buffer = model.buffers[std::size_t(bv.buffer)];
    if (bv.byteOffset > buffer.data.size() || bv.byteLength > buffer.data.size() - bv.byteOffset)
        throw InputError(path, what + ": buffer view " + std::to_string(viewIndex) + " lies outside its buffer (" +
                                   std::to_string(buffer.data.size()) + " bytes)");
    if (byteOffset < 0 || std::size_t(byteOffset) > bv.byteLength || bytes > bv.byteLength - std::size_t(byteOffset))
        throw InputError(path, what + " reads past the end of buffer view " + std::to_string(viewIndex) + " (" +
                                   std::to_string(bytes) + " bytes at offset " + std::to_string(byteOffset) + ", view " +
                                   std::to_string(bv.byteLength) + " bytes)");
    return buffer.data.data() + bv.byteOffset + std::size_t(byteOffset);
}

void checkSparse(const tinygltf::Model& model, const tinygltf::Accessor& a, const std::string& path, const std::string& name,
                 std::size_t elementBytes, CheckedView& view) {
    const auto& sparse = a.sparse;
    if (sparse.count < 1 || std::size_t(sparse.count) > view.count)
        throw InputError(path, name + " has a sparse count of " + std::to_string(sparse.count) + " (must be 1 to " +
                                   std::to_string(view.count) + ")");
    view.sparseCount = std::size_t(sparse.count);
    view.sparseIndexType = sparse.indices.componentType;
    const int indexBytes = componentBytes(sparse.indices.componentType);
    if (sparse.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        sparse.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        sparse.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
        throw InputError(path, name + ": sparse indices must be unsigned byte, short or int");
    view.sparseIndices = checkedViewBytes(model, sparse.indices.bufferView, sparse.indices.byteOffset,
                                          view.sparseCount * std::size_t(indexBytes), path, name + " sparse indices");
    view.sparseValues = checkedViewBytes(model, sparse.values.bufferView, sparse.values.byteOffset,
                                         view.sparseCount * elementBytes, path, name + " sparse values");
    for (std::size_t k = 0; k < view.sparseCount; ++k) {
        const double index = readComponent(view.sparseIndices + k * std::size_t(indexBytes), view.sparseIndexType, false);
        if (index >= double(view.count))
            throw InputError(path, name + ": sparse index " + std::to_string(std::uint64_t(index)) + " out of range (" +
                                       std::to_string(view.count) + " elements)");
    }
}

CheckedView checkAccessor(const tinygltf::Model& model, int accessorIndex, const std::string& path,
                          const std::string& what) {
    if (accessorIndex < 0 || std::size_t(accessorIndex) >= model.accessors.size())
        throw InputError(path, what + " refers to accessor " + std::to_string(accessorIndex) + ", which does not exist");
    const tinygltf::Accessor& a = model.accessors[std::size_t(accessorIndex)];
    const std::string name = what + " (accessor " + std::to_string(accessorIndex) + ")";
    CheckedView view;
    view.count = a.count;
    view.componentType = a.componentType;
    view.components = typeComponents(a.type);
    view.normalized = a.normalized;
    const int bytes = componentBytes(a.componentType);
    if (bytes == 0 || view.components == 0) throw InputError(path, name + " has an invalid component type or type");
    const std::size_t elementBytes = std::size_t(bytes) * std::size_t(view.components);
    if (a.sparse.isSparse) checkSparse(model, a, path, name, elementBytes, view);
    if (a.bufferView < 0) {  // glTF: an accessor without a buffer view reads as zeros
        // Nothing bounds such an accessor's count but memory: refuse counts no real (sparse) attribute has.
        constexpr std::size_t kMaxViewlessElements = std::size_t(1) << 26;
        if (view.count > kMaxViewlessElements)
            throw InputError(path, name + " has no buffer view and " + std::to_string(view.count) +
                                       " elements, more than hemibake reads without one (" +
                                       std::to_string(kMaxViewlessElements) + ")");
        return view;
    }
    if (std::size_t(a.bufferView) >= model.bufferViews.size())
        throw InputError(path, name + " refers to buffer view " + std::to_string(a.bufferView) + ", which does not exist");
    const tinygltf::BufferView& bv = model.bufferViews[std::size_t(a.bufferView)];
    if (bv.buffer < 0 || std::size_t(bv.buffer) >= model.buffers.size())
        throw InputError(path, name + " uses a buffer view whose buffer does not exist");
    const tinygltf::Buffer& buffer = model.buffers[std::size_t(bv.buffer)];
    view.stride = bv.byteStride ? bv.byteStride : elementBytes;
    if (view.stride < elementBytes)
        throw InputError(path, name + " has a byte stride smaller than its element size");
    // Overflow-safe range checks: every byte the accessor reads must lie inside the view and the view inside the buffer.
    if (bv.byteOffset > buffer.data.size() || bv.byteLength > buffer.data.size() - bv.byteOffset)
        throw InputError(path, name + ": buffer view " + std::to_string(a.bufferView) + " lies outside its buffer (" +
                                   std::to_string(buffer.data.size()) + " bytes)");
    if (view.count > 0) {
        const std::size_t lastStart = a.byteOffset + (view.count - 1) * view.stride;
        if ((view.count - 1) > (SIZE_MAX - a.byteOffset) / view.stride || lastStart + elementBytes > bv.byteLength)
            throw InputError(path, name + " reads past the end of buffer view " + std::to_string(a.bufferView) + " (" +
                                       std::to_string(view.count) + " elements, " + std::to_string(bv.byteLength) +
                                       " bytes)");
    }
    view.base = buffer.data.data() + bv.byteOffset + a.byteOffset;
    return view;
}

// Calls read(element, bytes) for every element of the accessor: the base data (skipped when there is none: zeros),
// then the sparse substitutions, which overwrite.
template <class Read>
void forEachElement(const CheckedView& v, Read&& read) {
    if (v.base)
        for (std::size_t i = 0; i < v.count; ++i) read(i, v.base + i * v.stride);
    const std::size_t elementBytes = std::size_t(componentBytes(v.componentType)) * std::size_t(v.components);
    const std::size_t indexBytes = std::size_t(componentBytes(v.sparseIndexType));
    for (std::size_t k = 0; k < v.sparseCount; ++k)
        read(std::size_t(readComponent(v.sparseIndices + k * indexBytes, v.sparseIndexType, false)),
             v.sparseValues + k * elementBytes);
}

}  // namespace

std::vector<double> readAccessorFloats(const tinygltf::Model& model, int accessorIndex, int components,
                                       const std::string& path, const std::string& what) {
    const CheckedView v = checkAccessor(model, accessorIndex, path, what);
    if (v.components != components)
        throw InputError(path, what + " (accessor " + std::to_string(accessorIndex) + ") has " +
                                   std::to_string(v.components) + " components, expected " + std::to_string(components));
    std::vector<double> out(v.count * std::size_t(components), 0.0);
    const int bytes = componentBytes(v.componentType);
    forEachElement(v, [&](std::size_t i, const unsigned char* e) {
        for (int c = 0; c < components; ++c)
            out[i * std::size_t(components) + std::size_t(c)] = readComponent(e + c * bytes, v.componentType, v.normalized);
    });
    return out;
}

std::vector<std::uint32_t> readAccessorIndices(const tinygltf::Model& model, int accessorIndex, const std::string& path,
                                               const std::string& what) {
    const CheckedView v = checkAccessor(model, accessorIndex, path, what);
    const bool integer = v.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                         v.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
                         v.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    if (v.components != 1 || !integer)
        throw InputError(path, what + " (accessor " + std::to_string(accessorIndex) +
                                   ") must be unsigned byte, short or int scalars");
    std::vector<std::uint32_t> out(v.count, 0u);
    forEachElement(v, [&](std::size_t i, const unsigned char* e) {
        out[i] = std::uint32_t(readComponent(e, v.componentType, false));
    });
    return out;
}

std::vector<std::array<std::uint32_t, 3>> assembleTriangles(int mode, const std::vector<std::uint32_t>& idx) {
    std::vector<std::array<std::uint32_t, 3>> tris;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        for (std::size_t i = 0; i + 2 < idx.size(); i += 3) tris.push_back({idx[i], idx[i + 1], idx[i + 2]});
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        for (std::size_t i = 0; i + 2 < idx.size(); ++i)
            tris.push_back(i % 2 == 0 ? std::array<std::uint32_t, 3>{idx[i], idx[i + 1], idx[i + 2]}
                                      : std::array<std::uint32_t, 3>{idx[i + 1], idx[i], idx[i + 2]});
    } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
        for (std::size_t i = 1; i + 1 < idx.size(); ++i) tris.push_back({idx[0], idx[i], idx[i + 1]});
    }
    return tris;
}

}  // namespace hemibake
