#include "baker/probes/cube_map_solid_angle.h"

#include <cmath>

namespace hemibake {

namespace {
double cornerArea(double s, double t) { return std::atan2(s * t, std::sqrt(s * s + t * t + 1.0)); }
}  // namespace

double cubeTexelSolidAngle(double s0, double t0, double s1, double t1) {
    return cornerArea(s1, t1) - cornerArea(s0, t1) - cornerArea(s1, t0) + cornerArea(s0, t0);
}

std::vector<double> cubeFaceSolidAngles(int resolution) {
    std::vector<double> out(std::size_t(resolution) * std::size_t(resolution));
    const double step = 2.0 / resolution;
    for (int j = 0; j < resolution; ++j)
        for (int i = 0; i < resolution; ++i)
            out[std::size_t(j) * std::size_t(resolution) + std::size_t(i)] =
                cubeTexelSolidAngle(-1.0 + i * step, -1.0 + j * step, -1.0 + (i + 1) * step, -1.0 + (j + 1) * step);
    return out;
}

}  // namespace hemibake
