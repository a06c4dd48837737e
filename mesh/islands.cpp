#include "mesh/islands.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "mesh/union_find.h"

namespace hemibake {
namespace {

// Euclidean distance between two boxes (0 when they touch or overlap).
double boxGapM(const Bounds& a, const Bounds& b) {
    const glm::dvec3 gap = glm::max(glm::dvec3(0.0), glm::max(a.min - b.max, b.min - a.max));
    return glm::length(gap);
}

// At most this many grid cells along the longest axis of the islands' lookup grid.
constexpr int kMostCellsPerAxis = 32;

}  // namespace

SceneIslands::SceneIslands(std::span<const Bounds> partBoundsIn, const glm::dvec3& frameCentre) {
    // A box with a non-finite corner (not from the loader, which refuses such positions) counts as empty: NaN
    // would break the sweep's ordering.
    std::vector<Bounds> partBounds(partBoundsIn.begin(), partBoundsIn.end());
    for (Bounds& b : partBounds)
        if (!std::isfinite(b.min.x + b.min.y + b.min.z + b.max.x + b.max.y + b.max.z)) b = Bounds{};
    const std::size_t n = partBounds.size();
    Bounds all;
    for (const Bounds& b : partBounds)
        if (!b.empty()) all.extend(b.min), all.extend(b.max);
    const glm::dvec3 extent = all.size();
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;

    // Sweep: a part's interval along the axis, grown by its diagonal at both ends. Two parts within the joining gap
    // (at most the larger diagonal) have overlapping intervals, so only parts still open when one starts are tested.
    std::vector<std::uint32_t> order;
    order.reserve(n);
    for (std::size_t i = 0; i < n; ++i)
        if (!partBounds[i].empty()) order.push_back(std::uint32_t(i));
    auto start = [&](std::uint32_t i) { return partBounds[i].min[axis] - partBounds[i].diagonal(); };
    auto end = [&](std::uint32_t i) { return partBounds[i].max[axis] + partBounds[i].diagonal(); };
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
        const double sa = start(a), sb = start(b);
        return sa != sb ? sa < sb : a < b;
    });
    UnionFind groups(n);
    std::vector<std::uint32_t> open;
    for (std::uint32_t i : order) {
        const double s = start(i);
        open.erase(std::remove_if(open.begin(), open.end(), [&](std::uint32_t j) { return end(j) < s; }), open.end());
        for (std::uint32_t j : open) {
            if (groups.find(i) == groups.find(j)) continue;
            const double joinM = std::max(partBounds[i].diagonal(), partBounds[j].diagonal());
            if (boxGapM(partBounds[i], partBounds[j]) <= joinM) groups.unite(i, j);
        }
        open.push_back(i);
    }

    // Islands numbered by their lowest part, so the numbering does not depend on the sweep.
    std::map<std::uint32_t, std::uint32_t> islandOfRoot;
    islandOfPart_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const auto [it, added] = islandOfRoot.emplace(groups.find(std::uint32_t(i)), std::uint32_t(bounds_.size()));
        if (added) bounds_.emplace_back();
        islandOfPart_[i] = it->second;
        if (partBounds[i].empty()) continue;
        bounds_[it->second].extend(partBounds[i].min);
        bounds_[it->second].extend(partBounds[i].max);
    }
    farthestM_.resize(bounds_.size(), 0.0);
    for (std::size_t k = 0; k < bounds_.size(); ++k) {
        if (bounds_[k].empty()) continue;
        const glm::dvec3 far = glm::max(glm::abs(bounds_[k].min - frameCentre), glm::abs(bounds_[k].max - frameCentre));
        farthestM_[k] = std::max({far.x, far.y, far.z});
    }

    // Lookup grid: cells of equal size along the longest axis, each listing the islands whose boxes meet it.
    if (bounds_.size() < 2 || all.empty()) return;
    gridBounds_ = all;
    const double longest = std::max({extent.x, extent.y, extent.z});
    const double cell = longest > 0.0 ? longest / kMostCellsPerAxis : 1.0;
    for (int a = 0; a < 3; ++a) {
        cells_[a] = std::clamp(int(std::ceil(extent[a] / cell)), 1, kMostCellsPerAxis);
        cellSizeM_[a] = extent[a] > 0.0 ? extent[a] / cells_[a] : 1.0;
    }
    auto cellRange = [&](const Bounds& b, glm::ivec3& lo, glm::ivec3& hi) {
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::clamp(int(std::floor((b.min[a] - all.min[a]) / cellSizeM_[a])), 0, cells_[a] - 1);
            hi[a] = std::clamp(int(std::floor((b.max[a] - all.min[a]) / cellSizeM_[a])), 0, cells_[a] - 1);
        }
    };
    const std::size_t cellCount = std::size_t(cells_.x) * std::size_t(cells_.y) * std::size_t(cells_.z);
    std::vector<std::vector<std::uint32_t>> perCell(cellCount);
    for (std::size_t k = 0; k < bounds_.size(); ++k) {
        if (bounds_[k].empty()) continue;
        glm::ivec3 lo, hi;
        cellRange(bounds_[k], lo, hi);
        for (int z = lo.z; z <= hi.z; ++z)
            for (int y = lo.y; y <= hi.y; ++y)
                for (int x = lo.x; x <= hi.x; ++x) perCell[cellIndex({x, y, z})].push_back(std::uint32_t(k));
    }
    cellStart_.assign(cellCount + 1, 0);
    for (std::size_t c = 0; c < cellCount; ++c) cellStart_[c + 1] = cellStart_[c] + std::uint32_t(perCell[c].size());
    cellIslands_.reserve(cellStart_.back());
    for (const auto& list : perCell) cellIslands_.insert(cellIslands_.end(), list.begin(), list.end());
}

SceneIslands SceneIslands::ofScene(const Scene& scene) {
    std::vector<Bounds> parts(scene.instances.size());
    Bounds all;
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const SurfaceMesh& mesh = scene.instances[i].mesh;
        for (auto v : mesh.vertices()) parts[i].extend(toGlm(mesh.point(v)));
        if (!parts[i].empty()) all.extend(parts[i].min), all.extend(parts[i].max);
    }
    return SceneIslands(parts, all.empty() ? glm::dvec3(0.0) : all.centre());
}

SceneIslands SceneIslands::ofElements(const ElementArrays& elements, const glm::dvec3& frameCentre) {
    std::vector<Bounds> parts;
    for (std::size_t e = 0; e < elements.size(); ++e) {
        const std::size_t i = elements.instance[e];
        if (i >= parts.size()) parts.resize(i + 1);
        for (std::uint32_t v : elements.triangles[e]) parts[i].extend(elements.vertices[v]);
    }
    return SceneIslands(parts, frameCentre);
}

double SceneIslands::distanceToIsland(std::size_t island, const glm::dvec3& p) const {
    const Bounds& b = bounds_[island];
    if (b.empty()) return std::numeric_limits<double>::infinity();
    return glm::length(glm::max(glm::dvec3(0.0), glm::max(b.min - p, p - b.max)));
}

std::size_t SceneIslands::islandAt(const glm::dvec3& p) const {
    if (bounds_.size() < 2) return 0;
    std::size_t best = bounds_.size();
    double bestM = std::numeric_limits<double>::infinity();
    auto consider = [&](std::size_t k) {
        const double d = distanceToIsland(k, p);
        if (d < bestM || (d == bestM && k < best)) best = k, bestM = d;
    };
    if (!cellStart_.empty()) {
        glm::ivec3 c;
        bool inside = true;
        for (int a = 0; a < 3; ++a) {
            const double t = std::floor((p[a] - gridBounds_.min[a]) / cellSizeM_[a]);
            inside = inside && t >= 0.0 && t < double(cells_[a]);
            c[a] = inside ? int(t) : 0;
        }
        if (inside) {
            const std::size_t cell = cellIndex(c);
            for (std::uint32_t i = cellStart_[cell]; i < cellStart_[cell + 1]; ++i) consider(cellIslands_[i]);
            if (best < bounds_.size()) return best;
        }
    }
    // A cell no island meets, or outside the grid: the nearest of all islands.
    for (std::size_t k = 0; k < bounds_.size(); ++k) consider(k);
    return best < bounds_.size() ? best : 0;
}

double SceneIslands::lengthM(std::size_t island, double relative, double floatSteps) const {
    if (island >= bounds_.size()) return 0.0;
    return std::max(relative * bounds_[island].diagonal(), floatSteps * floatStepM(farthestM_[island]));
}

double SceneIslands::largestLengthM(double relative, double floatSteps) const {
    double largest = 0.0;
    for (std::size_t k = 0; k < bounds_.size(); ++k) largest = std::max(largest, lengthM(k, relative, floatSteps));
    return largest;
}

double SceneIslands::largestDiagonalM() const {
    double largest = 0.0;
    for (const Bounds& b : bounds_)
        if (const double d = b.diagonal(); std::isfinite(d)) largest = std::max(largest, d);  // empty: 0
    return largest;
}

}  // namespace hemibake
