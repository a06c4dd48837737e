#include "mesh/pack.h"
#include "mesh/frame_math.h"

#include <algorithm>
#include <limits>
#include <map>
#include <numeric>
#include <unordered_map>

namespace hemibake {

namespace {

// A horizontal run of texels [a, b) in one row.
struct Run {
    std::int32_t a, b;
};

// One orientation of a chart, rasterized. Coordinates are relative to the footprint's bounding box:
// atlas T = scale·R(angle)·uv + shift + (X, Y) where (X, Y) is where the box's top-left texel lands.
struct Footprint {
    double angle = 0.0;
    glm::dvec2 shift{0.0};
    int width = 0, height = 0;
    std::uint32_t texels = 0;
    // Covered texels as runs per row: row r's runs are runs[rowStart[r] .. rowStart[r+1]).
    std::vector<std::uint32_t> rowStart;
    std::vector<Run> runs;
    // The footprint dilated by the padding (square structuring element), rows −pad .. height+pad−1 stored
    // from index 0; x relative to the box (may be negative).
    std::vector<std::uint32_t> dilatedRowStart;
    std::vector<Run> dilatedRuns;
    std::vector<std::int32_t> dilatedMaxRun;  // per dilated row: longest run (a row of the canvas needs a gap this long)
    std::int32_t dilatedMinRun = 0;           // the smallest of those over non-empty rows
};

bool sameShape(const Footprint& a, const Footprint& b) {
    if (a.width != b.width || a.height != b.height || a.rowStart != b.rowStart || a.runs.size() != b.runs.size()) return false;
    for (std::size_t k = 0; k < a.runs.size(); ++k)
        if (a.runs[k].a != b.runs[k].a || a.runs[k].b != b.runs[k].b) return false;
    return true;
}

struct Prepared {
    double scale = 0.0;
    bool scaledDown = false;
    int orientations = 1;
    Footprint fp[4];
    std::uint64_t shapeHash = 0;  // of every orientation's runs: equal charts hash alike (Canvas::place's resume)
};

std::uint64_t shapeHash(const Prepared& p) {
    std::uint64_t h = splitMix64(std::uint64_t(p.orientations));
    for (int o = 0; o < p.orientations; ++o) {
        const Footprint& f = p.fp[o];
        h = splitMix64(h ^ (std::uint64_t(std::uint32_t(f.width)) << 32 | std::uint32_t(f.height)));
        for (const Run& r : f.runs) h = splitMix64(h ^ (std::uint64_t(std::uint32_t(r.a)) << 32 | std::uint32_t(r.b)));
        for (std::uint32_t k : f.rowStart) h = splitMix64(h ^ k);
    }
    return h;
}


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
    auto bit = [&](int i, int j) { return bits[std::size_t(j) * std::size_t(bw) + std::size_t(i)] != 0; };
    auto appendRuns = [](std::vector<Run>& runs, const std::uint8_t* row, int n, int offset) {
        for (int i = 0; i < n;) {
            if (!row[i]) {
                ++i;
                continue;
            }
            int k = i;
            while (k < n && row[k]) ++k;
            runs.push_back({i + offset, k + offset});
            i = k;
        }
    };
    std::vector<std::uint8_t> row(std::size_t(fp.width + 2 * pad));
    fp.rowStart.push_back(0);
    for (int j = 0; j < fp.height; ++j) {
        for (int i = 0; i < fp.width; ++i) row[std::size_t(i)] = bit(x0 + i, y0 + j) ? 1 : 0;
        appendRuns(fp.runs, row.data(), fp.width, 0);
        fp.rowStart.push_back(std::uint32_t(fp.runs.size()));
    }
    // Square dilation, separable: rows first (horizontal), then columns.
    const int dw = fp.width + 2 * pad, dh = fp.height + 2 * pad;
    std::vector<std::uint8_t> horiz(std::size_t(dw) * std::size_t(fp.height), 0);
    for (int j = 0; j < fp.height; ++j)
        for (std::uint32_t r = fp.rowStart[std::size_t(j)]; r < fp.rowStart[std::size_t(j) + 1]; ++r)
            for (int i = fp.runs[r].a; i < fp.runs[r].b + 2 * pad; ++i) horiz[std::size_t(j) * std::size_t(dw) + std::size_t(i)] = 1;
    fp.dilatedRowStart.push_back(0);
    for (int j = 0; j < dh; ++j) {  // dilated row j ↔ footprint row j − pad
        std::fill(row.begin(), row.end(), 0);
        for (int src = std::max(0, j - 2 * pad); src <= std::min(fp.height - 1, j); ++src)
            for (int i = 0; i < dw; ++i) row[std::size_t(i)] |= horiz[std::size_t(src) * std::size_t(dw) + std::size_t(i)];
        const std::size_t before = fp.dilatedRuns.size();
        appendRuns(fp.dilatedRuns, row.data(), dw, -pad);
        fp.dilatedRowStart.push_back(std::uint32_t(fp.dilatedRuns.size()));
        int longest = 0;
        for (std::size_t k = before; k < fp.dilatedRuns.size(); ++k) longest = std::max(longest, fp.dilatedRuns[k].b - fp.dilatedRuns[k].a);
        fp.dilatedMaxRun.push_back(longest);
    }
    fp.dilatedMinRun = std::numeric_limits<std::int32_t>::max();
    for (int longest : fp.dilatedMaxRun)
        if (longest > 0) fp.dilatedMinRun = std::min(fp.dilatedMinRun, longest);
    if (fp.dilatedMinRun == std::numeric_limits<std::int32_t>::max()) fp.dilatedMinRun = 1;
    return fp;
}

struct Placement {
    int orientation = 0;
    int x = 0, y = 0;  // top-left of the footprint box
};

// One square atlas being filled. Occupied texels are kept as sorted runs per row, so charts can drop into
// holes and notches of others. A chart goes where the square holding everything placed so far grows least
// (xatlas' metric), ties going to the smaller extent area, then the higher, then the left-most position; its
// footprint dilated by the padding must miss every footprint already placed. Placements can be rolled back
// (to try a whole group of charts).
class Canvas {
public:
    Canvas(int size, int pad, int border)
        : size_(size), pad_(pad), border_(border), occupied_(std::size_t(size)), bigGaps_(std::size_t(size)), internalGap_(std::size_t(size), 0),
          lastEnd_(std::size_t(size), -pad), curW_(border), curH_(border) {}

    int extent() const { return std::max(curW_, curH_) + border_; }

    struct Mark {
        std::size_t journal;
        int curW, curH;
    };
    Mark mark() const { return {journal_.size(), curW_, curH_}; }
    void rollback(const Mark& m) {
        ++rollbacks_;
        while (journal_.size() > m.journal) {
            const auto entry = journal_.back();  // not a structured binding: lambdas capture those only from C++20/clang 16
            const auto row = entry.first;
            const Run run = entry.second;
            journal_.pop_back();
            auto& occ = occupied_[std::size_t(row)];
            auto it = std::find_if(occ.begin(), occ.end(), [&](const Run& r) { return r.a == run.a && r.b == run.b; });
            if (it != occ.end()) occ.erase(it);
            updateGap(row);
        }
        curW_ = m.curW;
        curH_ = m.curH;
    }

    bool place(const Prepared& p, Placement& out) {
        // Phase 1: a position inside the current square (no growth; all such positions score alike, the
        // highest then left-most wins). Phase 2, only if there is none: positions that grow the square to the
        // right or downwards, scored by the grown square, then its area.
        // A chart shaped like one placed inside the square before, with the square unchanged and nothing rolled
        // back since, fits in no row above the one that took it, in any orientation (each was searched at least
        // that far, and placements only fill): its search resumes at that row. Levels have long runs of equal charts
        // (crate and shelf faces), each of which rescanned the rows above: 23.7 of the 100k level's 24 s unwrap.
        // Kept per shape, not only for the last chart: a level's instances of one mesh come one after another in
        // the atlas, each a sequence of different charts, which reset the resume for the last chart alone (10-copy
        // tiled level: pack 3.66 → 3.34 s; most of what is left is the scan below the resumed row, ≈ 95 rows a chart).
        const auto memo = lastInsideOf_.find(p.shapeHash);
        const LastInside* last = memo == lastInsideOf_.end() ? nullptr : &memo->second;
        const bool resume = last && last->curW == curW_ && last->curH == curH_ && last->rollbacks == rollbacks_ &&
                            sameCharts(*last->prepared, p);
        int bestX = -1, bestY = 0, bestO = 0;
        for (int o = 0; o < p.orientations; ++o) {
            const Footprint& f = p.fp[o];
            const int xhi = std::min(curW_, size_ - border_) - f.width, yhi = std::min(curH_, size_ - border_) - f.height;
            const int ylimit = bestX >= 0 ? std::min(yhi, bestY - 1) : yhi;
            if (xhi < border_) continue;
            // Coarse test per row: its longest free gap (left of curW + pad) must hold the footprint's
            // shortest dilated run. A window of rows containing a failing row q rules out every Y whose window
            // contains q, so the scan jumps past it.
            auto rowFails = [&](int row) {
                if (row < 0 || row >= size_) return false;
                return std::max(internalGap_[std::size_t(row)], curW_ + pad_ - lastEnd_[std::size_t(row)]) < f.dilatedMinRun;
            };
            for (int Y = resume ? std::max(border_, last->y) : border_; Y <= ylimit;) {
                int fail = std::numeric_limits<int>::min();
                for (int row = Y + f.height + pad_ - 1; row >= Y - pad_; --row)
                    if (rowFails(row)) {
                        fail = row;
                        break;
                    }
                if (fail != std::numeric_limits<int>::min()) {
                    Y = fail + pad_ + 1;
                    continue;
                }
                const int X = leftmost(f, Y, border_, xhi, true);
                if (X >= 0) {
                    bestX = X;
                    bestY = Y;
                    bestO = o;
                    break;
                }
                ++Y;
            }
        }
        if (bestX >= 0) {
            lastInsideOf_[p.shapeHash] = {&p, bestY, curW_, curH_, rollbacks_};
        } else {
            int bestScore = std::numeric_limits<int>::max();
            long long bestArea = 0;
            auto consider = [&](int X, int Y, int o) {
                const Footprint& f = p.fp[o];
                const int w2 = std::max(curW_, X + f.width), h2 = std::max(curH_, Y + f.height);
                const int score = std::max(w2, h2);
                const long long area = (long long)w2 * h2;
                if (bestX < 0 || score < bestScore || (score == bestScore && area < bestArea) ||
                    (score == bestScore && area == bestArea && (Y < bestY || (Y == bestY && X < bestX)))) {
                    bestScore = score;
                    bestArea = area;
                    bestX = X;
                    bestY = Y;
                    bestO = o;
                }
            };
            for (int o = 0; o < p.orientations; ++o) {
                const Footprint& f = p.fp[o];
                const int xmax = size_ - border_ - f.width, ymax = size_ - border_ - f.height;
                if (xmax < border_ || ymax < border_) continue;
                // Right strip: the chart sticks out past curW.
                const int rx0 = std::max(border_, curW_ - f.width + 1);
                for (int Y = border_; Y <= ymax; ++Y) {
                    if (bestX >= 0 && std::max(curH_, Y + f.height) > bestScore) break;
                    const int xlim = bestX >= 0 ? std::min(xmax, bestScore - f.width) : xmax;
                    if (xlim < rx0) break;
                    const int X = leftmost(f, Y, rx0, xlim, false);
                    if (X >= 0) consider(X, Y, o);
                }
                // Bottom strip: the chart sticks out past curH.
                for (int Y = std::max(border_, curH_ - f.height + 1); Y <= ymax; ++Y) {
                    if (bestX >= 0 && std::max(curH_, Y + f.height) > bestScore) break;
                    const int xlim = bestX >= 0 ? std::min(xmax, bestScore - f.width) : xmax;
                    if (xlim < border_) break;
                    const int X = leftmost(f, Y, border_, xlim, false);
                    if (X >= 0) {
                        consider(X, Y, o);
                        break;  // lower positions only grow the square further
                    }
                }
            }
        }
        if (bestX < 0) return false;
        const Footprint& f = p.fp[bestO];
        for (int r = 0; r < f.height; ++r) {
            const int row = bestY + r;
            auto& occ = occupied_[std::size_t(row)];
            for (std::uint32_t k = f.rowStart[std::size_t(r)]; k < f.rowStart[std::size_t(r) + 1]; ++k) {
                const Run run{f.runs[k].a + bestX, f.runs[k].b + bestX};
                occ.insert(std::lower_bound(occ.begin(), occ.end(), run, [](const Run& l, const Run& rr) { return l.a < rr.a; }), run);
                journal_.push_back({row, run});
            }
            updateGap(row);
        }
        curW_ = std::max(curW_, bestX + f.width);
        curH_ = std::max(curH_, bestY + f.height);
        out = {bestO, bestX, bestY};
        return true;
    }

    // Left-most X in [xlo, xhi] where the dilated footprint placed with its box at (X, Y) misses every occupied
    // texel, or −1. `inside`: the footprint stays left of curW + pad, so rows whose free gaps there are all
    // too short are rejected without looking at their runs.
    int leftmost(const Footprint& f, int Y, int xlo, int xhi, bool inside) {
        if (xhi < xlo) return -1;
        if (inside) {
            auto tooShort = [&](int r) {
                const int row = Y + r;
                if (row < 0 || row >= size_) return false;
                const int gap = std::max(internalGap_[std::size_t(row)], curW_ + pad_ - lastEnd_[std::size_t(row)]);
                return gap < f.dilatedMaxRun[std::size_t(r + pad_)];
            };
            if (quickRow_ >= -pad_ && quickRow_ < f.height + pad_ && tooShort(quickRow_)) return -1;
            for (int r = -pad_; r < f.height + pad_; ++r)
                if (tooShort(r)) {
                    quickRow_ = r;
                    return -1;
                }
        }
        if (firstRow_ < -pad_ || firstRow_ >= f.height + pad_) firstRow_ = -pad_;
        initFeasible(f, Y, firstRow_, xlo, xhi);
        for (int r = -pad_; r < f.height + pad_ && !feasible_.empty(); ++r) {
            if (r == firstRow_) continue;
            restrict(f, Y, r);
            if (feasible_.empty()) firstRow_ = r;
        }
        return feasible_.empty() ? -1 : feasible_.front().a;
    }

private:
    // Longest free gap of a row before its last run (from −pad, the canvas edge counting as free) and the end
    // of that run: cheap necessary tests for placements.
    void updateGap(int row) {
        int prev = -pad_, best = 0;
        auto& big = bigGaps_[std::size_t(row)];
        big.clear();
        for (const Run& r : occupied_[std::size_t(row)]) {
            best = std::max(best, r.a - prev);
            if (r.a - prev >= kBigGap) big.push_back({prev, r.a});
            prev = std::max(prev, r.b);
        }
        internalGap_[std::size_t(row)] = best;
        lastEnd_[std::size_t(row)] = prev;
    }

    // Starts feasible_ as the X in [xlo, xhi] allowed by row r alone. A row with one dilated run at least
    // kBigGap long only fits into the row's big gaps (or past its last run), which are few.
    void initFeasible(const Footprint& f, int Y, int r, int xlo, int xhi) {
        feasible_.assign(1, {xlo, xhi + 1});
        const int row = Y + r;
        if (row < 0 || row >= size_) return;
        const std::uint32_t d0 = f.dilatedRowStart[std::size_t(r + pad_)], d1 = f.dilatedRowStart[std::size_t(r + pad_) + 1];
        if (d1 - d0 != 1 || f.dilatedRuns[d0].b - f.dilatedRuns[d0].a < kBigGap) {
            restrict(f, Y, r);
            return;
        }
        const Run dr = f.dilatedRuns[d0];
        feasible_.clear();
        auto add = [&](int a, int b) {  // X ∈ [a, b] ∩ [xlo, xhi]
            a = std::max(a, xlo);
            b = std::min(b, xhi);
            if (a <= b) feasible_.push_back({a, b + 1});
        };
        for (const Run& g : bigGaps_[std::size_t(row)])
            if (g.b - g.a >= dr.b - dr.a) add(g.a - dr.a, g.b - dr.b);
        add(lastEnd_[std::size_t(row)] - dr.a, xhi);
    }

    // Removes from feasible_ every X at which row r of the dilated footprint (placed at row Y) hits an
    // occupied run: X is blocked by occupied [o0, o1) and chart run [a, b) when X+a < o1 and X+b > o0.
    // Each candidate interval looks up only the runs that can block it.
    void restrict(const Footprint& f, int Y, int r) {
        const int row = Y + r;
        if (row < 0 || row >= size_ || feasible_.empty()) return;
        const auto& occ = occupied_[std::size_t(row)];
        if (occ.empty()) return;
        const std::uint32_t d0 = f.dilatedRowStart[std::size_t(r + pad_)], d1 = f.dilatedRowStart[std::size_t(r + pad_) + 1];
        if (d0 == d1) return;
        next_.clear();
        for (const Run& fr : feasible_) {
            blocked_.clear();
            for (std::uint32_t d = d0; d < d1; ++d) {
                const Run dr = f.dilatedRuns[d];
                auto it = std::lower_bound(occ.begin(), occ.end(), fr.a + dr.a, [](const Run& l, int v) { return l.b <= v; });
                for (; it != occ.end() && it->a - dr.b + 1 < fr.b; ++it) blocked_.push_back({it->a - dr.b + 1, it->b - dr.a});
            }
            if (blocked_.empty()) {
                next_.push_back(fr);
                continue;
            }
            if (d1 - d0 > 1) std::sort(blocked_.begin(), blocked_.end(), [](const Run& l, const Run& rr) { return l.a < rr.a; });
            int a = fr.a;
            for (std::size_t bj = 0; a < fr.b; ++bj) {
                if (bj >= blocked_.size() || blocked_[bj].a >= fr.b) {
                    next_.push_back({a, fr.b});
                    break;
                }
                if (blocked_[bj].a > a) next_.push_back({a, blocked_[bj].a});
                a = std::max(a, blocked_[bj].b);
            }
        }
        feasible_.swap(next_);
    }

    int size_, pad_, border_;
    std::vector<std::vector<Run>> occupied_;
    std::vector<std::vector<Run>> bigGaps_;  // per row: free gaps of at least kBigGap before the last run
    std::vector<std::int32_t> internalGap_, lastEnd_;
    int curW_, curH_;
    int firstRow_ = 0, quickRow_ = 0;  // rows that rejected the last candidates: tried first next time
    std::size_t rollbacks_ = 0;
    struct LastInside {  // a chart placed inside the square, and where (see place)
        const Prepared* prepared = nullptr;
        int y = 0;
        int curW = 0, curH = 0;
        std::size_t rollbacks = 0;
    };
    std::unordered_map<std::uint64_t, LastInside> lastInsideOf_;  // by Prepared::shapeHash: the last of that shape
    static bool sameCharts(const Prepared& a, const Prepared& b) {
        if (&a == &b || a.orientations != b.orientations) return &a == &b;
        for (int o = 0; o < a.orientations; ++o)
            if (!sameShape(a.fp[o], b.fp[o])) return false;
        return true;
    }
    static constexpr int kBigGap = 8;
    std::vector<std::pair<int, Run>> journal_;
    std::vector<Run> feasible_, next_, blocked_;
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
    int pad() const { return pad_; }
    int border() const { return border_; }
    const Prepared& prepared(std::size_t i) const { return prepared_[i]; }

    // Rasterizes chart i at `scale`, shrinking it until it fits into a maxAtlasSize atlas.
    void prepare(std::size_t i, double scale) {
        Prepared& p = prepared_[i];
        const double angle = s_.allowRotation ? bestAngle(charts_[i].uv) : 0.0;
        p.scaledDown = scale < s_.texelsPerUnit;
        // Shrink to the atlas before rasterizing: the raster is as large as the chart at this scale, and a chart
        // far larger than an atlas (a 100 km floor at 8 texels/m) would need terabytes.
        glm::dvec2 lo, hi;
        extentAt(charts_[i].uv, angle, lo, hi);
        const double extent = std::max(hi.x - lo.x, hi.y - lo.y) * scale;
        const double fits = std::max(1.0, double(avail(s_.maxAtlasSize) - 2));
        if (extent > fits) {
            scale *= fits / extent;
            p.scaledDown = true;
        }
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
            for (int o = 1; o < 4; ++o) {
                Footprint fp = rasterize(charts_[i], angle + 0.5 * M_PI * o, p.scale, pad_);
                // Symmetric charts (rectangles, squares) repeat footprints: keep distinct ones only.
                bool repeated = false;
                for (int k = 0; k < p.orientations && !repeated; ++k) repeated = sameShape(p.fp[k], fp);
                if (!repeated) p.fp[p.orientations++] = std::move(fp);
            }
        p.shapeHash = shapeHash(p);
    }

    // Texels a chart takes in a well-packed atlas: its footprint plus its share of the padding around it.
    double estimateArea(std::size_t i) const {
        const Footprint& f = prepared_[i].fp[0];
        return double(f.texels) + double(pad_) * double(f.width + f.height) + double(pad_) * double(pad_);
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

    // Atlas size for a used square of `extent` texels: rounded up to a multiple or a power of two.
    int roundSize(int extent) const {
        int size = std::max(extent, 1);
        if (s_.powerOfTwo) {
            int p = 1;
            while (p < size) p *= 2;
            size = p;
        } else {
            const int m = std::max(1, s_.sizeMultiple);
            size = ((size + m - 1) / m) * m;
        }
        return std::min(size, s_.maxAtlasSize);
    }

    // Packs `order` into one maxAtlasSize canvas; returns the atlas size that holds it, or 0 if it does not fit.
    int packAll(const std::vector<std::size_t>& order, std::vector<Placement>& out) const {
        Canvas canvas(s_.maxAtlasSize, pad_, border_);
        out.assign(order.size(), {});
        for (std::size_t n = 0; n < order.size(); ++n)
            if (!canvas.place(prepared_[order[n]], out[n])) return 0;
        return roundSize(canvas.extent());
    }

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
    settings.maxAtlasSize = std::clamp(settings.maxAtlasSize, 8, 8192);  // float UVs keep kCoverageShrinkTexels valid
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
    auto finish = [&] {
        for (const auto& c : result.charts) result.scaledDownCharts += c.scaledDown ? 1 : 0;
        if (result.scaledDownCharts)
            result.warnings.push_back(std::to_string(result.scaledDownCharts) + " charts were scaled down to fit a " +
                                      std::to_string(settings.maxAtlasSize) + " atlas");
        return result;
    };

    // Everything in one atlas, all charts sorted largest first (unless their area alone exceeds it).
    std::vector<std::size_t> all(charts.size());
    std::iota(all.begin(), all.end(), 0);
    double totalArea = 0.0;
    for (std::size_t i : all) totalArea += packer.estimateArea(i);
    const double capacity = double(packer.avail(settings.maxAtlasSize)) * double(packer.avail(settings.maxAtlasSize));
    if (totalArea <= capacity) {
        const auto order = packer.sorted(all);
        std::vector<Placement> placement;
        if (const int size = packer.packAll(order, placement); size > 0) {
            commit(order, placement, size);
            return finish();
        }
    }

    // Several atlases. Groups (instances) that cannot fit one atlas alone are scaled down first.
    std::map<std::int32_t, std::vector<std::size_t>> groupMap;
    for (std::size_t i = 0; i < charts.size(); ++i)
        groupMap[settings.keepGroupsTogether ? charts[i].group : std::int32_t(i)].push_back(i);
    struct Group {
        std::vector<std::size_t> charts;
        double area = 0.0;
    };
    std::vector<Group> groups;
    for (auto& [id, ids] : groupMap) {
        Group g;
        g.charts = packer.sorted(ids);
        for (std::size_t i : g.charts) g.area += packer.estimateArea(i);
        if (g.area > 0.25 * capacity) {  // might not fit alone
            std::vector<Placement> placement;
            double factor = g.area > 0.8 * capacity ? std::sqrt(0.8 * capacity / g.area) : 1.0;
            bool scaled = false, fits = false;
            for (int attempt = 0; attempt < 60 && !fits; ++attempt) {
                if (factor < 1.0) {
                    for (std::size_t i : g.charts) packer.prepare(i, packer.prepared(i).scale * factor);
                    g.charts = packer.sorted(g.charts);
                    scaled = true;
                }
                fits = packer.packAll(g.charts, placement) > 0;
                factor = 0.95;
            }
            // Past a point shrinking gains nothing: every chart keeps one texel and its padding. Such a group would be
            // left out of every atlas (its charts without one), so it is an error the user can act on.
            if (!fits)
                throw PackError(charts[g.charts.front()].group, g.charts.size(),
                                "its " + std::to_string(g.charts.size()) + " charts do not fit one " +
                                    std::to_string(settings.maxAtlasSize) + "-texel atlas with " +
                                    std::to_string(settings.paddingTexels) + " texels of padding between them, "
                                    "however small (raise the maximum atlas size or lower the padding)");
            g.area = 0.0;
            for (std::size_t i : g.charts) g.area += packer.estimateArea(i);
            if (scaled)
                result.warnings.push_back("chart group " + std::to_string(id) + " is larger than one " +
                                          std::to_string(settings.maxAtlasSize) + " atlas; scaled down to fit");
        }
        groups.push_back(std::move(g));
    }
    std::stable_sort(groups.begin(), groups.end(), [](const Group& a, const Group& b) { return a.area > b.area; });

    // Fill atlases greedily: each group goes into the current atlas if all its charts fit (else it is rolled
    // back and waits for the next atlas).
    std::vector<bool> done(groups.size(), false);
    std::size_t remaining = groups.size();
    while (remaining > 0) {
        Canvas canvas(settings.maxAtlasSize, packer.pad(), packer.border());
        std::vector<std::size_t> order;
        std::vector<Placement> placement;
        int failures = 0;  // after this many groups in a row do not fit, the atlas counts as full
        for (std::size_t g = 0; g < groups.size() && failures < 16; ++g) {
            if (done[g]) continue;
            const auto mark = canvas.mark();
            const std::size_t before = order.size();
            bool ok = true;
            for (std::size_t i : groups[g].charts) {
                Placement pl;
                if (!canvas.place(packer.prepared(i), pl)) {
                    ok = false;
                    break;
                }
                order.push_back(i);
                placement.push_back(pl);
            }
            if (!ok) {
                canvas.rollback(mark);
                order.resize(before);
                placement.resize(before);
                ++failures;
                continue;
            }
            failures = 0;
            done[g] = true;
            --remaining;
        }
        if (order.empty()) {  // cannot happen: every group that might not fit alone was packed alone above
            for (std::size_t g = 0; g < groups.size(); ++g)
                if (!done[g])
                    throw PackError(charts[groups[g].charts.front()].group, groups[g].charts.size(),
                                    "its " + std::to_string(groups[g].charts.size()) + " charts do not fit an empty " +
                                        std::to_string(settings.maxAtlasSize) + "-texel atlas");
        }
        int size = packer.roundSize(canvas.extent());
        if (remaining == 0) {
            // The last atlas: repacking its charts sorted together may give a smaller square.
            std::vector<Placement> repacked;
            const auto sortedOrder = packer.sorted(order);
            if (const int s = packer.packAll(sortedOrder, repacked); s > 0 && s < size) {
                commit(sortedOrder, repacked, s);
                break;
            }
        }
        commit(order, placement, size);
    }
    return finish();
}

}  // namespace hemibake
