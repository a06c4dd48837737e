#pragma once
// How converged a solve is, as the user should read it: not the size of the last update (which understates
// the error by up to 1/(1−ρ), GROUND_TRUTH §2.D) but a bound on what is still missing.
#include <cstdint>
#include <vector>

namespace hemibake {

struct ConvergenceRecord {
    std::uint64_t shots = 0;        // hemicube shots so far (gather: sweeps)
    double seconds = 0.0;           // since the solve started
    double unshotFraction = 0.0;    // unshot power / injected power
    // Upper bound on the relative error of the total exitance still to come: the unshot power reflected at most
    // ρ_max per bounce, U/(1−ρ_max), over the exitance power so far.
    double errorBound = 0.0;
    // In the local phase (after the bulk), the worst element's bound (ProgressiveShooter::localBound: light
    // still to arrive there over what it has); −1 before it.
    double localBound = -1.0;
    // In the local phase (0 before it): its round (1, 2, …: each evaluates the bound and shoots the patches that hold
    // it open), the round's patches and how many it has shot, and of those the patches that had never shot (while
    // any is left the worst bound is ∞: nothing is known of where its light goes). The progress a person can follow.
    std::uint64_t localRound = 0;
    std::size_t localRoundPatches = 0;
    std::uint64_t localRoundShots = 0;
    std::size_t localNeverShotPatches = 0;
};

class ConvergenceHistory {
public:
    // Records sparsely: at shot counts 1, 2, 4, 8, … and at least every `minSeconds`, plus the final state, so
    // the history stays short for long solves but still draws a curve.
    explicit ConvergenceHistory(double minSeconds = 0.25) : minSeconds_(minSeconds) {}
    bool wants(std::uint64_t shots, double seconds) const;
    void add(const ConvergenceRecord& record);
    const std::vector<ConvergenceRecord>& records() const { return records_; }

private:
    double minSeconds_;
    std::uint64_t nextShots_ = 1;
    double lastSeconds_ = -1e30;
    std::vector<ConvergenceRecord> records_;
};

// U / (1 − ρ_max) / exitance, guarded for ρ_max → 1 and empty scenes.
double exitanceErrorBound(double unshotPowerW, double exitancePowerW, double maxReflectance);

}  // namespace hemibake
