#pragma once
// Real L2 spherical harmonics of incident radiance (CONVENTIONS.md "Spherical harmonics"): 9 coefficients per
// colour channel in the order l00, l1-1, l10, l11, l2-2, l2-1, l20, l21, l22, evaluated on the glTF frame's
// unit vector (x, y, z) as written (y up): Y1-1 ∝ y, Y10 ∝ z, Y11 ∝ x (Ramamoorthi & Hanrahan 2001).
//
// Irradiance from radiance coefficients is a per-band scale (the clamped-cosine convolution, Â_l = π, 2π/3,
// π/4) followed by evaluation. L2 reproduces irradiance to within 3/32 of ∫L dω (the directional-light worst
// case, GROUND_TRUTH §6) and exactly for radiance linear in the direction (uniform sky over a black ground).
#include <array>
#include <string>

#include <glm/glm.hpp>

namespace hemibake {

inline constexpr int kShCoefficients = 9;

// Band l of coefficient k (0, 1, 1, 1, 2, 2, 2, 2, 2).
constexpr int shBand(int k) { return k == 0 ? 0 : (k < 4 ? 1 : 2); }

// The basis at unit vector d, with the exact constants (0.282095, 0.488603, 1.092548, 0.315392, 0.546274 rounded).
std::array<double, kShCoefficients> shBasis(const glm::dvec3& d);

// Clamped-cosine convolution per band: Â_0 = π, Â_1 = 2π/3, Â_2 = π/4.
double shCosineLobe(int band);

struct ShRgb {
    std::array<glm::dvec3, kShCoefficients> c{};  // coefficient k, per channel

    // Adds radiance L arriving from unit direction d over solid angle dω (a quadrature sample of ∫ L Y dω).
    void addSample(const glm::dvec3& d, const glm::dvec3& radiance, double solidAngleSr);
    // Incident radiance reconstructed in unit direction d.
    glm::dvec3 radiance(const glm::dvec3& d) const;
    // Irradiance E at a surface with unit normal n, W·m⁻² (not clamped: L2 rings slightly negative behind
    // directional light).
    glm::dvec3 irradiance(const glm::dvec3& n) const;
    // E/π, the lightmap texel quantity (CONVENTIONS.md "What a lightmap texel stores").
    glm::dvec3 irradianceOverPi(const glm::dvec3& n) const { return irradiance(n) / 3.14159265358979323846; }
    // Multiplies band l by weights[l].
    void scaleBands(const glm::dvec3& weights);
};

// Windows against ringing (Sloan 2008): multiply band l by w_l. They trade ringing for blur, biasing even the
// otherwise exact uniform-sky case: E(up) becomes (w0 + w1)/2 · π instead of π (GROUND_TRUTH §6).
enum class ShWindow {
    None,      // (1, 1, 1)
    Gaussian,  // exp(−a·l(l+1)), a = 0.0931: (1, 0.830, 0.572); no negative lobe for a directional light
};

glm::dvec3 shWindowWeights(ShWindow window);
const char* shWindowName(ShWindow window);
ShWindow parseShWindow(const std::string& name);  // throws std::invalid_argument

}  // namespace hemibake
