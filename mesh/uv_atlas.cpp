#include "mesh/uv_atlas.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

#include "mesh/errors.h"

namespace hemibake {

namespace {

using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

std::array<std::int32_t, 3> faceVertices(const SurfaceMesh& mesh, int f) { return faceCorners(mesh, f); }

// Existing TEXCOORD_1 usable as-is: every coordinate finite and inside [0,1] (with a little slack).
bool existingUvUsable(const SurfaceMesh& mesh) {
    for (auto v : mesh.vertices()) {
        const auto& uv = mesh.lightmapUv(v);
        for (int k = 0; k < 2; ++k)
            if (!std::isfinite(uv[k]) || uv[k] < -1e-6f || uv[k] > 1.0f + 1e-6f) return false;
    }
    return true;
}

}  // namespace

PackSettings UnwrapSettings::packSettings() const {
    PackSettings p;
    p.texelsPerUnit = texelsPerUnit;
    p.maxAtlasSize = maxAtlasSize;
    p.paddingTexels = paddingTexels;
    p.borderTexels = borderTexels;
    p.allowRotation = allowRotation;
    p.powerOfTwo = powerOfTwo;
    p.sizeMultiple = sizeMultiple;
    p.keepGroupsTogether = true;
    return p;
}

UvAtlas unwrapScene(const Scene& scene, const UnwrapSettings& settings) {
    const auto t0 = Clock::now();
    UvAtlas out;
    out.texelsPerUnit = settings.texelsPerUnit;
    out.instances.resize(scene.instances.size());
    auto& st = out.stats;
    st.instances = scene.instances.size();

    struct Pending {
        std::int32_t instance;
        ParamChart chart;
    };
    std::vector<Pending> pending;
    // Per instance: the input vertex at each face corner, in the corner order of the parameterized mesh.
    std::vector<std::vector<std::int32_t>> corners(scene.instances.size());
    std::vector<std::int32_t> existing;  // instances keeping their UVs

    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const MeshInstance& inst = scene.instances[i];
        const SurfaceMesh& mesh = inst.mesh;
        st.triangles += mesh.n_faces();
        if (mesh.n_faces() == 0) continue;
        if (settings.keepExistingUv && inst.hasLightmapUv) {
            if (existingUvUsable(mesh)) {
                existing.push_back(std::int32_t(i));
                continue;
            }
            out.warnings.push_back("instance " + std::to_string(i) + " ('" + inst.source.nodeName +
                                   "'): TEXCOORD_1 outside [0,1]; unwrapped anew");
        }
        const auto tc = Clock::now();
        std::optional<WeldedMesh> welded;
        if (settings.charts.weldVertices) welded = weldCoincidentVertices(mesh);
        const SurfaceMesh& work = welded ? welded->mesh : mesh;
        if (welded) {
            corners[i] = std::move(welded->cornerSource);
        } else {
            corners[i].resize(3 * mesh.n_faces());
            for (std::size_t f = 0; f < mesh.n_faces(); ++f) {
                const auto c = faceCorners(mesh, int(f));
                std::copy(c.begin(), c.end(), corners[i].begin() + std::ptrdiff_t(3 * f));
            }
        }
        const ChartSet charts = computeCharts(work, settings.charts);
        const auto tp = Clock::now();
        ParameterizationResult param = parameterizeCharts(work, charts, settings.parameterize);
        const auto te = Clock::now();
        st.chartSeconds += seconds(tc, tp);
        st.parameterizeSeconds += seconds(tp, te);
        st.chartSplits += charts.nonDiskSplits + param.stats.splits;
        st.badUvTriangles += param.stats.flippedOrDegenerate;
        st.stretch.merge(param.stats.stretch);
        for (auto& c : param.charts) pending.push_back({std::int32_t(i), std::move(c)});
    }

    // Pack.
    const auto tk = Clock::now();
    std::vector<PackChartInput> inputs;
    inputs.reserve(pending.size());
    for (const auto& p : pending) inputs.push_back({p.chart.uv, p.chart.triangles, p.instance});
    PackResult packed;
    try {
        packed = packCharts(inputs, settings.packSettings());
    } catch (const PackError& e) {
        const SourcePrimitive& src = scene.instances[std::size_t(e.group())].source;
        const std::string node = src.nodeName.empty() ? "node " + std::to_string(src.node) : "node '" + src.nodeName + "'";
        throw InputError(scene.path, node + " (mesh " + std::to_string(src.mesh) + " primitive " + std::to_string(src.primitive) +
                                         "): " + e.what());
    }
    st.packSeconds = seconds(tk, Clock::now());
    for (const auto& w : packed.warnings) out.warnings.push_back(w);
    st.scaledDownCharts = packed.scaledDownCharts;
    for (std::size_t a = 0; a < packed.atlasSize.size(); ++a) out.atlases.push_back({packed.atlasSize[a], 0, 0, 0, 0.0});

    // Unwrapped arrays, chart by chart, grouped per instance (pending is in instance order). A chart's unwrapped
    // vertices are the distinct input vertices at its face corners.
    StampedMap unwrappedOf;
    for (std::size_t n = 0; n < pending.size(); ++n) {
        const std::int32_t i = pending[n].instance;
        const ParamChart& pc = pending[n].chart;
        const PackedChart& pk = packed.charts[n];
        UnwrappedInstance& ui = out.instances[std::size_t(i)];
        if (ui.chartCount == 0) {
            ui.firstChart = std::uint32_t(out.charts.size());
            ui.atlas = pk.atlas;
            unwrappedOf.resize(scene.instances[std::size_t(i)].mesh.n_vertices());
        }
        unwrappedOf.reset();
        ++ui.chartCount;
        const double size = double(packed.atlasSize[std::size_t(pk.atlas)]);
        AtlasChart ac;
        ac.instance = i;
        ac.atlas = pk.atlas;
        ac.firstVertex = std::uint32_t(ui.uv.size());
        ac.firstTriangle = std::uint32_t(ui.triangles.size());
        ac.triangleCount = std::uint32_t(pc.triangles.size());
        ac.method = pc.method;
        ac.scaledDown = pk.scaledDown;
        ac.texelsPerUnit = pk.scale;
        ac.x = pk.x;
        ac.y = pk.y;
        ac.width = pk.width;
        ac.height = pk.height;
        ac.footprintTexels = pk.footprintTexels;
        ac.areaM2 = pc.areaM2;
        ac.stretch = pc.stretch;
        std::vector<glm::vec2> localUv(pc.vertices.size());
        for (std::size_t v = 0; v < pc.vertices.size(); ++v)
            localUv[v] = glm::vec2(glm::clamp(pk.toTexels(pc.uv[v]) / size, 0.0, 1.0));
        for (std::size_t t = 0; t < pc.triangles.size(); ++t) {
            const int f = pc.faces[t];
            std::array<std::uint32_t, 3> tri{};
            for (std::size_t k = 0; k < 3; ++k) {
                const std::int32_t source = corners[std::size_t(i)][3 * std::size_t(f) + k];
                std::int32_t u = unwrappedOf.get(std::size_t(source));
                if (u < 0) {
                    u = std::int32_t(ui.uv.size());
                    unwrappedOf.set(std::size_t(source), u);
                    ui.uv.push_back(localUv[std::size_t(pc.triangles[t][k])]);
                    ui.vertexSource.push_back(source);
                }
                tri[k] = std::uint32_t(u);
            }
            ui.triangles.push_back(tri);
            ui.faceSource.push_back(f);
        }
        ac.vertexCount = std::uint32_t(ui.uv.size()) - ac.firstVertex;
        ++out.atlases[std::size_t(pk.atlas)].charts;
        switch (pc.method) {
            case ParamMethod::Planar: ++st.planarCharts; break;
            case ParamMethod::Lscm: ++st.lscmCharts; break;
            case ParamMethod::PerTriangle: ++st.perTriangleCharts; break;
            default: break;
        }
        out.charts.push_back(ac);
    }
    pending.clear();

    // Instances keeping their UVs: one atlas each, one pseudo-chart.
    for (std::int32_t i : existing) {
        const SurfaceMesh& mesh = scene.instances[std::size_t(i)].mesh;
        double area3 = 0.0, areaUv = 0.0;
        UnwrappedInstance& ui = out.instances[std::size_t(i)];
        ui.existingUv = true;
        for (auto v : mesh.vertices()) {
            const auto& uv = mesh.lightmapUv(v);
            ui.uv.push_back(glm::clamp(glm::vec2(uv[0], uv[1]), 0.0f, 1.0f));
            ui.vertexSource.push_back(v.idx());
        }
        for (auto f : mesh.faces()) {
            const auto v = faceVertices(mesh, f.idx());
            ui.triangles.push_back({std::uint32_t(v[0]), std::uint32_t(v[1]), std::uint32_t(v[2])});
            ui.faceSource.push_back(f.idx());
            area3 += mesh.faceArea(f);
            const glm::dvec2 a = ui.uv[std::size_t(v[0])], b = ui.uv[std::size_t(v[1])], c = ui.uv[std::size_t(v[2])];
            areaUv += 0.5 * std::abs((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
        }
        int size = areaUv > 0.0 ? int(std::ceil(settings.texelsPerUnit * std::sqrt(area3 / areaUv))) : settings.maxAtlasSize;
        if (settings.powerOfTwo) {
            int p = 1;
            while (p < size) p *= 2;
            size = p;
        } else {
            const int m = std::max(1, settings.sizeMultiple);
            size = ((size + m - 1) / m) * m;
        }
        size = std::clamp(size, 4, std::clamp(settings.maxAtlasSize, 4, 8192));
        ui.atlas = std::int32_t(out.atlases.size());
        out.atlases.push_back({size, 1, 0, 0, 0.0});
        ui.firstChart = std::uint32_t(out.charts.size());
        ui.chartCount = 1;
        AtlasChart ac;
        ac.instance = i;
        ac.atlas = ui.atlas;
        ac.vertexCount = std::uint32_t(ui.uv.size());
        ac.triangleCount = std::uint32_t(ui.triangles.size());
        ac.method = ParamMethod::Existing;
        ac.texelsPerUnit = areaUv > 0.0 ? double(size) * std::sqrt(areaUv / area3) : 0.0;
        ac.width = ac.height = size;
        ac.areaM2 = area3;
        out.charts.push_back(ac);
        ++st.existingUvInstances;
    }

    // Coverage of the final UVs (as the texel stage and a renderer see them) and the instances' rectangles.
    std::vector<std::vector<std::uint32_t>> chartsOfAtlas(out.atlases.size());
    for (std::size_t c = 0; c < out.charts.size(); ++c) chartsOfAtlas[std::size_t(out.charts[c].atlas)].push_back(std::uint32_t(c));
    for (std::size_t a = 0; a < out.atlases.size(); ++a) {
        AtlasPage& page = out.atlases[a];
        const int S = page.size;
        std::vector<std::int32_t> owner(std::size_t(S) * std::size_t(S), -1);
        for (std::uint32_t c : chartsOfAtlas[a]) {
            const AtlasChart& ac = out.charts[c];
            UnwrappedInstance& ui = out.instances[std::size_t(ac.instance)];
            int x0 = S, y0 = S, x1 = -1, y1 = -1;
            for (std::uint32_t t = ac.firstTriangle; t < ac.firstTriangle + ac.triangleCount; ++t) {
                const auto& tri = ui.triangles[t];
                glm::dvec2 p[3];
                for (int k = 0; k < 3; ++k) p[k] = glm::dvec2(ui.uv[tri[std::size_t(k)]]) * double(S);
                forEachTouchedTexel(p[0], p[1], p[2], kCoverageShrinkTexels, [&](long x, long y) {
                    if (x < 0 || y < 0 || x >= S || y >= S) return;
                    auto& o = owner[std::size_t(y) * std::size_t(S) + std::size_t(x)];
                    if (o < 0) {
                        o = std::int32_t(c);
                        ++page.coveredTexels;
                    } else if (o != std::int32_t(c)) {
                        ++page.overlappingTexels;
                    }
                    x0 = std::min(x0, int(x));
                    y0 = std::min(y0, int(y));
                    x1 = std::max(x1, int(x));
                    y1 = std::max(y1, int(y));
                });
            }
            if (ac.method == ParamMethod::Existing && x1 >= 0) {
                out.charts[c].x = x0;
                out.charts[c].y = y0;
                out.charts[c].width = x1 - x0 + 1;
                out.charts[c].height = y1 - y0 + 1;
                out.charts[c].footprintTexels = std::uint32_t(page.coveredTexels);
            }
        }
        page.utilization = S > 0 ? double(page.coveredTexels) / (double(S) * double(S)) : 0.0;
        st.coveredTexels += page.coveredTexels;
        st.overlappingTexels += page.overlappingTexels;
        st.atlasTexels += std::uint64_t(S) * std::uint64_t(S);
    }
    st.utilization = st.atlasTexels ? double(st.coveredTexels) / double(st.atlasTexels) : 0.0;
    for (auto& ui : out.instances) {
        if (ui.chartCount == 0) continue;
        int x0 = std::numeric_limits<int>::max(), y0 = x0, x1 = std::numeric_limits<int>::min(), y1 = x1;
        for (std::uint32_t c = ui.firstChart; c < ui.firstChart + ui.chartCount; ++c) {
            const AtlasChart& ac = out.charts[c];
            x0 = std::min(x0, ac.x);
            y0 = std::min(y0, ac.y);
            x1 = std::max(x1, ac.x + ac.width);
            y1 = std::max(y1, ac.y + ac.height);
        }
        ui.rect = {x0, y0, x1 - x0, y1 - y0};
    }
    st.charts = out.charts.size() - st.existingUvInstances;
    st.totalSeconds = seconds(t0, Clock::now());
    return out;
}

}  // namespace hemibake
