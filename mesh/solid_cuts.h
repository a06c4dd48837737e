#pragma once
// Faces cut where solids cross them, their buried parts dropped (issue 15): levels as artists build them overlap —
// a floor slab runs under every wall, walls reach into the slabs, props are sunk into floors — and an element of
// the slab that runs under a wall would take light in one room and give it to both. Cutting each face along the
// lines where other solids' surfaces cross it, and dropping the pieces inside a solid, leaves every face, and so
// every patch and element bisected from it, wholly on one side of every wall.
//
// A solid is a connected part of one instance (vertices welded by exact position) whose surface is closed and
// oriented — every edge is used as often in one direction as in the other — and encloses a positive volume:
// boxes, extruded walls with holes, cylinders. Open surfaces (a single quad, a room made of unconnected panels)
// cut nothing; their covers are left to exposed-area trimming (baker/solve/exposed_area.h).
//
// Per triangle: the planes of the solid triangles that actually intersect it (Möller's interval test) are its cut
// lines; the triangle is split along all of them (an arrangement of convex pieces, each wholly inside or wholly
// outside every solid, because the solids' boundaries inside the triangle lie on those lines), and a piece is
// dropped when a point just off its front (its centroid lifted along the face normal) is inside a solid (winding
// number > ½). The lift decides contact: a block standing exactly on a floor covers the floor under it and the
// floor covers the block's bottom (both dropped), while two coplanar faces looking the same way both stay.
// Double-sided faces are dropped only when both sides are covered. A face is never cut by its own solid.
//
// Gap cuts: a solid wholly in front of a face and nearer than the gap distance (its nearest point) cuts the face
// along the outline it casts along the face's normal: the planes of its triangles that cross a copy of the face's
// plane moved into the solid, stood upright on the face. Nothing is dropped there.
//
// New vertices on an input edge are computed from that edge's end points and keyed by (edge, plane), so the two
// triangles sharing the edge get the same vertex; cut lines run across the whole triangle and may end on an edge
// the neighbour does not cut (a T-vertex, which mesh/subdivision's boundary conforming splits).
#include <array>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>

#include "mesh/patches.h"
#include "mesh/scene.h"

namespace hemibake {

// The closed solids of a scene, ready to cut faces with. Built once per scene; read-only afterwards (thread-safe
// to share).
class SolidSet {
public:
    // Finds the solids of every instance. `toleranceM` is the distance below which two points are one (the
    // scene's rounding scale, e.g. 1e-7 × its diagonal). Never throws on geometry: what is not closed is skipped.
    SolidSet(const Scene& scene, double toleranceM);

    std::size_t size() const { return solids_.size(); }
    double toleranceM() const { return toleranceM_; }

    struct Solid {
        std::size_t instance = 0;
        int component = 0;                        // connected part of the instance's mesh (componentOf)
        glm::dvec3 lo{0.0}, hi{0.0};              // bounds
        std::vector<std::array<glm::dvec3, 3>> triangles;
        std::vector<std::size_t> planeOfTriangle;  // index into planes (coplanar triangles share one)
        std::vector<glm::dvec4> planes;            // unit normal (outward) and offset: n·x + w = 0
    };
    const std::vector<Solid>& solids() const { return solids_; }
    // The connected part of instance `instance` that its input triangle `sourceFace` belongs to (the numbering
    // Solid::component uses), or -1.
    int componentOf(std::size_t instance, int sourceFace) const {
        const std::vector<int>& c = faceComponent_[instance];
        return sourceFace >= 0 && std::size_t(sourceFace) < c.size() ? c[std::size_t(sourceFace)] : -1;
    }

    // Winding number of solid s's surface around p (1 inside, 0 outside, ½ on it).
    double windingNumber(std::size_t s, const glm::dvec3& p) const;
    // Appends to `out` the solids whose bounds, grown by the tolerance, overlap [lo, hi] (each once, ascending).
    void overlapping(const glm::dvec3& lo, const glm::dvec3& hi, std::vector<std::size_t>& out) const;

private:
    std::vector<Solid> solids_;
    // Solids hashed into a uniform grid of cells (cellM), large ones listed apart, for overlapping().
    double cellM_ = 1.0;
    std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
    std::vector<std::size_t> large_;
    std::vector<std::vector<int>> faceComponent_;  // per instance, by source face
    double toleranceM_;
};

// A mesh of instance `instance` (its input mesh, or that mesh bisected) cut along the solids that cross its faces,
// buried parts dropped (see above), and along the outline a solid within `gapM` in front of a face casts straight
// onto it (both sides kept: a light panel hung 5 cm under a ceiling, whose trapped light would otherwise be averaged
// with the open ceiling around it; 0 = no gap cuts). Faces no solid crosses are copied unchanged; pieces keep their face's material,
// instance and source face, and their vertices interpolate normals and both UV sets. `fromFace`, when given, gets
// each output face's input face index. Thread-safe for different meshes; never throws on geometry.
SurfaceMesh cutAlongSolids(const SurfaceMesh& mesh, std::size_t instance, const SolidSet& solids, bool doubleSided,
                           double gapM = 0.0, SolidCutStats* stats = nullptr, std::vector<int>* fromFace = nullptr);

}  // namespace hemibake
