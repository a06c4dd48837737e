#include "baker/solve/convergence.h"

#include <algorithm>
#include <limits>

namespace hemibake {

bool ConvergenceHistory::wants(std::uint64_t shots, double seconds) const {
    return shots >= nextShots_ || seconds - lastSeconds_ >= minSeconds_;
}

void ConvergenceHistory::add(const ConvergenceRecord& record) {
    if (!records_.empty() && records_.back().shots == record.shots) records_.pop_back();
    records_.push_back(record);
    while (nextShots_ <= record.shots) nextShots_ *= 2;
    lastSeconds_ = record.seconds;
}

double exitanceErrorBound(double unshotPowerW, double exitancePowerW, double maxReflectance) {
    if (unshotPowerW <= 0.0) return 0.0;
    if (!(exitancePowerW > 0.0)) return std::numeric_limits<double>::infinity();
    const double gap = std::max(1.0 - maxReflectance, 1e-12);
    return unshotPowerW / gap / exitancePowerW;
}

}  // namespace hemibake
