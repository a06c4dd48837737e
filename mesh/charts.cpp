#include "mesh/charts.h"
#include "mesh/surface_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <queue>

#include <Eigen/Dense>
#include <OpenMesh/Core/System/omstream.hh>

namespace hemibake {

namespace {

using HalfedgeHandle = SurfaceMesh::HalfedgeHandle;
using FaceHandle = SurfaceMesh::FaceHandle;


std::array<HalfedgeHandle, 3> faceHalfedges(const SurfaceMesh& mesh, int f) {
    const HalfedgeHandle h0 = mesh.halfedge_handle(FaceHandle(f));
    const HalfedgeHandle h1 = mesh.next_halfedge_handle(h0);
    const HalfedgeHandle h2 = mesh.next_halfedge_handle(h1);
    return {h0, h1, h2};
}

// Face across halfedge h, or -1 at a mesh boundary.
int faceAcross(const SurfaceMesh& mesh, HalfedgeHandle h) {
    const FaceHandle g = mesh.face_handle(mesh.opposite_halfedge_handle(h));
    return g.is_valid() ? g.idx() : -1;
}

double edgeLength(const SurfaceMesh& mesh, HalfedgeHandle h) {
    return (mesh.point(mesh.to_vertex_handle(h)) - mesh.point(mesh.from_vertex_handle(h))).norm();
}

// Area-weighted centroid and principal axes (largest first) of a face set.
void principalAxes(const FaceGeometry& g, std::span<const std::int32_t> faces, glm::dvec3& centre, glm::dvec3& e1,
                   glm::dvec3& e2) {
    double wsum = 0.0;
    glm::dvec3 c(0.0);
    for (int f : faces) {
        const double w = g.area[std::size_t(f)] > 0.0 ? g.area[std::size_t(f)] : 1e-300;
        c += w * g.centroid[std::size_t(f)];
        wsum += w;
    }
    c /= wsum;
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (int f : faces) {
        const double w = g.area[std::size_t(f)] > 0.0 ? g.area[std::size_t(f)] : 1e-300;
        const glm::dvec3 d = g.centroid[std::size_t(f)] - c;
        const Eigen::Vector3d v(d.x, d.y, d.z);
        cov += w * v * v.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
    const Eigen::Vector3d a = es.eigenvectors().col(2), b = es.eigenvectors().col(1);
    centre = c;
    e1 = {a.x(), a.y(), a.z()};
    e2 = {b.x(), b.y(), b.z()};
}

}  // namespace

FaceGeometry computeFaceGeometry(const SurfaceMesh& mesh) {
    FaceGeometry g;
    const std::size_t n = mesh.n_faces();
    g.normal.resize(n);
    g.centroid.resize(n);
    g.area.resize(n);
    for (std::size_t f = 0; f < n; ++f) {
        const auto hs = faceHalfedges(mesh, int(f));
        const glm::dvec3 a = toGlm(mesh.point(mesh.to_vertex_handle(hs[0])));
        const glm::dvec3 b = toGlm(mesh.point(mesh.to_vertex_handle(hs[1])));
        const glm::dvec3 c = toGlm(mesh.point(mesh.to_vertex_handle(hs[2])));
        const glm::dvec3 cr = glm::cross(b - a, c - a);
        const double len = glm::length(cr);
        g.area[f] = 0.5 * len;
        g.normal[f] = len > 0.0 && std::isfinite(len) ? cr / len : glm::dvec3(0.0);
        g.centroid[f] = (a + b + c) / 3.0;
    }
    return g;
}

ChartWorkspace::ChartWorkspace(const SurfaceMesh& m)
    : mesh(m), geometry(computeFaceGeometry(m)), faceMark(m.n_faces()), vertexMark(m.n_vertices()),
      halfedgeMark(m.n_halfedges()) {}

ChartTopology chartTopology(ChartWorkspace& ws, std::span<const std::int32_t> faces, bool wantLoops) {
    const SurfaceMesh& mesh = ws.mesh;
    ChartTopology t;
    ws.faceMark.reset();
    for (int f : faces) ws.faceMark.set(std::size_t(f), 1);
    ws.vertexMark.reset();
    ws.halfedgeMark.reset();
    auto inChart = [&](int g) { return g >= 0 && ws.faceMark.has(std::size_t(g)); };
    std::vector<HalfedgeHandle> boundary;
    for (int f : faces) {
        ++t.faces;
        for (HalfedgeHandle h : faceHalfedges(mesh, f)) {
            const int v = mesh.to_vertex_handle(h).idx();
            if (!ws.vertexMark.has(std::size_t(v))) {
                ws.vertexMark.set(std::size_t(v), 1);
                ++t.vertices;
            }
            const int g = faceAcross(mesh, h);
            if (!inChart(g)) {
                ++t.edges;
                boundary.push_back(h);
            } else if (h.idx() < mesh.opposite_halfedge_handle(h).idx()) {
                ++t.edges;
            }
        }
    }
    auto nextBoundary = [&](HalfedgeHandle h) {
        HalfedgeHandle n = mesh.next_halfedge_handle(h);
        for (int guard = 0; guard < 1 << 20; ++guard) {
            if (!inChart(faceAcross(mesh, n))) return n;
            n = mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(n));
        }
        return n;
    };
    for (HalfedgeHandle start : boundary) {
        if (ws.halfedgeMark.has(std::size_t(start.idx()))) continue;
        ++t.boundaryLoops;
        std::vector<std::int32_t> loop;
        HalfedgeHandle h = start;
        do {
            ws.halfedgeMark.set(std::size_t(h.idx()), 1);
            if (wantLoops) loop.push_back(mesh.to_vertex_handle(h).idx());
            h = nextBoundary(h);
        } while (h != start && !ws.halfedgeMark.has(std::size_t(h.idx())));
        if (wantLoops) t.loops.push_back(std::move(loop));
    }
    return t;
}

bool facesArePlanar(const FaceGeometry& g, std::span<const std::int32_t> faces, double toleranceRad, glm::dvec3* meanNormal) {
    glm::dvec3 sum(0.0);
    for (int f : faces) sum += g.area[std::size_t(f)] * g.normal[std::size_t(f)];
    const double len = glm::length(sum);
    const glm::dvec3 n = len > 0.0 ? sum / len : glm::dvec3(0.0, 0.0, 1.0);
    if (meanNormal) *meanNormal = n;
    if (!(len > 0.0)) return false;
    const double cosTol = std::cos(toleranceRad);
    for (int f : faces) {
        if (g.area[std::size_t(f)] <= 0.0) continue;
        if (glm::dot(g.normal[std::size_t(f)], n) < cosTol) return false;
    }
    return true;
}

std::vector<std::vector<std::int32_t>> connectedComponents(ChartWorkspace& ws, std::span<const std::int32_t> faces) {
    const SurfaceMesh& mesh = ws.mesh;
    ws.faceMark.reset();
    for (int f : faces) ws.faceMark.set(std::size_t(f), 0);  // 0 = member, unvisited; 1 = visited
    std::vector<std::vector<std::int32_t>> parts;
    std::vector<std::int32_t> stack;
    for (int seed : faces) {
        if (ws.faceMark.get(std::size_t(seed)) != 0) continue;
        std::vector<std::int32_t> part;
        ws.faceMark.set(std::size_t(seed), 1);
        stack.push_back(seed);
        while (!stack.empty()) {
            const int f = stack.back();
            stack.pop_back();
            part.push_back(f);
            for (HalfedgeHandle h : faceHalfedges(mesh, f)) {
                const int g = faceAcross(mesh, h);
                if (g >= 0 && ws.faceMark.get(std::size_t(g)) == 0) {
                    ws.faceMark.set(std::size_t(g), 1);
                    stack.push_back(g);
                }
            }
        }
        parts.push_back(std::move(part));
    }
    return parts;
}

std::vector<std::vector<std::int32_t>> splitFacesByPlane(ChartWorkspace& ws, std::span<const std::int32_t> faces,
                                                         const glm::dvec3& origin, const glm::dvec3& axis) {
    const FaceGeometry& g = ws.geometry;
    std::vector<std::int32_t> sideA, sideB;
    for (int f : faces) (glm::dot(g.centroid[std::size_t(f)] - origin, axis) < 0.0 ? sideA : sideB).push_back(f);
    if (sideA.empty() || sideB.empty()) {
        // Everything on one side: split at the median projection (keeps the recursion finite).
        std::vector<std::int32_t> sorted(faces.begin(), faces.end());
        std::stable_sort(sorted.begin(), sorted.end(), [&](int a, int b) {
            return glm::dot(g.centroid[std::size_t(a)], axis) < glm::dot(g.centroid[std::size_t(b)], axis);
        });
        const std::size_t half = sorted.size() / 2;
        sideA.assign(sorted.begin(), sorted.begin() + std::ptrdiff_t(half));
        sideB.assign(sorted.begin() + std::ptrdiff_t(half), sorted.end());
    }
    std::vector<std::vector<std::int32_t>> parts;
    for (auto* side : {&sideA, &sideB}) {
        if (side->empty()) continue;
        for (auto& p : connectedComponents(ws, *side)) parts.push_back(std::move(p));
    }
    return parts;
}

std::vector<std::vector<std::int32_t>> splitFacesInHalf(ChartWorkspace& ws, std::span<const std::int32_t> faces) {
    glm::dvec3 c, e1, e2;
    principalAxes(ws.geometry, faces, c, e1, e2);
    return splitFacesByPlane(ws, faces, c, e1);
}

std::vector<std::vector<std::int32_t>> splitIntoDisks(ChartWorkspace& ws, std::vector<std::int32_t> faces, int maxDepth,
                                                      std::size_t* splits) {
    std::vector<std::vector<std::int32_t>> result;
    std::vector<std::pair<std::vector<std::int32_t>, int>> stack;
    stack.emplace_back(std::move(faces), 0);
    auto allDisks = [&](const std::vector<std::vector<std::int32_t>>& parts) {
        for (const auto& p : parts)
            if (!chartTopology(ws, p).isDisk()) return false;
        return true;
    };
    while (!stack.empty()) {
        auto [part, depth] = std::move(stack.back());
        stack.pop_back();
        if (part.empty()) continue;
        const ChartTopology topo = chartTopology(ws, part, true);
        if (topo.isDisk() || part.size() == 1) {
            result.push_back(std::move(part));
            continue;
        }
        if (depth >= maxDepth) {
            for (int f : part) result.push_back({f});
            continue;
        }
        if (splits) ++*splits;
        glm::dvec3 c, e1, e2;
        principalAxes(ws.geometry, part, c, e1, e2);
        // Candidate cuts: through the centre of a hole (every loop but the longest), then through the chart's centre.
        std::vector<std::pair<glm::dvec3, glm::dvec3>> candidates;
        if (topo.loops.size() >= 2) {
            std::size_t longest = 0;
            for (std::size_t i = 1; i < topo.loops.size(); ++i)
                if (topo.loops[i].size() > topo.loops[longest].size()) longest = i;
            for (std::size_t i = 0; i < topo.loops.size() && candidates.size() < 4; ++i) {
                if (i == longest) continue;
                glm::dvec3 hc(0.0);
                for (int v : topo.loops[i]) hc += toGlm(ws.mesh.point(SurfaceMesh::VertexHandle(v)));
                hc /= double(topo.loops[i].size());
                candidates.push_back({hc, e1});
                candidates.push_back({hc, e2});
            }
        }
        candidates.push_back({c, e1});
        candidates.push_back({c, e2});
        std::vector<std::vector<std::int32_t>> chosen;
        for (const auto& [o, axis] : candidates) {
            auto parts = splitFacesByPlane(ws, part, o, axis);
            if (allDisks(parts)) {
                chosen = std::move(parts);
                break;
            }
        }
        if (chosen.empty()) chosen = splitFacesByPlane(ws, part, c, e1);
        for (auto& p : chosen) stack.emplace_back(std::move(p), depth + 1);
    }
    return result;
}

ChartSet computeCharts(const SurfaceMesh& mesh, const ChartSettings& s) {
    ChartWorkspace ws(mesh);
    const FaceGeometry& g = ws.geometry;
    const std::size_t nF = mesh.n_faces();
    const double creaseCos = std::cos(s.creaseAngleDegrees * M_PI / 180.0);
    constexpr double kInf = std::numeric_limits<double>::infinity();

    auto isHard = [&](int f, HalfedgeHandle h) {
        const int o = faceAcross(mesh, h);
        if (o < 0) return true;
        if (s.splitAtMaterials && mesh.material(FaceHandle(f)) != mesh.material(FaceHandle(o))) return true;
        if (g.area[std::size_t(f)] > 0.0 && g.area[std::size_t(o)] > 0.0 &&
            glm::dot(g.normal[std::size_t(f)], g.normal[std::size_t(o)]) < creaseCos)
            return true;
        return false;
    };

    std::vector<std::int32_t> faceChart(nF, -1);
    std::vector<std::int32_t> order(nF);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return g.area[std::size_t(a)] > g.area[std::size_t(b)]; });

    struct Growing {
        glm::dvec3 sumNormal{0.0};
        glm::dvec3 normal{0.0};
        double area = 0.0;
        double boundary = 0.0;
    };
    std::vector<std::vector<std::int32_t>> grown;
    std::size_t mergedCharts = 0;

    using Candidate = std::pair<double, std::int32_t>;
    std::priority_queue<Candidate, std::vector<Candidate>, std::greater<>> queue;

    auto cost = [&](const Growing& chart, int chartId, int f) {
        if (g.area[std::size_t(f)] <= 0.0) return 0.0;
        const double d = glm::dot(g.normal[std::size_t(f)], chart.normal);
        if (s.maxNormalDeviationCos > -1.0 && d < s.maxNormalDeviationCos) return kInf;  // ≤ −1: no limit
        double lIn = 0.0, lOut = 0.0;
        for (HalfedgeHandle h : faceHalfedges(mesh, f)) {
            const double l = edgeLength(mesh, h);
            const int o = faceAcross(mesh, h);
            (o >= 0 && faceChart[std::size_t(o)] == chartId ? lIn : lOut) += l;
        }
        const double newArea = chart.area + g.area[std::size_t(f)];
        const double newBoundary = chart.boundary + lOut - lIn;
        if (s.maxChartAreaM2 > 0.0 && newArea > s.maxChartAreaM2) return kInf;
        const double normalDeviation = std::min(1.0 - d, 1.0);
        double roundness = 0.0;
        if (chart.area > 0.0 && newBoundary > 0.0 && newArea > 0.0)
            roundness = 1.0 - (chart.boundary * chart.boundary / chart.area) / (newBoundary * newBoundary / newArea);
        const double straightness = lIn + lOut > 0.0 ? std::min((lOut - lIn) / (lOut + lIn), 0.0) : 0.0;
        return s.normalDeviationWeight * normalDeviation + s.roundnessWeight * roundness +
               s.straightnessWeight * straightness;
    };

    for (int seed : order) {
        if (faceChart[std::size_t(seed)] >= 0) continue;
        const int chartId = int(grown.size());
        grown.emplace_back();
        Growing chart;
        auto add = [&](int f) {
            faceChart[std::size_t(f)] = chartId;
            grown.back().push_back(f);
            double lIn = 0.0, lOut = 0.0;
            for (HalfedgeHandle h : faceHalfedges(mesh, f)) {
                const double l = edgeLength(mesh, h);
                const int o = faceAcross(mesh, h);
                (o >= 0 && faceChart[std::size_t(o)] == chartId && o != f ? lIn : lOut) += l;
            }
            chart.boundary += lOut - lIn;
            chart.area += g.area[std::size_t(f)];
            chart.sumNormal += g.area[std::size_t(f)] * g.normal[std::size_t(f)];
            const double len = glm::length(chart.sumNormal);
            if (len > 0.0) chart.normal = chart.sumNormal / len;
            for (HalfedgeHandle h : faceHalfedges(mesh, f)) {
                const int o = faceAcross(mesh, h);
                if (o < 0 || faceChart[std::size_t(o)] >= 0 || isHard(f, h)) continue;
                const double c = cost(chart, chartId, o);
                if (c <= s.maxCost) queue.push({c, o});
            }
        };
        add(seed);
        while (!queue.empty()) {
            const auto [oldCost, f] = queue.top();
            queue.pop();
            if (faceChart[std::size_t(f)] >= 0) continue;
            const double c = cost(chart, chartId, f);
            if (!(c <= s.maxCost)) continue;
            if (c > oldCost + 1e-12 && !queue.empty() && c > queue.top().first) {
                queue.push({c, f});
                continue;
            }
            add(f);
        }
    }

    // Merge small leftover charts into the neighbour they share most of their boundary with, when the merged
    // chart's faces stay within mergeNormalCos of its mean normal and it is still a disk (xatlas merges
    // similarly). Fewer tiny charts means fewer seams and less padding.
    if (s.mergeSmallCharts && grown.size() > 1) {
        std::vector<double> area(grown.size(), 0.0);
        std::vector<glm::dvec3> sumN(grown.size(), glm::dvec3(0.0));
        for (std::size_t c = 0; c < grown.size(); ++c)
            for (int f : grown[c]) {
                area[c] += g.area[std::size_t(f)];
                sumN[c] += g.area[std::size_t(f)] * g.normal[std::size_t(f)];
            }
        std::vector<double> sortedArea(area);
        std::nth_element(sortedArea.begin(), sortedArea.begin() + std::ptrdiff_t(sortedArea.size() / 2), sortedArea.end());
        const double small = 0.5 * sortedArea[sortedArea.size() / 2];
        std::vector<std::int32_t> order2(grown.size());
        std::iota(order2.begin(), order2.end(), 0);
        std::stable_sort(order2.begin(), order2.end(), [&](int a, int b) { return area[std::size_t(a)] < area[std::size_t(b)]; });
        std::vector<std::pair<int, double>> shared;
        for (int c : order2) {
            auto& faces = grown[std::size_t(c)];
            if (faces.empty() || area[std::size_t(c)] >= small) continue;
            shared.clear();
            double boundary = 0.0;
            for (int f : faces)
                for (HalfedgeHandle h : faceHalfedges(mesh, f)) {
                    const int o = faceAcross(mesh, h);
                    if (o >= 0 && faceChart[std::size_t(o)] == c) continue;
                    const double l = edgeLength(mesh, h);
                    boundary += l;
                    if (o < 0 || isHard(f, h)) continue;
                    const int n = faceChart[std::size_t(o)];
                    auto it = std::find_if(shared.begin(), shared.end(), [&](const auto& p) { return p.first == n; });
                    if (it == shared.end())
                        shared.push_back({n, l});
                    else
                        it->second += l;
                }
            std::sort(shared.begin(), shared.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
            for (const auto& [n, length] : shared) {
                if (length < 0.3 * boundary) break;
                const glm::dvec3 mergedSum = sumN[std::size_t(c)] + sumN[std::size_t(n)];
                const double len = glm::length(mergedSum);
                if (!(len > 0.0)) continue;
                const glm::dvec3 mean = mergedSum / len;
                bool ok = true;
                for (const auto* list : {&faces, &grown[std::size_t(n)]})
                    for (int f : *list)
                        if (g.area[std::size_t(f)] > 0.0 && glm::dot(g.normal[std::size_t(f)], mean) < s.mergeNormalCos) {
                            ok = false;
                            break;
                        }
                if (!ok) continue;
                std::vector<std::int32_t> merged = grown[std::size_t(n)];
                merged.insert(merged.end(), faces.begin(), faces.end());
                if (!chartTopology(ws, merged).isDisk() && !facesArePlanar(g, merged, s.planarToleranceRad)) continue;
                for (int f : faces) faceChart[std::size_t(f)] = n;
                grown[std::size_t(n)] = std::move(merged);
                faces.clear();
                area[std::size_t(n)] += area[std::size_t(c)];
                sumN[std::size_t(n)] = mergedSum;
                ++mergedCharts;
                break;
            }
        }
        grown.erase(std::remove_if(grown.begin(), grown.end(), [](const auto& v) { return v.empty(); }), grown.end());
    }

    // Finalize: planar flags, disk topology for curved charts.
    ChartSet out;
    out.mergedCharts = mergedCharts;
    out.faceChart.assign(nF, -1);
    out.chartFaceStart.push_back(0);
    auto emit = [&](const std::vector<std::int32_t>& faces, bool planar, const glm::dvec3& n) {
        const int id = int(out.planar.size());
        double area = 0.0;
        for (int f : faces) {
            out.faceChart[std::size_t(f)] = id;
            out.chartFaces.push_back(f);
            area += g.area[std::size_t(f)];
        }
        out.chartFaceStart.push_back(std::uint32_t(out.chartFaces.size()));
        out.planar.push_back(planar ? 1 : 0);
        out.normal.push_back(n);
        out.areaM2.push_back(area);
    };
    for (auto& faces : grown) {
        glm::dvec3 n;
        const bool planar = facesArePlanar(g, faces, s.planarToleranceRad, &n);
        if (planar && s.allowPlanarHoles) {
            if (faces.size() > 1 && !chartTopology(ws, faces).isDisk()) ++out.planarWithHoles;
            emit(faces, true, n);
            continue;
        }
        if (chartTopology(ws, faces).isDisk()) {
            emit(faces, planar, n);
            continue;
        }
        for (auto& part : splitIntoDisks(ws, std::move(faces), s.maxSplitDepth, &out.nonDiskSplits)) {
            glm::dvec3 pn;
            const bool pp = facesArePlanar(g, part, s.planarToleranceRad, &pn);
            emit(part, pp, pn);
        }
    }
    return out;
}

}  // namespace hemibake

namespace hemibake {

std::array<std::int32_t, 3> faceCorners(const SurfaceMesh& mesh, int f) {
    auto h = mesh.halfedge_handle(SurfaceMesh::FaceHandle(f));
    std::array<std::int32_t, 3> v{};
    for (int k = 0; k < 3; ++k, h = mesh.next_halfedge_handle(h)) v[std::size_t(k)] = mesh.to_vertex_handle(h).idx();
    return v;
}

std::optional<WeldedMesh> weldCoincidentVertices(const SurfaceMesh& mesh) {
    const std::size_t nV = mesh.n_vertices();
    // Representative of each vertex: the first vertex with a bit-identical position (−0 taken as +0).
    std::vector<std::int32_t> rep(nV);
    std::vector<std::int32_t> order(nV);
    std::iota(order.begin(), order.end(), 0);
    auto key = [&](int v) {
        const auto& p = mesh.point(SurfaceMesh::VertexHandle(v));
        return std::array<double, 3>{p[0] + 0.0, p[1] + 0.0, p[2] + 0.0};
    };
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key(a) < key(b); });
    std::size_t merged = 0;
    for (std::size_t i = 0; i < nV; ++i) {
        const int v = order[i];
        if (i > 0 && key(order[i - 1]) == key(v)) {
            rep[std::size_t(v)] = rep[std::size_t(order[i - 1])];
            ++merged;
        } else {
            rep[std::size_t(v)] = v;
        }
    }
    if (merged == 0) return std::nullopt;
    // OpenMesh reports refused (non-manifold) faces on omerr; those are handled below.
    struct Muted {
        bool was = omerr().is_enabled();
        Muted() { omerr().disable(); }
        ~Muted() { if (was) omerr().enable(); }
    } muted;

    WeldedMesh w;
    SurfaceMesh& out = w.mesh;
    out.reserve(nV - merged, 3 * mesh.n_faces() / 2, mesh.n_faces());
    std::vector<SurfaceMesh::VertexHandle> welded(nV);
    for (std::size_t v = 0; v < nV; ++v)
        if (rep[v] == std::int32_t(v)) welded[v] = out.add_vertex(mesh.point(SurfaceMesh::VertexHandle(int(v))));
    w.cornerSource.resize(3 * mesh.n_faces());
    w.mergedVertices = merged;
    for (std::size_t f = 0; f < mesh.n_faces(); ++f) {
        const auto c = faceCorners(mesh, int(f));
        SurfaceMesh::VertexHandle wv[3];
        for (int k = 0; k < 3; ++k) wv[k] = welded[std::size_t(rep[std::size_t(c[std::size_t(k)])])];
        SurfaceMesh::FaceHandle fh;
        if (wv[0] != wv[1] && wv[1] != wv[2] && wv[0] != wv[2]) fh = out.add_face(wv[0], wv[1], wv[2]);
        if (!fh.is_valid()) {
            // Would be non-manifold (or degenerate): keep the face on vertices of its own.
            for (int k = 0; k < 3; ++k) wv[k] = out.add_vertex(mesh.point(SurfaceMesh::VertexHandle(c[std::size_t(k)])));
            fh = out.add_face(wv[0], wv[1], wv[2]);
        }
        out.material(fh) = mesh.material(SurfaceMesh::FaceHandle(int(f)));
        out.instance(fh) = mesh.instance(SurfaceMesh::FaceHandle(int(f)));
        out.sourceFace(fh) = mesh.sourceFace(SurfaceMesh::FaceHandle(int(f)));
        // Welded corner order (halfedge order) is a rotation of (wv0, wv1, wv2).
        const auto wc = faceCorners(out, fh.idx());
        for (int k = 0; k < 3; ++k)
            for (int j = 0; j < 3; ++j)
                if (wc[std::size_t(k)] == wv[j].idx()) w.cornerSource[3 * std::size_t(fh.idx()) + std::size_t(k)] = c[std::size_t(j)];
    }
    return w;
}

}  // namespace hemibake
