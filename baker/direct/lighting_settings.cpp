#include "baker/direct/lighting_settings.h"

#include <stdexcept>

namespace hemibake {

const char* emitterLightingName(EmitterLighting mode) {
    return mode == EmitterLighting::Rays ? "rays" : "hemicube";
}

EmitterLighting parseEmitterLighting(const std::string& name) {
    if (name == "rays") return EmitterLighting::Rays;
    if (name == "hemicube") return EmitterLighting::Hemicube;
    throw std::invalid_argument("unknown emitter lighting '" + name + "' (rays or hemicube)");
}

}  // namespace hemibake
