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
};

CheckedView checkAccessor(const tinygltf::Model& model, int accessorIndex, const std::string& path,
                          const std::string& what) {
    if (accessorIndex < 0 || std::size_t(accessorIndex) >= model.accessors.size())
        throw InputError(path, what + " refers to accessor " + std::to_string(accessorIndex) + ", which does not exist");
    const tinygltf::Accessor& a = model.accessors[std::size_t(accessorIndex)];
    const std::string name = what + " (accessor " + std::to_string(accessorIndex) + ")";
    if (a.sparse.isSparse) throw InputError(path, name + " is sparse, which hemibake does not read");
    CheckedView view;
    view.count = a.count;
    view.componentType = a.componentType;
    view.components = typeComponents(a.type);
    view.normalized = a.normalized;
    const int bytes = componentBytes(a.componentType);
    if (bytes == 0 || view.components == 0) throw InputError(path, name + " has an invalid component type or type");
    if (a.bufferView < 0) return view;  // glTF: an accessor without a buffer view reads as zeros
    if (std::size_t(a.bufferView) >= model.bufferViews.size())
        throw InputError(path, name + " refers to buffer view " + std::to_string(a.bufferView) + ", which does not exist");
    const tinygltf::BufferView& bv = model.bufferViews[std::size_t(a.bufferView)];
    if (bv.buffer < 0 || std::size_t(bv.buffer) >= model.buffers.size())
        throw InputError(path, name + " uses a buffer view whose buffer does not exist");
    const tinygltf::Buffer& buffer = model.buffers[std::size_t(bv.buffer)];
    const std::size_t elementBytes = std::size_t(bytes) * std::size_t(view.components);
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

}  // namespace

std::vector<double> readAccessorFloats(const tinygltf::Model& model, int accessorIndex, int components,
                                       const std::string& path, const std::string& what) {
    const CheckedView v = checkAccessor(model, accessorIndex, path, what);
    if (v.components != components)
        throw InputError(path, what + " (accessor " + std::to_string(accessorIndex) + ") has " +
                                   std::to_string(v.components) + " components, expected " + std::to_string(components));
    std::vector<double> out(v.count * std::size_t(components), 0.0);
    if (!v.base) return out;
    const int bytes = componentBytes(v.componentType);
    for (std::size_t i = 0; i < v.count; ++i) {
        const unsigned char* e = v.base + i * v.stride;
        for (int c = 0; c < components; ++c)
            out[i * std::size_t(components) + std::size_t(c)] = readComponent(e + c * bytes, v.componentType, v.normalized);
    }
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
    if (!v.base) return out;
    for (std::size_t i = 0; i < v.count; ++i)
        out[i] = std::uint32_t(readComponent(v.base + i * v.stride, v.componentType, false));
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
