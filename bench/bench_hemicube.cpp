// Hemicubes per second on generated scenes (random boxes in a room, ~1k / 10k / 100k triangles), for the
// item buffer (shooting) at R = 32…256 and the radiance gather at R = 64, with 1 and 2 worker threads.
//
//   build/bench/bench_hemicube --benchmark_counters_tabular=true
//
// The machine's other load matters a lot with 2 cores: note `uptime` next to any numbers you keep.
// Each iteration renders a batch of hemicubes at random points on random elements (facing along the
// element normal, randomly rotated), spread over the workers with tbb::parallel_for; contexts and scene
// uploads are warmed up before timing, as a bake would amortise them.
#include <benchmark/benchmark.h>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdlib>
#include <map>
#include <memory>
#include <random>
#include <vector>

#include "baker/direct/emissive_area_lights.h"
#include "baker/lightmap/ray_gatherer.h"
#include "baker/rays/embree_scene.h"
#include "mesh/gltf_loader.h"
#include "mesh/subdivision.h"
#include "raster/hemicube_pool.h"

namespace hemibake {
namespace {

class Generator {
public:
    explicit Generator(std::uint32_t seed) : rng_(seed) {}

    // Quad p0 + s·u + t·v split into n×n cells (2 triangles each, vertices shared as subdivision leaves
    // them); front = u × v.
    void grid(const glm::dvec3& p0, const glm::dvec3& u, const glm::dvec3& v, int n) {
        const auto base = static_cast<std::uint32_t>(vertices_.size());
        for (int j = 0; j <= n; ++j)
            for (int i = 0; i <= n; ++i) vertices_.push_back(p0 + (double(i) / n) * u + (double(j) / n) * v);
        auto at = [&](int i, int j) { return base + static_cast<std::uint32_t>(j * (n + 1) + i); };
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                triangles_.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
                triangles_.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
            }
    }
    void box(const glm::dvec3& lo, const glm::dvec3& hi, int n, bool inward) {
        const glm::dvec3 s = hi - lo, x(s.x, 0, 0), y(0, s.y, 0), z(0, 0, s.z);
        auto face = [&](const glm::dvec3& p0, const glm::dvec3& u, const glm::dvec3& v) {
            inward ? grid(p0, u, v, n) : grid(p0 + u, -u, v, n);  // mirrored for outward faces
        };
        face(lo, x, y);
        face(lo + z, y, x);
        face(lo, z, x);
        face(lo + y, x, z);
        face(lo, y, z);
        face(lo + x, z, y);
    }
    double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }
    std::mt19937& rng() { return rng_; }

    PatchMesh build() {
        PatchMesh mesh;
        ElementArrays& e = mesh.elements;
        Bounds bounds;
        for (const glm::dvec3& p : vertices_) bounds.extend(p);
        e.vertices = vertices_;
        e.triangles = triangles_;
        for (const auto& t : triangles_) {
            const glm::dvec3 a = vertices_[t[0]], b = vertices_[t[1]], c = vertices_[t[2]];
            const glm::dvec3 cross = glm::cross(b - a, c - a);
            e.normal.push_back(glm::vec3(glm::normalize(cross)));
            e.centroid.push_back((a + b + c) / 3.0);
            e.areaM2.push_back(0.5 * glm::length(cross));
        }
        mesh.origin = bounds.centre();
        mesh.sceneDiagonalM = bounds.diagonal();
        return mesh;
    }

private:
    std::mt19937 rng_;
    std::vector<glm::dvec3> vertices_;
    std::vector<std::array<std::uint32_t, 3>> triangles_;
};

// A 10 × 4 × 8 m room (walls gridded roomGrid²) with `boxes` outward boxes (faces gridded boxGrid²).
PatchMesh roomWithBoxes(int roomGrid, int boxes, int boxGrid) {
    Generator g(1234);
    g.box({0, 0, 0}, {10, 4, 8}, roomGrid, true);
    for (int k = 0; k < boxes; ++k) {
        const glm::dvec3 size(g.uniform(0.2, 1.5), g.uniform(0.2, 1.5), g.uniform(0.2, 1.5));
        const glm::dvec3 lo(g.uniform(0.1, 9.9 - size.x), g.uniform(0.0, 3.9 - size.y), g.uniform(0.1, 7.9 - size.z));
        g.box(lo, lo + size, boxGrid, false);
    }
    return g.build();
}

struct SceneSpec {
    int roomGrid, boxes, boxGrid;
};
// 12·roomGrid² + 12·boxes·boxGrid² triangles: 1008, 9984, 104448.
const std::map<int, SceneSpec> kScenes = {{1, {6, 48, 1}}, {10, {16, 64, 3}}, {100, {48, 100, 8}}};

const PatchMesh& scene(int kiloTriangles) {
    static std::map<int, std::unique_ptr<PatchMesh>> cache;
    auto& slot = cache[kiloTriangles];
    if (!slot) {
        const SceneSpec s = kScenes.at(kiloTriangles);
        slot = std::make_unique<PatchMesh>(roomWithBoxes(s.roomGrid, s.boxes, s.boxGrid));
    }
    return *slot;
}

// Hemicubes at element centroids facing along the element normals, as shooting from patches would place them.
std::vector<HemicubeFrame> frames(const PatchMesh& mesh, int count) {
    std::mt19937 rng(99);
    std::uniform_int_distribution<std::size_t> pick(0, mesh.elements.size() - 1);
    std::vector<HemicubeFrame> result;
    for (int k = 0; k < count; ++k) {
        const std::size_t e = pick(rng);
        result.push_back(HemicubeFrame::randomlyRotated(mesh.elements.centroid[e], glm::dvec3(mesh.elements.normal[e]), k));
    }
    return result;
}

enum class Mode { Items, Gather };

void runHemicubes(benchmark::State& state, Mode mode) {
    const int kiloTriangles = static_cast<int>(state.range(0));
    const int resolution = static_cast<int>(state.range(1));
    const int threads = static_cast<int>(state.range(2));
    const PatchMesh& mesh = scene(kiloTriangles);
    const int batch = 64;
    const std::vector<HemicubeFrame> batchFrames = frames(mesh, batch);

    tbb::task_arena arena(threads);
    HemicubePool pool(mesh, resolution);
    pool.setElementRadiance(std::vector<glm::vec3>(mesh.elements.size(), glm::vec3(1.0f)));
    tbb::enumerable_thread_specific<FormFactorList> lists;
    std::atomic<std::uint64_t> trianglesDrawn{0};
    auto render = [&] {
        arena.execute([&] {
            tbb::parallel_for(0, batch, [&](int i) {
                HemicubeRenderer& renderer = pool.local();
                const std::uint64_t before = renderer.drawTotals().triangles;
                if (mode == Mode::Items)
                    renderer.renderFormFactors(batchFrames[i], lists.local());
                else
                    benchmark::DoNotOptimize(renderer.gatherIrradianceOverPi(batchFrames[i], glm::vec3(0.5f)));
                trianglesDrawn += renderer.drawTotals().triangles - before;
            });
        });
    };
    render();  // warm-up: every worker creates its context and uploads the scene
    trianglesDrawn = 0;
    for (auto _ : state) render();
    double checksum = 0.0;
    for (const FormFactorList& l : lists) checksum += l.sum();
    benchmark::DoNotOptimize(checksum);

    const double hemicubes = double(state.iterations()) * batch;
    state.SetItemsProcessed(static_cast<std::int64_t>(hemicubes));
    state.counters["triangles"] = double(mesh.elements.size());
    state.counters["workers"] = double(pool.workerCount());
    // Triangles sent to llvmpipe per hemicube (summed over the five faces), as a fraction of the scene.
    state.counters["drawn"] = double(trianglesDrawn.load()) /
                              (hemicubes * double(mesh.elements.size()));
    state.counters["hemicubes/s"] = benchmark::Counter(hemicubes, benchmark::Counter::kIsRate);
}

void BM_ItemBuffer(benchmark::State& state) { runHemicubes(state, Mode::Items); }

// examples/level_small.gltf at the default preset's sizes (7 rooms and corridors whose walls stand in the slabs):
// what occlusion culling saves where rooms hide each other. One worker, so the numbers are per core.
// HEMIBAKE_BENCH_LEVEL=path.gltf measures another level (e.g. one from examples/generate_level.py).
const Scene& levelSmallScene() {
    static const Scene scene = [] {
        const char* level = std::getenv("HEMIBAKE_BENCH_LEVEL");
        return loadGltf(level != nullptr && *level != '\0' ? std::string(level)
                                                              : std::string(HEMIBAKE_SOURCE_DIR) + "/examples/level_small.gltf");
    }();
    return scene;
}

const PatchMesh& levelSmall() {
    static const PatchMesh mesh = [] {
        SubdivisionSettings settings;
        settings.patchSizeM = 3.2;
        settings.elementSizeM = 1.6;
        return subdivide(levelSmallScene(), settings);
    }();
    return mesh;
}

void BM_LevelHemicubes(benchmark::State& state) {
    const bool occlusion = state.range(0) != 0;
    const int resolution = static_cast<int>(state.range(1));
    const bool gather = state.range(2) != 0;
    const auto trianglesPerChunk = static_cast<std::uint32_t>(state.range(3));
    const PatchMesh& mesh = levelSmall();
    OcclusionCullingSettings culling;
    culling.enabled = occlusion;
    GlContext context;
    SceneBuffers buffers(context, mesh, trianglesPerChunk);
    buffers.setElementRadiance(std::vector<glm::vec3>(mesh.elements.size(), glm::vec3(1.0f)));
    HemicubeRenderer renderer(buffers, resolution, culling);
    const std::vector<HemicubeFrame> batchFrames = frames(mesh, 64);
    FormFactorList list;
    // The floor culling could reach: triangles of the chunks that hold a visible element (item renders only;
    // counted once per hemicube, where "drawn" counts a chunk once per face it is drawn on).
    std::vector<std::uint32_t> chunkOf(mesh.elements.size());
    const auto chunks = buffers.chunks();
    for (std::size_t c = 0; c < chunks.size(); ++c)
        for (GLint t = chunks[c].firstVertex / 3; t < (chunks[c].firstVertex + chunks[c].vertexCount) / 3; ++t)
            chunkOf[buffers.drawOrder()[std::size_t(t)]] = std::uint32_t(c);
    std::vector<std::uint8_t> chunkSeen(chunks.size(), 0);
    double visibleTriangles = 0.0;
    auto render = [&] {
        for (const HemicubeFrame& frame : batchFrames) {
            if (gather) {
                benchmark::DoNotOptimize(renderer.gatherIrradianceOverPi(frame, glm::vec3(0.5f)));
                continue;
            }
            renderer.renderFormFactors(frame, list);
            std::fill(chunkSeen.begin(), chunkSeen.end(), std::uint8_t(0));
            for (std::uint32_t e : list.elements)
                if (!chunkSeen[chunkOf[e]]) {
                    chunkSeen[chunkOf[e]] = 1;
                    visibleTriangles += chunks[chunkOf[e]].vertexCount / 3;
                }
        }
    };
    render();
    const HemicubeDrawTotals before = renderer.drawTotals();
    visibleTriangles = 0.0;
    for (auto _ : state) render();
    const HemicubeDrawTotals& after = renderer.drawTotals();
    const double hemicubes = double(after.hemicubes - before.hemicubes);
    state.SetItemsProcessed(static_cast<std::int64_t>(hemicubes));
    state.counters["triangles"] = double(mesh.elements.size());
    // Triangles sent to llvmpipe per hemicube (summed over the five faces, occluder pass included) / scene.
    state.counters["drawn"] = double(after.triangles - before.triangles) /
                              (hemicubes * double(mesh.elements.size()));
    if (!gather) state.counters["visible"] = visibleTriangles / (hemicubes * double(mesh.elements.size()));
    state.counters["occluders"] =
        double(after.occluderTriangles - before.occluderTriangles) / (hemicubes * double(mesh.elements.size()));
    state.counters["ms/hemicube"] = benchmark::Counter(hemicubes / 1e3, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_LevelHemicubes)
    ->ArgNames({"occlusion", "R", "gather", "chunk"})
    ->ArgsProduct({{0, 1}, {64, 128}, {0, 1}, {SceneBuffers::kDefaultTrianglesPerChunk}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);
// Chunk size against time: smaller chunks draw fewer triangles but cost more box tests (docs/performance.md).
BENCHMARK(BM_LevelHemicubes)
    ->Name("BM_LevelChunkSize")
    ->ArgNames({"occlusion", "R", "gather", "chunk"})
    ->ArgsProduct({{1}, {64}, {0}, {4, 8, 16, 32, 64}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);
void BM_RadianceGather(benchmark::State& state) { runHemicubes(state, Mode::Gather); }

// The final gather by rays at the level hemicubes' points (baker/lightmap/ray_gatherer.h): what BM_LevelHemicubes'
// gather rows cost as rays, per point and per ray, on one worker or two.
void BM_LevelRayGather(benchmark::State& state) {
    const int rays = static_cast<int>(state.range(0));
    const int threads = static_cast<int>(state.range(1));
    const PatchMesh& mesh = levelSmall();
    RayGatherer gatherer(mesh, rays, 1);
    gatherer.setElementRadiance(std::vector<glm::vec3>(mesh.elements.size(), glm::vec3(1.0f)));
    std::vector<GatherPoint> points;
    for (const HemicubeFrame& f : frames(mesh, 64)) points.push_back({f.position, glm::vec3(f.normal)});
    std::vector<glm::dvec3> out;
    tbb::task_arena arena(threads);
    std::uint64_t sweep = 0;
    for (auto _ : state) arena.execute([&] { gatherer.gather(points, glm::vec3(0.5f), ++sweep, out); });
    const double gathered = double(state.iterations()) * double(points.size());
    state.SetItemsProcessed(static_cast<std::int64_t>(gathered));
    state.counters["triangles"] = double(mesh.elements.size());
    state.counters["ms/point"] = benchmark::Counter(gathered / 1e3, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    state.counters["Mrays/s"] = benchmark::Counter(gathered * gatherer.raysPerPoint() / 1e6, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_LevelRayGather)
    ->ArgNames({"rays", "threads"})
    ->ArgsProduct({{1024, 4096, 16384}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);

// The emitters as each element of the level sees them (baker/direct/emissive_area_lights.h): what the direct light's
// per-element setup costs, one worker; a level of the same kind but more rooms should cost the same per element.
void BM_LevelEmitterViews(benchmark::State& state) {
    const PatchMesh& mesh = levelSmall();
    const EmbreeScene rays(levelSmallScene());
    const EmissiveAreaLights lights(mesh, rays, 4);
    EmissiveAreaLights::ReceiverView view;
    const std::size_t stride = std::max<std::size_t>(1, mesh.elements.size() / 20000);
    const ElementArrays& el = mesh.elements;
    std::size_t viewed = 0, perPoint = 0, constant = 0, farConstant = 0;
    for (auto _ : state)
        for (std::size_t e = 0; e < el.size(); e += stride) {
            const auto& tri = el.triangles[e];
            const glm::dvec3 receiver[3] = {el.vertices[tri[0]], el.vertices[tri[1]], el.vertices[tri[2]]};
            lights.viewFrom(receiver, glm::normalize(glm::dvec3(el.normal[e])), view);
            ++viewed;
            perPoint += view.perPoint.size() + view.frontOnly.size();
            constant += view.constant.size();
            farConstant += view.farConstant.size();
        }
    state.SetItemsProcessed(static_cast<std::int64_t>(viewed));
    state.counters["emitters"] = double(lights.triangleCount());
    state.counters["perPoint"] = double(perPoint) / double(viewed);
    state.counters["clusters"] = double(constant) / double(viewed);
    state.counters["farClusters"] = double(farConstant) / double(viewed);
    state.counters["us/element"] = benchmark::Counter(double(viewed) / 1e6, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_LevelEmitterViews)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

BENCHMARK(BM_ItemBuffer)
    ->ArgNames({"ktris", "R", "threads"})
    ->ArgsProduct({{1, 10, 100}, {32, 64, 128, 256}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);
BENCHMARK(BM_RadianceGather)
    ->ArgNames({"ktris", "R", "threads"})
    ->ArgsProduct({{1, 10, 100}, {64}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);

}  // namespace
}  // namespace hemibake

BENCHMARK_MAIN();
