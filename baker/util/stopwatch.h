#pragma once
// Wall-clock seconds for stage timings and convergence histories (steady clock). Not thread-safe.
#include <chrono>

namespace hemibake {

class Stopwatch {
public:
    // Seconds since construction (or the last restart).
    double seconds() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }
    // Seconds since the previous lap (or construction): consecutive, non-overlapping stage times.
    double lap() {
        const Clock::time_point now = Clock::now();
        const double s = std::chrono::duration<double>(now - lapStart_).count();
        lapStart_ = now;
        return s;
    }

private:
    using Clock = std::chrono::steady_clock;
    Clock::time_point start_ = Clock::now();
    Clock::time_point lapStart_ = start_;
};

}  // namespace hemibake
