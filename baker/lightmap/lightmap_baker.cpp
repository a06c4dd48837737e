#include "baker/lightmap/lightmap_baker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

#include <tbb/parallel_for.h>

#include "baker/direct/direct_light.h"
#include "baker/lightmap/adaptive_placement.h"
#include "baker/direct/emissive_area_lights.h"
#include "baker/lightmap/element_interpolation.h"
#include "baker/lightmap/ray_gatherer.h"
#include "baker/lightmap/texel_light.h"
#include "baker/rays/embree_scene.h"
#include "baker/solve/gatherer.h"
#include "baker/solve/solve_scene.h"
#include "baker/util/colour.h"
#include "baker/util/stopwatch.h"
#include "raster/hemicube_pool.h"

namespace hemibake {

namespace {

// Texels inside geometry saw mostly back faces: each takes the mean of its valid continuous neighbours (a few rings).
// Under a wall's foot those neighbours lie on two sides that cannot see each other, and whatever value the texel gets
// reaches both sides through the GPU's bilinear filter: so the neighbours are grouped by mutual visibility and the
// darkest side's mean is taken. A light leak along a dark room's wall foot is what users notice; a slightly darker
// line at the lit room's wall foot reads as the contact shadow that is there anyway.
void refillInvalid(const AtlasTexels& texels, double texelSizeM, const EmbreeScene& rays, std::vector<glm::dvec3>& value,
                   std::vector<std::uint8_t>& invalid) {
    const TexelGrid grid(texels);
    for (int ring = 0; ring < 4; ++ring) {
        std::vector<std::pair<std::size_t, glm::dvec3>> fixes;
        std::mutex fixesMutex;
        tbb::parallel_for(std::size_t(0), texels.count(), [&](std::size_t i) {
            if (!invalid[i]) return;
            struct Side {
                std::size_t first;  // a member the others can see
                glm::dvec3 sum{0.0};
                int count = 0;
            };
            std::vector<Side> sides;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const std::int32_t j = grid.find(texels.x[i] + dx, texels.y[i] + dy);
                    if (j < 0 || invalid[std::size_t(j)] || !continuousSurface(texels, i, std::size_t(j), 3.0 * texelSizeM)) continue;
                    const auto jj = std::size_t(j);
                    auto side = std::find_if(sides.begin(), sides.end(), [&](const Side& s) {
                        return !rays.occluded(texels.position[s.first], texels.position[jj]);
                    });
                    if (side == sides.end()) side = sides.insert(sides.end(), Side{jj});
                    side->sum += value[jj];
                    ++side->count;
                }
            if (sides.empty()) return;
            glm::dvec3 fill(0.0);
            double darkest = std::numeric_limits<double>::infinity();
            for (const Side& s : sides) {
                const glm::dvec3 mean = s.sum / double(s.count);
                if (channelSum(mean) < darkest) {
                    darkest = channelSum(mean);
                    fill = mean;
                }
            }
            const std::lock_guard<std::mutex> lock(fixesMutex);
            fixes.emplace_back(i, fill);
        });
        if (fixes.empty()) break;
        for (const auto& [i, v] : fixes) {
            value[i] = v;
            invalid[i] = 0;
        }
    }
}

}  // namespace

std::size_t dilate(LightmapImage& image, int iterations) {
    std::size_t filled = 0;
    const int s = image.size;
    for (int it = 0; it < iterations; ++it) {
        std::vector<std::pair<std::size_t, glm::vec3>> fills;
        for (int y = 0; y < s; ++y)
            for (int x = 0; x < s; ++x) {
                if (image.state[image.index(x, y)] != TexelState::Empty) continue;
                glm::vec3 sum(0.0f);
                int count = 0;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int nx = x + dx, ny = y + dy;
                        if (nx < 0 || ny < 0 || nx >= s || ny >= s) continue;
                        if (image.state[image.index(nx, ny)] == TexelState::Empty) continue;
                        sum += image.irradianceOverPi[image.index(nx, ny)];
                        ++count;
                    }
                if (count) fills.emplace_back(image.index(x, y), sum / float(count));
            }
        for (const auto& [i, v] : fills) {
            image.irradianceOverPi[i] = v;
            image.state[i] = TexelState::Dilated;
        }
        filled += fills.size();
    }
    return filled;
}

namespace {

// Direct light is computed and reported in slices of this many texels (a second or two on a level).
constexpr std::size_t kDirectSliceTexels = 1 << 16;

// What every atlas's texels are computed from: the solved elements as the gather and the interpolation see them,
// and the ray-traced direct light.
class TexelSolver {
public:
    TexelSolver(const Scene& scene, const SolvedScene& solved, const EmbreeScene& rays, const LightmapSettings& settings,
                const SolveSettings& solve, const UvAtlas& atlas, const std::vector<AtlasTexels>& texels,
                LightmapStats& stats, const LightmapProgress& progress)
        : scene_(scene), solved_(solved), atlas_(atlas), settings_(settings), solve_(solve),
          // Ray-traced direct light at every texel: punctual lights, and emitters when the solver ray traced them
          // (its decision, in its report); the gather then sees emitters without their emission.
          rays_(rays),
          areaLights_(solved.report.emittersByRays ? makeEmissiveAreaLights(solved.mesh, rays, solve.lighting) : nullptr),
          gatherer_(*solved.pool, solve.solver.seed ^ 0x5EEDull),
          interpolator_(solved.mesh, displayIrradiance(solved)) {
        if (!scene.lights.empty() || areaLights_) {
            DirectLightSettings ds;
            ds.sunAngularDiameterRad = solve.lighting.sunAngularDiameterRad;
            direct_ = std::make_unique<DirectLight>(scene, rays, ds, areaLights_.get());
            // Direct light at every texel of every atlas first: the gathers of one atlas see the others' texels.
            const Stopwatch directClock;
            directValue_.resize(texels.size());
            std::size_t total = 0, done = 0;
            for (const AtlasTexels& t : texels) total += t.count();
            for (std::size_t a = 0; a < texels.size(); ++a) {
                directValue_[a].resize(texels[a].count());
                // In slices, reporting after each: on a level at 16 texels/m this is minutes of shadow rays.
                for (std::size_t first = 0; first < texels[a].count(); first += kDirectSliceTexels) {
                    const std::size_t last = std::min(texels[a].count(), first + kDirectSliceTexels);
                    tbb::parallel_for(first, last, [&](std::size_t i) { directValue_[a][i] = directAt(a, texels[a], i); });
                    done += last - first;
                    if (progress) progress(LightmapPhase::DirectLight, done, total);
                }
            }
            stats.seconds.direct = directClock.seconds();
        }
        if (settings.mode == TexelMode::Gather) {
            std::vector<glm::vec3> radiance(solved.mesh.elements.size());
            for (std::size_t e = 0; e < radiance.size(); ++e)
                radiance[e] = solved.solution.gatherRadiance(solved.mesh, e, areaLights_ != nullptr);
            std::shared_ptr<TexelLight> light;
            if (settings.gatherTexelDirect && direct_ && !texels.empty()) {
                const Stopwatch texelLightClock;
                std::vector<glm::dvec3> elementDirectOverPi(solved.solution.rayTracedIrradiance);
                for (glm::dvec3& d : elementDirectOverPi) d /= M_PI;
                light = makeTexelLight(scene, solved.mesh, atlas, texels, directValue_, elementDirectOverPi, radiance,
                                       stats.texelDirect);
                stats.seconds.texelLight = texelLightClock.seconds();
            }
            if (settings.finalGather == FinalGather::Rays) {
                rayGatherer_ = solved.elementRays
                                   ? std::make_unique<RayGatherer>(*solved.elementRays, raysPerTexel(settings, *solved.pool),
                                                                   solve.solver.seed ^ 0x5EEDull)
                                   : std::make_unique<RayGatherer>(solved.mesh, raysPerTexel(settings, *solved.pool),
                                                                   solve.solver.seed ^ 0x5EEDull);
                rayGatherer_->setInsideBackFraction(settings.invalidBackfaceFraction);
            }
            show(radiance, std::move(light));
        }
    }

    // Rays per gathered texel: as set, or 0 = as many as the gather hemicube's front face has pixels (R²).
    static int raysPerTexel(const LightmapSettings& settings, const HemicubePool& pool) {
        const int r = settings.gatherResolution > 0 ? settings.gatherResolution : pool.resolution();
        return settings.gatherRays > 0 ? settings.gatherRays : r * r;
    }

    // What the next gathers see: element radiance and the light inside elements.
    void show(const std::vector<glm::vec3>& radiance, std::shared_ptr<const TexelLight> light) {
        if (rayGatherer_) {
            rayGatherer_->setElementRadiance(radiance);
            rayGatherer_->setTexelLight(std::move(light));
        } else {
            solved_.pool->setTexelLight(std::move(light));
            gatherer_.setElementRadiance(radiance);
        }
    }

    // E/π at the points (texels `ids` of one atlas) by the final gather's method (rays or hemicubes); counts rays
    // traced in `stats`. A texel's rays depend on its index and `sweep` only, not on the batch it is gathered in.
    void gatherAt(const std::vector<GatherPoint>& points, const std::vector<std::uint32_t>& ids, std::uint64_t sweep,
                  std::vector<glm::dvec3>& out, std::vector<float>* backface, LightmapStats& stats) {
        if (rayGatherer_) {
            const RayGatherer::RayCounts counts =
                rayGatherer_->gather(points, solve_.lighting.skyRadiance, sweep, out, backface, ids);
            stats.gatherRaysPerTexel = rayGatherer_->raysPerPoint();
            stats.gatherRaysTraced += counts.traced;
            stats.gatherRaysEscaped += counts.escaped;
            stats.gatherStoppedInside += counts.stoppedInside;
        } else {
            gatherer_.gather(points, solve_.lighting.skyRadiance, sweep, out, backface);
        }
    }

    // E/π of atlas `a`'s texels by adaptively placed final gathers (rays or hemicubes) plus direct light per texel.
    // `inside` receives the texels found inside geometry (before they were refilled).
    std::vector<glm::dvec3> gathered(std::size_t a, const AtlasTexels& t, double texelSizeM, LightmapStats& stats,
                                     const std::function<void(std::size_t)>& advanced, std::vector<std::uint8_t>& inside) {
        const GatherFn gather = [&](const std::vector<std::uint32_t>& ids, std::vector<glm::dvec3>& out,
                                    std::vector<float>& backface) {
            std::vector<GatherPoint> points(ids.size());
            for (std::size_t k = 0; k < ids.size(); ++k) points[k] = {t.position[ids[k]], t.normal[ids[k]]};
            gatherAt(points, ids, a + 1, out, &backface, stats);
        };
        const ProbeFn probe = [&](const std::vector<std::uint32_t>& ids, std::vector<glm::dvec3>& out,
                                  std::vector<double>& standardError) {
            std::vector<GatherPoint> points(ids.size());
            for (std::size_t k = 0; k < ids.size(); ++k) points[k] = {t.position[ids[k]], t.normal[ids[k]]};
            stats.gatherRaysTraced += rayGatherer_->probe(points, solve_.lighting.skyRadiance, a + 1, out, standardError, ids).traced;
        };
        // Direct light at every texel: its shadows are as sharp as the texel grid allows.
        static const std::vector<glm::dvec3> kNone;
        const std::vector<glm::dvec3>& directValue = direct_ ? directValue_[a] : kNone;
        std::vector<glm::dvec3> value;
        std::vector<std::uint8_t> invalid;
        Stopwatch clock;
        static const ProbeFn kNoProbe;
        const bool probes = rayGatherer_ && rayGatherer_->canProbe();
        placeGathers(t, settings_, texelSizeM, rays_, gather, probes ? probe : kNoProbe, directValue, stats, value, invalid, advanced);
        stats.seconds.gather += clock.lap();
        stats.invalid += std::size_t(std::count(invalid.begin(), invalid.end(), 1));
        inside = invalid;
        refillInvalid(t, texelSizeM, rays_, value, invalid);
        stats.seconds.refill += clock.lap();
        for (std::size_t i = 0; i < directValue.size(); ++i) value[i] += directValue[i];
        return value;
    }

    // Texels facing another surface across a gap narrower than elements (the top of a light panel 5 cm under a
    // ceiling, and the ceiling above it) see light that varies within the elements across the gap, and bounces back
    // and forth in it: each pass re-gathers them seeing every texel's light of the pass before (texel_light.h), one
    // bounce in the gap at texel resolution per pass, until a pass changes them by at most gapTolerance of their light
    // (the elements cannot converge the gap: they let the light it traps spread and escape). `values` (E/π per
    // texel per atlas) are updated in place.
    void refineGaps(const std::vector<AtlasTexels>& texels, std::vector<std::vector<glm::dvec3>>& values,
                    const std::vector<std::vector<std::uint8_t>>& inside, LightmapStats& stats) {
        if (settings_.gapPasses <= 0 || settings_.mode != TexelMode::Gather || texels.empty()) return;
        const double gapM = kGapPerElementSize * solve_.subdivision.elementSizeM;
        std::vector<std::vector<std::uint32_t>> gaps(texels.size());
        std::vector<std::vector<std::uint8_t>> isGap(texels.size());
        std::size_t count = 0;
        for (std::size_t a = 0; a < texels.size(); ++a) {
            const AtlasTexels& t = texels[a];
            std::vector<std::uint8_t> gap(t.count(), 0);
            tbb::parallel_for(std::size_t(0), t.count(), [&](std::size_t i) {
                const glm::dvec3 n(t.normal[i]);
                gap[i] = !inside[a][i] &&
                         rays_.occludedRay(rays_.offsetFromSurface(t.position[i], n), n, gapM, EmbreeScene::RayEnds::Lifted);
            });
            for (std::size_t i = 0; i < t.count(); ++i)
                if (gap[i]) gaps[a].push_back(std::uint32_t(i));
            count += gaps[a].size();
            isGap[a] = std::move(gap);
        }
        stats.gapTexels = count;
        if (count == 0) return;
        const PatchMesh& mesh = solved_.mesh;
        for (int pass = 0; pass < settings_.gapPasses; ++pass) {
            std::vector<glm::vec3> radiance(mesh.elements.size());
            std::vector<glm::dvec3> elementOverPi(mesh.elements.size());
            for (std::size_t e = 0; e < radiance.size(); ++e) {
                radiance[e] = solved_.solution.gatherRadiance(mesh, e, areaLights_ != nullptr);
                elementOverPi[e] = solved_.solution.displayIrradiance(e) / M_PI;
            }
            TexelLightStats ts;
            // Not normalised to the elements in the gap: there they are what is wrong (a 1.6 m element lets the light
            // the panel reflects spread and escape, where in the gap it bounces back and forth).
            std::shared_ptr<const TexelLight> light =
                makeTexelLight(scene_, mesh, atlas_, texels, values, elementOverPi, radiance, ts, &isGap);
            show(radiance, std::move(light));
            std::vector<std::vector<glm::dvec3>> next(texels.size());
            for (std::size_t a = 0; a < texels.size(); ++a) {
                std::vector<GatherPoint> points(gaps[a].size());
                for (std::size_t k = 0; k < points.size(); ++k)
                    points[k] = {texels[a].position[gaps[a][k]], texels[a].normal[gaps[a][k]]};
                gatherAt(points, gaps[a], (std::uint64_t(pass) + 1) * 0x10000ull + a, next[a], nullptr, stats);
            }
            double change = 0.0, total = 0.0;
            for (std::size_t a = 0; a < texels.size(); ++a)
                for (std::size_t k = 0; k < gaps[a].size(); ++k) {
                    glm::dvec3& v = values[a][gaps[a][k]];
                    const glm::dvec3 updated = next[a][k] + (direct_ ? directValue_[a][gaps[a][k]] : glm::dvec3(0.0));
                    change += std::abs(channelSum(updated - v));
                    total += channelSum(updated);
                    v = updated;
                }
            ++stats.gapPasses;
            stats.gapLastChange = total > 0.0 ? change / total : 0.0;
            if (stats.gapLastChange <= settings_.gapTolerance) break;
        }
    }

    // E/π of atlas `a`'s texels interpolated from the elements, plus direct light per texel.
    std::vector<glm::dvec3> interpolated(std::size_t a, const AtlasTexels& t) const {
        std::vector<glm::dvec3> value(t.count(), glm::dvec3(0.0));
        tbb::parallel_for(std::size_t(0), t.count(), [&](std::size_t i) {
            const SurfaceMesh& m = scene_.instances[std::size_t(t.instance[i])].mesh;
            const auto sourceFace = std::uint32_t(m.sourceFace(SurfaceMesh::FaceHandle(t.face[i])));
            const auto e = interpolator_.locate(std::uint32_t(t.instance[i]), sourceFace, t.position[i]);
            if (e) value[i] = interpolator_.valueAt(*e, t.position[i]) / M_PI;
            if (direct_) value[i] += directValue_[a][i];
        });
        return value;
    }

private:
    glm::dvec3 directAt(std::size_t a, const AtlasTexels& t, std::size_t i) const {
        return direct_->irradianceOverPiAt(t.position[i], t.normal[i], std::uint32_t(i * 2654435761u + a));
    }

    // Interpolated texels take only what the elements know better than a ray at the texel: the rest is evaluated
    // per texel, with its sharp shadows.
    std::vector<glm::dvec3> displayIrradiance(const SolvedScene& solved) const {
        const bool subtractRayTraced = !scene_.lights.empty() || areaLights_;
        std::vector<glm::dvec3> irradiance(solved.mesh.elements.size());
        for (std::size_t e = 0; e < irradiance.size(); ++e) {
            irradiance[e] = solved.solution.displayIrradiance(e);
            if (subtractRayTraced && e < solved.solution.rayTracedIrradiance.size())
                irradiance[e] = glm::max(irradiance[e] - solved.solution.rayTracedIrradiance[e], glm::dvec3(0.0));
        }
        return irradiance;
    }

    // A surface nearer than this fraction of the element size faces a texel across a gap (refineGaps).
    // An eighth: a light panel 5 cm under a ceiling is a gap for any element over 0.4 m; shelves 0.4 m apart are
    // not at 1.6 m elements (a quarter made 9 % of level_small's texels gap texels, for no gain).
    static constexpr double kGapPerElementSize = 0.125;

    const Scene& scene_;
    const SolvedScene& solved_;
    const UvAtlas& atlas_;
    const LightmapSettings& settings_;
    const SolveSettings& solve_;
    const EmbreeScene& rays_;
    std::unique_ptr<EmissiveAreaLights> areaLights_;
    std::unique_ptr<DirectLight> direct_;
    std::vector<std::vector<glm::dvec3>> directValue_;  // E/π per texel per atlas, when there is ray-traced light
    Gatherer gatherer_;
    std::unique_ptr<RayGatherer> rayGatherer_;  // the final gather by rays (FinalGather::Rays), else hemicubes
    ElementInterpolator interpolator_;
};

}  // namespace

std::vector<LightmapImage> bakeLightmaps(const Scene& scene, const SolvedScene& solved, const UvAtlas& atlas,
                                         const std::vector<AtlasTexels>& texels, const EmbreeScene& rays,
                                         const LightmapSettings& settings, const SolveSettings& solve, LightmapStats& stats,
                                         const LightmapProgress& progress) {
    std::vector<LightmapImage> images(texels.size());
    std::size_t total = 0, done = 0;
    for (const AtlasTexels& t : texels) total += t.count();
    stats.texels = total;
    const double texelSizeM = atlas.texelsPerUnit > 0.0 ? 1.0 / atlas.texelsPerUnit : 0.0;
    Stopwatch clock;
    TexelSolver solver(scene, solved, rays, settings, solve, atlas, texels, stats, progress);
    stats.seconds.setup = std::max(0.0, clock.lap() - stats.seconds.direct - stats.seconds.texelLight);
    std::vector<std::vector<glm::dvec3>> values(texels.size());
    std::vector<std::vector<std::uint8_t>> inside(texels.size());
    for (std::size_t a = 0; a < texels.size(); ++a) {
        if (settings.mode == TexelMode::Gather) {
            values[a] = solver.gathered(a, texels[a], texelSizeM, stats, [&](std::size_t k) {
                done += k;
                if (progress) progress(LightmapPhase::Texels, done, total);
            }, inside[a]);
        } else {
            values[a] = solver.interpolated(a, texels[a]);
            done += texels[a].count();
            if (progress) progress(LightmapPhase::Texels, done, total);
        }
    }
    clock.lap();
    solver.refineGaps(texels, values, inside, stats);
    stats.seconds.gaps = clock.lap();
    for (std::size_t a = 0; a < texels.size(); ++a) {
        const AtlasTexels& t = texels[a];
        const std::vector<glm::dvec3>& value = values[a];
        LightmapImage& image = images[a];
        image.resize(t.size);
        for (std::size_t i = 0; i < t.count(); ++i) {
            const std::size_t px = image.index(t.x[i], t.y[i]);
            image.irradianceOverPi[px] = glm::vec3(value[i]);
            image.state[px] = TexelState::Covered;
        }
    }
    return images;
}

}  // namespace hemibake
