#pragma once
// Gathering: every receiver renders a radiance hemicube of the current solution and sums it into E/π. One
// sweep over all receivers is one Jacobi step (one more bounce); the receiver-centred hemicube also fixes
// what shooting gets wrong for small receivers (aliasing, GROUND_TRUTH §3.7).
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "mesh/patches.h"

namespace hemibake {

class HemicubePool;

struct GatherPoint {
    glm::dvec3 position;
    glm::vec3 normal;
};

class Gatherer {
public:
    Gatherer(HemicubePool& pool, std::uint64_t seed) : pool_(pool), seed_(seed) {}

    // Shows the solution: outgoing radiance per element (W·m⁻²·sr⁻¹, B/π), to every worker's context.
    void setElementRadiance(const std::vector<glm::vec3>& radiance);
    // E/π at every point, in parallel. `sweep` decorrelates hemicube rotations between sweeps.
    // `backfaceFraction`, if given, receives each point's hemicube weight that saw back faces.
    void gather(const std::vector<GatherPoint>& points, glm::vec3 skyRadiance, std::uint64_t sweep,
                std::vector<glm::dvec3>& irradianceOverPi, std::vector<float>* backfaceFraction = nullptr);

private:
    HemicubePool& pool_;
    std::uint64_t seed_;
};

// Receivers at element centroids.
std::vector<GatherPoint> elementGatherPoints(const PatchMesh& mesh);

}  // namespace hemibake
