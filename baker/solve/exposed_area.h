#pragma once
// Elements partly inside or under other geometry (a floor element straddling the footprint of a block standing
// on it) take part in the solve only with their exposed part. The covered part is not a surface: no viewer and
// no hemicube ever sees it, so an element receives power in proportion to its exposed area; dividing that power
// by the whole triangle's area (ProgressiveShooter: ΔE_j = ΔB_i·F_ij·A_i/A_j) would make it dark by its covered
// fraction, while the texels on its exposed part, each gathering at a visible point, are right.
//
// So after subdivision each element's area becomes its exposed area, its centroid (where hemicubes, gathers
// and sky rays are placed) moves onto the exposed part, and its patch's area, centroid and area-weighted means
// are recomputed as mesh/subdivision.cpp forms them. Everything weighted by element area (shooting power, the
// absorbed-power ledger, the ambient term, gathering) then follows.
//
// A point is covered when it is enclosed by back faces of single-sided surfaces (counted as for texels,
// baker/inside_geometry.h): more than `coveredBackfaceFraction` (0.9) of the texel criterion's cosine-weighted
// rays meet them, and so does every ray of a ring just above the surface (10° elevation), which is what tells a
// closed cover (a block standing on the floor) from a roof open at the sides. Points are the k × k stratified
// points of the triangle (the centroids of its k² congruent sub-triangles, as DirectLight::
// elementIrradianceOverPi uses).
//
// Not the texels' criterion (10 % of the cosine-weighted hemisphere): that also calls the floor under a table
// top made of one single-sided quad "inside", yet that floor is seen and lit from the sides, so its element's
// power includes it; leaving it out of the area would pour that light onto the rest of the element (as every
// gather sees it), and make an element wholly under the table 1/minFraction times too bright. Texels there are
// refilled by the bake either way. The reverse error is benign: a point left uncovered that gets no light
// (under a block floating over a gap, within ≈ 6 gap widths of its edge, where the ring sees out) only leaves
// its element darker, as it was without trimming.
//
// Emitters are trimmed like every element: what the covered part of an emitter would emit lands on the back
// faces covering it and never reaches the scene. Back-side copies of double-sided surfaces are tested on
// their own side (their normal), so each side is trimmed by what covers that side.
#include <cmath>
#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "baker/rays/inside_geometry.h"
#include "baker/solve/solve_settings.h"
#include "mesh/patches.h"
#include "mesh/scene.h"

namespace hemibake {

class EmbreeScene;

struct ExposedAreaReport {
    std::size_t elementsTrimmed = 0;  // partly exposed: area reduced
    std::size_t elementsCovered = 0;  // nothing exposed: kept at minFraction of its triangle
    double areaRemovedM2 = 0.0;       // triangle area minus exposed area, summed over elements
};

// Per element: the exposed fraction of its triangle (in [0, 1], before the minFraction floor; exactly 1 when
// every point is open) and the point to place hemicubes at (the triangle's centroid when nothing is covered or
// nothing is exposed, otherwise the exposed point nearest the exposed part's centroid, so it never lies under
// the cover even when the exposed part is not convex). Parallel over elements (oneTBB); deterministic.
struct ElementExposure {
    std::vector<double> fraction;
    std::vector<glm::dvec3> centroid;
};
ElementExposure measureExposure(const Scene& scene, const EmbreeScene& rays, const PatchMesh& mesh,
                                const ExposedAreaSettings& settings = {});

// measureExposure, then trims `mesh` as described above. Elements and patches with nothing covered are left
// bit-for-bit as they were.
ExposedAreaReport applyExposedAreas(const Scene& scene, const EmbreeScene& rays, PatchMesh& mesh,
                                    const ExposedAreaSettings& settings = {});

}  // namespace hemibake
