#include "baker/bake_settings.h"

#include <stdexcept>

namespace hemibake {

const char* solverKindName(SolverKind kind) {
    switch (kind) {
        case SolverKind::Shoot: return "shoot";
        case SolverKind::Gather: return "gather";
        case SolverKind::Hybrid: return "hybrid";
    }
    return "?";
}

SolverKind parseSolverKind(const std::string& name) {
    if (name == "shoot") return SolverKind::Shoot;
    if (name == "gather") return SolverKind::Gather;
    if (name == "hybrid") return SolverKind::Hybrid;
    throw std::invalid_argument("unknown solver '" + name + "' (shoot, gather or hybrid)");
}

const char* emitterLightingName(EmitterLighting mode) {
    return mode == EmitterLighting::Rays ? "rays" : "hemicube";
}

EmitterLighting parseEmitterLighting(const std::string& name) {
    if (name == "rays") return EmitterLighting::Rays;
    if (name == "hemicube") return EmitterLighting::Hemicube;
    throw std::invalid_argument("unknown emitter lighting '" + name + "' (rays or hemicube)");
}

}  // namespace hemibake
