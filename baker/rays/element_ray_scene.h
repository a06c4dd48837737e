#pragma once
// Which of the solver's elements a ray meets: what a hemicube pixel shows. Two ways to find it:
//  - into the input's faces (an EmbreeScene), each hit's element found inside its face: what the solve uses. A
//    point on no element of its face (a part buried in a solid and cut away) lets the ray go on past it.
//  - into a BVH of the elements themselves (primID = element index; float vertices relative to the centre of the
//    elements' bounds, as in EmbreeScene): built from a mesh alone (tests, tools).
//
// A double-sided surface is two coincident elements with opposite normals (mesh/patches.h). The ray meets the one
// whose front it sees (in the elements' BVH an intersection filter drops the other; in a face, the side it arrives on
// picks the copy), at the same distance (a hemicube pushes the other back in depth instead). An element without
// such a twin seen from behind is a Back hit.
//
// Thread safety: trace() may run concurrently.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "mesh/islands.h"
#include "mesh/patches.h"

namespace hemibake {

struct ElementHit {
    enum class Kind { Sky, Front, Back } kind = Kind::Sky;
    std::uint32_t element = 0;
    double b1 = 0.0, b2 = 0.0;  // barycentric weights of the element's corners 1 and 2
    double distanceM = 0.0;     // along the unit direction
};

class EmbreeScene;

class ElementRayScene {
public:
    // Builds the BVH over `mesh`'s elements; `mesh` must outlive this. Throws std::runtime_error if Embree fails.
    explicit ElementRayScene(const PatchMesh& mesh);
    // Traces into `input`'s faces instead (no BVH of its own) and finds each hit's element inside its face: `mesh` must
    // be subdivided from input.scene(), and both must outlive this. Elements cut along solids leave most of a BVH's
    // cost in their slivers (docs/performance.md, session 39); the input's faces have none. A hit where the face has no
    // element (a part buried in a solid, trimmed away) goes on past it, as the elements' own BVH would let it.
    ElementRayScene(const PatchMesh& mesh, const EmbreeScene& input);
    ~ElementRayScene();
    ElementRayScene(const ElementRayScene&) = delete;
    ElementRayScene& operator=(const ElementRayScene&) = delete;

    // The nearest element along each ray from `origin` (lifted off its surface, see lift()) in unit directions `dirs`
    // (a hemisphere's strata), traced in packets of 16: neighbouring directions share most of their BVH traversal.
    // Throws std::invalid_argument unless `hits` is as long as `dirs`.
    void trace(const glm::dvec3& origin, std::span<const glm::dvec3> dirs, std::span<ElementHit> hits) const;
    // The same with an origin per ray (each lifted): rays from points spread over a patch. Throws
    // std::invalid_argument unless `origins` and `hits` are as long as `dirs`.
    void trace(std::span<const glm::dvec3> origins, std::span<const glm::dvec3> dirs, std::span<ElementHit> hits) const;
    // A ray origin above surface point p along unit normal n: far enough that float error cannot put it back
    // under the surface at any angle (EmbreeScene::kRayEpsilonRelative of the diagonal of the elements' island at p,
    // at least kRayEpsilonFloatSteps float steps there: mesh/islands.h), so nothing nearer than that is skipped.
    glm::dvec3 lift(const glm::dvec3& p, const glm::dvec3& n) const { return p + rayOffsetAtM(p) * n; }
    double rayOffsetAtM(const glm::dvec3& p) const {
        return islandOffsetM_.size() == 1 ? islandOffsetM_[0] : islandOffsetM_[islands_.islandAt(p)];
    }
    double rayOffsetM() const { return rayOffsetM_; }  // the largest of any island
    std::size_t twinElements() const { return twins_; }  // elements with a coincident opposite copy

private:
    struct Embree;
    struct Faces;
    template <class OriginOf>
    void traceFaces(const OriginOf& originOf, std::span<const glm::dvec3> dirs, std::span<ElementHit> hits) const;
    template <class OriginOf>
    void tracePackets(const OriginOf& originOf, std::span<const glm::dvec3> dirs, std::span<ElementHit> hits) const;
    const PatchMesh& mesh_;
    std::unique_ptr<Embree> embree_;  // the elements' BVH, or
    std::unique_ptr<Faces> faces_;    // the input's faces and the elements in each
    SceneIslands islands_;               // of the elements, grouped by instance
    std::vector<double> islandOffsetM_;  // per island (one entry with one island)
    double rayOffsetM_ = 0.0;
    std::size_t twins_ = 0;
};

}  // namespace hemibake
