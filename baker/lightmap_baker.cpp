#include "baker/lightmap_baker.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "baker/direct_light.h"
#include "baker/element_interpolation.h"
#include "baker/emissive_area_lights.h"
#include "baker/embree_scene.h"
#include "baker/gatherer.h"
#include "raster/hemicube_pool.h"

namespace hemibake {

namespace {

double channelSum(const glm::dvec3& v) { return v.x + v.y + v.z; }

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

// Elias-style adaptive placement over one atlas. `gather` renders a list of texels; returns rendered count.
void placeAdaptively(const AtlasTexels& texels, const LightmapSettings& ls, double texelSizeM,
                     const std::function<void(const std::vector<std::uint32_t>&, std::vector<glm::dvec3>&,
                                              std::vector<float>&)>& gather,
                     const std::vector<glm::dvec3>& direct, std::vector<glm::dvec3>& value,
                     std::vector<std::uint8_t>& invalid, LightmapStats& stats,
                     const std::function<void(std::size_t)>& advanced) {
    const TexelGrid grid(texels);
    const std::size_t n = texels.count();
    value.assign(n, glm::dvec3(0.0));
    invalid.assign(n, 0);
    std::vector<std::uint8_t> done(n, 0);
    int coarse = 1;
    while (coarse * 2 <= std::max(ls.latticeStep, 1)) coarse *= 2;
    double floor = 0.0;  // absolute agreement floor, from the coarse level's mean
    std::vector<std::uint32_t> batch;
    std::vector<glm::dvec3> gathered;
    std::vector<float> backface;
    // Per level: the coarse lattice, then edge midpoints (between two lattice points on a row or column), then
    // cell centres (which can then use the midpoints around them as well as the diagonal corners).
    enum class Phase { Lattice, EdgeMidpoints, CellCentres };
    auto render = [&](Phase phase, int step) {
        gather(batch, gathered, backface);
        for (std::size_t k = 0; k < batch.size(); ++k) {
            value[batch[k]] = gathered[k];
            invalid[batch[k]] = backface[k] > ls.invalidBackfaceFraction;
            done[batch[k]] = 1;
        }
        stats.rendered += batch.size();
        if (phase == Phase::Lattice && step == coarse && !batch.empty()) {
            double mean = 0.0;
            for (const glm::dvec3& g : gathered) mean += channelSum(g);
            floor = 0.01 * mean / double(batch.size());
        }
        advanced(batch.size());
        batch.clear();
    };
    for (int step = coarse; step >= 1; step /= 2) {
        for (const Phase phase : {Phase::Lattice, Phase::EdgeMidpoints, Phase::CellCentres}) {
            if (phase == Phase::Lattice && step != coarse) continue;
            const double reach = 1.5 * std::sqrt(2.0) * step * texelSizeM;  // world distance of a lattice neighbour
            for (std::size_t i = 0; i < n; ++i) {
                const int x = texels.x[i], y = texels.y[i];
                if (done[i] || x % step || y % step) continue;
                if (phase == Phase::Lattice) {
                    batch.push_back(std::uint32_t(i));
                    continue;
                }
                const bool oddX = (x / step) % 2 == 1, oddY = (y / step) % 2 == 1;
                if ((oddX != oddY) != (phase == Phase::EdgeMidpoints)) continue;
                auto valueAt = [&](int dx, int dy, glm::dvec3& v) {
                    const std::int32_t j = grid.find(x + dx, y + dy);
                    if (j < 0 || !done[std::size_t(j)] || invalid[std::size_t(j)] ||
                        !continuous(texels, i, std::size_t(j), 3.0 * reach))
                        return false;
                    v = value[std::size_t(j)];
                    return true;
                };
                // Interpolate only where the light is locally smooth, and then to second order: a linear average
                // of a curved profile is biased (a wall lit from above is concave across its middle, and every
                // interpolated texel there would come out a little dark). Edge midpoints use the cubic through
                // the four lattice points on their line; cell centres 2·(axis mean) − (diagonal mean), which is
                // exact for any quadratic. The curvature each scheme drops decides where a hemicube is needed.
                bool ok = false;
                glm::dvec3 estimate(0.0);
                double curvature = 0.0, scale = 0.0;
                if (phase == Phase::EdgeMidpoints) {
                    const int ux = oddX ? step : 0, uy = oddY ? step : 0;
                    glm::dvec3 b, c, a, d;
                    if (valueAt(-ux, -uy, b) && valueAt(ux, uy, c)) {
                        ok = true;
                        scale = std::max(channelSum(b), channelSum(c));
                        if (valueAt(-3 * ux, -3 * uy, a) && valueAt(3 * ux, 3 * uy, d)) {
                            estimate = (9.0 * (b + c) - a - d) / 16.0;
                            curvature = std::abs(channelSum(-a + b + c - d)) / 16.0;  // |cubic − linear| at the midpoint
                        } else {
                            estimate = 0.5 * (b + c);
                            curvature = std::abs(channelSum(b - c));  // at a chart edge: plain agreement
                        }
                    }
                } else {
                    glm::dvec3 c00, c10, c01, c11, l, r, u, dn;
                    if (valueAt(-step, -step, c00) && valueAt(step, -step, c10) && valueAt(-step, step, c01) &&
                        valueAt(step, step, c11)) {
                        ok = true;
                        const glm::dvec3 diagonal = 0.25 * (c00 + c10 + c01 + c11);
                        scale = std::max({channelSum(c00), channelSum(c10), channelSum(c01), channelSum(c11)});
                        curvature = std::abs(channelSum(c00 + c11 - c10 - c01)) / 2.0;  // the twist term
                        estimate = diagonal;
                        if (valueAt(-step, 0, l) && valueAt(step, 0, r) && valueAt(0, -step, u) && valueAt(0, step, dn)) {
                            const glm::dvec3 axis = 0.25 * (l + r + u + dn);
                            estimate = 2.0 * axis - diagonal;
                            curvature = std::max(curvature, std::abs(channelSum(axis - diagonal)));
                        }
                    }
                }
                // The tolerance is relative to what the texel will hold: the gathered light plus the direct light
                // added by rays afterwards (a faint bounce beside a bright direct term needs no hemicube).
                if (!direct.empty()) scale += channelSum(direct[i]);
                if (ok && curvature <= ls.interpolationTolerance * (scale + floor)) {
                    value[i] = glm::max(estimate, glm::dvec3(0.0));
                    done[i] = 1;
                    ++stats.interpolated;
                } else {
                    batch.push_back(std::uint32_t(i));
                }
            }
            render(phase, step);
        }
    }
}

// Texels inside geometry saw mostly back faces: take the mean of valid continuous neighbours (a few rings).
void refillInvalid(const AtlasTexels& texels, double texelSizeM, std::vector<glm::dvec3>& value,
                   std::vector<std::uint8_t>& invalid) {
    const TexelGrid grid(texels);
    for (int ring = 0; ring < 4; ++ring) {
        std::vector<std::pair<std::size_t, glm::dvec3>> fixes;
        for (std::size_t i = 0; i < texels.count(); ++i) {
            if (!invalid[i]) continue;
            glm::dvec3 sum(0.0);
            int count = 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const std::int32_t j = grid.find(texels.x[i] + dx, texels.y[i] + dy);
                    if (j < 0 || invalid[std::size_t(j)] || !continuous(texels, i, std::size_t(j), 3.0 * texelSizeM)) continue;
                    sum += value[std::size_t(j)];
                    ++count;
                }
            if (count) fixes.emplace_back(i, sum / double(count));
        }
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

std::vector<LightmapImage> bakeLightmaps(const Scene& scene, const PatchMesh& mesh, const RadiositySolution& solution,
                                         const UvAtlas& atlas, const std::vector<AtlasTexels>& texels, HemicubePool& pool,
                                         const EmbreeScene& rays, const BakeSettings& settings, LightmapStats& stats,
                                         const LightmapProgress& progress) {
    const LightmapSettings& ls = settings.lightmap;
    std::vector<LightmapImage> images(texels.size());
    std::size_t total = 0, done = 0;
    for (const AtlasTexels& t : texels) total += t.count();
    stats.texels = total;
    const double texelSizeM = atlas.texelsPerUnit > 0.0 ? 1.0 / atlas.texelsPerUnit : 0.0;

    // Ray-traced direct light at every texel: punctual lights, and emitters when the solver ray traced them
    // (same decision, same inputs); the gather then sees emitters without their emission.
    const std::unique_ptr<EmissiveAreaLights> areaLights = makeEmissiveAreaLights(mesh, rays, settings.lighting);
    std::unique_ptr<DirectLight> direct;
    if (!scene.lights.empty() || areaLights) {
        DirectLightSettings ds;
        ds.sunAngularDiameterRad = settings.lighting.sunAngularDiameterRad;
        direct = std::make_unique<DirectLight>(scene, rays, ds, areaLights.get());
    }
    std::vector<glm::vec3> radiance(mesh.elements.size());
    std::vector<glm::dvec3> displayIrradiance(mesh.elements.size());
    for (std::size_t e = 0; e < mesh.elements.size(); ++e) {
        radiance[e] = solution.gatherRadiance(mesh, e, areaLights != nullptr);
        // Interpolated texels take only what the elements know better than a ray at the texel: the rest is
        // evaluated per texel below, with its sharp shadows.
        displayIrradiance[e] = solution.displayIrradiance(e);
        if (direct && e < solution.rayTracedIrradiance.size())
            displayIrradiance[e] = glm::max(displayIrradiance[e] - solution.rayTracedIrradiance[e], glm::dvec3(0.0));
    }
    Gatherer gatherer(pool, settings.solver.seed ^ 0x5EEDull);
    if (ls.mode == TexelMode::Gather) gatherer.setElementRadiance(radiance);
    const ElementInterpolator interpolator(mesh, displayIrradiance);

    for (std::size_t a = 0; a < texels.size(); ++a) {
        const AtlasTexels& t = texels[a];
        LightmapImage& image = images[a];
        image.resize(t.size);
        std::vector<glm::dvec3> value;
        std::vector<std::uint8_t> invalid(t.count(), 0);
        if (ls.mode == TexelMode::Gather) {
            auto gather = [&](const std::vector<std::uint32_t>& ids, std::vector<glm::dvec3>& out, std::vector<float>& backface) {
                std::vector<GatherPoint> points(ids.size());
                for (std::size_t k = 0; k < ids.size(); ++k) points[k] = {t.position[ids[k]], t.normal[ids[k]]};
                gatherer.gather(points, settings.lighting.skyRadiance, a + 1, out, &backface);
            };
            // Direct light at every texel: its shadows are as sharp as the texel grid allows.
            std::vector<glm::dvec3> directValue;
            if (direct) {
                directValue.resize(t.count());
                tbb::parallel_for(std::size_t(0), t.count(), [&](std::size_t i) {
                    directValue[i] = direct->irradianceOverPiAt(t.position[i], t.normal[i], std::uint32_t(i * 2654435761u + a));
                });
            }
            placeAdaptively(t, ls, texelSizeM, gather, directValue, value, invalid, stats, [&](std::size_t k) {
                done += k;
                if (progress) progress(done, total);
            });
            stats.invalid += std::size_t(std::count(invalid.begin(), invalid.end(), 1));
            refillInvalid(t, texelSizeM, value, invalid);
            for (std::size_t i = 0; i < directValue.size(); ++i) value[i] += directValue[i];
        } else {
            value.assign(t.count(), glm::dvec3(0.0));
            const auto& inst = scene.instances;
            tbb::parallel_for(std::size_t(0), t.count(), [&](std::size_t i) {
                const SurfaceMesh& m = inst[std::size_t(t.instance[i])].mesh;
                const auto sourceFace = std::uint32_t(m.sourceFace(SurfaceMesh::FaceHandle(t.face[i])));
                const auto e = interpolator.locate(std::uint32_t(t.instance[i]), sourceFace, t.position[i]);
                if (e) value[i] = interpolator.valueAt(*e, t.position[i]) / M_PI;
                if (direct)
                    value[i] += direct->irradianceOverPiAt(t.position[i], t.normal[i], std::uint32_t(i * 2654435761u + a));
            });
            done += t.count();
            if (progress) progress(done, total);
        }
        for (std::size_t i = 0; i < t.count(); ++i) {
            const std::size_t px = image.index(t.x[i], t.y[i]);
            image.irradianceOverPi[px] = glm::vec3(value[i]);
            image.state[px] = TexelState::Covered;
        }
    }
    return images;
}

}  // namespace hemibake
