#include "baker/solve/solve_settings.h"

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

const char* rowSamplingName(RowSampling sampling) {
    switch (sampling) {
        case RowSampling::Hemicube: return "hemicube";
        case RowSampling::Rays: return "rays";
    }
    return "?";
}

RowSampling parseRowSampling(const std::string& name) {
    if (name == "rays") return RowSampling::Rays;
    if (name == "hemicube") return RowSampling::Hemicube;
    throw std::invalid_argument("unknown row sampling '" + name + "' (hemicube or rays)");
}

}  // namespace hemibake
