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
    int maxRayTracedEmitters = 4096;    // more emitter input triangles than this (per side of a double-sided face)
                                        // near one receiver (emitterTrianglesNearOneReceiver: within a few element
                                        // sizes, where each costs a contour per point; far ones are clustered):
                                        // fall back to Hemicube. 30 copies of a generated level: 192
    glm::vec3 skyRadiance{0.0f};        // uniform sky, W·m⁻²·sr⁻¹, seen where rays and hemicube pixels escape
    // Cosine-weighted visibility rays per element for direct sky light, spread over its lightSamplesPerElement
    // points. A room lit through windows has only some hundred elements, so their noise does not average out:
    // at 64 rays the rooms of a generated level moved by up to ±3 % between sampling patterns; 1,024 rays cost
    // ~3 s per 20k elements.
    int skySamplesPerElement = 1024;
    float sunAngularDiameterRad = 0.0f; // > 0: directional lights become soft-shadowed discs (the sun: 0.0093)
    // Stratified points per element for punctual light shadows (and the sky's rays): a sun patch's edge through a
    // window crosses few elements, so their 16-point error (±1/8 of an element) moved whole rooms by 1–2 %; 64.
    int lightSamplesPerElement = 64;
};

}  // namespace hemibake
