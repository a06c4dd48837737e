#pragma once
// Chart segmentation for lightmap unwrapping (xatlas-style region growing on OpenMesh).
//
// Charts grow one at a time from the largest unassigned face. A face joins the growing chart across a soft
// edge when its normal lies within `maxNormalDeviationCos` of the chart's area-weighted mean normal and its
// cost  normalDeviationWeight·(1 − n·N) + roundnessWeight·roundness + straightnessWeight·straightness  is at
// most `maxCost` (the metrics of xatlas: roundness compares boundary²/area before and after, straightness
// rewards faces that close gaps). Hard edges never join charts: mesh boundaries, material boundaries and
// creases sharper than `creaseAngleDegrees`.
//
// Small leftover charts are then merged into the neighbour they share most boundary with, if the merged chart
// stays within mergeNormalCos of its mean normal and remains a disk.
//
// Every curved chart is a topological disk (one boundary loop, Euler characteristic 1); a grown chart with
// holes or handles is split (through a hole where possible, else halved along its principal axis) until all
// pieces are disks. Planar charts (all face normals within `planarToleranceRad` of the mean) are projected
// exactly, which is injective whatever their topology, so by default they keep their holes (a wall with a
// window stays one chart); set `allowPlanarHoles = false` to split them too.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "mesh/surface_mesh.h"

namespace hemibake {

struct ChartSettings {
    double maxNormalDeviationCos = 0.95;  // face normal · chart mean normal must exceed this to join (≤ −1: no limit)
    double creaseAngleDegrees = 45.0;     // dihedral angles above this always separate charts
    double planarToleranceRad = 1e-3;     // all normals within this angle of the mean → planar chart
    double maxCost = 2.0;
    double normalDeviationWeight = 2.0;
    double roundnessWeight = 0.01;
    double straightnessWeight = 6.0;
    double maxChartAreaM2 = 0.0;  // 0 = unlimited
    bool splitAtMaterials = true;
    bool allowPlanarHoles = true;
    bool weldVertices = true;  // unwrapScene: segment on weldCoincidentVertices(mesh) (see below)
    bool mergeSmallCharts = true;  // charts under half the median area join a neighbour sharing ≥ 30% of
    double mergeNormalCos = 0.85;  // their boundary if all merged normals stay within this of the mean
    int maxSplitDepth = 16;  // non-disk splitting recursion limit; beyond it the chart falls apart into faces
};

// Charts of one mesh as flat arrays. Chart c's faces are chartFaces[chartFaceStart[c] .. chartFaceStart[c+1]).
struct ChartSet {
    std::vector<std::int32_t> faceChart;        // per mesh face (face handle index): its chart
    std::vector<std::uint32_t> chartFaceStart;  // size() + 1 entries
    std::vector<std::int32_t> chartFaces;       // mesh face indices grouped by chart
    std::vector<std::uint8_t> planar;           // per chart: 1 if planar (exact projection)
    std::vector<glm::dvec3> normal;             // per chart: area-weighted mean face normal, unit
    std::vector<double> areaM2;                 // per chart
    std::size_t nonDiskSplits = 0;              // splits made to keep curved charts disks
    std::size_t planarWithHoles = 0;            // planar charts kept whole although not disks
    std::size_t mergedCharts = 0;               // small charts merged into a neighbour

    std::size_t size() const { return planar.size(); }
    std::span<const std::int32_t> faces(std::size_t c) const {
        return {chartFaces.data() + chartFaceStart[c], chartFaces.data() + chartFaceStart[c + 1]};
    }
};

ChartSet computeCharts(const SurfaceMesh& mesh, const ChartSettings& settings = {});

// ---- Helpers shared with parameterization -----------------------------------------------------------------

// Per-face geometry in double precision. Degenerate faces get a zero normal.
struct FaceGeometry {
    std::vector<glm::dvec3> normal;
    std::vector<glm::dvec3> centroid;
    std::vector<double> area;
};
FaceGeometry computeFaceGeometry(const SurfaceMesh& mesh);

// Generation-stamped per-element scratch (faces, vertices or halfedges of one mesh) so that per-chart work
// costs O(chart), not O(mesh): reset() is O(1).
class StampedMap {
public:
    explicit StampedMap(std::size_t n = 0) : stamp_(n, 0), value_(n, 0) {}
    void resize(std::size_t n) { stamp_.assign(n, 0); value_.assign(n, 0); generation_ = 1; }
    void reset() {
        if (++generation_ == 0) { std::fill(stamp_.begin(), stamp_.end(), 0u); generation_ = 1; }
    }
    bool has(std::size_t i) const { return stamp_[i] == generation_; }
    std::int32_t get(std::size_t i) const { return stamp_[i] == generation_ ? value_[i] : -1; }
    void set(std::size_t i, std::int32_t v) { stamp_[i] = generation_; value_[i] = v; }

private:
    std::vector<std::uint32_t> stamp_;
    std::vector<std::int32_t> value_;
    std::uint32_t generation_ = 1;
};

struct ChartTopology {
    int vertices = 0;
    int edges = 0;
    int faces = 0;
    int boundaryLoops = 0;
    std::vector<std::vector<std::int32_t>> loops;  // boundary loops as mesh vertex indices, in order
    int euler() const { return vertices - edges + faces; }
    bool isDisk() const { return boundaryLoops == 1 && euler() == 1; }
};

// Workspace for chart operations on one mesh (scratch maps and face geometry).
struct ChartWorkspace {
    explicit ChartWorkspace(const SurfaceMesh& mesh);
    const SurfaceMesh& mesh;
    FaceGeometry geometry;
    StampedMap faceMark;
    StampedMap vertexMark;
    StampedMap halfedgeMark;
};

ChartTopology chartTopology(ChartWorkspace& ws, std::span<const std::int32_t> faces, bool wantLoops = false);

// True if all non-degenerate face normals lie within `toleranceRad` of their area-weighted mean; the mean
// normal is written to `meanNormal` (unit; +z if the faces have no area).
bool facesArePlanar(const FaceGeometry& g, std::span<const std::int32_t> faces, double toleranceRad,
                    glm::dvec3* meanNormal = nullptr);

// Splits faces in two by the plane through `origin` with normal `axis` (face centroids decide the side) and
// returns the edge-connected components of both sides. With an all-on-one-side result it splits at the
// median projection instead, so a set of ≥ 2 faces always comes back as ≥ 2 parts.
std::vector<std::vector<std::int32_t>> splitFacesByPlane(ChartWorkspace& ws, std::span<const std::int32_t> faces,
                                                         const glm::dvec3& origin, const glm::dvec3& axis);

// Halves faces across their principal axis (area-weighted centroid covariance), as above.
std::vector<std::vector<std::int32_t>> splitFacesInHalf(ChartWorkspace& ws, std::span<const std::int32_t> faces);

// Splits faces until every part is a disk, preferring cuts through holes. Parts already disks are returned
// as they are; beyond maxDepth the remaining parts become single faces. `splits` counts the cuts made.
std::vector<std::vector<std::int32_t>> splitIntoDisks(ChartWorkspace& ws, std::vector<std::int32_t> faces, int maxDepth,
                                                      std::size_t* splits = nullptr);

// Non-indexed and split-normal glTF meshes share no vertices between triangles that touch, which would make
// every triangle a chart. Segmentation and parameterization therefore run on a copy whose coincident vertices
// (bit-identical positions) are merged wherever that keeps the mesh manifold; faces keep their indices and
// corner k of welded face f (halfedge order) came from vertex cornerSource[3f + k] of the input.
struct WeldedMesh {
    SurfaceMesh mesh;
    std::vector<std::int32_t> cornerSource;
    std::size_t mergedVertices = 0;
};
// nullopt when no two vertices coincide (use the input as it is).
std::optional<WeldedMesh> weldCoincidentVertices(const SurfaceMesh& mesh);

// Mesh vertex indices of face f's corners in halfedge order (the order every chart routine uses).
std::array<std::int32_t, 3> faceCorners(const SurfaceMesh& mesh, int f);

// Edge-connected components of a face set.
std::vector<std::vector<std::int32_t>> connectedComponents(ChartWorkspace& ws, std::span<const std::int32_t> faces);

}  // namespace hemibake
