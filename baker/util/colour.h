#pragma once
// Colour helpers shared by the stages: scalar measures of an RGB triple.
#include <glm/glm.hpp>

namespace hemibake {

// r + g + b: the scalar the solver orders, bounds and compares by (power summed over channels).
inline double channelSum(const glm::dvec3& v) { return v.x + v.y + v.z; }
inline double channelSum(const glm::vec3& v) { return double(v.x) + double(v.y) + double(v.z); }

}  // namespace hemibake
