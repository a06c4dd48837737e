#pragma once
// How light enters the scene: emitters, the sky, punctual lights (the direct-light stage's knobs; the solve and
// the lightmap stages both read them).
#include <string>

#include <glm/glm.hpp>

namespace hemibake {

enum class EmitterLighting {
    Hemicube,  // emitters shoot their power through item-buffer hemicubes like every other patch
    Rays,      // direct light from emitters by Lambert's formula and shadow rays (EmissiveAreaLights); bounces shoot
};
const char* emitterLightingName(EmitterLighting mode);
EmitterLighting parseEmitterLighting(const std::string& name);  // throws std::invalid_argument

struct LightingSettings {
    EmitterLighting emitters = EmitterLighting::Hemicube;
    int emitterSamples = 16;            // shadow rays per point towards emissive surfaces (Rays); presets 64–4096
    int maxRayTracedEmitters = 4096;    // more emitting elements than this: fall back to Hemicube (cost per point)
    glm::vec3 skyRadiance{0.0f};        // uniform sky, W·m⁻²·sr⁻¹, seen where rays and hemicube pixels escape
    int skySamplesPerElement = 64;      // cosine-weighted visibility rays for direct sky light
    float sunAngularDiameterRad = 0.0f; // > 0: directional lights become soft-shadowed discs (the sun: 0.0093)
    int lightSamplesPerElement = 16;    // stratified points per element for punctual light shadows
};

}  // namespace hemibake
