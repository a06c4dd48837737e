#pragma once
// Vectors as JSON arrays [x, y, z], for the reports the commands print.
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace hemibake::cli {

inline nlohmann::json jsonVec(const glm::dvec3& v) { return {v.x, v.y, v.z}; }
inline nlohmann::json jsonVec(const glm::vec3& v) { return {v.x, v.y, v.z}; }

}  // namespace hemibake::cli
