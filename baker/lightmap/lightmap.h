#pragma once
// A baked lightmap atlas: E/π per texel (CONVENTIONS.md: incident irradiance over π, W·m⁻²·sr⁻¹, linear RGB,
// direct + indirect, excluding the surface's own emission). Rows top to bottom, as glTF UVs address them:
// texel (x, y) has its centre at UV ((x+0.5)/size, (y+0.5)/size).
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace hemibake {

enum class TexelState : std::uint8_t {
    Empty = 0,    // no chart covers it; holds 0
    Covered = 1,  // a chart texel with a baked value
    Dilated = 2,  // padding filled from covered neighbours (so bilinear filtering at chart edges stays clean)
};

struct LightmapImage {
    int size = 0;                          // square, texels
    std::vector<glm::vec3> irradianceOverPi;  // size × size
    std::vector<TexelState> state;            // size × size

    void resize(int s) {
        size = s;
        irradianceOverPi.assign(std::size_t(s) * std::size_t(s), glm::vec3(0.0f));
        state.assign(std::size_t(s) * std::size_t(s), TexelState::Empty);
    }
    std::size_t index(int x, int y) const { return std::size_t(y) * std::size_t(size) + std::size_t(x); }
};

}  // namespace hemibake
