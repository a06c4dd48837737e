#include "mesh/pack.h"

#include <algorithm>
#include <limits>
#include <map>
#include <numeric>
#include <climits>
#include <cstdlib>

namespace hemibake {

namespace {

// One orientation of a chart, rasterized. Coordinates are relative to the footprint's bounding box:
// atlas T = scale·R(angle)·uv + shift + (X, Y) where (X, Y) is where the box's top-left texel lands.
struct Footprint {
    double angle = 0.0;
    glm::dvec2 shift{0.0};
    int width = 0, height = 0;
    std::uint32_t texels = 0;
    std::vector<std::int32_t> bottom;  // per column: first covered row (height if the column is empty)
    std::vector<std::int32_t> top;     // per column: last covered row + 1 (0 if empty)
    std::vector<std::int32_t> dilatedBottom;  // per column k ∈ [-pad, width+pad): lowest row of the dilated footprint
};

struct Prepared {
    double scale = 0.0;
    bool scaledDown = false;
    int orientations = 1;
    Footprint fp[4];
};

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

std::vector<glm::dvec2> convexHull(std::vector<glm::dvec2> pts) {
    std::sort(pts.begin(), pts.end(), [](const glm::dvec2& a, const glm::dvec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
    if (pts.size() < 3) return pts;
    std::vector<glm::dvec2> h(2 * pts.size());
    std::size_t k = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
        while (k >= 2 && cross2(h[k - 1] - h[k - 2], pts[i] - h[k - 2]) <= 0) --k;
        h[k++] = pts[i];
    }
    for (std::size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
        while (k >= t && cross2(h[k - 1] - h[k - 2], pts[i] - h[k - 2]) <= 0) --k;
        h[k++] = pts[i];
    }
    h.resize(k - 1);
    return h;
}

glm::dvec2 rotate(const glm::dvec2& p, double c, double s) { return {c * p.x - s * p.y, s * p.x + c * p.y}; }

void extentAt(std::span<const glm::dvec2> pts, double angle, glm::dvec2& lo, glm::dvec2& hi) {
    const double c = std::cos(angle), s = std::sin(angle);
    lo = glm::dvec2(std::numeric_limits<double>::infinity());
    hi = -lo;
    for (const auto& p : pts) {
        const glm::dvec2 q = rotate(p, c, s);
        lo = glm::min(lo, q);
        hi = glm::max(hi, q);
    }
}

// Rotation that turns the chart's minimal-area bounding box axis-aligned and landscape (width ≥ height).
double bestAngle(std::span<const glm::dvec2> uv) {
    std::vector<glm::dvec2> hull = convexHull(std::vector<glm::dvec2>(uv.begin(), uv.end()));
    glm::dvec2 lo, hi;
    extentAt(hull, 0.0, lo, hi);
    double best = 0.0;
    double bestArea = (hi.x - lo.x) * (hi.y - lo.y);
    const std::size_t n = hull.size();
    const std::size_t step = std::max<std::size_t>(1, n / 256);
    for (std::size_t i = 0; i < n && n >= 3; i += step) {
        const glm::dvec2 e = hull[(i + 1) % n] - hull[i];
        if (e.x == 0.0 && e.y == 0.0) continue;
        const double a = -std::atan2(e.y, e.x);
        extentAt(hull, a, lo, hi);
        const double area = (hi.x - lo.x) * (hi.y - lo.y);
        if (area < bestArea * (1.0 - 1e-9)) {
            bestArea = area;
            best = a;
        }
    }
    extentAt(hull, best, lo, hi);
    if (hi.y - lo.y > (hi.x - lo.x) * (1.0 + 1e-9)) best += 0.5 * M_PI;
    // Snap near-multiples of 90° so axis-aligned charts stay exactly axis-aligned.
    const double quarter = std::round(best / (0.5 * M_PI));
    if (std::abs(best - quarter * 0.5 * M_PI) < 1e-12) best = quarter * 0.5 * M_PI;
    return best;
}

Footprint rasterize(const PackChartInput& chart, double angle, double scale, int pad) {
    Footprint fp;
    fp.angle = angle;
    const double c = std::cos(angle), s = std::sin(angle);
    // Exact zero for exact quarter turns (cos(π/2) is not 0 in floating point).
    const double cc = std::abs(c) < 1e-15 ? 0.0 : c, ss = std::abs(s) < 1e-15 ? 0.0 : s;
    std::vector<glm::dvec2> q(chart.uv.size());
    glm::dvec2 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < q.size(); ++i) {
        q[i] = scale * rotate(chart.uv[i], cc, ss);
        lo = glm::min(lo, q[i]);
        hi = glm::max(hi, q[i]);
    }
    for (auto& p : q) p -= lo;
    const int bw = int(std::ceil(hi.x - lo.x)) + 2, bh = int(std::ceil(hi.y - lo.y)) + 2;
    std::vector<std::uint8_t> bits(std::size_t(bw) * std::size_t(bh), 0);
    int x0 = bw, y0 = bh, x1 = -1, y1 = -1;
    for (const auto& t : chart.triangles) {
        forEachTouchedTexel(q[std::size_t(t[0])], q[std::size_t(t[1])], q[std::size_t(t[2])], kPackShrinkTexels, [&](long i, long j) {
            if (i < 0 || j < 0 || i >= bw || j >= bh) return;  // cannot happen: q ∈ [0, extent]
            auto& b = bits[std::size_t(j) * std::size_t(bw) + std::size_t(i)];
            if (!b) {
                b = 1;
                ++fp.texels;
                x0 = std::min(x0, int(i));
                x1 = std::max(x1, int(i));
                y0 = std::min(y0, int(j));
                y1 = std::max(y1, int(j));
            }
        });
    }
    if (x1 < 0) {  // no area at all (degenerate chart): reserve one texel
        x0 = y0 = x1 = y1 = 0;
        bits[0] = 1;
        fp.texels = 1;
    }
    fp.width = x1 - x0 + 1;
    fp.height = y1 - y0 + 1;
    fp.shift = -lo - glm::dvec2(x0, y0);
    fp.bottom.assign(std::size_t(fp.width), fp.height);
    fp.top.assign(std::size_t(fp.width), 0);
    for (int j = y0; j <= y1; ++j)
        for (int i = x0; i <= x1; ++i)
            if (bits[std::size_t(j) * std::size_t(bw) + std::size_t(i)]) {
                const std::size_t col = std::size_t(i - x0);
                fp.bottom[col] = std::min(fp.bottom[col], j - y0);
                fp.top[col] = std::max(fp.top[col], j - y0 + 1);
            }
    // Square dilation by pad: column k sees the bottoms of columns k-pad .. k+pad, lowered by pad.
    fp.dilatedBottom.assign(std::size_t(fp.width + 2 * pad), std::numeric_limits<std::int32_t>::max());
    for (int k = -pad; k < fp.width + pad; ++k) {
        int m = std::numeric_limits<int>::max();
        for (int cc2 = std::max(0, k - pad); cc2 <= std::min(fp.width - 1, k + pad); ++cc2)
            if (fp.top[std::size_t(cc2)] > 0) m = std::min(m, fp.bottom[std::size_t(cc2)]);
        fp.dilatedBottom[std::size_t(k + pad)] = m == std::numeric_limits<int>::max() ? m : m - pad;
    }
    return fp;
}

struct Placement {
    int orientation = 0;
    int x = 0, y = 0;  // top-left of the footprint box
};

class Packer {
public:
    Packer(std::span<const PackChartInput> charts, const PackSettings& s) : charts_(charts), s_(s) {
        pad_ = std::max(0, s.paddingTexels);
        border_ = std::max(0, s.borderTexels);
        prepared_.resize(charts.size());
        for (std::size_t i = 0; i < charts.size(); ++i) prepare(i, s.texelsPerUnit);
    }

    int avail(int size) const { return size - 2 * border_; }

    // Rasterizes chart i at `scale`, shrinking it until it fits into a maxAtlasSize atlas.
    void prepare(std::size_t i, double scale) {
        Prepared& p = prepared_[i];
        const double angle = s_.allowRotation ? bestAngle(charts_[i].uv) : 0.0;
        p.scaledDown = scale < s_.texelsPerUnit;
        for (int attempt = 0;; ++attempt) {
            p.scale = scale;
            p.fp[0] = rasterize(charts_[i], angle, scale, pad_);
            const int maxDim = std::max(p.fp[0].width, p.fp[0].height);
            if (maxDim <= avail(s_.maxAtlasSize) || attempt > 60) break;
            scale *= 0.98 * double(avail(s_.maxAtlasSize)) / double(maxDim);
            p.scaledDown = true;
        }
        p.orientations = 1;
        if (s_.allowRotation)
            for (int o = 1; o < 4; ++o) p.fp[p.orientations++] = rasterize(charts_[i], angle + 0.5 * M_PI * o, p.scale, pad_);
    }

    double estimateArea(std::size_t i) const {
        const Footprint& f = prepared_[i].fp[0];
        return double(f.width + pad_) * double(f.height + pad_);
    }

    // Packs `order` (already sorted) into one atlas of `size`; false if some chart does not fit.
    bool pack(const std::vector<std::size_t>& order, int size, std::vector<Placement>& out) const {
        std::vector<std::int32_t> sky(std::size_t(size), 0);
        out.assign(order.size(), {});
        const int lim = size - border_;
        for (std::size_t n = 0; n < order.size(); ++n) {
            const Prepared& p = prepared_[order[n]];
            int bestScore = std::numeric_limits<int>::max(), bestX = -1, bestY = 0, bestO = 0;
            for (int o = 0; o < p.orientations; ++o) {
                const Footprint& f = p.fp[o];
                if (f.width > lim - border_ || f.height > lim - border_) continue;
                for (int X = border_; X + f.width <= lim; ++X) {
                    int Y = border_;
                    bool ok = true;
                    const int kLo = std::max(-pad_, -X), kHi = std::min(f.width + pad_, size - X);
                    for (int k = kLo; k < kHi; ++k) {
                        const int db = f.dilatedBottom[std::size_t(k + pad_)];
                        if (db == std::numeric_limits<std::int32_t>::max()) continue;
                        Y = std::max(Y, sky[std::size_t(X + k)] - db);
                        if (Y + f.height >= bestScore || Y + f.height > lim) {
                            ok = false;
                            break;
                        }
                    }
                    if (!ok) continue;
                    static const int H = getenv("PACKH") ? atoi(getenv("PACKH")) : 0;
                    if (H == 1) {
                        // waste-based
                        long waste = 0;
                        for (int k = kLo; k < kHi; ++k) {
                            const int db = f.dilatedBottom[std::size_t(k + pad_)];
                            if (db == std::numeric_limits<std::int32_t>::max()) continue;
                            waste += (Y + db) - sky[std::size_t(X + k)];
                        }
                        const long sc = waste * 4 + long(Y + f.height) * 0;
                        static thread_local long bestW; if (bestX < 0 || o == 0 && X == border_) bestW = LONG_MAX;
                        if (sc >= bestW) continue;
                        bestW = sc;
                        bestX = X; bestY = Y; bestO = o; bestScore = std::numeric_limits<int>::max();
                        continue;
                    }
                    bestScore = Y + f.height;
                    bestX = X;
                    bestY = Y;
                    bestO = o;
                }
            }
            if (bestX < 0) return false;
            const Footprint& f = p.fp[bestO];
            for (int c = 0; c < f.width; ++c)
                if (f.top[std::size_t(c)] > 0)
                    sky[std::size_t(bestX + c)] = std::max(sky[std::size_t(bestX + c)], bestY + f.top[std::size_t(c)]);
            out[n] = {bestO, bestX, bestY};
        }
        return true;
    }

    std::vector<std::size_t> sorted(std::vector<std::size_t> ids) const {
        std::stable_sort(ids.begin(), ids.end(), [&](std::size_t a, std::size_t b) {
            const Footprint& fa = prepared_[a].fp[0];
            const Footprint& fb = prepared_[b].fp[0];
            const int ma = std::max(fa.width, fa.height), mb = std::max(fb.width, fb.height);
            if (ma != mb) return ma > mb;
            return fa.texels > fb.texels;
        });
        return ids;
    }

    std::vector<int> candidateSizes(int lo, int hi) const {
        std::vector<int> sizes;
        if (s_.powerOfTwo) {
            for (int s = 1; s <= hi; s *= 2)
                if (s >= lo) sizes.push_back(s);
            if (sizes.empty() || sizes.back() != hi) sizes.push_back(hi);
        } else {
            const int m = std::max(1, s_.sizeMultiple);
            for (int s = ((lo + m - 1) / m) * m; s < hi; s += m) sizes.push_back(s);
            sizes.push_back(hi);
        }
        return sizes;
    }

    // Smallest size in [lower bound, max] that holds the charts (bisection), or 0 if even max fails.
    int fitSize(const std::vector<std::size_t>& order, std::vector<Placement>& out) const {
        double area = 0.0;
        int maxDim = 1;
        for (std::size_t i : order) {
            area += estimateArea(i);
            maxDim = std::max({maxDim, prepared_[i].fp[0].width, prepared_[i].fp[0].height});
        }
        const int lo = std::max(int(std::ceil(std::sqrt(area))) + 2 * border_, maxDim + 2 * border_);
        const std::vector<int> sizes = candidateSizes(std::min(lo, s_.maxAtlasSize), s_.maxAtlasSize);
        std::vector<Placement> trial;
        if (!pack(order, sizes.back(), trial)) return 0;
        std::size_t a = 0, b = sizes.size() - 1;  // sizes[b] fits
        out = trial;
        while (a < b) {
            const std::size_t mid = (a + b) / 2;
            if (pack(order, sizes[mid], trial)) {
                b = mid;
                out = trial;
            } else {
                a = mid + 1;
            }
        }
        // out holds the placement for sizes[b] only if the last success was at b.
        if (!pack(order, sizes[b], out)) return 0;
        return sizes[b];
    }

    const Prepared& prepared(std::size_t i) const { return prepared_[i]; }
    int pad() const { return pad_; }

private:
    std::span<const PackChartInput> charts_;
    PackSettings s_;
    int pad_ = 0, border_ = 0;
    std::vector<Prepared> prepared_;
};

}  // namespace

double PackResult::utilization() const {
    std::uint64_t used = 0, total = 0;
    for (std::size_t a = 0; a < atlasSize.size(); ++a) {
        used += atlasFootprintTexels[a];
        total += std::uint64_t(atlasSize[a]) * std::uint64_t(atlasSize[a]);
    }
    return total ? double(used) / double(total) : 0.0;
}

PackResult packCharts(std::span<const PackChartInput> charts, const PackSettings& settingsIn) {
    PackSettings settings = settingsIn;
    settings.maxAtlasSize = std::clamp(settings.maxAtlasSize, 8, 16384);
    settings.paddingTexels = std::max(0, settings.paddingTexels);
    settings.borderTexels = std::clamp(settings.borderTexels, 0, settings.maxAtlasSize / 4);
    PackResult result;
    result.charts.resize(charts.size());
    if (charts.empty()) return result;
    Packer packer(charts, settings);

    auto commit = [&](const std::vector<std::size_t>& order, const std::vector<Placement>& placement, int size) {
        const int atlas = int(result.atlasSize.size());
        result.atlasSize.push_back(size);
        std::uint64_t used = 0;
        for (std::size_t n = 0; n < order.size(); ++n) {
            const Prepared& p = packer.prepared(order[n]);
            const Footprint& f = p.fp[placement[n].orientation];
            PackedChart& pc = result.charts[order[n]];
            pc.atlas = atlas;
            pc.angleRad = f.angle;
            pc.scale = p.scale;
            pc.offset = f.shift + glm::dvec2(placement[n].x, placement[n].y);
            pc.x = placement[n].x;
            pc.y = placement[n].y;
            pc.width = f.width;
            pc.height = f.height;
            pc.footprintTexels = f.texels;
            pc.scaledDown = p.scaledDown;
            used += f.texels;
        }
        result.atlasFootprintTexels.push_back(used);
    };

    std::vector<std::size_t> all(charts.size());
    std::iota(all.begin(), all.end(), 0);
    {
        const auto order = packer.sorted(all);
        std::vector<Placement> placement;
        if (const int size = packer.fitSize(order, placement); size > 0) {
            commit(order, placement, size);
            for (const auto& c : result.charts) result.scaledDownCharts += c.scaledDown ? 1 : 0;
            if (result.scaledDownCharts)
                result.warnings.push_back(std::to_string(result.scaledDownCharts) +
                                          " charts larger than the atlas were scaled down to fit");
            return result;
        }
    }

    // Several atlases: gather groups, shrink groups that cannot fit one atlas, fill atlases group by group.
    std::map<std::int32_t, std::vector<std::size_t>> groupMap;
    for (std::size_t i = 0; i < charts.size(); ++i)
        groupMap[settings.keepGroupsTogether ? charts[i].group : std::int32_t(i)].push_back(i);
    struct Group {
        std::vector<std::size_t> charts;
        double area = 0.0;
    };
    std::vector<Group> groups;
    const double capacity = double(packer.avail(settings.maxAtlasSize)) * double(packer.avail(settings.maxAtlasSize));
    for (auto& [id, ids] : groupMap) {
        Group g;
        g.charts = packer.sorted(ids);
        for (std::size_t i : g.charts) g.area += packer.estimateArea(i);
        std::vector<Placement> placement;
        double factor = g.area > 0.85 * capacity ? std::sqrt(0.85 * capacity / g.area) : 1.0;
        for (int attempt = 0; attempt < 40; ++attempt) {
            if (factor < 1.0) {
                for (std::size_t i : g.charts) packer.prepare(i, packer.prepared(i).scale * factor);
                g.charts = packer.sorted(g.charts);
                g.area = 0.0;
                for (std::size_t i : g.charts) g.area += packer.estimateArea(i);
            }
            if (packer.pack(g.charts, settings.maxAtlasSize, placement)) break;
            factor = 0.9;
        }
        if (factor < 1.0)
            result.warnings.push_back("chart group " + std::to_string(id) + " is larger than one " +
                                      std::to_string(settings.maxAtlasSize) + " atlas; scaled down to fit");
        groups.push_back(std::move(g));
    }
    std::stable_sort(groups.begin(), groups.end(), [](const Group& a, const Group& b) { return a.area > b.area; });

    std::vector<bool> done(groups.size(), false);
    std::size_t remaining = groups.size();
    while (remaining > 0) {
        // Take groups (largest first) while their area fits a fill target, then drop the last ones until
        // the set packs; try to add more groups afterwards.
        std::vector<std::size_t> chosen;
        double area = 0.0;
        for (std::size_t g = 0; g < groups.size(); ++g) {
            if (done[g]) continue;
            if (chosen.empty() || area + groups[g].area <= 0.9 * capacity) {
                chosen.push_back(g);
                area += groups[g].area;
            }
        }
        auto orderOf = [&](const std::vector<std::size_t>& gs) {
            std::vector<std::size_t> ids;
            for (std::size_t g : gs) ids.insert(ids.end(), groups[g].charts.begin(), groups[g].charts.end());
            return packer.sorted(ids);
        };
        std::vector<Placement> placement;
        std::vector<std::size_t> order = orderOf(chosen);
        while (!packer.pack(order, settings.maxAtlasSize, placement)) {
            chosen.pop_back();  // never empties: a lone group always packs (scaled above)
            order = orderOf(chosen);
        }
        for (std::size_t g : chosen) done[g] = true;
        remaining -= chosen.size();
        // Last atlas: shrink it.
        int size = settings.maxAtlasSize;
        if (remaining == 0) {
            std::vector<Placement> smaller;
            if (const int s = packer.fitSize(order, smaller); s > 0) {
                size = s;
                placement = std::move(smaller);
            }
        }
        commit(order, placement, size);
    }
    for (const auto& c : result.charts) result.scaledDownCharts += c.scaledDown ? 1 : 0;
    if (result.scaledDownCharts)
        result.warnings.push_back(std::to_string(result.scaledDownCharts) + " charts were scaled down to fit an atlas");
    return result;
}

}  // namespace hemibake
