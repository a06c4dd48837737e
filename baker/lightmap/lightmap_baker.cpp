#include "baker/lightmap/lightmap_baker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

#include <tbb/parallel_for.h>

#include "baker/direct/direct_light.h"
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


// One atlas's texels on its grid, for neighbour lookups.
struct TexelGrid {
    const AtlasTexels& t;
    std::vector<std::int32_t> at;  // size² → texel index or -1
    explicit TexelGrid(const AtlasTexels& texels) : t(texels), at(std::size_t(texels.size) * std::size_t(texels.size), -1) {
        for (std::size_t i = 0; i < t.count(); ++i) at[std::size_t(t.y[i]) * std::size_t(t.size) + t.x[i]] = std::int32_t(i);
    }
    std::int32_t find(int x, int y) const {
        if (x < 0 || y < 0 || x >= t.size || y >= t.size) return -1;
        return at[std::size_t(y) * std::size_t(t.size) + std::size_t(x)];
    }
};

// Neighbours can stand in for each other only on one continuous piece of surface: same instance, similar
// normal, and as far apart in the world as in the atlas (a chart boundary breaks that).
bool continuous(const AtlasTexels& t, std::size_t a, std::size_t b, double maxDistanceM) {
    return t.instance[a] == t.instance[b] && glm::dot(t.normal[a], t.normal[b]) > 0.9f &&
           glm::length(t.position[a] - t.position[b]) <= maxDistanceM;
}

using GatherFn = std::function<void(const std::vector<std::uint32_t>&, std::vector<glm::dvec3>&, std::vector<float>&)>;

// Elias-style adaptive placement over one atlas: per level the coarse lattice, then edge midpoints (between two
// lattice points on a row or column), then cell centres (which can then use the midpoints around them as well as
// the diagonal corners). `gather` renders a list of texels.
class AdaptivePlacer {
public:
    AdaptivePlacer(const AtlasTexels& texels, const LightmapSettings& settings, double texelSizeM, const EmbreeScene& rays,
                   const GatherFn& gather, const std::vector<glm::dvec3>& direct, LightmapStats& stats)
        : t_(texels), grid_(texels), settings_(settings), texelSizeM_(texelSizeM), rays_(rays), gather_(gather),
          direct_(direct), stats_(stats), done_(texels.count(), 0) {
        while (coarse_ * 2 <= std::max(settings.latticeStep, 1)) coarse_ *= 2;
    }

    // Fills `value` (E/π gathered, without direct light) and `invalid` (inside geometry) for every texel; `advanced`
    // gets the texels finished (gathered or interpolated) after each phase, so over the run it sums to every texel.
    void run(std::vector<glm::dvec3>& value, std::vector<std::uint8_t>& invalid, const std::function<void(std::size_t)>& advanced) {
        const std::size_t n = t_.count();
        value.assign(n, glm::dvec3(0.0));
        invalid.assign(n, 0);
        value_ = &value;
        invalid_ = &invalid;
        for (int step = coarse_; step >= 1; step /= 2)
            for (const Phase phase : {Phase::Lattice, Phase::EdgeMidpoints, Phase::CellCentres}) {
                if (phase == Phase::Lattice && step != coarse_) continue;
                for (std::size_t i = 0; i < n; ++i) visit(phase, step, i);
                render(phase, step);
                advanced(finished_);
                finished_ = 0;
            }
    }

private:
    enum class Phase { Lattice, EdgeMidpoints, CellCentres };
    // What interpolation would give at a texel, the curvature it drops there, and the spread of the neighbours it
    // used (a step between two neighbours has no curvature at all, only spread).
    struct Estimate {
        bool ok = false;
        glm::dvec3 value{0.0};
        double curvature = 0.0, spread = 0.0, scale = 0.0;
    };

    // Interpolates texel i when its neighbours at this step agree, else queues it for a hemicube.
    void visit(Phase phase, int step, std::size_t i) {
        const int x = t_.x[i], y = t_.y[i];
        if (done_[i] || x % step || y % step) return;
        if (phase == Phase::Lattice) {
            batch_.push_back(std::uint32_t(i));
            ++stats_.renderedLattice;
            return;
        }
        const bool oddX = (x / step) % 2 == 1, oddY = (y / step) % 2 == 1;
        if ((oddX != oddY) != (phase == Phase::EdgeMidpoints)) return;
        missing_ = Missing::None;
        Estimate e = phase == Phase::EdgeMidpoints ? edgeMidpoint(i, step, oddX, oddY) : cellCentre(i, step);
        // The tolerance is relative to what the texel will hold: the gathered light plus the direct light added
        // by rays afterwards (a faint bounce beside a bright direct term needs no hemicube).
        if (!direct_.empty()) e.scale += channelSum(direct_[i]);
        // Interpolating across a step of contrast Δ errs by up to Δ/2 at the texel: a spread of up to twice the
        // tolerance keeps that error within it.
        const double allowed = settings_.interpolationTolerance * (e.scale + floor_);
        if (e.ok && e.curvature <= allowed && e.spread <= 2.0 * allowed) {
            (*value_)[i] = glm::max(e.value, glm::dvec3(0.0));
            done_[i] = 1;
            ++finished_;
            ++stats_.interpolated;
        } else {
            batch_.push_back(std::uint32_t(i));
            ++(e.ok ? stats_.renderedDisagreeing : stats_.renderedUnsupported);
            if (!e.ok) {
                LightmapStats::UnsupportedBy& by = stats_.renderedUnsupportedBy;
                ++(missing_ == Missing::Inside ? by.insideGeometry : missing_ == Missing::OutOfSight ? by.outOfSight : by.chartEdge);
            }
        }
    }

    // The value of a finished, valid neighbour on the same piece of surface and in sight of the texel (a wall
    // standing on the surface between them hides one from the other), if there is one.
    // The first missing one is recorded in missing_ (why the texel had to be gathered).
    bool neighbour(std::size_t i, int dx, int dy, int step, glm::dvec3& v) const {
        const double reach = 1.5 * std::sqrt(2.0) * step * texelSizeM_;  // world distance of a lattice neighbour
        const std::int32_t j = grid_.find(t_.x[i] + dx, t_.y[i] + dy);
        const auto missing = [this](Missing why) {
            if (missing_ == Missing::None) missing_ = why;
            return false;
        };
        if (j < 0 || !done_[std::size_t(j)] || !continuous(t_, i, std::size_t(j), 3.0 * reach)) return missing(Missing::ChartEdge);
        if ((*invalid_)[std::size_t(j)]) return missing(Missing::Inside);
        if (!inSight(i, std::size_t(j))) return missing(Missing::OutOfSight);
        v = (*value_)[std::size_t(j)];
        return true;
    }

    bool inSight(std::size_t i, std::size_t j) const {
        const glm::dvec3 from = rays_.offsetFromSurface(t_.position[i], glm::dvec3(t_.normal[i]));
        const glm::dvec3 to = rays_.offsetFromSurface(t_.position[j], glm::dvec3(t_.normal[j]));
        return !rays_.occluded(from, to, EmbreeScene::RayEnds::Lifted);
    }

    static double spreadOf(std::initializer_list<glm::dvec3> values) {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (const glm::dvec3& v : values) {
            lo = std::min(lo, channelSum(v));
            hi = std::max(hi, channelSum(v));
        }
        return hi - lo;
    }

    // Interpolate only where the light is locally smooth, and then to second order: a linear average of a curved
    // profile is biased (a wall lit from above is concave across its middle, and every interpolated texel there
    // would come out a little dark). Edge midpoints use the cubic through the four lattice points on their line.
    Estimate edgeMidpoint(std::size_t i, int step, bool oddX, bool oddY) const {
        Estimate e;
        const int ux = oddX ? step : 0, uy = oddY ? step : 0;
        glm::dvec3 b, c, a, d;
        if (!neighbour(i, -ux, -uy, step, b) || !neighbour(i, ux, uy, step, c)) return e;
        e.ok = true;
        e.scale = std::max(channelSum(b), channelSum(c));
        e.spread = spreadOf({b, c});
        if (neighbour(i, -3 * ux, -3 * uy, step, a) && neighbour(i, 3 * ux, 3 * uy, step, d)) {
            e.value = (9.0 * (b + c) - a - d) / 16.0;
            e.curvature = std::abs(channelSum(-a + b + c - d)) / 16.0;  // |cubic − linear| at the midpoint
        } else {
            e.value = 0.5 * (b + c);
            e.curvature = std::abs(channelSum(b - c));  // at a chart edge: plain agreement
        }
        return e;
    }

    // Cell centres: 2·(axis mean) − (diagonal mean), exact for any quadratic; the twist term and the axis/diagonal
    // disagreement measure what it drops.
    Estimate cellCentre(std::size_t i, int step) const {
        Estimate e;
        glm::dvec3 c00, c10, c01, c11, l, r, u, dn;
        if (!neighbour(i, -step, -step, step, c00) || !neighbour(i, step, -step, step, c10) ||
            !neighbour(i, -step, step, step, c01) || !neighbour(i, step, step, step, c11))
            return e;
        e.ok = true;
        const glm::dvec3 diagonal = 0.25 * (c00 + c10 + c01 + c11);
        e.scale = std::max({channelSum(c00), channelSum(c10), channelSum(c01), channelSum(c11)});
        e.spread = spreadOf({c00, c10, c01, c11});
        e.curvature = std::abs(channelSum(c00 + c11 - c10 - c01)) / 2.0;  // the twist term
        e.value = diagonal;
        if (neighbour(i, -step, 0, step, l) && neighbour(i, step, 0, step, r) && neighbour(i, 0, -step, step, u) &&
            neighbour(i, 0, step, step, dn)) {
            const glm::dvec3 axis = 0.25 * (l + r + u + dn);
            e.value = 2.0 * axis - diagonal;
            e.curvature = std::max(e.curvature, std::abs(channelSum(axis - diagonal)));
            e.spread = std::max(e.spread, spreadOf({l, r, u, dn}));
        }
        return e;
    }

    // Renders the queued texels; the coarse lattice's mean sets the absolute agreement floor.
    void render(Phase phase, int step) {
        gather_(batch_, gathered_, backface_);
        for (std::size_t k = 0; k < batch_.size(); ++k) {
            (*value_)[batch_[k]] = gathered_[k];
            (*invalid_)[batch_[k]] = backface_[k] > settings_.invalidBackfaceFraction;
            done_[batch_[k]] = 1;
        }
        stats_.rendered += batch_.size();
        finished_ += batch_.size();
        if (phase == Phase::Lattice && step == coarse_ && !batch_.empty()) {
            double mean = 0.0;
            for (const glm::dvec3& g : gathered_) mean += channelSum(g);
            floor_ = 0.01 * mean / double(batch_.size());
        }
        batch_.clear();
    }

    const AtlasTexels& t_;
    const TexelGrid grid_;
    const LightmapSettings& settings_;
    const double texelSizeM_;
    const EmbreeScene& rays_;
    const GatherFn& gather_;
    const std::vector<glm::dvec3>& direct_;
    LightmapStats& stats_;
    std::vector<std::uint8_t> done_;
    std::vector<glm::dvec3>* value_ = nullptr;
    std::vector<std::uint8_t>* invalid_ = nullptr;
    int coarse_ = 1;
    double floor_ = 0.0;  // absolute agreement floor, from the coarse level's mean
    std::vector<std::uint32_t> batch_;
    std::vector<glm::dvec3> gathered_;
    std::vector<float> backface_;
    enum class Missing { None, ChartEdge, Inside, OutOfSight };
    mutable Missing missing_ = Missing::None;  // the first neighbour the texel being visited lacked
    std::size_t finished_ = 0;  // texels finished (gathered or interpolated) since progress was last reported
};

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
                    if (j < 0 || invalid[std::size_t(j)] || !continuous(texels, i, std::size_t(j), 3.0 * texelSizeM)) continue;
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
        // Direct light at every texel: its shadows are as sharp as the texel grid allows.
        static const std::vector<glm::dvec3> kNone;
        const std::vector<glm::dvec3>& directValue = direct_ ? directValue_[a] : kNone;
        std::vector<glm::dvec3> value;
        std::vector<std::uint8_t> invalid;
        Stopwatch clock;
        AdaptivePlacer(t, settings_, texelSizeM, rays_, gather, directValue, stats).run(value, invalid, advanced);
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
