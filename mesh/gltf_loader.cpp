#include "mesh/gltf_loader.h"

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <sstream>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <OpenMesh/Core/System/omstream.hh>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "mesh/errors.h"
#include "mesh/gltf_accessor.h"
#include "mesh/gltf_data_uri.h"

namespace hemibake {

namespace {

namespace fs = std::filesystem;

// tinygltf's messages span lines, repeat the file name and quote whole data URIs; keep the first meaningful line,
// without URI payloads, and never more than a few hundred characters.
std::string firstLine(const std::string& text) {
    std::string line;
    for (char c : text) {
        if (c == '\n' || c == '\r') {
            if (!line.empty()) break;
            continue;
        }
        line += c;
    }
    if (line.empty()) return "could not be parsed as glTF";
    line = elideDataUris(line);
    constexpr std::size_t kMaxLength = 300;
    if (line.size() > kMaxLength) line = line.substr(0, kMaxLength) + "…";
    return line;
}

// World coordinates are metres; no bakeable scene reaches this far from the origin (16 Earth radii: Earth-centred
// georeferenced tiles, ~6.4e6 m out, still load). Beyond it lies a unit or scale error, and sizes derived from the
// scene (texels, patches) would exhaust memory instead of failing with a message.
constexpr double kMaxWorldCoordinateM = 1e8;
// Nodes whose transforms collapse triangles are each named in a warning up to this many; the rest are summed up.
constexpr std::size_t kMaxCollapseWarnings = 8;

float srgbToLinear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

glm::dmat4 nodeLocalMatrix(const tinygltf::Node& node) {
    if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());  // column-major, as glm
    glm::dmat4 m(1.0);
    if (node.translation.size() == 3)
        m = glm::translate(m, glm::dvec3(node.translation[0], node.translation[1], node.translation[2]));
    if (node.rotation.size() == 4)
        m *= glm::mat4_cast(glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]));
    if (node.scale.size() == 3) m = glm::scale(m, glm::dvec3(node.scale[0], node.scale[1], node.scale[2]));
    return m;
}

bool allFinite(const glm::dmat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

// The matrix that carries normals through `m`: the inverse transpose, or for a singular `m` (which has none) the
// cofactor matrix, its limit up to scale (a quad flattened along its own normal keeps that normal).
glm::dmat3 normalMatrixFor(const glm::dmat3& m) {
    const glm::dmat3 cofactor(glm::cross(m[1], m[2]), glm::cross(m[2], m[0]), glm::cross(m[0], m[1]));
    const double det = glm::dot(m[0], cofactor[0]);
    if (det != 0.0) {
        const glm::dmat3 n = glm::transpose(glm::inverse(m));
        bool finite = true;
        for (int c = 0; c < 3; ++c) finite = finite && std::isfinite(n[c].x + n[c].y + n[c].z);
        if (finite) return n;
        return det < 0.0 ? -cofactor : cofactor;
    }
    return cofactor;
}

// Silences OpenMesh's own complaints (e.g. "complex edge") while we handle the failures ourselves.
class OpenMeshErrorsMuted {
public:
    OpenMeshErrorsMuted() : wasEnabled_(omerr().is_enabled()) { omerr().disable(); }
    ~OpenMeshErrorsMuted() { if (wasEnabled_) omerr().enable(); }
private:
    bool wasEnabled_;
};

class GltfSceneReader {
public:
    GltfSceneReader(const tinygltf::Model& model, const std::string& path) : model_(model), path_(path) {}

    Scene read() {
        scene_.path = path_;
        for (std::size_t i = 0; i < model_.buffers.size(); ++i) {
            // tinygltf decodes base64 up to the first character outside the alphabet and keeps what it got.
            const std::string& uri = model_.buffers[i].uri;
            if (uri.rfind("data:", 0) == 0)
                if (const std::string problem = dataUriProblem(uri); !problem.empty())
                    throw InputError(path_, "buffer " + std::to_string(i) + ": " + problem);
        }
        readMaterials();
        if (model_.scenes.empty()) throw InputError(path_, "the file has no scene");
        int sceneIndex = model_.defaultScene >= 0 ? model_.defaultScene : 0;
        if (std::size_t(sceneIndex) >= model_.scenes.size())
            throw InputError(path_, "default scene " + std::to_string(sceneIndex) + " does not exist");
        std::vector<std::uint8_t> state(model_.nodes.size(), kUnvisited);
        for (int root : model_.scenes[std::size_t(sceneIndex)].nodes) visitTree(root, state);
        if (collapsingNodes_ > kMaxCollapseWarnings)
            warn("and " + std::to_string(collapsingNodes_ - kMaxCollapseWarnings) +
                 " more nodes whose singular transforms collapse triangles to zero area (dropped)");
        if (scene_.triangleCount() == 0) {
            if (collapsedTriangles_ > 0)
                throw InputError(path_, "the scene has no triangles to bake: " + firstCollapsingNode_ +
                                            (collapsingNodes_ > 1 ? " and " + std::to_string(collapsingNodes_ - 1) +
                                                                        " more nodes have singular transforms that collapse their "
                                                                  : " has a singular transform that collapses its ") +
                                            std::to_string(collapsedTriangles_) + " triangles to zero area");
            throw InputError(path_, "the scene has no triangles to bake (empty scene)");
        }
        return std::move(scene_);
    }

private:
    static constexpr std::uint8_t kUnvisited = 0, kOnPath = 1, kDone = 2;

    void warn(const std::string& message) { scene_.report.warnings.push_back(message); }

    std::string nodeLabel(int index) const {
        const std::string& name = model_.nodes[std::size_t(index)].name;
        return name.empty() ? "node " + std::to_string(index) : "node '" + name + "' (node " + std::to_string(index) + ")";
    }
    void readMaterials() {
        for (std::size_t i = 0; i < model_.materials.size(); ++i) {
            const tinygltf::Material& gm = model_.materials[i];
            Material m;
            m.name = gm.name.empty() ? "material" + std::to_string(i) : gm.name;
            const auto& bc = gm.pbrMetallicRoughness.baseColorFactor;
            if (bc.size() >= 3) m.reflectanceFactor = glm::vec3(float(bc[0]), float(bc[1]), float(bc[2]));
            for (int c = 0; c < 3; ++c)
                if (!(m.reflectanceFactor[c] >= 0.0f && m.reflectanceFactor[c] <= 0.999f)) {
                    warn("material '" + m.name + "': reflectance outside [0, 0.999] clamped");
                    break;
                }
            m.reflectanceFactor = glm::clamp(m.reflectanceFactor, glm::vec3(0.0f), glm::vec3(0.999f));
            if (std::isnan(m.reflectanceFactor.x + m.reflectanceFactor.y + m.reflectanceFactor.z))
                throw InputError(path_, "material '" + m.name + "' has a non-finite baseColorFactor");
            const tinygltf::TextureInfo& tex = gm.pbrMetallicRoughness.baseColorTexture;
            if (tex.index >= 0) {
                m.reflectanceTexture = textureFor(tex.index, m.name);
                m.reflectanceTexCoord = tex.texCoord;
            }
            double strength = 1.0;
            auto ext = gm.extensions.find("KHR_materials_emissive_strength");
            if (ext != gm.extensions.end() && ext->second.Has("emissiveStrength"))
                strength = ext->second.Get("emissiveStrength").GetNumberAsDouble();
            if (gm.emissiveFactor.size() >= 3)
                m.emittedRadiance = glm::vec3(glm::dvec3(gm.emissiveFactor[0], gm.emissiveFactor[1], gm.emissiveFactor[2]) *
                                              strength);
            const glm::vec3 le = m.emittedRadiance;
            if (!std::isfinite(le.x + le.y + le.z) || le.x < 0.0f || le.y < 0.0f || le.z < 0.0f)
                throw InputError(path_, "material '" + m.name + "' has a negative or non-finite emission");
            if (gm.emissiveTexture.index >= 0)
                warn("material '" + m.name + "': emissiveTexture is ignored (emission is emissiveFactor x strength)");
            m.doubleSided = gm.doubleSided;
            scene_.materials.push_back(std::move(m));
        }
    }

    int textureFor(int gltfTexture, const std::string& materialName) {
        if (std::size_t(gltfTexture) >= model_.textures.size())
            throw InputError(path_, "material '" + materialName + "' uses texture " + std::to_string(gltfTexture) +
                                        ", which does not exist");
        const int source = model_.textures[std::size_t(gltfTexture)].source;
        if (source < 0 || std::size_t(source) >= model_.images.size())
            throw InputError(path_, "texture " + std::to_string(gltfTexture) + " has no valid image source");
        auto it = imageToTexture_.find(source);
        if (it != imageToTexture_.end()) return it->second;
        const tinygltf::Image& img = model_.images[std::size_t(source)];
        const std::size_t pixels = std::size_t(std::max(img.width, 0)) * std::size_t(std::max(img.height, 0));
        const int bytesPerComponent = img.bits == 16 ? 2 : 1;
        if (pixels == 0 || img.component < 1 ||
            img.image.size() < pixels * std::size_t(img.component) * std::size_t(bytesPerComponent))
            throw InputError(path_, "image " + std::to_string(source) + " ('" + img.uri + "') could not be decoded");
        Texture t;
        t.width = img.width;
        t.height = img.height;
        t.linearRgb.resize(pixels * 3);
        std::array<float, 256> lut8{};
        for (int i = 0; i < 256; ++i) lut8[std::size_t(i)] = srgbToLinear(float(i) / 255.0f);
        for (std::size_t p = 0; p < pixels; ++p)
            for (int c = 0; c < 3; ++c) {
                const int src = std::min(c, img.component - 1);  // grey images replicate their one channel
                const std::size_t at = (p * std::size_t(img.component) + std::size_t(src)) * std::size_t(bytesPerComponent);
                float value;
                if (bytesPerComponent == 1) {
                    value = lut8[img.image[at]];
                } else {
                    const std::uint16_t v = std::uint16_t(img.image[at] | (img.image[at + 1] << 8));
                    value = srgbToLinear(float(v) / 65535.0f);
                }
                t.linearRgb[p * 3 + std::size_t(c)] = value;
            }
        scene_.textures.push_back(std::move(t));
        const int index = int(scene_.textures.size()) - 1;
        imageToTexture_[source] = index;
        return index;
    }

    int defaultMaterial() {
        if (defaultMaterial_ < 0) {
            Material m;
            m.name = "default";
            m.reflectanceFactor = glm::vec3(0.8f);
            scene_.materials.push_back(m);
            defaultMaterial_ = int(scene_.materials.size()) - 1;
        }
        return defaultMaterial_;
    }

    // Depth-first over the node tree without recursion (hierarchies tens of thousands deep are legal glTF), in the
    // order a recursive walk takes: a node, then each child's subtree in turn.
    struct Frame {
        int node;
        glm::dmat4 world;
        std::size_t nextChild = 0;
    };

    void visitTree(int root, std::vector<std::uint8_t>& state) {
        std::vector<Frame> stack;
        enterNode(root, glm::dmat4(1.0), state, stack);
        while (!stack.empty()) {
            Frame& top = stack.back();
            const std::vector<int>& children = model_.nodes[std::size_t(top.node)].children;
            if (top.nextChild < children.size()) {
                const int child = children[top.nextChild++];
                const glm::dmat4 parentWorld = top.world;  // enterNode may reallocate the stack
                enterNode(child, parentWorld, state, stack);
            } else {
                state[std::size_t(top.node)] = kDone;
                stack.pop_back();
            }
        }
    }

    void enterNode(int index, const glm::dmat4& parent, std::vector<std::uint8_t>& state, std::vector<Frame>& stack) {
        if (index < 0 || std::size_t(index) >= model_.nodes.size())
            throw InputError(path_, "the scene refers to node " + std::to_string(index) + ", which does not exist");
        if (state[std::size_t(index)] == kOnPath)
            throw InputError(path_, "node " + std::to_string(index) + " is its own ancestor (cycle in the node hierarchy)");
        // glTF: the hierarchy is a set of disjoint trees. A node reached twice would be baked twice, and a chain of
        // nodes listing the next one twice would be walked 2^n times.
        if (state[std::size_t(index)] == kDone)
            throw InputError(path_, nodeLabel(index) + " is reached twice from the scene (a node may have only one parent)");
        state[std::size_t(index)] = kOnPath;
        const tinygltf::Node& node = model_.nodes[std::size_t(index)];
        const glm::dmat4 world = parent * nodeLocalMatrix(node);
        if (!allFinite(world))
            throw InputError(path_, "node " + std::to_string(index) + " has a non-finite transform");
        ++scene_.report.nodes;
        if (node.mesh >= 0) {
            if (std::size_t(node.mesh) >= model_.meshes.size())
                throw InputError(path_, "node " + std::to_string(index) + " refers to mesh " + std::to_string(node.mesh) +
                                            ", which does not exist");
            ++scene_.report.meshNodes;
            const tinygltf::Mesh& mesh = model_.meshes[std::size_t(node.mesh)];
            std::size_t collapsed = 0, triangles = 0;
            for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
                const PrimitiveCounts counts = readPrimitive(index, node.mesh, int(p), world);
                collapsed += counts.collapsed;
                triangles += counts.triangles;
            }
            if (collapsed > 0) reportCollapse(index, collapsed, triangles);
        }
        if (node.camera >= 0) readCamera(index, world);
        if (node.extras.IsObject() && node.extras.Has("hemibake_probe") && node.extras.Get("hemibake_probe").IsBool() &&
            node.extras.Get("hemibake_probe").Get<bool>())
            scene_.probePositions.push_back(glm::dvec3(world[3]));  // the node's world translation
        auto light = node.extensions.find("KHR_lights_punctual");
        if (light != node.extensions.end() && light->second.Has("light"))
            readLight(index, light->second.Get("light").GetNumberAsInt(), world);
        stack.push_back({index, world, 0});
    }

    // A node whose transform is singular (a zero matrix, a zero scale) flattens its triangles; they are dropped, and
    // the user is told which node did it.
    void reportCollapse(int index, std::size_t collapsed, std::size_t triangles) {
        collapsedTriangles_ += collapsed;
        if (collapsingNodes_++ == 0) firstCollapsingNode_ = nodeLabel(index);
        if (collapsingNodes_ <= kMaxCollapseWarnings)
            warn(nodeLabel(index) + ": its transform is singular and collapses " + std::to_string(collapsed) + " of its " +
                 std::to_string(triangles) + " triangles to zero area; they are dropped");
    }

    // A direction carried through a node's world transform; nullopt when the transform collapses it.
    static std::optional<glm::vec3> worldDirection(const glm::dmat4& world, const glm::dvec3& local) {
        const glm::dvec3 d = glm::dmat3(world) * local;
        const double len = glm::length(d);
        if (!(len > 0.0) || !std::isfinite(len)) return std::nullopt;
        return glm::vec3(d / len);
    }

    void readCamera(int nodeIndex, const glm::dmat4& world) {
        const tinygltf::Node& node = model_.nodes[std::size_t(nodeIndex)];
        if (std::size_t(node.camera) >= model_.cameras.size())
            throw InputError(path_, "node '" + node.name + "' refers to a camera that does not exist");
        const tinygltf::Camera& gc = model_.cameras[std::size_t(node.camera)];
        if (gc.type != "perspective") {
            warn("camera '" + gc.name + "' is not perspective and is skipped");
            return;
        }
        Camera c;
        c.name = !gc.name.empty() ? gc.name : node.name;
        const auto forward = worldDirection(world, glm::dvec3(0, 0, -1)), up = worldDirection(world, glm::dvec3(0, 1, 0));
        if (!forward || !up) {
            warn("camera '" + c.name + "' on " + nodeLabel(nodeIndex) + " is skipped: the node's transform is singular");
            return;
        }
        c.position = glm::dvec3(world[3]);
        c.forward = *forward;
        c.up = *up;
        c.yfovRadians = float(gc.perspective.yfov);
        c.aspectRatio = float(gc.perspective.aspectRatio);
        c.znear = float(gc.perspective.znear);
        scene_.cameras.push_back(c);
    }

    void readLight(int nodeIndex, int index, const glm::dmat4& world) {
        if (index < 0 || std::size_t(index) >= model_.lights.size())
            throw InputError(path_, "a node refers to light " + std::to_string(index) + ", which does not exist");
        const tinygltf::Light& gl = model_.lights[std::size_t(index)];
        PunctualLight l;
        l.name = gl.name.empty() ? "light" + std::to_string(index) : gl.name;
        glm::dvec3 color(1.0);
        if (gl.color.size() == 3) color = glm::dvec3(gl.color[0], gl.color[1], gl.color[2]);
        l.intensity = glm::vec3(color * gl.intensity);
        if (!std::isfinite(l.intensity.x + l.intensity.y + l.intensity.z) || glm::any(glm::lessThan(l.intensity, glm::vec3(0.0f))))
            throw InputError(path_, "light '" + l.name + "' has a negative or non-finite intensity");
        if (gl.type == "point") l.type = LightType::Point;
        else if (gl.type == "spot") l.type = LightType::Spot;
        else if (gl.type == "directional") l.type = LightType::Directional;
        else throw InputError(path_, "light '" + l.name + "' has unknown type '" + gl.type + "'");
        l.position = glm::dvec3(world[3]);
        const auto direction = worldDirection(world, glm::dvec3(0, 0, -1));
        if (!direction) {
            if (l.type != LightType::Point) {
                warn("light '" + l.name + "' on " + nodeLabel(nodeIndex) + " is skipped: the node's transform is singular");
                return;
            }
            l.direction = glm::vec3(0.0f, 0.0f, -1.0f);  // a point light has no direction
        } else {
            l.direction = *direction;
        }
        l.innerConeAngle = float(gl.spot.innerConeAngle);
        l.outerConeAngle = float(gl.spot.outerConeAngle);
        l.range = float(gl.range);
        scene_.lights.push_back(l);
    }

    struct PrimitiveCounts {
        std::size_t triangles = 0;  // triangles in the primitive
        std::size_t collapsed = 0;  // of those, with area in the mesh's own frame and none in world space
    };

    PrimitiveCounts readPrimitive(int nodeIndex, int meshIndex, int primIndex, const glm::dmat4& world) {
        PrimitiveCounts counts;
        const tinygltf::Primitive& prim = model_.meshes[std::size_t(meshIndex)].primitives[std::size_t(primIndex)];
        const std::string where = "mesh " + std::to_string(meshIndex) + " primitive " + std::to_string(primIndex);
        const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
            warn(where + ": points/lines (mode " + std::to_string(mode) + ") skipped");
            ++scene_.report.skippedPrimitives;
            return counts;
        }
        auto attr = prim.attributes.find("POSITION");
        if (attr == prim.attributes.end()) throw InputError(path_, where + " has no POSITION attribute");
        const std::vector<double> pos = readAccessorFloats(model_, attr->second, 3, path_, where + " POSITION");
        const std::size_t vertexCount = pos.size() / 3;
        for (double v : pos)
            if (!std::isfinite(v)) throw InputError(path_, where + " POSITION has non-finite (NaN or infinite) values");
        // World positions once, checked: a finite transform can still overflow them, or carry them absurdly far.
        std::vector<glm::dvec3> worldPos(vertexCount);
        for (std::size_t i = 0; i < vertexCount; ++i) {
            const glm::dvec3 p = glm::dvec3(world * glm::dvec4(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2], 1.0));
            if (!std::isfinite(p.x + p.y + p.z))
                throw InputError(path_, nodeLabel(nodeIndex) + ": " + where +
                                            " has non-finite world coordinates after the node transform (overflow)");
            const double far = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
            if (far > kMaxWorldCoordinateM) {
                std::ostringstream o;
                o << nodeLabel(nodeIndex) << ": " << where << " reaches world coordinate " << far
                  << " m, beyond hemibake's limit of " << kMaxWorldCoordinateM
                  << " m from the origin (a unit or scale error in the node transform?)";
                throw InputError(path_, o.str());
            }
            worldPos[i] = p;
        }

        std::vector<double> normals, uv0, uv1;
        if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
            normals = readAccessorFloats(model_, it->second, 3, path_, where + " NORMAL");
            if (normals.size() != pos.size()) throw InputError(path_, where + " NORMAL count differs from POSITION count");
        }
        int materialIndex = prim.material;
        if (materialIndex >= int(model_.materials.size()))
            throw InputError(path_, where + " refers to material " + std::to_string(materialIndex) + ", which does not exist");
        if (materialIndex < 0) materialIndex = defaultMaterial();
        const Material& material = scene_.materials[std::size_t(materialIndex)];
        const std::string uv0Name = "TEXCOORD_" + std::to_string(material.reflectanceTexCoord);
        if (auto it = prim.attributes.find(uv0Name); it != prim.attributes.end()) {
            uv0 = readAccessorFloats(model_, it->second, 2, path_, where + " " + uv0Name);
            if (uv0.size() / 2 != vertexCount) throw InputError(path_, where + " " + uv0Name + " count differs from POSITION count");
        } else if (material.reflectanceTexture >= 0) {
            warn(where + ": material '" + material.name + "' has a base-colour texture but the primitive has no " + uv0Name +
                 " (the texture is read at UV (0, 0))");
        }
        if (auto it = prim.attributes.find("TEXCOORD_1"); it != prim.attributes.end()) {
            uv1 = readAccessorFloats(model_, it->second, 2, path_, where + " TEXCOORD_1");
            if (uv1.size() / 2 != vertexCount) throw InputError(path_, where + " TEXCOORD_1 count differs from POSITION count");
        }

        std::vector<std::uint32_t> indices;
        if (prim.indices >= 0) {
            indices = readAccessorIndices(model_, prim.indices, path_, where + " indices");
            for (std::uint32_t i : indices)
                if (i >= vertexCount)
                    throw InputError(path_, where + ": index " + std::to_string(i) + " out of range (" +
                                                std::to_string(vertexCount) + " vertices)");
        } else {
            indices.resize(vertexCount);
            for (std::size_t i = 0; i < vertexCount; ++i) indices[i] = std::uint32_t(i);
        }
        const auto triangles = assembleTriangles(mode, indices);
        counts.triangles = triangles.size();

        MeshInstance inst;
        inst.source = {nodeIndex, meshIndex, primIndex, model_.nodes[std::size_t(nodeIndex)].name};
        inst.material = materialIndex;
        inst.hasLightmapUv = !uv1.empty();
        inst.hasNormals = !normals.empty();
        const int instanceIndex = int(scene_.instances.size());
        // A mirroring transform flips the winding; re-reverse it so counter-clockwise stays the front.
        const bool mirrored = glm::determinant(glm::dmat3(world)) < 0.0;
        const glm::dmat3 normalMatrix = normalMatrixFor(glm::dmat3(world));

        SurfaceMesh& mesh = inst.mesh;
        std::vector<SurfaceMesh::VertexHandle> handle(vertexCount);
        auto makeVertex = [&](std::uint32_t i) {
            const glm::dvec3& p = worldPos[i];
            auto v = mesh.add_vertex({p.x, p.y, p.z});
            mesh.sourceVertex(v) = int(i);
            if (!normals.empty()) {
                glm::dvec3 n = normalMatrix * glm::dvec3(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
                const double len = glm::length(n);
                n = len > 0.0 && std::isfinite(len) ? n / len : glm::dvec3(0.0);
                mesh.set_normal(v, {n.x, n.y, n.z});
            }
            if (!uv0.empty()) mesh.set_texcoord2D(v, {float(uv0[2 * i]), float(uv0[2 * i + 1])});
            if (!uv1.empty()) mesh.lightmapUv(v) = {float(uv1[2 * i]), float(uv1[2 * i + 1])};
            return v;
        };
        auto vertex = [&](std::uint32_t i) {
            if (!handle[i].is_valid()) handle[i] = makeVertex(i);
            return handle[i];
        };

        OpenMeshErrorsMuted muted;
        std::size_t nonManifold = 0;
        for (std::size_t t = 0; t < triangles.size(); ++t) {
            auto tri = triangles[t];
            if (mirrored) std::swap(tri[1], tri[2]);
            if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] ||
                !hasArea(worldPos[tri[0]], worldPos[tri[1]], worldPos[tri[2]])) {
                ++scene_.report.degenerateTriangles;
                auto local = [&](std::uint32_t i) { return glm::dvec3(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]); };
                if (tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2] && hasArea(local(tri[0]), local(tri[1]), local(tri[2])))
                    ++counts.collapsed;  // the node's transform flattened it
                continue;
            }
            // Named in order: argument evaluation order is unspecified and vertex numbering should not depend on it.
            const auto v0 = vertex(tri[0]), v1 = vertex(tri[1]), v2 = vertex(tri[2]);
            auto f = mesh.add_face(v0, v1, v2);
            if (!f.is_valid()) {
                // Non-manifold or duplicated face: keep it as a separate sheet so no surface is lost.
                ++nonManifold;
                const auto s0 = makeVertex(tri[0]), s1 = makeVertex(tri[1]), s2 = makeVertex(tri[2]);
                f = mesh.add_face(s0, s1, s2);
                if (!f.is_valid()) continue;
            }
            mesh.material(f) = materialIndex;
            mesh.instance(f) = instanceIndex;
            mesh.sourceFace(f) = int(t);
        }
        if (nonManifold)
            warn(where + ": " + std::to_string(nonManifold) + " non-manifold triangles kept as separate sheets");
        if (mesh.n_faces() == 0) return counts;
        mesh.update_face_normals();
        if (normals.empty()) mesh.update_vertex_normals();
        ++scene_.report.primitives;
        scene_.instances.push_back(std::move(inst));
        return counts;
    }

    // Zero-area: collinear or repeated corners, relative to the triangle's own size.
    static bool hasArea(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
        const double area2 = glm::length(glm::cross(b - a, c - a));
        const double longest2 = std::max({glm::dot(b - a, b - a), glm::dot(c - b, c - b), glm::dot(a - c, a - c)});
        return area2 > 1e-12 * longest2;
    }

    const tinygltf::Model& model_;
    std::string path_;
    Scene scene_;
    std::map<int, int> imageToTexture_;
    int defaultMaterial_ = -1;
    std::size_t collapsingNodes_ = 0, collapsedTriangles_ = 0;
    std::string firstCollapsingNode_;
};

}  // namespace

namespace {

// The glTF JSON of a file tinygltf refused (error path only): the whole file, or a .glb's first chunk.
nlohmann::json rawGltfJson(const std::string& path, bool binary) {
    std::ifstream in(path, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (binary) {
        if (bytes.size() < 20) return nullptr;
        std::uint32_t length = 0;
        std::memcpy(&length, bytes.data() + 12, 4);
        bytes = bytes.substr(20, length);
    }
    return nlohmann::json::parse(bytes, nullptr, false);
}

// Names the buffer or image whose data URI tinygltf could not decode, and what is wrong with it; "" if none is.
std::string dataUriFailure(const nlohmann::json& gltf) {
    if (!gltf.is_object()) return "";
    for (const char* kind : {"buffers", "images"}) {
        const auto list = gltf.find(kind);
        if (list == gltf.end() || !list->is_array()) continue;
        for (std::size_t i = 0; i < list->size(); ++i) {
            const nlohmann::json& item = (*list)[i];
            if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
            const std::string& uri = item["uri"].get_ref<const std::string&>();
            if (uri.rfind("data:", 0) != 0) continue;
            const std::string what = std::string(kind) == "buffers" ? "buffer " : "image ";
            std::size_t bytes = 0;
            if (std::string problem = dataUriProblem(uri, &bytes); !problem.empty()) return what + std::to_string(i) + ": " + problem;
            if (std::string(kind) == "buffers" && item.contains("byteLength") && item["byteLength"].is_number_unsigned() &&
                item["byteLength"].get<std::uint64_t>() != bytes)
                return what + std::to_string(i) + ": data URI holds " + std::to_string(bytes) + " bytes, but its byteLength is " +
                       std::to_string(item["byteLength"].get<std::uint64_t>());
        }
    }
    return "";
}

// tinygltf's error, as one short line naming what failed.
std::string describeLoadFailure(const std::string& path, bool binary, const std::string& err) {
    if (err.find("data:") != std::string::npos || err.find("Failed to decode 'uri'") != std::string::npos)
        if (std::string problem = dataUriFailure(rawGltfJson(path, binary)); !problem.empty()) return problem;
    // "Unknown image format. STB cannot decode image data for image[3] name = ..."
    constexpr std::string_view kUndecodable = "cannot decode image data for image[";
    if (const std::size_t at = err.find(kUndecodable); at != std::string::npos) {
        const std::size_t begin = at + kUndecodable.size(), end = err.find(']', begin);
        if (end != std::string::npos)
            return "image " + err.substr(begin, end - begin) + " could not be decoded (corrupt, or not a PNG or JPEG)";
    }
    return firstLine(err);
}

// A URI that is an absolute path ("/data/level.bin", an RFC 3986 absolute-path reference) names that very file, but
// tinygltf joins every URI to the glTF's folder: such a file was found when the glTF was named by a relative path
// and not when by an absolute one (a bake loaded, its `reference --texels`, which reopens bake.json's absolute path,
// did not). `folder` is the folder tinygltf joins to (its GetBaseDir of the glTF's path).
std::string resolveAbsoluteUri(const std::string& joined, void* folder) {
    const std::string& base = *static_cast<const std::string*>(folder);
    if (base.empty() || joined.compare(0, base.size(), base) != 0) return joined;
    const std::size_t uri = base.back() == '/' ? base.size() : base.size() + 1;  // where JoinPath put the URI
    return joined.size() > uri && joined[uri] == '/' ? joined.substr(uri) : joined;
}

}  // namespace

void readTinyGltf(const std::string& path, tinygltf::TinyGLTF& loader, tinygltf::Model& model) {
    std::error_code ec;
    if (!fs::exists(path, ec)) throw InputError(path, "file not found");
    if (fs::is_directory(path, ec)) throw InputError(path, "is a directory, not a glTF file");
    unsigned char header[12] = {};
    std::size_t headerBytes = 0;
    {
        std::ifstream in(path, std::ios::binary);
        if (!in) throw InputError(path, "cannot be opened for reading");
        in.read(reinterpret_cast<char*>(header), sizeof header);
        headerBytes = std::size_t(in.gcount());
    }
    const char* magic = reinterpret_cast<const char*>(header);
    const bool binary = headerBytes >= 4 && std::string(magic, 4) == "glTF";
    std::string ext = fs::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".glb" && !binary) throw InputError(path, "not a binary glTF (.glb): bad magic bytes");
    if (!binary && magic[0] != '{' && magic[0] != ' ' && magic[0] != '\n' && magic[0] != '\r' && magic[0] != '\t' &&
        header[0] != 0xEF)
        throw InputError(path, "not a glTF file (neither JSON nor binary glTF)");
    if (binary) {
        const std::uintmax_t size = fs::file_size(path, ec);
        std::uint32_t declared = 0;
        std::memcpy(&declared, header + 8, 4);
        if (headerBytes < sizeof header)
            throw InputError(path, "truncated binary glTF: " + std::to_string(size) + " bytes, less than its 12-byte header");
        if (!ec && declared > size)
            throw InputError(path, "truncated binary glTF: its header says " + std::to_string(declared) + " bytes, the file has " +
                                       std::to_string(size));
    }
    std::string folder = path.substr(0, path.find_last_of("/\\") == std::string::npos ? 0 : path.find_last_of("/\\"));
    loader.SetFsCallbacks({&tinygltf::FileExists, &resolveAbsoluteUri, &tinygltf::ReadWholeFile, &tinygltf::WriteWholeFile,
                           &folder});
    // `folder` dies with this call: the loader goes back to tinygltf's own callbacks however the load ends.
    struct RestoreFs {
        tinygltf::TinyGLTF& loader;
        ~RestoreFs() {
            loader.SetFsCallbacks({&tinygltf::FileExists, &tinygltf::ExpandFilePath, &tinygltf::ReadWholeFile,
                                   &tinygltf::WriteWholeFile, nullptr});
        }
    } restoreFs{loader};
    std::string err, warnText;
    const bool ok = binary ? loader.LoadBinaryFromFile(&model, &err, &warnText, path)
                           : loader.LoadASCIIFromFile(&model, &err, &warnText, path);
    if (!ok) throw InputError(path, describeLoadFailure(path, binary, err));
}

Scene loadGltf(const std::string& path) {
    tinygltf::TinyGLTF loader;
    tinygltf::Model model;
    readTinyGltf(path, loader, model);
    if (model.asset.version.rfind("2.", 0) != 0)
        throw InputError(path, "asset version '" + model.asset.version + "' is not glTF 2.x");
    return GltfSceneReader(model, path).read();
}

}  // namespace hemibake
