// What the lightmap unwrap (charts → parameterization → packing, mesh/uv_atlas.h) and the texel placement after it
// (mesh/texels.h) cost as a level grows: the bake's "unwrap" stage, with the medium preset's 4 texels per metre of
// bench/levels.py's speed runs and the default 1024-texel atlases.
//
//   HEMIBAKE_BENCH_TILED=tiled-10000.gltf,tiled-100000.gltf,tiled-300000.gltf build/bench/bench_unwrap
//
// Any levels will do (examples/generate_level.py --tiles N makes N copies of one). Without the variable the
// benchmark fails. "ns/triangle" flat across the levels is a stage linear in the level.
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "bench/bench_levels.h"
#include "mesh/gltf_loader.h"
#include "mesh/texels.h"
#include "mesh/uv_atlas.h"

namespace hemibake {
namespace {

const Scene& level(std::size_t index) {
    static std::map<std::size_t, std::unique_ptr<Scene>> cache;
    auto& slot = cache[index];
    if (!slot) slot = std::make_unique<Scene>(loadGltf(benchTiledLevels().at(index)));
    return *slot;
}

UnwrapSettings mediumSpeedRunSettings() {
    UnwrapSettings s;
    s.texelsPerUnit = 4.0;
    return s;
}

std::size_t triangleCount(const Scene& scene) {
    std::size_t n = 0;
    for (const MeshInstance& instance : scene.instances) n += instance.mesh.n_faces();
    return n;
}

// Args: level index (into HEMIBAKE_BENCH_TILED), stage (0 = unwrapScene, 1 = computeTexels on its atlas).
void BM_UnwrapAgainstLevelSize(benchmark::State& state) {
    const std::vector<std::string> files = benchTiledLevels();
    if (files.empty()) {
        state.SkipWithError("HEMIBAKE_BENCH_TILED is not set (comma-separated glTF levels)");
        return;
    }
    if (std::size_t(state.range(0)) >= files.size()) {
        state.SkipWithError("fewer levels in HEMIBAKE_BENCH_TILED than this argument asks");
        return;
    }
    const Scene& scene = level(std::size_t(state.range(0)));
    const UnwrapSettings settings = mediumSpeedRunSettings();
    const bool texels = state.range(1) == 1;
    const UvAtlas prepared = texels ? unwrapScene(scene, settings) : UvAtlas{};
    std::size_t atlases = 0, covered = 0;
    double layoutChecksum = 0.0;  // where the charts went: equal sums, equal layouts (for comparing packers)
    for (auto _ : state) {
        if (texels) {
            const std::vector<AtlasTexels> t = computeTexels(scene, prepared, {});
            covered = 0;
            for (const AtlasTexels& a : t) covered += a.x.size();
            atlases = t.size();
        } else {
            const UvAtlas atlas = unwrapScene(scene, settings);
            atlases = atlas.atlases.size();
            layoutChecksum = 0.0;
            for (const UnwrappedInstance& u : atlas.instances)
                for (std::size_t k = 0; k < u.uv.size(); ++k)
                    layoutChecksum += double(k % 7 + 1) * (double(u.uv[k].x) + 3.0 * double(u.uv[k].y)) + double(u.atlas);
            covered = 0;
            for (const auto& a : atlas.atlases) covered += std::size_t(a.coveredTexels);
        }
    }
    const double triangles = double(triangleCount(scene));
    state.counters["triangles"] = triangles;
    state.counters["atlases"] = double(atlases);
    state.counters["texels"] = double(covered);
    if (!texels) state.counters["layout"] = layoutChecksum;
    state.counters["ns/triangle"] = benchmark::Counter(double(state.iterations()) * triangles * 1e-9,
                                                       benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_UnwrapAgainstLevelSize)
    ->ArgNames({"level", "stage"})
    ->ArgsProduct({{0, 1, 2, 3}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);

}  // namespace
}  // namespace hemibake

BENCHMARK_MAIN();
