#include "mesh/solid_cuts.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <tuple>

#include "mesh/cell_key.h"
#include "mesh/union_find.h"
#include "mesh/surface_mesh.h"

namespace hemibake {

namespace {


struct PositionLess {
    bool operator()(const glm::dvec3& a, const glm::dvec3& b) const {
        if (a.x != b.x) return a.x < b.x;
        if (a.y != b.y) return a.y < b.y;
        return a.z < b.z;
    }
};

// Snaps a signed distance within the tolerance to exactly 0 (the point is on the plane).
double snapped(double d, double tol) { return std::abs(d) <= tol ? 0.0 : d; }

// Where a triangle (distances d to a plane, snapped) meets the plane, as an interval along `dir`.
bool planeInterval(const std::array<glm::dvec3, 3>& p, const std::array<double, 3>& d, const glm::dvec3& dir,
                   double& lo, double& hi) {
    lo = 1e300;
    hi = -1e300;
    for (int i = 0; i < 3; ++i) {
        const int j = (i + 1) % 3;
        if (d[std::size_t(i)] == 0.0) {
            const double s = glm::dot(p[std::size_t(i)], dir);
            lo = std::min(lo, s);
            hi = std::max(hi, s);
        }
        if (d[std::size_t(i)] * d[std::size_t(j)] < 0.0) {
            const double t = d[std::size_t(i)] / (d[std::size_t(i)] - d[std::size_t(j)]);
            const double s = glm::dot(p[std::size_t(i)] + t * (p[std::size_t(j)] - p[std::size_t(i)]), dir);
            lo = std::min(lo, s);
            hi = std::max(hi, s);
        }
    }
    return lo <= hi;
}

glm::dvec4 planeOf(const std::array<glm::dvec3, 3>& t) {
    const glm::dvec3 c = glm::cross(t[1] - t[0], t[2] - t[0]);
    const double len = glm::length(c);
    if (!(len > 0.0)) return glm::dvec4(0.0);
    const glm::dvec3 n = c / len;
    return {n, -glm::dot(n, t[0])};
}

// Whether solid triangle s crosses triangle t along a segment (Möller's interval test, touching included; coplanar
// triangles do not cross: their outlines come from the neighbouring faces). If so, `segment` is where s meets t's
// plane (not clipped to t).
bool crosses(const std::array<glm::dvec3, 3>& t, const glm::dvec4& planeT, const std::array<glm::dvec3, 3>& s,
             const glm::dvec4& planeS, double tol, std::array<glm::dvec3, 2>& segment) {
    std::array<double, 3> dT{}, dS{};
    int posT = 0, negT = 0, posS = 0, negS = 0;
    for (int i = 0; i < 3; ++i) {
        dT[std::size_t(i)] = snapped(glm::dot(glm::dvec3(planeS), t[std::size_t(i)]) + planeS.w, tol);
        dS[std::size_t(i)] = snapped(glm::dot(glm::dvec3(planeT), s[std::size_t(i)]) + planeT.w, tol);
        posT += dT[std::size_t(i)] > 0.0;
        negT += dT[std::size_t(i)] < 0.0;
        posS += dS[std::size_t(i)] > 0.0;
        negS += dS[std::size_t(i)] < 0.0;
    }
    if (posT == 3 || negT == 3 || posS == 3 || negS == 3) return false;
    if (posT + negT == 0 || posS + negS == 0) return false;  // coplanar
    const glm::dvec3 dir = glm::cross(glm::dvec3(planeT), glm::dvec3(planeS));
    if (!(glm::dot(dir, dir) > 1e-24)) return false;
    double loT, hiT, loS, hiS;
    if (!planeInterval(t, dT, dir, loT, hiT) || !planeInterval(s, dS, dir, loS, hiS)) return false;
    if (std::max(loT, loS) > std::min(hiT, hiS) + tol) return false;
    // The end points of s's crossing: the points of s on t's plane at the interval's ends.
    std::vector<glm::dvec3> points;
    for (int i = 0; i < 3; ++i) {
        const int j = (i + 1) % 3;
        if (dS[std::size_t(i)] == 0.0) points.push_back(s[std::size_t(i)]);
        if (dS[std::size_t(i)] * dS[std::size_t(j)] < 0.0) {
            const double u = dS[std::size_t(i)] / (dS[std::size_t(i)] - dS[std::size_t(j)]);
            points.push_back(s[std::size_t(i)] + u * (s[std::size_t(j)] - s[std::size_t(i)]));
        }
    }
    auto along = [&](const glm::dvec3& q) { return glm::dot(q, dir); };
    const auto [lo, hi] = std::minmax_element(points.begin(), points.end(),
                                              [&](const glm::dvec3& a, const glm::dvec3& b) { return along(a) < along(b); });
    segment = {*lo, *hi};
    return true;
}

// A vertex of a piece being cut: its id in the output, position, barycentric coordinates in the input triangle,
// and the input edge it lies on (a == b: it is corner a; a < 0: inside the triangle).
struct PieceVertex {
    int id;
    glm::dvec3 p;
    glm::dvec3 bary;
    int a, b;
};
using Piece = std::vector<PieceVertex>;

// The input edge both vertices lie on, as (lower id, higher id), or (-1, -1).
std::pair<int, int> commonEdge(const PieceVertex& u, const PieceVertex& v) {
    if (u.a < 0 || v.a < 0) return {-1, -1};
    const bool uCorner = u.a == u.b, vCorner = v.a == v.b;
    if (uCorner && vCorner) return u.a == v.a ? std::pair{-1, -1} : std::pair{std::min(u.a, v.a), std::max(u.a, v.a)};
    if (uCorner) return (u.a == v.a || u.a == v.b) ? std::pair{v.a, v.b} : std::pair{-1, -1};
    if (vCorner) return (v.a == u.a || v.a == u.b) ? std::pair{u.a, u.b} : std::pair{-1, -1};
    return (u.a == v.a && u.b == v.b) ? std::pair{u.a, u.b} : std::pair{-1, -1};
}

// Area of a convex piece (a fan from its first vertex).
double pieceArea(const Piece& piece) {
    double area = 0.0;
    for (std::size_t i = 1; i + 1 < piece.size(); ++i)
        area += 0.5 * glm::length(glm::cross(piece[i].p - piece[0].p, piece[i + 1].p - piece[0].p));
    return area;
}

struct OutVertex {
    glm::dvec3 p;
    OpenMesh::Vec3d normal;
    OpenMesh::Vec2f uv0, uv1;
    int sourceVertex;
    bool pending;  // made by a cut: attributes still to interpolate (OpenMesh vectors start uninitialised: set them)
};

}  // namespace

SolidSet::SolidSet(const Scene& scene, double toleranceM) : toleranceM_(toleranceM) {
    faceComponent_.resize(scene.instances.size());
    for (std::size_t inst = 0; inst < scene.instances.size(); ++inst) {
        const SurfaceMesh& m = scene.instances[inst].mesh;
        // Weld by exact position: glTF exporters give every face its own vertices.
        std::map<glm::dvec3, int, PositionLess> weld;
        std::vector<int> welded(m.n_vertices());
        for (auto v : m.vertices())
            welded[std::size_t(v.idx())] = weld.emplace(toGlm(m.point(v)), int(weld.size())).first->second;
        UnionFind parts(weld.size());
        std::vector<std::array<int, 3>> tri(m.n_faces());
        for (auto f : m.faces()) {
            int k = 0;
            for (auto v : m.fv_range(f)) tri[std::size_t(f.idx())][std::size_t(k++)] = welded[std::size_t(v.idx())];
            const auto& t = tri[std::size_t(f.idx())];
            parts.unite(std::uint32_t(t[0]), std::uint32_t(t[1]));
            parts.unite(std::uint32_t(t[0]), std::uint32_t(t[2]));
        }
        std::map<std::uint32_t, int> componentOfRoot;
        std::vector<int> component(m.n_faces());
        for (std::size_t f = 0; f < tri.size(); ++f)
            component[f] = componentOfRoot.emplace(parts.find(std::uint32_t(tri[f][0])), int(componentOfRoot.size())).first->second;
        std::vector<int>& bySource = faceComponent_[inst];
        for (auto f : m.faces()) {
            const int src = m.sourceFace(f);
            if (src < 0) continue;
            if (std::size_t(src) >= bySource.size()) bySource.resize(std::size_t(src) + 1, -1);
            bySource[std::size_t(src)] = component[std::size_t(f.idx())];
        }

        // Closed and oriented: every welded edge used as often in one direction as in the other.
        const std::size_t count = componentOfRoot.size();
        std::vector<std::map<std::pair<int, int>, int>> balance(count);
        std::vector<double> volume(count, 0.0);
        std::vector<glm::dvec3> lo(count, glm::dvec3(1e300)), hi(count, glm::dvec3(-1e300));
        for (auto f : m.faces()) {
            const auto c = std::size_t(component[std::size_t(f.idx())]);
            const auto& t = tri[std::size_t(f.idx())];
            for (int k = 0; k < 3; ++k) {
                const int a = t[std::size_t(k)], b = t[std::size_t((k + 1) % 3)];
                balance[c][{std::min(a, b), std::max(a, b)}] += a < b ? 1 : -1;
            }
            for (auto v : m.fv_range(f)) {
                lo[c] = glm::min(lo[c], toGlm(m.point(v)));
                hi[c] = glm::max(hi[c], toGlm(m.point(v)));
            }
        }
        std::vector<Solid> found(count);
        for (auto f : m.faces()) {
            const auto c = std::size_t(component[std::size_t(f.idx())]);
            std::array<glm::dvec3, 3> p{};
            int k = 0;
            for (auto v : m.fv_range(f)) p[std::size_t(k++)] = toGlm(m.point(v));
            const glm::dvec3 o = 0.5 * (lo[c] + hi[c]);  // volume about the bounds' centre: exact far from the origin
            volume[c] += glm::dot(p[0] - o, glm::cross(p[1] - o, p[2] - o)) / 6.0;
            found[c].triangles.push_back(p);
        }
        for (std::size_t c = 0; c < count; ++c) {
            const bool closed = std::all_of(balance[c].begin(), balance[c].end(), [](const auto& e) { return e.second == 0; });
            const glm::dvec3 size = hi[c] - lo[c];
            const double thin = std::max(toleranceM_, 1e-6 * glm::length(size));
            if (!closed || !(volume[c] > thin * glm::length(size) * glm::length(size))) continue;
            Solid& s = found[c];
            s.instance = inst;
            s.component = int(c);
            s.lo = lo[c];
            s.hi = hi[c];
            for (const auto& t : s.triangles) {
                const glm::dvec4 plane = planeOf(t);
                std::size_t k = 0;
                // Coplanar triangles share a plane, so a wall face of many triangles is one cut line.
                const std::size_t searched = std::min<std::size_t>(s.planes.size(), 256);
                for (; k < searched; ++k)
                    if (glm::dot(glm::dvec3(s.planes[k]), glm::dvec3(plane)) > 1.0 - 1e-12 &&
                        std::abs(glm::dot(glm::dvec3(plane), t[0]) + s.planes[k].w) <= toleranceM_)
                        break;
                if (k == searched) {
                    k = s.planes.size();
                    s.planes.push_back(plane);
                }
                s.planeOfTriangle.push_back(k);
            }
            solids_.push_back(std::move(s));
        }
    }

    // Grid cells about the median solid's size, so a lookup visits a few cells and a few solids each.
    if (solids_.empty()) return;
    std::vector<double> sizes;
    glm::dvec3 sceneLo(1e300), sceneHi(-1e300);
    for (const Solid& s : solids_) {
        sizes.push_back(glm::length(s.hi - s.lo));
        sceneLo = glm::min(sceneLo, s.lo);
        sceneHi = glm::max(sceneHi, s.hi);
    }
    std::nth_element(sizes.begin(), sizes.begin() + std::ptrdiff_t(sizes.size() / 2), sizes.end());
    cellM_ = std::max({sizes[sizes.size() / 2], glm::length(sceneHi - sceneLo) / 64.0, 1e-12});
    auto cell = [this](double x) { return std::int64_t(std::floor(x / cellM_)); };
    for (std::size_t i = 0; i < solids_.size(); ++i) {
        const Solid& s = solids_[i];
        const glm::dvec3 a = s.lo - toleranceM_, b = s.hi + toleranceM_;
        const double cellsSpanned = double(cell(b.x) - cell(a.x) + 1) * double(cell(b.y) - cell(a.y) + 1) *
                                    double(cell(b.z) - cell(a.z) + 1);
        if (cellsSpanned > 4096.0) {
            large_.push_back(i);
            continue;
        }
        for (std::int64_t x = cell(a.x); x <= cell(b.x); ++x)
            for (std::int64_t y = cell(a.y); y <= cell(b.y); ++y)
                for (std::int64_t z = cell(a.z); z <= cell(b.z); ++z) cells_[cellKey(x, y, z)].push_back(i);
    }
}

void SolidSet::overlapping(const glm::dvec3& lo, const glm::dvec3& hi, std::vector<std::size_t>& out) const {
    const std::size_t first = out.size();
    auto overlaps = [&](const Solid& s) {
        return s.lo.x <= hi.x + toleranceM_ && lo.x <= s.hi.x + toleranceM_ && s.lo.y <= hi.y + toleranceM_ &&
               lo.y <= s.hi.y + toleranceM_ && s.lo.z <= hi.z + toleranceM_ && lo.z <= s.hi.z + toleranceM_;
    };
    for (std::size_t i : large_)
        if (overlaps(solids_[i])) out.push_back(i);
    if (!cells_.empty()) {
        auto cell = [this](double x) { return std::int64_t(std::floor(x / cellM_)); };
        const glm::dvec3 a = lo - toleranceM_, b = hi + toleranceM_;
        const double cellsSpanned = double(cell(b.x) - cell(a.x) + 1) * double(cell(b.y) - cell(a.y) + 1) *
                                    double(cell(b.z) - cell(a.z) + 1);
        if (cellsSpanned > double(cells_.size())) {
            for (std::size_t i = 0; i < solids_.size(); ++i)
                if (overlaps(solids_[i])) out.push_back(i);
        } else {
            for (std::int64_t x = cell(a.x); x <= cell(b.x); ++x)
                for (std::int64_t y = cell(a.y); y <= cell(b.y); ++y)
                    for (std::int64_t z = cell(a.z); z <= cell(b.z); ++z) {
                        auto it = cells_.find(cellKey(x, y, z));
                        if (it == cells_.end()) continue;
                        for (std::size_t i : it->second)
                            if (overlaps(solids_[i])) out.push_back(i);
                    }
        }
    }
    std::sort(out.begin() + std::ptrdiff_t(first), out.end());
    out.erase(std::unique(out.begin() + std::ptrdiff_t(first), out.end()), out.end());
}

double SolidSet::windingNumber(std::size_t s, const glm::dvec3& p) const {
    // Σ of the triangles' signed solid angles (Van Oosterom & Strackee) / 4π.
    double sum = 0.0;
    for (const auto& t : solids_[s].triangles) {
        const glm::dvec3 a = t[0] - p, b = t[1] - p, c = t[2] - p;
        const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
        const double num = glm::dot(a, glm::cross(b, c));
        const double den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
        sum += 2.0 * std::atan2(num, den);
    }
    return sum / (4.0 * M_PI);
}

SurfaceMesh cutAlongSolids(const SurfaceMesh& mesh, std::size_t instance, const SolidSet& solids, bool doubleSided,
                           double gapM, SolidCutStats* stats, std::vector<int>* fromFace) {
    const double tol = solids.toleranceM();
    SolidCutStats local;

    std::vector<OutVertex> verts;
    verts.reserve(mesh.n_vertices());
    for (auto v : mesh.vertices())
        verts.push_back({toGlm(mesh.point(v)), mesh.normal(v), mesh.texcoord2D(v), mesh.lightmapUv(v), mesh.sourceVertex(v), false});
    struct OutFace {
        std::array<int, 3> v;
        int from;  // input face
    };
    std::vector<OutFace> faces;
    faces.reserve(mesh.n_faces());
    // Vertices on input edges, keyed by (edge, plane); inside a triangle, by (piece edge, plane).
    std::map<std::tuple<int, int, std::uint64_t>, int> edgeVertex;

    std::vector<std::size_t> candidates;
    // Cut lines of one triangle: a solid's plane and where its triangles in that plane meet the triangle's plane.
    std::map<std::uint64_t, std::vector<std::array<glm::dvec3, 2>>> lines;
    std::map<std::uint64_t, glm::dvec4> linePlanes;  // the plane each line cuts along
    std::vector<Piece> pieces, next;
    for (auto f : mesh.faces()) {
        std::array<int, 3> ids{};
        std::array<glm::dvec3, 3> p{};
        int k = 0;
        for (auto v : mesh.fv_range(f)) {
            ids[std::size_t(k)] = v.idx();
            p[std::size_t(k)] = toGlm(mesh.point(v));
            ++k;
        }
        const glm::dvec4 planeT = planeOf(p);
        candidates.clear();
        const double reachM = std::max(gapM, 0.0);
        solids.overlapping(glm::min(p[0], glm::min(p[1], p[2])) - reachM, glm::max(p[0], glm::max(p[1], p[2])) + reachM,
                           candidates);
        candidates.erase(std::remove_if(candidates.begin(), candidates.end(),
                                        [&](std::size_t s) {
                                            const SolidSet::Solid& solid = solids.solids()[s];
                                            return solid.instance == instance &&
                                                   solid.component == solids.componentOf(instance, mesh.sourceFace(f));
                                        }),
                         candidates.end());
        if (candidates.empty() || glm::dvec3(planeT) == glm::dvec3(0.0)) {
            faces.push_back({ids, f.idx()});
            continue;
        }
        lines.clear();
        linePlanes.clear();
        const glm::dvec3 normalT(planeT);
        const double lift = 16.0 * tol;
        bool gapCut = false;
        for (std::size_t s : candidates) {
            const SolidSet::Solid& solid = solids.solids()[s];
            // Where the solid lies along the face's normal: crossing its plane, or wholly in front of (behind) it.
            double dMin = std::numeric_limits<double>::infinity(), dMax = -dMin;
            for (const auto& st : solid.triangles)
                for (const glm::dvec3& q : st) {
                    const double d = glm::dot(normalT, q) + planeT.w;
                    dMin = std::min(dMin, d);
                    dMax = std::max(dMax, d);
                }
            // A solid hanging within gapM of the face (a light panel under a ceiling): cut along the outline it
            // casts straight onto the face, found where its surface crosses a copy of the face's plane moved into
            // it, and keep both sides. The gap's light then lands on elements of its own.
            double shiftM = 0.0;
            if (dMin > lift && dMin <= gapM) shiftM = dMin + 0.5 * (std::min(dMax, dMin + gapM) - dMin);
            else if (doubleSided && dMax < -lift && dMax >= -gapM) shiftM = dMax - 0.5 * (dMax - std::max(dMin, dMax - gapM));
            std::array<glm::dvec3, 3> shifted = p;
            for (glm::dvec3& q : shifted) q += shiftM * normalT;
            const glm::dvec4 shiftedPlane(normalT, planeT.w - shiftM);
            const glm::dvec3 tLo = glm::min(shifted[0], glm::min(shifted[1], shifted[2])) - tol,
                             tHi = glm::max(shifted[0], glm::max(shifted[1], shifted[2])) + tol;
            for (std::size_t t = 0; t < solid.triangles.size(); ++t) {
                const auto& st = solid.triangles[t];
                const std::size_t plane = solid.planeOfTriangle[t];
                const glm::dvec3 sLo = glm::min(st[0], glm::min(st[1], st[2])), sHi = glm::max(st[0], glm::max(st[1], st[2]));
                if (glm::any(glm::lessThan(sHi, tLo)) || glm::any(glm::greaterThan(sLo, tHi))) continue;
                std::array<glm::dvec3, 2> segment;
                if (!crosses(shifted, shiftedPlane, st, solid.planes[plane], tol, segment)) continue;
                const std::uint64_t key = (std::uint64_t(s) << 32) | std::uint64_t(plane);
                glm::dvec4 cut = solid.planes[plane];
                if (shiftM != 0.0) {
                    // The plane through the cast outline, square to the face: the solid's plane tilted upright.
                    const glm::dvec3 n(cut);
                    const glm::dvec3 upright = n - glm::dot(n, normalT) * normalT;
                    const double length = glm::length(upright);
                    if (!(length > 1e-6)) continue;  // parallel to the face: casts no outline
                    const glm::dvec3 onFace = 0.5 * (segment[0] + segment[1]) - shiftM * normalT;
                    cut = glm::dvec4(upright / length, -glm::dot(upright / length, onFace));
                    for (glm::dvec3& q : segment) q -= shiftM * normalT;
                    gapCut = true;
                }
                lines[key].push_back(segment);
                linePlanes[key] = cut;
            }
        }

        pieces.assign(1, Piece{{ids[0], p[0], {1, 0, 0}, ids[0], ids[0]},
                               {ids[1], p[1], {0, 1, 0}, ids[1], ids[1]},
                               {ids[2], p[2], {0, 0, 1}, ids[2], ids[2]}});
        auto cornerPosition = [&](int id) {
            for (int c = 0; c < 3; ++c)
                if (ids[std::size_t(c)] == id) return std::pair{p[std::size_t(c)], glm::dvec3(c == 0, c == 1, c == 2)};
            return std::pair{glm::dvec3(0.0), glm::dvec3(0.0)};
        };
        // The vertex where piece edge (u, v) meets `plane` (distances du, dv of opposite signs).
        auto cutVertex = [&](const PieceVertex& u, const PieceVertex& v, double du, double dv, std::uint64_t line,
                             const glm::dvec4& plane) {
            const auto [ea, eb] = commonEdge(u, v);
            if (ea >= 0) {
                const auto key = std::tuple{ea, eb, line};
                const auto [pa, ba] = cornerPosition(ea);
                const auto [pb, bb] = cornerPosition(eb);
                const double da = glm::dot(glm::dvec3(plane), pa) + plane.w, db = glm::dot(glm::dvec3(plane), pb) + plane.w;
                const double t = std::clamp(da / (da - db), 0.0, 1.0);
                const glm::dvec3 bary = ba + t * (bb - ba);
                auto it = edgeVertex.find(key);
                if (it == edgeVertex.end()) {
                    it = edgeVertex.emplace(key, int(verts.size())).first;
                    verts.push_back({pa + t * (pb - pa), OpenMesh::Vec3d(0.0), OpenMesh::Vec2f(0.0f), OpenMesh::Vec2f(0.0f), -1, true});
                }
                return PieceVertex{it->second, verts[std::size_t(it->second)].p, bary, ea, eb};
            }
            const bool uFirst = u.id < v.id;
            const PieceVertex& lo = uFirst ? u : v;
            const PieceVertex& hi = uFirst ? v : u;
            const double dlo = uFirst ? du : dv, dhi = uFirst ? dv : du;
            const double t = dlo / (dlo - dhi);
            const glm::dvec3 bary = lo.bary + t * (hi.bary - lo.bary);
            const auto key = std::tuple{lo.id, hi.id, line};
            auto it = edgeVertex.find(key);
            if (it == edgeVertex.end()) {
                it = edgeVertex.emplace(key, int(verts.size())).first;
                verts.push_back({lo.p + t * (hi.p - lo.p), OpenMesh::Vec3d(0.0), OpenMesh::Vec2f(0.0f), OpenMesh::Vec2f(0.0f), -1, true});
            }
            return PieceVertex{it->second, verts[std::size_t(it->second)].p, bary, -1, -1};
        };
        // Whether a segment of the line runs through the piece's interior (Cyrus–Beck against its edges, pieces
        // being convex and wound as the triangle): a piece the solid's surface does not enter needs no cut, which
        // keeps cuts where the solid is instead of across the whole triangle.
        auto entered = [&](const Piece& piece, const std::vector<std::array<glm::dvec3, 2>>& segments) {
            for (const auto& [a, b] : segments) {
                double t0 = 0.0, t1 = 1.0;
                for (std::size_t i = 0; i < piece.size() && t0 < t1; ++i) {
                    const glm::dvec3 e = piece[(i + 1) % piece.size()].p - piece[i].p;
                    const double len = glm::length(e);
                    if (!(len > 0.0)) continue;
                    const glm::dvec3 inward = glm::cross(normalT, e) / len;
                    const double fa = glm::dot(inward, a - piece[i].p), fb = glm::dot(inward, b - piece[i].p);
                    if (fa < tol && fb < tol) t1 = -1.0;
                    else if (fa < tol) t0 = std::max(t0, (tol - fa) / (fb - fa));
                    else if (fb < tol) t1 = std::min(t1, (tol - fa) / (fb - fa));
                }
                if (t0 < t1 && (t1 - t0) * glm::length(b - a) > tol) return true;
            }
            return false;
        };
        for (const auto& [line, segments] : lines) {
            const glm::dvec4 plane = linePlanes.at(line);
            next.clear();
            for (Piece& piece : pieces) {
                std::vector<double> d(piece.size());
                bool pos = false, neg = false;
                for (std::size_t i = 0; i < piece.size(); ++i) {
                    d[i] = snapped(glm::dot(glm::dvec3(plane), piece[i].p) + plane.w, tol);
                    pos |= d[i] > 0.0;
                    neg |= d[i] < 0.0;
                }
                if (!pos || !neg || !entered(piece, segments)) {
                    next.push_back(std::move(piece));
                    continue;
                }
                Piece in, out;
                for (std::size_t i = 0; i < piece.size(); ++i) {
                    const std::size_t j = (i + 1) % piece.size();
                    if (d[i] <= 0.0) in.push_back(piece[i]);
                    if (d[i] >= 0.0) out.push_back(piece[i]);
                    if (d[i] * d[j] < 0.0) {
                        const PieceVertex x = cutVertex(piece[i], piece[j], d[i], d[j], line, plane);
                        in.push_back(x);
                        out.push_back(x);
                    }
                }
                next.push_back(std::move(in));
                next.push_back(std::move(out));
            }
            std::swap(pieces, next);
        }

        // Keep a piece unless a point just off its front (and, double-sided, its back) is inside a solid.
        const glm::dvec3& normal = normalT;
        auto covered = [&](const glm::dvec3& q) {
            for (std::size_t s : candidates) {
                const SolidSet::Solid& solid = solids.solids()[s];
                if (glm::any(glm::lessThan(q, solid.lo)) || glm::any(glm::greaterThan(q, solid.hi))) continue;
                if (solids.windingNumber(s, q) > 0.5) return true;
            }
            return false;
        };
        const double faceArea = 0.5 * glm::length(glm::cross(p[1] - p[0], p[2] - p[0]));
        std::vector<const Piece*> keep;
        for (const Piece& piece : pieces) {
            glm::dvec3 centre(0.0);
            for (const PieceVertex& v : piece) centre += v.p;
            centre /= double(piece.size());
            const bool buried = covered(centre + lift * normal) && (!doubleSided || covered(centre - lift * normal));
            if (buried)
                local.areaDroppedM2 += pieceArea(piece);
            else
                keep.push_back(&piece);
        }
        if (pieces.size() == 1) {
            if (keep.size() == 1) faces.push_back({ids, f.idx()});
            else ++local.facesDropped;
            continue;
        }
        ++local.facesCut;
        if (gapCut) ++local.facesCutAtGaps;
        local.piecesDropped += pieces.size() - keep.size();
        if (keep.empty()) ++local.facesDropped;

        // Attributes of new vertices from the input triangle's corners.
        std::array<SurfaceMesh::VertexHandle, 3> corner;
        k = 0;
        for (auto v : mesh.fv_range(f)) corner[std::size_t(k++)] = v;
        auto attributes = [&](OutVertex& out, const glm::dvec3& bary) {
            OpenMesh::Vec3d n(0.0);
            OpenMesh::Vec2f uv0(0.0f), uv1(0.0f);
            int nearest = 0;
            for (int c = 0; c < 3; ++c) {
                const double w = bary[c];
                n += w * mesh.normal(corner[std::size_t(c)]);
                uv0 += float(w) * mesh.texcoord2D(corner[std::size_t(c)]);
                uv1 += float(w) * mesh.lightmapUv(corner[std::size_t(c)]);
                if (bary[c] > bary[nearest]) nearest = c;
            }
            const double len = n.norm();
            out.normal = len > 0.0 ? n / len : mesh.normal(corner[0]);
            out.uv0 = uv0;
            out.uv1 = uv1;
            out.sourceVertex = mesh.sourceVertex(corner[std::size_t(nearest)]);
            out.pending = false;
        };
        for (const Piece* kp : keep) {
            Piece piece;
            for (const PieceVertex& v : *kp)
                if (piece.empty() || v.id != piece.back().id) piece.push_back(v);
            while (piece.size() > 1 && piece.front().id == piece.back().id) piece.pop_back();
            if (piece.size() < 3) continue;
            for (const PieceVertex& v : piece)
                if (verts[std::size_t(v.id)].pending) attributes(verts[std::size_t(v.id)], v.bary);
            if (!(pieceArea(piece) > 1e-12 * faceArea)) continue;
            // A convex piece: drop the vertices along its sides (where other lines ended; the boundary conforming
            // of mesh/subdivision splits the neighbour's edge there again) and fan from a corner.
            Piece corners;
            for (std::size_t i = 0; i < piece.size(); ++i) {
                const glm::dvec3& a = piece[(i + piece.size() - 1) % piece.size()].p;
                const glm::dvec3& b = piece[(i + 1) % piece.size()].p;
                const glm::dvec3 ab = b - a;
                const double len = glm::length(ab);
                if (len > 0.0 && glm::length(glm::cross(ab, piece[i].p - a)) / len <= tol) continue;
                corners.push_back(piece[i]);
            }
            if (corners.size() < 3) continue;
            for (std::size_t i = 1; i + 1 < corners.size(); ++i)
                faces.push_back({{corners[0].id, corners[i].id, corners[i + 1].id}, f.idx()});
        }
    }

    // The output mesh: used vertices only, faces in input order; a face OpenMesh refuses (a non-manifold edge)
    // gets its own vertices, as the loader makes sheets.
    SurfaceMesh out;
    if (fromFace) fromFace->clear();
    std::vector<SurfaceMesh::VertexHandle> handle(verts.size());
    auto addVertex = [&](int i) {
        const OutVertex& v = verts[std::size_t(i)];
        const auto h = out.add_vertex({v.p.x, v.p.y, v.p.z});
        out.set_normal(h, v.normal);
        out.set_texcoord2D(h, v.uv0);
        out.lightmapUv(h) = v.uv1;
        out.sourceVertex(h) = v.sourceVertex;
        return h;
    };
    for (const OutFace& face : faces) {
        std::array<SurfaceMesh::VertexHandle, 3> h;
        for (int c = 0; c < 3; ++c) {
            auto& known = handle[std::size_t(face.v[std::size_t(c)])];
            if (!known.is_valid()) known = addVertex(face.v[std::size_t(c)]);
            h[std::size_t(c)] = known;
        }
        auto added = out.add_face(h[0], h[1], h[2]);
        if (!added.is_valid()) added = out.add_face(addVertex(face.v[0]), addVertex(face.v[1]), addVertex(face.v[2]));
        if (!added.is_valid()) continue;
        if (fromFace) fromFace->push_back(face.from);
        const SurfaceMesh::FaceHandle from(face.from);
        out.material(added) = mesh.material(from);
        out.instance(added) = mesh.instance(from);
        out.sourceFace(added) = mesh.sourceFace(from);
    }
    out.update_face_normals();
    if (stats) *stats += local;
    return out;
}

}  // namespace hemibake
