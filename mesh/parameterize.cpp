#include "mesh/parameterize.h"
#include "mesh/frame_math.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_set>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

namespace hemibake {

namespace {

glm::dvec3 point(const SurfaceMesh& mesh, int v) {
    const auto& p = mesh.point(SurfaceMesh::VertexHandle(v));
    return {p[0], p[1], p[2]};
}


// An orthonormal basis (t, b) of the plane with normal n, with t × b = n.
void planeBasis(const glm::dvec3& n, glm::dvec3& t, glm::dvec3& b) {
    const glm::dvec3 a = std::abs(n.x) < 0.6 ? glm::dvec3(1, 0, 0) : (std::abs(n.y) < 0.6 ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, 1));
    t = glm::normalize(a - n * glm::dot(a, n));
    b = glm::cross(n, t);
}

double triangleArea3d(const SurfaceMesh& mesh, const ParamChart& c, std::size_t t) {
    const auto& tri = c.triangles[t];
    const glm::dvec3 a = point(mesh, c.vertices[std::size_t(tri[0])]);
    const glm::dvec3 b = point(mesh, c.vertices[std::size_t(tri[1])]);
    const glm::dvec3 d = point(mesh, c.vertices[std::size_t(tri[2])]);
    return 0.5 * glm::length(glm::cross(b - a, d - a));
}

double triangleAreaUv(const ParamChart& c, std::size_t t) {
    const auto& tri = c.triangles[t];
    const glm::dvec2 a = c.uv[std::size_t(tri[0])], b = c.uv[std::size_t(tri[1])], d = c.uv[std::size_t(tri[2])];
    return 0.5 * cross2(b - a, d - a);
}

bool segmentsIntersect(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c, const glm::dvec2& d) {
    auto orient = [](const glm::dvec2& p, const glm::dvec2& q, const glm::dvec2& r) { return cross2(q - p, r - p); };
    auto onSegment = [](const glm::dvec2& p, const glm::dvec2& q, const glm::dvec2& r) {
        return std::min(p.x, q.x) <= r.x && r.x <= std::max(p.x, q.x) && std::min(p.y, q.y) <= r.y && r.y <= std::max(p.y, q.y);
    };
    const double d1 = orient(c, d, a), d2 = orient(c, d, b), d3 = orient(a, b, c), d4 = orient(a, b, d);
    if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
    if (d1 == 0 && onSegment(c, d, a)) return true;
    if (d2 == 0 && onSegment(c, d, b)) return true;
    if (d3 == 0 && onSegment(a, b, c)) return true;
    if (d4 == 0 && onSegment(a, b, d)) return true;
    return false;
}

}  // namespace

const char* paramMethodName(ParamMethod m) {
    switch (m) {
        case ParamMethod::Planar: return "planar";
        case ParamMethod::Lscm: return "lscm";
        case ParamMethod::PerTriangle: return "per-triangle";
        case ParamMethod::Existing: return "existing";
    }
    return "?";
}

void StretchStats::merge(const StretchStats& o) {
    const double a = areaM2, b = o.areaM2, s = a + b;
    if (!(b > 0.0)) return;
    if (!(a > 0.0)) {
        *this = o;
        return;
    }
    l2 = std::sqrt((l2 * l2 * a + o.l2 * o.l2 * b) / s);
    linf = std::max(linf, o.linf);
    meanAngle = (meanAngle * a + o.meanAngle * b) / s;
    maxAngle = std::max(maxAngle, o.maxAngle);
    meanArea = (meanArea * a + o.meanArea * b) / s;
    maxArea = std::max(maxArea, o.maxArea);
    areaM2 = s;
}

ParamChart makeLocalChart(ChartWorkspace& ws, std::span<const std::int32_t> faces) {
    const SurfaceMesh& mesh = ws.mesh;
    ParamChart c;
    c.faces.assign(faces.begin(), faces.end());
    c.triangles.reserve(faces.size());
    ws.vertexMark.reset();
    for (int f : faces) {
        auto h = mesh.halfedge_handle(SurfaceMesh::FaceHandle(f));
        std::array<std::int32_t, 3> tri{};
        for (int k = 0; k < 3; ++k, h = mesh.next_halfedge_handle(h)) {
            const int v = mesh.to_vertex_handle(h).idx();
            int local = ws.vertexMark.get(std::size_t(v));
            if (local < 0) {
                local = int(c.vertices.size());
                ws.vertexMark.set(std::size_t(v), local);
                c.vertices.push_back(v);
            }
            tri[std::size_t(k)] = local;
        }
        c.triangles.push_back(tri);
        c.areaM2 += ws.geometry.area[std::size_t(f)];
    }
    c.uv.assign(c.vertices.size(), glm::dvec2(0.0));
    return c;
}

void projectPlanar(const SurfaceMesh& mesh, ParamChart& chart, const glm::dvec3& n) {
    glm::dvec3 t, b;
    planeBasis(n, t, b);
    const glm::dvec3 o = point(mesh, chart.vertices[0]);
    for (std::size_t i = 0; i < chart.vertices.size(); ++i) {
        const glm::dvec3 d = point(mesh, chart.vertices[i]) - o;
        chart.uv[i] = {glm::dot(d, t), glm::dot(d, b)};
    }
}

bool normalizeArea(const SurfaceMesh& mesh, ParamChart& chart) {
    double a3 = 0.0, auv = 0.0;
    for (std::size_t t = 0; t < chart.triangles.size(); ++t) {
        a3 += triangleArea3d(mesh, chart, t);
        auv += triangleAreaUv(chart, t);
    }
    if (!(auv > 0.0) || !(a3 > 0.0) || !std::isfinite(auv)) return false;
    const double s = std::sqrt(a3 / auv);
    for (auto& p : chart.uv) p *= s;
    return true;
}

bool solveLscm(const SurfaceMesh& mesh, ParamChart& chart) {
    const std::size_t n = chart.vertices.size();
    if (n < 3) return false;
    // Best-fit plane: area-weighted mean normal; projected positions seed the pins.
    glm::dvec3 sumN(0.0);
    for (const auto& tri : chart.triangles) {
        const glm::dvec3 a = point(mesh, chart.vertices[std::size_t(tri[0])]);
        const glm::dvec3 b = point(mesh, chart.vertices[std::size_t(tri[1])]);
        const glm::dvec3 d = point(mesh, chart.vertices[std::size_t(tri[2])]);
        sumN += glm::cross(b - a, d - a);
    }
    if (!(glm::length(sumN) > 0.0)) return false;
    glm::dvec3 t, b;
    planeBasis(glm::normalize(sumN), t, b);
    const glm::dvec3 o = point(mesh, chart.vertices[0]);
    std::vector<glm::dvec2> proj(n);
    glm::dvec2 mean(0.0);
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec3 d = point(mesh, chart.vertices[i]) - o;
        proj[i] = {glm::dot(d, t), glm::dot(d, b)};
        mean += proj[i];
    }
    mean /= double(n);
    double sxx = 0, sxy = 0, syy = 0;
    for (const auto& p : proj) {
        const glm::dvec2 d = p - mean;
        sxx += d.x * d.x;
        sxy += d.x * d.y;
        syy += d.y * d.y;
    }
    const double angle = 0.5 * std::atan2(2.0 * sxy, sxx - syy);
    const glm::dvec2 axis(std::cos(angle), std::sin(angle));
    std::size_t pin0 = 0, pin1 = 0;
    for (std::size_t i = 1; i < n; ++i) {
        if (glm::dot(proj[i], axis) < glm::dot(proj[pin0], axis)) pin0 = i;
        if (glm::dot(proj[i], axis) > glm::dot(proj[pin1], axis)) pin1 = i;
    }
    if (pin0 == pin1) return false;

    std::vector<int> column(n, -1);
    int free = 0;
    for (std::size_t i = 0; i < n; ++i)
        if (i != pin0 && i != pin1) column[i] = free++;
    const int nFree = free;
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(chart.triangles.size() * 12);
    std::vector<double> rhs;
    rhs.reserve(chart.triangles.size() * 2);
    int row = 0;
    for (const auto& tri : chart.triangles) {
        const glm::dvec3 p0 = point(mesh, chart.vertices[std::size_t(tri[0])]);
        const glm::dvec3 p1 = point(mesh, chart.vertices[std::size_t(tri[1])]);
        const glm::dvec3 p2 = point(mesh, chart.vertices[std::size_t(tri[2])]);
        const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0;
        const glm::dvec3 nrm = glm::cross(e1, e2);
        const double dT = glm::length(nrm);  // twice the area
        const double l1 = glm::length(e1);
        if (!(dT > 1e-14 * std::max(glm::dot(e1, e1), glm::dot(e2, e2))) || !(l1 > 0.0)) continue;
        const glm::dvec3 X = e1 / l1;
        const glm::dvec3 Y = glm::cross(nrm / dT, X);
        const glm::dvec2 z[3] = {{0.0, 0.0}, {l1, 0.0}, {glm::dot(e2, X), glm::dot(e2, Y)}};
        const glm::dvec2 W[3] = {z[2] - z[1], z[0] - z[2], z[1] - z[0]};
        const double s = 1.0 / std::sqrt(dT);
        double bRe = 0.0, bIm = 0.0;
        for (int j = 0; j < 3; ++j) {
            const std::size_t v = std::size_t(tri[std::size_t(j)]);
            const double a = W[j].x * s, bb = W[j].y * s;
            // Re: a·u − b·v ; Im: b·u + a·v
            if (column[v] < 0) {
                const glm::dvec2 pin = proj[v];
                bRe -= a * pin.x - bb * pin.y;
                bIm -= bb * pin.x + a * pin.y;
            } else {
                const int cu = column[v], cv = nFree + column[v];
                triplets.emplace_back(row, cu, a);
                triplets.emplace_back(row, cv, -bb);
                triplets.emplace_back(row + 1, cu, bb);
                triplets.emplace_back(row + 1, cv, a);
            }
        }
        rhs.push_back(bRe);
        rhs.push_back(bIm);
        row += 2;
    }
    if (row == 0) return false;
    Eigen::SparseMatrix<double> A(row, 2 * nFree);
    A.setFromTriplets(triplets.begin(), triplets.end());
    const Eigen::Map<const Eigen::VectorXd> bvec(rhs.data(), Eigen::Index(rhs.size()));
    Eigen::VectorXd x;
    if (nFree > 0) {
        const Eigen::SparseMatrix<double> AtA = A.transpose() * A;
        const Eigen::VectorXd Atb = A.transpose() * bvec;
        Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(AtA);
        if (solver.info() != Eigen::Success) return false;
        x = solver.solve(Atb);
        if (solver.info() != Eigen::Success || !x.allFinite()) return false;
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (column[i] < 0)
            chart.uv[i] = proj[i];
        else
            chart.uv[i] = {x[column[i]], x[nFree + column[i]]};
    }
    return true;
}

std::size_t countBadTriangles(const SurfaceMesh& mesh, const ParamChart& chart, double minAreaRatio) {
    std::size_t bad = 0;
    for (std::size_t t = 0; t < chart.triangles.size(); ++t) {
        const auto& tri = chart.triangles[t];
        const glm::dvec3 a = point(mesh, chart.vertices[std::size_t(tri[0])]);
        const glm::dvec3 b = point(mesh, chart.vertices[std::size_t(tri[1])]);
        const glm::dvec3 c = point(mesh, chart.vertices[std::size_t(tri[2])]);
        const double a3 = 0.5 * glm::length(glm::cross(b - a, c - a));
        const double longest2 = std::max({glm::dot(b - a, b - a), glm::dot(c - b, c - b), glm::dot(a - c, a - c)});
        if (!(a3 > 0.5e-12 * longest2)) continue;  // zero-area input triangle: cannot map to anything but zero
        if (!(triangleAreaUv(chart, t) > minAreaRatio * a3)) ++bad;
    }
    return bad;
}

bool boundaryOverlaps(const ParamChart& chart) {
    // Boundary edges: directed triangle edges whose reverse is not in the chart.
    std::unordered_set<std::uint64_t> directed;
    directed.reserve(chart.triangles.size() * 3);
    auto key = [](std::int32_t a, std::int32_t b) { return (std::uint64_t(std::uint32_t(a)) << 32) | std::uint32_t(b); };
    for (const auto& t : chart.triangles)
        for (int k = 0; k < 3; ++k) directed.insert(key(t[std::size_t(k)], t[std::size_t((k + 1) % 3)]));
    std::vector<std::array<std::int32_t, 2>> edges;
    for (const auto& t : chart.triangles)
        for (int k = 0; k < 3; ++k) {
            const auto a = t[std::size_t(k)], b = t[std::size_t((k + 1) % 3)];
            if (!directed.count(key(b, a))) edges.push_back({a, b});
        }
    if (edges.size() < 4) return false;
    glm::dvec2 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    for (const auto& e : edges)
        for (auto v : e) {
            lo = glm::min(lo, chart.uv[std::size_t(v)]);
            hi = glm::max(hi, chart.uv[std::size_t(v)]);
        }
    const glm::dvec2 ext = hi - lo;
    const int cells = std::clamp(int(std::sqrt(double(edges.size()))), 1, 512);
    const double cellSize = std::max(ext.x, ext.y) / cells + 1e-300;
    const int nx = std::max(1, int(ext.x / cellSize) + 1), ny = std::max(1, int(ext.y / cellSize) + 1);
    std::vector<std::vector<std::int32_t>> grid(std::size_t(nx) * std::size_t(ny));
    for (std::size_t i = 0; i < edges.size(); ++i) {
        const glm::dvec2 a = chart.uv[std::size_t(edges[i][0])], b = chart.uv[std::size_t(edges[i][1])];
        const glm::dvec2 emin = glm::min(a, b) - lo, emax = glm::max(a, b) - lo;
        const int x0 = std::clamp(int(emin.x / cellSize), 0, nx - 1), x1 = std::clamp(int(emax.x / cellSize), 0, nx - 1);
        const int y0 = std::clamp(int(emin.y / cellSize), 0, ny - 1), y1 = std::clamp(int(emax.y / cellSize), 0, ny - 1);
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) grid[std::size_t(y) * std::size_t(nx) + std::size_t(x)].push_back(std::int32_t(i));
    }
    for (const auto& cell : grid) {
        for (std::size_t i = 0; i < cell.size(); ++i) {
            const auto& e = edges[std::size_t(cell[i])];
            for (std::size_t j = i + 1; j < cell.size(); ++j) {
                const auto& f = edges[std::size_t(cell[j])];
                if (e[0] == f[0] || e[0] == f[1] || e[1] == f[0] || e[1] == f[1]) continue;
                if (segmentsIntersect(chart.uv[std::size_t(e[0])], chart.uv[std::size_t(e[1])], chart.uv[std::size_t(f[0])],
                                      chart.uv[std::size_t(f[1])]))
                    return true;
            }
        }
    }
    return false;
}

StretchStats measureStretch(const SurfaceMesh& mesh, const ParamChart& chart) {
    StretchStats s;
    double sumA = 0, sumL2 = 0, sumAngle = 0, sumArea = 0;
    double linf = 0, maxAngle = 0, maxArea = 0;
    for (const auto& tri : chart.triangles) {
        const glm::dvec3 q1 = point(mesh, chart.vertices[std::size_t(tri[0])]);
        const glm::dvec3 q2 = point(mesh, chart.vertices[std::size_t(tri[1])]);
        const glm::dvec3 q3 = point(mesh, chart.vertices[std::size_t(tri[2])]);
        const glm::dvec2 p1 = chart.uv[std::size_t(tri[0])], p2 = chart.uv[std::size_t(tri[1])], p3 = chart.uv[std::size_t(tri[2])];
        const double a3 = 0.5 * glm::length(glm::cross(q2 - q1, q3 - q1));
        const double A2 = cross2(p2 - p1, p3 - p1);  // twice the UV area
        if (!(a3 > 0.0) || !(A2 > 0.0)) continue;
        const glm::dvec3 Ss = (q1 * (p2.y - p3.y) + q2 * (p3.y - p1.y) + q3 * (p1.y - p2.y)) / A2;
        const glm::dvec3 St = (q1 * (p3.x - p2.x) + q2 * (p1.x - p3.x) + q3 * (p2.x - p1.x)) / A2;
        const double a = glm::dot(Ss, Ss), b = glm::dot(Ss, St), c = glm::dot(St, St);
        const double root = std::sqrt((a - c) * (a - c) + 4.0 * b * b);
        const double G = std::sqrt(std::max(0.0, 0.5 * ((a + c) + root)));
        const double g = std::sqrt(std::max(0.0, 0.5 * ((a + c) - root)));
        const double l2sq = 0.5 * (a + c);
        const double angle = g > 0.0 ? G / g : std::numeric_limits<double>::infinity();
        const double areaScale = G * g;
        const double area = areaScale > 0.0 ? std::max(areaScale, 1.0 / areaScale) : std::numeric_limits<double>::infinity();
        sumA += a3;
        sumL2 += l2sq * a3;
        sumAngle += angle * a3;
        sumArea += area * a3;
        linf = std::max(linf, G);
        maxAngle = std::max(maxAngle, angle);
        maxArea = std::max(maxArea, area);
    }
    if (sumA > 0.0) {
        s.l2 = std::sqrt(sumL2 / sumA);
        s.linf = linf;
        s.meanAngle = sumAngle / sumA;
        s.maxAngle = maxAngle;
        s.meanArea = sumArea / sumA;
        s.maxArea = maxArea;
        s.areaM2 = sumA;
    }
    return s;
}

ParameterizationResult parameterizeCharts(const SurfaceMesh& mesh, const ChartSet& charts, const ParameterizeSettings& settings) {
    ChartWorkspace ws(mesh);
    ParameterizationResult result;
    auto& stats = result.stats;
    const double planarTol = settings.planarToleranceRad;

    auto emit = [&](ParamChart&& c, ParamMethod m, int source) {
        c.method = m;
        c.sourceChart = source;
        c.stretch = measureStretch(mesh, c);
        stats.stretch.merge(c.stretch);
        stats.flippedOrDegenerate += countBadTriangles(mesh, c, settings.minAreaRatio);
        switch (m) {
            case ParamMethod::Planar: ++stats.planar; break;
            case ParamMethod::Lscm: ++stats.lscm; break;
            case ParamMethod::PerTriangle: ++stats.perTriangle; break;
            default: break;
        }
        result.charts.push_back(std::move(c));
    };
    auto perTriangle = [&](std::span<const std::int32_t> faces, int source) {
        for (int f : faces) {
            const std::int32_t one[1] = {f};
            ParamChart c = makeLocalChart(ws, one);
            glm::dvec3 n = ws.geometry.normal[std::size_t(f)];
            if (glm::length(n) == 0.0) n = {0.0, 0.0, 1.0};
            projectPlanar(mesh, c, n);
            emit(std::move(c), ParamMethod::PerTriangle, source);
        }
    };

    struct Work {
        std::vector<std::int32_t> faces;
        int depth;
    };
    std::vector<Work> stack;
    for (std::size_t ci = 0; ci < charts.size(); ++ci) {
        const int source = int(ci);
        const auto cf = charts.faces(ci);
        stack.push_back({std::vector<std::int32_t>(cf.begin(), cf.end()), 0});
        bool first = true;
        while (!stack.empty()) {
            Work w = std::move(stack.back());
            stack.pop_back();
            if (w.faces.empty()) continue;
            glm::dvec3 n;
            const bool planar = (first && charts.planar[ci]) || facesArePlanar(ws.geometry, w.faces, planarTol, &n);
            if (first && charts.planar[ci]) n = charts.normal[ci];
            first = false;
            if (planar) {
                ParamChart c = makeLocalChart(ws, w.faces);
                projectPlanar(mesh, c, n);
                if (normalizeArea(mesh, c) && countBadTriangles(mesh, c, settings.minAreaRatio) == 0) {
                    emit(std::move(c), ParamMethod::Planar, source);
                    continue;
                }
            } else {
                if (!chartTopology(ws, w.faces).isDisk()) {
                    std::size_t cuts = 0;
                    auto parts = splitIntoDisks(ws, std::move(w.faces), settings.maxSplitDepth, &cuts);
                    stats.splits += cuts;
                    for (auto& p : parts) stack.push_back({std::move(p), w.depth + 1});
                    continue;
                }
                ParamChart c = makeLocalChart(ws, w.faces);
                const bool ok = solveLscm(mesh, c) && normalizeArea(mesh, c) &&
                                countBadTriangles(mesh, c, settings.minAreaRatio) == 0 &&
                                (!settings.checkBoundaryOverlap || !boundaryOverlaps(c));
                if (ok) {
                    emit(std::move(c), ParamMethod::Lscm, source);
                    continue;
                }
                ++stats.failedLscm;
            }
            if (w.faces.size() == 1 || w.depth >= settings.maxSplitDepth) {
                perTriangle(w.faces, source);
                continue;
            }
            ++stats.splits;
            for (auto& p : splitFacesInHalf(ws, w.faces)) stack.push_back({std::move(p), w.depth + 1});
        }
    }
    return result;
}

}  // namespace hemibake
