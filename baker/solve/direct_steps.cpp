#include "baker/solve/direct_steps.h"

#include <algorithm>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include "baker/direct/direct_light.h"
#include "baker/direct/emissive_area_lights.h"
#include "baker/util/colour.h"
#include "mesh/triangle_sampling.h"

namespace hemibake {

RefinementRequest findDirectLightSteps(const Scene& scene, const EmbreeScene& rays, const SolveSettings& settings,
                                       const RefinementRequest& base, DirectStepReport* report) {
    const DirectStepSettings& s = settings.directSteps;
    if (s.levels < 0 || s.samplesPerSide < 1 || s.emitterSamples < 1 || !(s.contrast > 0.0) || !(s.minSizeFraction > 0.0))
        throw std::invalid_argument("direct steps: levels >= 0, samplesPerSide and emitterSamples >= 1, contrast and "
                                    "minSizeFraction > 0");
    if (report) *report = {};
    RefinementRequest request = base;
    if (s.levels == 0) return {};
    PatchMesh mesh = subdivide(scene, settings.subdivision, base.regions.empty() ? nullptr : &base);
    // The light the solver will trace: punctual lights, and emitters when rays carry them (few shadow rays: a
    // step is a large difference, not a precise one).
    const std::unique_ptr<EmissiveAreaLights> areaLights =
        settings.lighting.emitters == EmitterLighting::Rays ? makeEmissiveAreaLights(mesh, rays, settings.lighting, s.emitterSamples)
                                                            : nullptr;
    if (scene.lights.empty() && !areaLights) return {};
    DirectLightSettings ds;
    ds.sunAngularDiameterRad = settings.lighting.sunAngularDiameterRad;
    const DirectLight direct(scene, rays, ds, areaLights.get());
    const double floorM = settings.subdivision.elementSizeM * s.minSizeFraction;
    const int k = s.samplesPerSide;
    for (int level = 0; level < s.levels; ++level) {
        const ElementArrays& el = mesh.elements;
        std::vector<std::uint8_t> steps(el.size(), 0);
        std::vector<double> peak(el.size(), 0.0);
        tbb::parallel_for(std::size_t(0), el.size(), [&](std::size_t e) {
            if (el.emittedRadiance[e] != glm::vec3(0.0f) || longestEdgeM(el, e) * 0.5 < floorM) return;
            double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
            std::uint32_t index = 0;
            forEachSubTriangleCentroid(k, [&](double wa, double wb) {
                const double v = channelSum(direct.irradianceOverPiAt(pointOnElement(el, e, wa, wb), el.normal[e],
                                                                      std::uint32_t(e * 2654435761u + index++)));
                lo = std::min(lo, v);
                hi = std::max(hi, v);
            });
            peak[e] = hi;
            steps[e] = hi - lo > s.contrast * hi ? 1 : 0;
        });
        // Steps too faint to matter beside the scene's light are left: a fraction of the mean peak over lit elements.
        double sum = 0.0, area = 0.0;
        for (std::size_t e = 0; e < el.size(); ++e)
            if (peak[e] > 0.0) sum += peak[e] * el.areaM2[e], area += el.areaM2[e];
        const double faint = area > 0.0 ? s.faintFraction * sum / area : 0.0;
        std::size_t found = 0;
        for (std::size_t e = 0; e < el.size(); ++e) {
            if (!steps[e] || !(peak[e] > faint)) continue;
            const double sizeM = std::max(0.5 * longestEdgeM(el, e), floorM);
            request.regions.push_back({el.centroid[e], farthestCornerM(el, e), sizeM});
            ++found;
            if (report) report->smallestSizeM = report->smallestSizeM == 0.0 ? sizeM : std::min(report->smallestSizeM, sizeM);
        }
        if (report) report->regions += found, report->levels += found ? 1 : 0;
        if (!found) break;
        if (level + 1 < s.levels) mesh = subdivide(scene, settings.subdivision, &request);
    }
    request.regions.erase(request.regions.begin(), request.regions.begin() + std::ptrdiff_t(base.regions.size()));
    return request;
}

}  // namespace hemibake
