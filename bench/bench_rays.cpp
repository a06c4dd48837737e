// What one ray into the solver's elements costs as the level grows, with the rays held fixed.
//
// A tiled level (examples/generate_level.py --uniform --tiles N) is N copies of one level, tile 0 at the origin. The
// rays here all start in tile 0 (element centroids, cosine-distributed directions, a fixed seed), so every scene
// traces exactly the same rays; only the BVH around them grows. They find the same surfaces but for the rays that
// leave tile 0 through a doorway and meet the next copy (hit counts within 0.5 %; the "checksum", the hits'
// summed distance, 4 % longer on 10 and 30 copies). That isolates the cost a larger level adds to each shot's row and each
// texel's gather, from the count of shots and texels (docs/performance.md, "Ray cost against level size").
//
//   HEMIBAKE_BENCH_TILED=tiled-10000.gltf,tiled-100000.gltf,tiled-300000.gltf build/bench/bench_rays
//
// The first file must be the single tile (it gives tile 0's bounds). Without the variable the benchmark fails.
//
// "spread" places the 2,048 origins differently: 0 = in tile 0 (the same rays in every level), 1 = over the whole
// level in random order (what a large level's work in atlas or bound order looks like), 2 = the same origins as
// 1 along a Z-curve (mesh/z_curve.h). 0 against 2 on one level is the BVH's size, 1 against 2 the order's effect.
// "directions" lays each origin's rays out as cosineDirections says (0 = independent, 1 = shuffled strata, 2 = strata
// in order); "input" = 1 traces the same rays against the input's triangles alone (EmbreeScene::intersectSides: no
// element found), 2 = the elements found inside the input's faces (ElementRayScene over an EmbreeScene, what the
// bake traces since session 39), 0 = the elements' own BVH (before).
#include <benchmark/benchmark.h>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "baker/pipeline/presets.h"
#include "baker/rays/element_ray_scene.h"
#include "baker/rays/embree_scene.h"
#include "baker/solve/room_scale.h"
#include "baker/solve/separate_sides.h"
#include "bench/bench_levels.h"
#include "mesh/frame_math.h"
#include "mesh/gltf_loader.h"
#include "mesh/z_curve.h"

namespace hemibake {
namespace {

// A level subdivided as the medium preset's solve does it (room-scale refinement, sides kept apart), with the sizes
// of a level past 28 m of diagonal for every file, so tile 0 becomes the same elements in all of them.
struct Level {
    Scene scene;
    std::unique_ptr<EmbreeScene> inputRays;
    PatchMesh mesh;
    std::unique_ptr<ElementRayScene> elementRays;  // the elements' own BVH
    std::unique_ptr<ElementRayScene> faceRays;     // the elements found in the input's faces
};

const Level& level(std::size_t index) {
    static std::map<std::size_t, std::unique_ptr<Level>> cache;
    auto& slot = cache[index];
    if (!slot) {
        slot = std::make_unique<Level>();
        slot->scene = loadGltf(benchTiledLevels().at(index));
        slot->inputRays = std::make_unique<EmbreeScene>(slot->scene);
        const SolveSettings settings = presetSettings("medium", 100.0).solve;
        const RefinementRequest request = findRoomScaleRegions(slot->scene, *slot->inputRays, settings);
        slot->mesh = subdivideApart(slot->scene, *slot->inputRays, settings.subdivision,
                                    request.regions.empty() ? nullptr : &request, settings.sides);
        slot->elementRays = std::make_unique<ElementRayScene>(slot->mesh);
        slot->faceRays = std::make_unique<ElementRayScene>(slot->mesh, *slot->inputRays);
    }
    return *slot;
}

struct RayOrigin {
    glm::dvec3 position, normal;
};

// Centroids of tile 0's elements (inside the single tile's bounds), in a fixed order, every stride-th one.
std::vector<RayOrigin> tileZeroOrigins(const PatchMesh& mesh, const Bounds& tile, std::size_t count) {
    std::vector<RayOrigin> all;
    for (std::size_t e = 0; e < mesh.elements.size(); ++e) {
        const glm::dvec3& c = mesh.elements.centroid[e];
        if (glm::all(glm::greaterThanEqual(c, tile.min)) && glm::all(glm::lessThanEqual(c, tile.max)))
            all.push_back({c, glm::dvec3(mesh.elements.normal[e])});
    }
    std::sort(all.begin(), all.end(), [](const RayOrigin& a, const RayOrigin& b) {
        const glm::dvec3 &p = a.position, &q = b.position;
        return p.x != q.x ? p.x < q.x : p.y != q.y ? p.y < q.y : p.z < q.z;
    });
    std::vector<RayOrigin> picked;
    const std::size_t stride = std::max<std::size_t>(1, all.size() / count);
    for (std::size_t k = 0; k < all.size() && picked.size() < count; k += stride) picked.push_back(all[k]);
    return picked;
}

// Cosine-distributed unit directions about n, `rays` of them, from `seed` (frame_math's Malley directions).
// layout (the "directions" argument): 0 = independent points of the square; 1 = one jittered point per stratum of
// a square grid, the strata in a shuffled order (the order a shooting row traces its rays in); 2 = the same, row
// after row of strata (the final gather's order: a packet of 16 looks into one narrow cone).
std::vector<glm::dvec3> cosineDirections(const glm::dvec3& n, int rays, std::uint64_t seed, int layout) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    glm::dvec3 t, b;
    orthonormalBasis(n, t, b);
    std::vector<glm::dvec3> dirs(static_cast<std::size_t>(rays));
    const int strata = int(std::lround(std::sqrt(double(rays))));
    std::vector<int> order(static_cast<std::size_t>(rays));
    for (int k = 0; k < rays; ++k) order[std::size_t(k)] = k;
    if (layout == 1) std::shuffle(order.begin(), order.end(), rng);
    for (int k = 0; k < rays; ++k) {
        const double u1 = u(rng), u2 = u(rng);
        if (layout == 0 || strata * strata != rays) {
            dirs[std::size_t(k)] = cosineDirection(t, b, n, u1, u2);
            continue;
        }
        const int d = layout == 2 ? k : order[std::size_t(k)];
        const int x = d % strata, y = d / strata;
        dirs[std::size_t(k)] = cosineDirection(t, b, n, (x + u1) / strata, (y + u2) / strata);
    }
    return dirs;
}

// Args: level index (into HEMIBAKE_BENCH_TILED), rays per origin, threads, spread (see the top).
void BM_ElementRaysAgainstLevelSize(benchmark::State& state) {
    const std::vector<std::string> files = benchTiledLevels();
    const auto index = std::size_t(state.range(0));
    if (files.empty()) {
        state.SkipWithError("HEMIBAKE_BENCH_TILED is not set (comma-separated tiled levels, the single tile first)");
        return;
    }
    if (index >= files.size()) {
        state.SkipWithError("fewer levels in HEMIBAKE_BENCH_TILED than this argument asks");
        return;
    }
    const int raysPerOrigin = int(state.range(1));
    const int threads = int(state.range(2));
    Bounds tile;
    for (const glm::dvec3& v : level(0).mesh.elements.vertices) tile.extend(v);
    const Level& lv = level(index);
    if (state.range(3) != 0) {
        tile = Bounds{};
        for (const glm::dvec3& v : lv.mesh.elements.vertices) tile.extend(v);
    }
    std::vector<RayOrigin> origins = tileZeroOrigins(lv.mesh, tile, 2048);
    if (state.range(3) == 1) std::shuffle(origins.begin(), origins.end(), std::mt19937_64(5));
    if (state.range(3) == 2) {
        std::vector<glm::dvec3> positions;
        for (const RayOrigin& o : origins) positions.push_back(o.position);
        std::vector<RayOrigin> sorted;
        for (std::uint32_t k : zCurveOrder(positions)) sorted.push_back(origins[k]);
        origins = std::move(sorted);
    }
    std::vector<std::vector<glm::dvec3>> dirs(origins.size());
    for (std::size_t k = 0; k < origins.size(); ++k) dirs[k] = cosineDirections(origins[k].normal, raysPerOrigin, k + 1, int(state.range(4)));
    std::atomic<std::uint64_t> hitCount{0};
    double distanceSum = 0.0;
    tbb::task_arena arena(threads);
    for (auto _ : state) {
        std::vector<double> distance(origins.size(), 0.0);
        std::atomic<std::uint64_t> hitsThisPass{0};
        arena.execute([&] {
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, origins.size(), 16), [&](const tbb::blocked_range<std::size_t>& r) {
                std::vector<ElementHit> hits(static_cast<std::size_t>(raysPerOrigin));
                std::uint64_t found = 0;
                std::vector<HitSide> sides(static_cast<std::size_t>(raysPerOrigin));
                for (std::size_t k = r.begin(); k != r.end(); ++k) {
                    if (state.range(5) == 1) {  // the input's triangles (EmbreeScene), not the elements
                        lv.inputRays->intersectSides(lv.inputRays->offsetFromSurface(origins[k].position, origins[k].normal),
                                                     dirs[k], std::numeric_limits<double>::infinity(),
                                                     EmbreeScene::RayEnds::Lifted, sides);
                        for (const HitSide& h : sides)
                            if (h.hit) {
                                ++found;
                                distance[k] += h.distanceM;
                            }
                        continue;
                    }
                    const ElementRayScene& rays = state.range(5) == 2 ? *lv.faceRays : *lv.elementRays;
                    rays.trace(rays.lift(origins[k].position, origins[k].normal), dirs[k], hits);
                    for (const ElementHit& h : hits)
                        if (h.kind != ElementHit::Kind::Sky) {
                            ++found;
                            distance[k] += h.distanceM;
                        }
                }
                hitsThisPass += found;
            });
        });
        hitCount = hitsThisPass.load();
        distanceSum = 0.0;
        for (double d : distance) distanceSum += d;
    }
    const double rays = double(state.iterations()) * double(origins.size()) * raysPerOrigin;
    state.SetItemsProcessed(std::int64_t(rays));
    state.counters["elements"] = double(lv.mesh.elements.size());
    state.counters["origins"] = double(origins.size());
    state.counters["twins"] = double(lv.elementRays->twinElements());
    state.counters["hits"] = double(hitCount.load());
    state.counters["checksum"] = distanceSum;  // the hits' summed distance: which surfaces the rays met
    state.counters["ns/ray"] = benchmark::Counter(rays * 1e-9, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ElementRaysAgainstLevelSize)
    ->ArgNames({"level", "rays", "threads", "spread", "directions", "input"})
    ->ArgsProduct({{0, 1, 2}, {256, 4096}, {1}, {0, 1, 2}, {0, 1, 2}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);

}  // namespace
}  // namespace hemibake

BENCHMARK_MAIN();
