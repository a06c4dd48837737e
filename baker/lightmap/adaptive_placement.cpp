#include "baker/lightmap/adaptive_placement.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "baker/rays/embree_scene.h"
#include "baker/util/colour.h"

namespace hemibake {

bool continuousSurface(const AtlasTexels& t, std::size_t a, std::size_t b, double maxDistanceM) {
    return t.instance[a] == t.instance[b] && glm::dot(t.normal[a], t.normal[b]) > 0.9f &&
           glm::length(t.position[a] - t.position[b]) <= maxDistanceM;
}

namespace {

// The most a probe's noise may excuse between a texel's interpolation beside a chart's edge and its probe: a tenth of
// the interpolated value (beyond the tolerance itself). Three standard errors alone let dips through: a probe of 64
// rays in a dark spot that sees a bright patch has an error as large as the dip (0.014 interpolated as 0.045 on the
// clean 10k level). Clean 10k level at 16 texels/m against 16,384 rays per texel, per texel RMS and final gather:
// gathered as before 1.655 %, 100.1 s; a tenth 1.672 %, 85.6 s; a quarter 1.687 %, 81.5 s; no bound 1.695 %, 78.6 s.
constexpr double kProbeLeniency = 0.1;

// Elias-style adaptive placement over one atlas: the coarse lattice and the charts' ends first, then per level edge
// midpoints (between two lattice points on a row or column) and cell centres (which can then use the midpoints around
// them as well as the diagonal corners). `gather` renders a list of texels.
class AdaptivePlacer {
public:
    // `probe` empty: texels beside a chart's edge are not interpolated along rows and columns (alongRowAndColumn).
    AdaptivePlacer(const AtlasTexels& texels, const LightmapSettings& settings, double texelSizeM, const EmbreeScene& rays,
                   const GatherFn& gather, const ProbeFn& probe, const std::vector<glm::dvec3>& direct, LightmapStats& stats)
        : t_(texels), grid_(texels), settings_(settings), texelSizeM_(texelSizeM), rays_(rays), gather_(gather),
          probe_(probe), direct_(direct), stats_(stats), done_(texels.count(), 0) {
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
                checkAgainstProbes();
                render(phase, step);
                advanced(finished_);
                finished_ = 0;
            }
        for (std::size_t i = 0; i < n && probe_; ++i) visitLeftover(i);
        checkAgainstProbes();
        render(Phase::Leftovers, 1);
        advanced(finished_);
        finished_ = 0;
    }

private:
    enum class Phase { Lattice, EdgeMidpoints, CellCentres, Leftovers };
    // What interpolation would give at a texel, the curvature it drops there, and the spread of the neighbours it
    // used (a step between two neighbours has no curvature at all, only spread).
    struct Estimate {
        bool ok = false;
        glm::dvec3 value{0.0};
        double curvature = 0.0, spread = 0.0, scale = 0.0;
    };

    // Interpolates texel i when its neighbours at this step agree, else queues it for a gather. On the lattice phase,
    // queues the lattice and the chart ends.
    void visit(Phase phase, int step, std::size_t i) {
        const int x = t_.x[i], y = t_.y[i];
        if (done_[i]) return;
        if (phase == Phase::Lattice && (x % step || y % step)) {
            if (!probe_ || !chartEnd(i)) return;
            batch_.push_back(std::uint32_t(i));
            ++stats_.renderedChartEnds;
            return;
        }
        if (x % step || y % step) return;
        if (phase == Phase::Lattice) {
            batch_.push_back(std::uint32_t(i));
            ++stats_.renderedLattice;
            ++latticeGathers_;
            return;
        }
        const bool oddX = (x / step) % 2 == 1, oddY = (y / step) % 2 == 1;
        if ((oddX != oddY) != (phase == Phase::EdgeMidpoints)) return;
        missing_ = Missing::None;
        Estimate e = phase == Phase::EdgeMidpoints ? edgeMidpoint(i, step, oddX, oddY) : cellCentre(i, step);
        // Beside a chart's edge the lattice neighbours are off the chart: the nearest finished texels along the row
        // and the column (the chart's ends gathered with the lattice) stand in for them.
        bool alongLines = false;
        if (!e.ok && missing_ == Missing::ChartEdge && probe_) {
            const Estimate l = alongRowAndColumn(i);
            if (!l.ok) return;  // neither line has finished texels on both sides yet: left for the last pass
            e = l;
            alongLines = true;
        }
        decide(i, e, alongLines);
    }

    // Texels beside chart edges that no line reached at their level (a texel next to a chart's corner, with only
    // candidates around it): with every other texel finished, along their rows and columns, or gathered.
    void visitLeftover(std::size_t i) {
        if (done_[i]) return;
        missing_ = Missing::ChartEdge;
        const Estimate e = alongRowAndColumn(i);
        decide(i, e, e.ok);
    }

    // Interpolates texel i from `e` if its neighbours agree (beside a chart's edge, `alongLines`, only once its probe
    // agrees too), else queues it for a gather and counts why.
    void decide(std::size_t i, Estimate e, bool alongLines) {
        // The tolerance is relative to what the texel will hold: the gathered light plus the direct light added
        // by rays afterwards (a faint bounce beside a bright direct term needs no hemicube).
        if (!direct_.empty()) e.scale += channelSum(direct_[i]);
        // Interpolating across a step of contrast Δ errs by up to Δ/2 at the texel: a spread of up to twice the
        // tolerance keeps that error within it.
        const double allowed = settings_.interpolationTolerance * (e.scale + floor_);
        const bool agree = e.ok && e.curvature <= allowed && e.spread <= 2.0 * allowed;
        if (agree && alongLines) {
            candidates_.push_back({std::uint32_t(i), glm::max(e.value, glm::dvec3(0.0)), allowed});  // checkAgainstProbes
        } else if (agree) {
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
        if (j < 0 || !done_[std::size_t(j)] || !continuousSurface(t_, i, std::size_t(j), 3.0 * reach)) return missing(Missing::ChartEdge);
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

    // Texel j lies next to texel i on the same piece of surface (dx, dy: its offset in texels).
    bool adjacent(std::size_t i, int dx, int dy) const {
        const std::int32_t j = grid_.find(t_.x[i] + dx, t_.y[i] + dy);
        const double reach = 1.5 * std::sqrt(2.0) * std::max(std::abs(dx), std::abs(dy)) * texelSizeM_;
        return j >= 0 && continuousSurface(t_, i, std::size_t(j), 3.0 * reach);
    }

    // A chart's end on a lattice row or column, or a corner of its outline: gathered with the lattice, so that the
    // texels between the last lattice point and the chart's edge have a finished neighbour on either side
    // (alongRowAndColumn). Without them every texel in that band was gathered: half the gathers on a level, whose
    // charts are mostly a few lattice cells wide.
    bool chartEnd(std::size_t i) const {
        const bool openX = !adjacent(i, -1, 0) || !adjacent(i, 1, 0);
        const bool openY = !adjacent(i, 0, -1) || !adjacent(i, 0, 1);
        return (openX && t_.y[i] % coarse_ == 0) || (openY && t_.x[i] % coarse_ == 0) || (openX && openY);
    }

    // The nearest finished texel from i towards (dx, dy), on i's piece of surface and within one lattice step: its
    // value and distance in texels. Fails at the chart's edge, or at a texel inside geometry or out of sight.
    bool nearestFinished(std::size_t i, int dx, int dy, glm::dvec3& v, int& distance) const {
        for (int k = 1; k <= coarse_; ++k) {
            if (!adjacent(i, k * dx, k * dy)) return false;
            const auto j = std::size_t(grid_.find(t_.x[i] + k * dx, t_.y[i] + k * dy));
            if (!done_[j]) continue;
            if ((*invalid_)[j] || !inSight(i, j)) return false;
            v = (*value_)[j];
            distance = k;
            return true;
        }
        return false;
    }

    // Linear interpolation between the nearest finished texels on either side along the row and along the column,
    // each pair no more than a lattice step apart; the mean of the lines that have both. Only plain agreement is
    // accepted (spread as curvature), as at a chart's edge before; two lines must also agree with each other.
    Estimate alongRowAndColumn(std::size_t i) const {
        Estimate e;
        int lines = 0;
        glm::dvec3 first(0.0);
        for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
            glm::dvec3 a, b;
            int da = 0, db = 0;
            if (!nearestFinished(i, -dx, -dy, a, da) || !nearestFinished(i, dx, dy, b, db) || da + db > coarse_) continue;
            const glm::dvec3 line = (double(db) * a + double(da) * b) / double(da + db);
            e.scale = std::max({e.scale, channelSum(a), channelSum(b)});
            e.spread = std::max(e.spread, std::abs(channelSum(a - b)));
            if (lines == 1) e.spread = std::max(e.spread, std::abs(channelSum(line - first)));
            if (lines == 0) first = line;
            e.value += line;
            ++lines;
        }
        if (lines == 0) return e;
        e.ok = true;
        e.value /= double(lines);
        e.curvature = e.spread;
        return e;
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

    // Two finished texels on a line can agree across a dip between them that nothing else sampled (a contact shadow
    // in the middle of a 4-texel chart: 0.016 interpolated as 0.095). Each candidate's own probe, 64 of its gather's
    // rays, must agree with its interpolation within the tolerance plus three of the probe's standard errors, and that
    // noise allowance at most kProbeLeniency of the value; the rest are gathered.
    void checkAgainstProbes() {
        if (candidates_.empty()) return;
        std::vector<std::uint32_t> ids(candidates_.size());
        for (std::size_t k = 0; k < ids.size(); ++k) ids[k] = candidates_[k].texel;
        probe_(ids, probed_, standardError_);
        stats_.probedBesideChartEdges += ids.size();
        for (std::size_t k = 0; k < ids.size(); ++k) {
            const Candidate& c = candidates_[k];
            const double noise = std::min(3.0 * standardError_[k], kProbeLeniency * channelSum(c.value));
            if (std::abs(channelSum(c.value - probed_[k])) <= c.allowed + noise) {
                (*value_)[c.texel] = c.value;
                done_[c.texel] = 1;
                ++finished_;
                ++stats_.interpolated;
                ++stats_.interpolatedBesideChartEdges;
            } else {
                batch_.push_back(c.texel);
                ++stats_.renderedDisagreeing;
            }
        }
        candidates_.clear();
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
        if (phase == Phase::Lattice && step == coarse_ && latticeGathers_ > 0) {
            // From the lattice points alone (the chart ends are queued among them).
            double mean = 0.0;
            for (std::size_t k = 0; k < batch_.size(); ++k)
                if (t_.x[batch_[k]] % coarse_ == 0 && t_.y[batch_[k]] % coarse_ == 0) mean += channelSum(gathered_[k]);
            floor_ = 0.01 * mean / double(latticeGathers_);
        }
        batch_.clear();
    }

    const AtlasTexels& t_;
    const TexelGrid grid_;
    const LightmapSettings& settings_;
    const double texelSizeM_;
    const EmbreeScene& rays_;
    const GatherFn& gather_;
    const ProbeFn& probe_;
    const std::vector<glm::dvec3>& direct_;
    LightmapStats& stats_;
    std::vector<std::uint8_t> done_;
    std::vector<glm::dvec3>* value_ = nullptr;
    std::vector<std::uint8_t>* invalid_ = nullptr;
    int coarse_ = 1;
    double floor_ = 0.0;  // absolute agreement floor, from the coarse level's mean
    std::size_t latticeGathers_ = 0;  // texels queued on the coarse lattice itself
    std::vector<std::uint32_t> batch_;
    struct Candidate {
        std::uint32_t texel;
        glm::dvec3 value;  // interpolated along its row and column
        double allowed;    // the agreement it passed
    };
    std::vector<Candidate> candidates_;  // interpolations beside chart edges awaiting their probes
    std::vector<glm::dvec3> probed_;
    std::vector<double> standardError_;
    std::vector<glm::dvec3> gathered_;
    std::vector<float> backface_;
    enum class Missing { None, ChartEdge, Inside, OutOfSight };
    mutable Missing missing_ = Missing::None;  // the first neighbour the texel being visited lacked
    std::size_t finished_ = 0;  // texels finished (gathered or interpolated) since progress was last reported
};

}  // namespace

void placeGathers(const AtlasTexels& texels, const LightmapSettings& settings, double texelSizeM, const EmbreeScene& rays,
                  const GatherFn& gather, const ProbeFn& probe, const std::vector<glm::dvec3>& direct, LightmapStats& stats,
                  std::vector<glm::dvec3>& value, std::vector<std::uint8_t>& invalid,
                  const std::function<void(std::size_t)>& advanced) {
    AdaptivePlacer(texels, settings, texelSizeM, rays, gather, probe, direct, stats).run(value, invalid, advanced);
}

}  // namespace hemibake
