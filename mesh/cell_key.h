#pragma once
// The hash key of an integer grid cell, for uniform grids kept in unordered maps (refinement regions, boundary
// vertices, solids).
#include <cstdint>

namespace hemibake {

inline std::uint64_t cellKey(std::int64_t x, std::int64_t y, std::int64_t z) {
    return std::uint64_t(x) * 0x9E3779B97F4A7C15ull ^ std::uint64_t(y) * 0xC2B2AE3D27D4EB4Full ^
           std::uint64_t(z) * 0x165667B19E3779F9ull;
}

}  // namespace hemibake
