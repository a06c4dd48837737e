#include "mesh/subdivision.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <map>
#include <optional>
#include <unordered_map>

#include <tbb/parallel_for.h>

#include "mesh/cell_key.h"
#include "mesh/errors.h"
#include "mesh/islands.h"
#include "mesh/solid_cuts.h"
#include "mesh/union_find.h"
#include "mesh/surface_mesh.h"

namespace hemibake {

namespace {


double emitterPatchSize(const SubdivisionSettings& s) {
    // Emitters shoot first and at close range; a quarter of the patch size keeps the proximity error of a
    // single hemicube per patch small (GROUND_TRUTH §3.4).
    return s.emitterPatchSizeM > 0.0 ? s.emitterPatchSizeM : s.patchSizeM / 4.0;
}

// Refines a copy of one instance's mesh into patches, then elements; each face remembers its patch.
struct RefinedInstance {
    SurfaceMesh mesh;
    OpenMesh::FPropHandleT<int> patchOfFace;
    int patchCount = 0;
};

// Finds, for a point, the finest size any refinement region containing it asks for (0 = none). Regions are
// hashed into grids by size class (radius within a factor of 2), each with cells of twice its largest radius, so
// a lookup visits 27 cells per class and only regions of about the cell's size: wall-side refinement makes many
// small regions beside a few large ones, and one grid sized for the largest would scan them all.
class RefinementLookup {
public:
    explicit RefinementLookup(const RefinementRequest* request) {
        if (!request) return;
        regions_ = &request->regions;
        std::map<int, std::vector<std::size_t>> byClass;
        for (std::size_t i = 0; i < regions_->size(); ++i) {
            const double r = (*regions_)[i].radiusM;
            byClass[r > 0.0 && std::isfinite(r) ? std::ilogb(r) : std::numeric_limits<int>::min()].push_back(i);
        }
        for (const auto& [sizeClass, members] : byClass) {
            Grid g;
            for (std::size_t i : members) g.cellM = std::max(g.cellM, 2.0 * (*regions_)[i].radiusM);
            for (std::size_t i : members) {
                const glm::dvec3& c = (*regions_)[i].centre;
                g.cells[cellKey(g.cell(c.x), g.cell(c.y), g.cell(c.z))].push_back(i);
            }
            grids_.push_back(std::move(g));
        }
    }
    double sizeAt(const glm::dvec3& p) const {
        double size = 0.0;
        for (const Grid& g : grids_)
            for (std::int64_t x = g.cell(p.x) - 1; x <= g.cell(p.x) + 1; ++x)
                for (std::int64_t y = g.cell(p.y) - 1; y <= g.cell(p.y) + 1; ++y)
                    for (std::int64_t z = g.cell(p.z) - 1; z <= g.cell(p.z) + 1; ++z) {
                        auto it = g.cells.find(cellKey(x, y, z));
                        if (it == g.cells.end()) continue;
                        for (std::size_t i : it->second) {
                            const auto& r = (*regions_)[i];
                            if (glm::length(p - r.centre) <= r.radiusM && (size == 0.0 || r.sizeM < size)) size = r.sizeM;
                        }
                    }
        return size;
    }

private:
    struct Grid {
        double cellM = 1e-12;
        std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells;
        std::int64_t cell(double x) const { return std::int64_t(std::floor(x / cellM)); }
    };
    std::vector<Grid> grids_;
    const std::vector<RefinementRequest::Region>* regions_ = nullptr;
};

// Patches are the faces of the mesh bisected to the patch size; where solids cut a face (solids given), each
// connected group of its kept pieces is one patch, so a patch never spans a wall while its pieces stay together.
RefinedInstance refine(const MeshInstance& instance, std::size_t instanceIndex, const SolidSet* solids, bool doubleSided,
                       double patchSizeM, double elementSizeM, double gapM, const RefinementLookup& lookup,
                       SolidCutStats& cutStats) {
    RefinedInstance r;
    r.mesh = instance.mesh;
    bisectLongEdges(r.mesh, patchSizeM);
    std::vector<int> patchOf(r.mesh.n_faces());
    for (auto f : r.mesh.faces()) patchOf[std::size_t(f.idx())] = f.idx();
    r.patchCount = int(r.mesh.n_faces());
    if (solids) {
        std::vector<int> fromFace;
        r.mesh = cutAlongSolids(r.mesh, instanceIndex, *solids, doubleSided, gapM, &cutStats, &fromFace);
        // Pieces of one patch face that share a vertex are one patch (pieces on two sides of a wall never do).
        UnionFind groups(r.mesh.n_faces());
        std::map<std::pair<int, int>, std::uint32_t> faceAtVertex;
        for (auto f : r.mesh.faces())
            for (auto v : r.mesh.fv_range(f)) {
                const auto [it, added] = faceAtVertex.emplace(std::pair{v.idx(), fromFace[std::size_t(f.idx())]}, f.idx());
                if (!added) groups.unite(std::uint32_t(f.idx()), it->second);
            }
        std::map<std::uint32_t, int> patchOfRoot;
        patchOf.assign(r.mesh.n_faces(), 0);
        for (auto f : r.mesh.faces())
            patchOf[std::size_t(f.idx())] =
                patchOfRoot.emplace(groups.find(std::uint32_t(f.idx())), int(patchOfRoot.size())).first->second;
        r.patchCount = int(patchOfRoot.size());
    }
    r.mesh.add_property(r.patchOfFace);
    for (auto f : r.mesh.faces()) r.mesh.property(r.patchOfFace, f) = patchOf[std::size_t(f.idx())];
    bisectLongEdges(r.mesh, std::min(elementSizeM, patchSizeM));
    bisectLongEdges(r.mesh, [&](const glm::dvec3& c) { return lookup.sizeAt(c); });
    return r;
}

// Separately meshed surfaces that touch along an edge (two walls of different sizes meeting at a corner) are
// bisected independently, so one side's vertices fall mid-edge on the other: T-junctions, along which
// rasterizers may leave sub-pixel cracks for a hemicube to see through. The same happens inside one surface where a
// cut along a solid ends on an edge its neighbour was not cut along (mesh/solid_cuts.h). Splitting every boundary
// edge at the boundary vertices that lie on it makes the shared edges identical on both sides. Vertices mid-face
// (a wall standing on a floor) are not handled here.
std::size_t conformBoundaries(std::vector<RefinedInstance>& parts, double tolM, double cellM) {
    auto cellOf = [cellM](double x) { return std::int64_t(std::floor(x / cellM)); };
    std::unordered_map<std::uint64_t, std::vector<glm::dvec3>> grid;
    for (std::size_t i = 0; i < parts.size(); ++i)
        for (auto v : parts[i].mesh.vertices())
            if (parts[i].mesh.is_boundary(v)) {
                const glm::dvec3 p = toGlm(parts[i].mesh.point(v));
                grid[cellKey(cellOf(p.x), cellOf(p.y), cellOf(p.z))].push_back(p);
            }
    // Each part splits only its own edges, at vertices gathered above before any split: parts are independent.
    std::vector<std::size_t> partSplits(parts.size(), 0);
    tbb::parallel_for(std::size_t(0), parts.size(), [&](std::size_t i) {
        SurfaceMesh& m = parts[i].mesh;
        std::size_t& splits = partSplits[i];
        std::vector<SurfaceMesh::HalfedgeHandle> boundary;
        for (auto h : m.halfedges())
            if (m.is_boundary(h)) boundary.push_back(h);
        for (auto h : boundary) {
            const auto va = m.from_vertex_handle(h), vb = m.to_vertex_handle(h);
            const glm::dvec3 a = toGlm(m.point(va)), b = toGlm(m.point(vb));
            const glm::dvec3 ab = b - a;
            const double len2 = glm::dot(ab, ab);
            if (!(len2 > 0.0)) continue;
            const double tTol = tolM / std::sqrt(len2);
            // The apex of the face along this edge may itself lie on the edge (a sliver thinner than the tolerance):
            // splitting there would leave two faces of no area, so it is not a T-junction to mend.
            const glm::dvec3 apex = toGlm(m.point(m.to_vertex_handle(m.next_halfedge_handle(m.opposite_halfedge_handle(h)))));
            std::vector<std::pair<double, glm::dvec3>> onEdge;
            const glm::dvec3 lo = glm::min(a, b) - tolM, hi = glm::max(a, b) + tolM;
            const glm::dvec3 reachLo = lo - tolM, reachHi = hi + tolM;  // twice the tolerance: no rounding decides
            for (std::int64_t x = cellOf(lo.x); x <= cellOf(hi.x); ++x)
                for (std::int64_t y = cellOf(lo.y); y <= cellOf(hi.y); ++y)
                    for (std::int64_t z = cellOf(lo.z); z <= cellOf(hi.z); ++z) {
                        auto it = grid.find(cellKey(x, y, z));
                        if (it == grid.end()) continue;
                        for (const glm::dvec3& bv : it->second) {
                            // Most of a cell's vertices are nowhere near the edge: a box test before the division.
                            if (glm::any(glm::lessThan(bv, reachLo)) || glm::any(glm::greaterThan(bv, reachHi))) continue;
                            const double t = glm::dot(bv - a, ab) / len2;
                            if (t <= tTol || t >= 1.0 - tTol) continue;
                            if (glm::length(a + t * ab - bv) > tolM || glm::length(bv - apex) <= tolM) continue;
                            onEdge.emplace_back(t, bv);
                        }
                    }
            std::sort(onEdge.begin(), onEdge.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
            auto from = va;
            double lastT = 0.0;
            for (const auto& [t, p] : onEdge) {
                if (t - lastT <= tTol) continue;  // the same point listed by several parts
                const auto rest = m.find_halfedge(from, vb);
                if (!rest.is_valid()) break;
                const auto v = m.add_vertex({p.x, p.y, p.z});
                const float f = float(t);
                auto n = m.normal(va) * (1.0 - t) + m.normal(vb) * t;
                const double nl = n.norm();
                m.set_normal(v, nl > 0.0 ? n / nl : m.normal(va));
                m.set_texcoord2D(v, (1.0f - f) * m.texcoord2D(va) + f * m.texcoord2D(vb));
                m.lightmapUv(v) = (1.0f - f) * m.lightmapUv(va) + f * m.lightmapUv(vb);
                m.split_edge_copy(m.edge_handle(rest), v);
                from = v;
                lastT = t;
                ++splits;
            }
        }
        m.update_face_normals();
    });
    std::size_t splits = 0;
    for (std::size_t n : partSplits) splits += n;
    return splits;
}

void validate(const SubdivisionSettings& s) {
    if (!(s.patchSizeM > 0.0) || !std::isfinite(s.patchSizeM)) throw std::invalid_argument("patch size must be > 0");
    if (!(s.elementSizeM > 0.0) || !std::isfinite(s.elementSizeM)) throw std::invalid_argument("element size must be > 0");
    if (s.emitterPatchSizeM < 0.0) throw std::invalid_argument("emitter patch size must be >= 0");
}

// Elements and vertices are indexed by 32-bit integers (ElementArrays). A triangle whose edges are at most s has at
// most the equilateral's area √3/4·s², so one of area A becomes at least A/(√3/4·s²) elements: when the scene needs
// more than an index holds at these sizes (a 100 km level at 5 cm elements: 10¹³), say so before bisecting, which
// would exhaust memory first.
void checkElementCount(const Scene& scene, const SubdivisionSettings& s) {
    double lowerBound = 0.0;
    for (const MeshInstance& instance : scene.instances) {
        const Material& material = scene.materials[std::size_t(instance.material)];
        const double patch = material.isEmissive() ? std::min(s.patchSizeM, emitterPatchSize(s)) : s.patchSizeM;
        const double edge = std::min(s.elementSizeM, patch);
        double area = 0.0;
        for (auto f : instance.mesh.faces()) area += instance.mesh.faceArea(f);
        lowerBound += (material.doubleSided ? 2.0 : 1.0) * area / (std::sqrt(3.0) / 4.0 * edge * edge);
    }
    constexpr double kMaxElements = double(std::numeric_limits<std::uint32_t>::max());
    if (lowerBound > kMaxElements) {
        std::ostringstream o;
        o << "subdividing at element size " << s.elementSizeM << " m (patch size " << s.patchSizeM << " m) needs at least "
          << lowerBound << " elements, more than hemibake can index (" << std::uint32_t(kMaxElements)
          << "): choose larger sizes";
        throw InputError(scene.path, o.str());
    }
}

}  // namespace

std::size_t bisectLongEdges(SurfaceMesh& mesh, double maxEdgeM) {
    return bisectLongEdges(mesh, [maxEdgeM](const glm::dvec3&) { return maxEdgeM; });
}

std::size_t bisectLongEdges(SurfaceMesh& mesh, const std::function<double(const glm::dvec3&)>& maxEdgeForFace) {
    std::size_t splits = 0;
    // Each pass at least halves the longest edges it splits, so 64 passes cover a 2^32 range of lengths; the cap
    // only matters for a face the split cannot shrink (a degenerate one), which would otherwise loop forever.
    int passes = 0;
    for (bool changed = true; changed && passes < 64; ++passes) {
        changed = false;
        const std::size_t faceCount = mesh.n_faces();  // faces created in this pass are visited in the next
        for (std::size_t i = 0; i < faceCount; ++i) {
            const SurfaceMesh::FaceHandle f{int(i)};
            glm::dvec3 centroid(0.0);
            for (auto v : mesh.fv_range(f)) centroid += toGlm(mesh.point(v)) / 3.0;
            const double maxEdgeM = maxEdgeForFace(centroid);
            if (!(maxEdgeM > 0.0)) continue;
            // An edge exactly at the limit must not split on rounding alone (it would, 1e5 m from the origin), so
            // the limit carries a relative tolerance far above double rounding and far below any meaningful length.
            double longest2 = maxEdgeM * maxEdgeM * (1.0 + 1e-6);
            SurfaceMesh::HalfedgeHandle longest;
            for (auto h : mesh.fh_range(f)) {
                const double len2 = mesh.calc_edge_sqr_length(h);
                if (len2 > longest2) {
                    longest2 = len2;
                    longest = h;
                }
            }
            if (!longest.is_valid()) continue;
            // A face with two coincident corners keeps its longest edge through any number of splits (the split
            // makes a copy of itself); splitting it only adds faces.
            {
                const auto h0 = mesh.halfedge_handle(f), h1 = mesh.next_halfedge_handle(h0);
                const OpenMesh::Vec3d p0 = mesh.point(mesh.from_vertex_handle(h0)), p1 = mesh.point(mesh.to_vertex_handle(h0)),
                                      p2 = mesh.point(mesh.to_vertex_handle(h1));
                if (!(OpenMesh::cross(p1 - p0, p2 - p0).sqrnorm() > 1e-24 * longest2 * longest2)) continue;
            }
            const auto a = mesh.from_vertex_handle(longest), b = mesh.to_vertex_handle(longest);
            const auto mid = mesh.add_vertex(0.5 * (mesh.point(a) + mesh.point(b)));
            auto n = mesh.normal(a) + mesh.normal(b);
            const double len = n.norm();
            mesh.set_normal(mid, len > 0.0 ? n / len : mesh.normal(a));
            mesh.set_texcoord2D(mid, 0.5f * (mesh.texcoord2D(a) + mesh.texcoord2D(b)));
            mesh.lightmapUv(mid) = 0.5f * (mesh.lightmapUv(a) + mesh.lightmapUv(b));
            mesh.split_edge_copy(mesh.edge_handle(longest), mid);
            ++splits;
            changed = true;
        }
    }
    mesh.update_face_normals();
    return splits;
}

PatchMesh subdivide(const Scene& scene, const SubdivisionSettings& settings, const RefinementRequest* refinement) {
    validate(settings);
    checkElementCount(scene, settings);
    const RefinementLookup lookup(refinement);
    PatchMesh out;
    const Bounds bounds = scene.bounds();
    out.origin = bounds.centre();
    out.sceneDiagonalM = bounds.diagonal();
    ElementArrays& el = out.elements;
    PatchArrays& pa = out.patches;

    // Tolerance: well above float rounding of glTF input coordinates, well below any modelled gap (1 mm walls). Of the
    // largest island, not the scene (mesh/islands.h): parts a kilometre apart are never within it of each other, and
    // the coordinates are doubles here, so no float step bounds it from below.
    const double tolM = std::max(SceneIslands::ofScene(scene).largestLengthM(1e-7, 0.0), 1e-7 * 1e-12);
    std::optional<SolidSet> solids;
    if (settings.cutAlongSolids) solids.emplace(scene, tolM);
    std::vector<RefinedInstance> refined(scene.instances.size());
    std::vector<SolidCutStats> cutStats(scene.instances.size());
    tbb::parallel_for(std::size_t(0), scene.instances.size(), [&](std::size_t i) {
        const MeshInstance& instance = scene.instances[i];
        const Material& material = scene.materials[std::size_t(instance.material)];
        const double patchSize = material.isEmissive() ? std::min(settings.patchSizeM, emitterPatchSize(settings))
                                                       : settings.patchSizeM;
        refined[i] = refine(instance, i, solids && solids->size() > 0 ? &*solids : nullptr, material.doubleSided,
                            patchSize, settings.elementSizeM, settings.elementSizeM * std::max(settings.gapCutFraction, 0.0),
                            lookup, cutStats[i]);
    });
    for (const SolidCutStats& c : cutStats) out.solidCuts += c;
    out.solidCuts.solids = solids ? solids->size() : 0;
    conformBoundaries(refined, tolM, std::max(settings.elementSizeM, 1e-9));

    for (std::size_t instIndex = 0; instIndex < scene.instances.size(); ++instIndex) {
        const MeshInstance& instance = scene.instances[instIndex];
        const Material& material = scene.materials[std::size_t(instance.material)];
        const RefinedInstance& r = refined[instIndex];
        const SurfaceMesh& m = r.mesh;

        // Counting sort of faces by patch, so each patch's elements are contiguous.
        std::vector<std::uint32_t> start(std::size_t(r.patchCount) + 1, 0);
        for (auto f : m.faces()) ++start[std::size_t(m.property(r.patchOfFace, f)) + 1];
        for (std::size_t p = 0; p < std::size_t(r.patchCount); ++p) start[p + 1] += start[p];
        std::vector<int> order(m.n_faces());
        {
            std::vector<std::uint32_t> cursor(start.begin(), start.end() - 1);
            for (auto f : m.faces()) order[cursor[std::size_t(m.property(r.patchOfFace, f))]++] = f.idx();
        }

        const int sides = material.doubleSided ? 2 : 1;
        for (int side = 0; side < sides; ++side) {
            const auto vertexBase = std::uint32_t(el.vertices.size());
            for (auto v : m.vertices()) {
                el.vertices.push_back(toGlm(m.point(v)));
                const auto uv = m.lightmapUv(v);
                el.vertexLightmapUv.emplace_back(uv[0], uv[1]);
            }
            for (int p = 0; p < r.patchCount; ++p) {
                const auto patchIndex = std::uint32_t(pa.size());
                const auto first = std::uint32_t(el.size());
                double patchArea = 0.0;
                glm::dvec3 areaCentroid(0.0), areaNormal(0.0), areaRho(0.0), areaLe(0.0);
                for (std::uint32_t k = start[std::size_t(p)]; k < start[std::size_t(p) + 1]; ++k) {
                    const SurfaceMesh::FaceHandle f{order[k]};
                    std::array<std::uint32_t, 3> tri{};
                    std::array<glm::vec2, 3> uv0{};
                    int c = 0;
                    for (auto v : m.fv_range(f)) {
                        tri[std::size_t(c)] = vertexBase + std::uint32_t(v.idx());
                        const auto t = m.texcoord2D(v);
                        uv0[std::size_t(c)] = {t[0], t[1]};
                        ++c;
                    }
                    if (side == 1) std::swap(tri[1], tri[2]);
                    const glm::dvec3 a = el.vertices[tri[0]], b = el.vertices[tri[1]], cc = el.vertices[tri[2]];
                    const glm::dvec3 cross = glm::cross(b - a, cc - a);
                    const double area = 0.5 * glm::length(cross);
                    const glm::dvec3 n = area > 0.0 ? cross / (2.0 * area) : glm::dvec3(0.0);  // set below
                    const glm::dvec3 centroid = (a + b + cc) / 3.0;
                    const glm::vec3 rho = scene.averageReflectance(instance.material, uv0[0], uv0[1], uv0[2]);
                    el.triangles.push_back(tri);
                    el.normal.push_back(glm::vec3(n));
                    el.centroid.push_back(centroid);
                    el.areaM2.push_back(area);
                    el.reflectance.push_back(rho);
                    el.emittedRadiance.push_back(material.emittedRadiance);
                    el.patch.push_back(patchIndex);
                    el.instance.push_back(std::uint32_t(instIndex));
                    el.sourceFace.push_back(std::uint32_t(m.sourceFace(f)));
                    el.backSide.push_back(std::uint8_t(side));
                    patchArea += area;
                    areaCentroid += area * centroid;
                    areaNormal += area * n;
                    areaRho += area * glm::dvec3(rho);
                    areaLe += area * glm::dvec3(material.emittedRadiance);
                }
                const std::uint32_t count = std::uint32_t(el.size()) - first;
                if (count == 0 || !(patchArea > 0.0)) {
                    // Not expected (the loader drops faces without area, conformBoundaries keeps slivers whole), but
                    // elements naming a patch that is never listed would break every consumer: drop them too.
                    el.truncateElements(first);
                    continue;
                }
                const double nLen = glm::length(areaNormal);
                const glm::dvec3 patchNormal = nLen > 0.0 ? areaNormal / nLen : glm::dvec3(0, 0, 1);
                // A piece left without area (cutting along solids and mending T-junctions can leave three vertices
                // on one line; a 300k-triangle level had 143) takes its patch's normal: it receives and sends
                // nothing, but rays leave every element along its normal (a zero one made them NaN).
                for (std::uint32_t e = first; e < first + count; ++e)
                    if (!(el.areaM2[e] > 0.0)) el.normal[e] = glm::vec3(patchNormal);
                pa.firstElement.push_back(first);
                pa.elementCount.push_back(count);
                pa.areaM2.push_back(patchArea);
                pa.centroid.push_back(areaCentroid / patchArea);
                pa.normal.push_back(glm::vec3(patchNormal));
                pa.reflectance.push_back(glm::vec3(areaRho / patchArea));
                pa.emittedRadiance.push_back(glm::vec3(areaLe / patchArea));
                pa.instance.push_back(std::uint32_t(instIndex));
            }
        }
    }
    return out;
}

SubdivisionStats countSubdivision(const Scene& scene, const SubdivisionSettings& settings) {
    const PatchMesh pm = subdivide(scene, settings);
    SubdivisionStats s;
    s.patches = pm.patches.size();
    s.elements = pm.elements.size();
    for (std::size_t p = 0; p < pm.patches.size(); ++p) {
        const glm::vec3 le = pm.patches.emittedRadiance[p];
        if (le.x > 0.0f || le.y > 0.0f || le.z > 0.0f) {
            ++s.emitterPatches;
            s.emitterElements += pm.patches.elementCount[p];
        }
    }
    return s;
}

}  // namespace hemibake
