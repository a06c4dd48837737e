#include "baker/probes/spherical_harmonics.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace hemibake {

namespace {
constexpr double kPi = std::numbers::pi;
// Exact values of the Ramamoorthi-Hanrahan constants: √(1/4π), √(3/4π), √(15/4π), √(5/16π), √(15/16π).
const double kY0 = std::sqrt(1.0 / (4.0 * kPi));
const double kY1 = std::sqrt(3.0 / (4.0 * kPi));
const double kY2 = std::sqrt(15.0 / (4.0 * kPi));
const double kY20 = std::sqrt(5.0 / (16.0 * kPi));
const double kY22 = std::sqrt(15.0 / (16.0 * kPi));
// exp(−a·l(l+1)) with a = 0.0931 (GROUND_TRUTH §6): the smallest Gaussian width that keeps a directional
// light's reconstructed irradiance non-negative.
constexpr double kGaussianWindowA = 0.0931;
}  // namespace

std::array<double, kShCoefficients> shBasis(const glm::dvec3& d) {
    const double x = d.x, y = d.y, z = d.z;
    return {kY0,
            kY1 * y,
            kY1 * z,
            kY1 * x,
            kY2 * x * y,
            kY2 * y * z,
            kY20 * (3.0 * z * z - 1.0),
            kY2 * x * z,
            kY22 * (x * x - y * y)};
}

double shCosineLobe(int band) {
    switch (band) {
        case 0: return kPi;
        case 1: return 2.0 * kPi / 3.0;
        case 2: return kPi / 4.0;
        default: throw std::invalid_argument("shCosineLobe: L2 has bands 0..2");
    }
}

void ShRgb::addSample(const glm::dvec3& d, const glm::dvec3& radiance, double solidAngleSr) {
    const auto y = shBasis(d);
    for (int k = 0; k < kShCoefficients; ++k) c[std::size_t(k)] += (y[std::size_t(k)] * solidAngleSr) * radiance;
}

glm::dvec3 ShRgb::radiance(const glm::dvec3& d) const {
    const auto y = shBasis(d);
    glm::dvec3 sum(0.0);
    for (int k = 0; k < kShCoefficients; ++k) sum += y[std::size_t(k)] * c[std::size_t(k)];
    return sum;
}

glm::dvec3 ShRgb::irradiance(const glm::dvec3& n) const {
    const auto y = shBasis(n);
    glm::dvec3 sum(0.0);
    for (int k = 0; k < kShCoefficients; ++k) sum += (shCosineLobe(shBand(k)) * y[std::size_t(k)]) * c[std::size_t(k)];
    return sum;
}

void ShRgb::scaleBands(const glm::dvec3& weights) {
    for (int k = 0; k < kShCoefficients; ++k) c[std::size_t(k)] *= weights[shBand(k)];
}

glm::dvec3 shWindowWeights(ShWindow window) {
    switch (window) {
        case ShWindow::None: return glm::dvec3(1.0);
        case ShWindow::Gaussian:
            return glm::dvec3(1.0, std::exp(-kGaussianWindowA * 2.0), std::exp(-kGaussianWindowA * 6.0));
    }
    return glm::dvec3(1.0);
}

const char* shWindowName(ShWindow window) { return window == ShWindow::Gaussian ? "gaussian" : "none"; }

ShWindow parseShWindow(const std::string& name) {
    if (name == "none") return ShWindow::None;
    if (name == "gaussian") return ShWindow::Gaussian;
    throw std::invalid_argument("unknown SH window '" + name + "' (none, gaussian)");
}

}  // namespace hemibake
