#pragma once
// The scene model every stage reads: world-space surfaces, materials in physical units, lights, cameras.
// Units follow ../shared/CONVENTIONS.md: metres, radiance in W·m⁻²·sr⁻¹, linear RGB.
#include <array>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mesh/surface_mesh.h"

namespace hemibake {

// A decoded texture in linear RGB (sRGB decoded at load), rows top to bottom as glTF UVs address them.
struct Texture {
    int width = 0;
    int height = 0;
    std::vector<float> linearRgb;  // width*height*3

    // Bilinear lookup with REPEAT wrapping at glTF UV (origin top-left, v down).
    glm::vec3 sample(glm::vec2 uv) const;
    glm::vec3 average() const;
};

struct Material {
    std::string name;
    glm::vec3 reflectanceFactor{1.0f};  // baseColorFactor.rgb, clamped to [0, 0.999] together with the texture
    int reflectanceTexture = -1;        // index into Scene::textures, or -1
    int reflectanceTexCoord = 0;        // which TEXCOORD_n the texture reads (only 0 is carried today)
    glm::vec3 emittedRadiance{0.0f};    // L_e, W·m⁻²·sr⁻¹: emissiveFactor × emissiveStrength
    bool doubleSided = false;

    bool isEmissive() const { return emittedRadiance.x > 0.0f || emittedRadiance.y > 0.0f || emittedRadiance.z > 0.0f; }
};

enum class LightType { Point, Spot, Directional };

// KHR_lights_punctual, in hemibake's units: point/spot intensity in W·sr⁻¹ per channel (candela in the file),
// directional in W·m⁻² per channel (lux in the file). `color` is already multiplied in.
struct PunctualLight {
    std::string name;
    LightType type = LightType::Point;
    glm::vec3 intensity{0.0f};
    glm::dvec3 position{0.0};
    glm::vec3 direction{0.0f, 0.0f, -1.0f};  // direction the light travels (node's -Z), unit
    float innerConeAngle = 0.0f;              // radians, spot only
    float outerConeAngle = 0.78539816f;       // radians, spot only
    float range = 0.0f;                       // 0 = unbounded (ignored unless an option says otherwise)
};

struct Camera {
    std::string name;
    glm::dvec3 position{0.0};
    glm::vec3 forward{0.0f, 0.0f, -1.0f};
    glm::vec3 up{0.0f, 1.0f, 0.0f};
    float yfovRadians = 0.8f;
    float aspectRatio = 0.0f;  // 0 when the file does not say
    float znear = 0.01f;
};

// Where a surface came from in the input glTF, so results can be written back to the same primitive.
struct SourcePrimitive {
    int node = -1;
    int mesh = -1;
    int primitive = -1;
    std::string nodeName;
};

// One glTF primitive placed by one node: its triangles in world space.
struct MeshInstance {
    SourcePrimitive source;
    int material = -1;  // index into Scene::materials (a default material is appended when a primitive has none)
    bool hasLightmapUv = false;  // the input carried TEXCOORD_1
    bool hasNormals = false;     // the input carried NORMAL (else vertex normals are face-derived)
    SurfaceMesh mesh;
};

struct Bounds {
    glm::dvec3 min{std::numeric_limits<double>::infinity()};
    glm::dvec3 max{-std::numeric_limits<double>::infinity()};
    bool empty() const { return !(min.x <= max.x); }
    void extend(const glm::dvec3& p) { min = glm::min(min, p); max = glm::max(max, p); }
    glm::dvec3 centre() const { return 0.5 * (min + max); }
    glm::dvec3 size() const { return empty() ? glm::dvec3(0.0) : max - min; }
    double diagonal() const { return glm::length(size()); }
};

struct LoadReport {
    std::size_t nodes = 0;              // nodes reached from the default scene
    std::size_t meshNodes = 0;          // of those, nodes that carry a mesh
    std::size_t primitives = 0;         // triangle primitives loaded (instances)
    std::size_t skippedPrimitives = 0;  // points/lines, skipped with a warning
    std::size_t degenerateTriangles = 0;  // zero-area triangles dropped
    std::vector<std::string> warnings;
};

struct Scene {
    std::string path;
    std::vector<Material> materials;
    std::vector<Texture> textures;
    std::vector<PunctualLight> lights;
    std::vector<Camera> cameras;
    std::vector<MeshInstance> instances;
    // Light-probe positions (world, metres) from nodes whose extras hold "hemibake_probe": true.
    std::vector<glm::dvec3> probePositions;
    LoadReport report;

    Bounds bounds() const;
    std::size_t triangleCount() const;
    double surfaceAreaM2() const;
    // Emitted power per channel in W: Σ over emissive triangles of π·L_e·area (one side).
    glm::dvec3 emittedPowerWatts() const;
    // Reflectance at a base-colour texture coordinate: factor × texture, clamped to [0, 0.999].
    glm::vec3 reflectance(int material, glm::vec2 uv) const;
    // Mean reflectance over a triangle with these base-colour texture coordinates at its corners.
    glm::vec3 averageReflectance(int material, glm::vec2 uvA, glm::vec2 uvB, glm::vec2 uvC) const;
};

}  // namespace hemibake
