#pragma once
// Which patch has the most unshot power, and how much is unshot in total, under frequent point updates.
// A complete binary tree over the patches keeps both the maximum and the sum of its leaves: an update is
// O(log n), the maximum and the total are O(1), and the total is a pairwise sum (no long-run drift from
// adding and subtracting into one accumulator).
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace hemibake {

class UnshotQueue {
public:
    explicit UnshotQueue(std::size_t count);
    // Sets one leaf and its ancestors. O(log n). Not thread-safe.
    void set(std::size_t index, double powerWatts);
    // The same tree, bit for bit, as set() on each update in turn (a later update of an index wins), but each
    // ancestor is recomputed once: a shot updates every patch its row reaches, mostly neighbours in index order, whose
    // paths to the root share all but their last few nodes (k updates cost about 2k + log n nodes, not k log n).
    // Sorts `updates`' copy of the touched leaves in `scratch_`. Not thread-safe.
    void setMany(std::span<const std::pair<std::uint32_t, double>> updates);
    double get(std::size_t index) const { return max_[leaves_ + index]; }
    std::size_t argmax() const;
    // Appends to `out` every index whose power is >= threshold (> 0), ascending; O(k log n) for k found.
    void collectAtLeast(double threshold, std::vector<std::uint32_t>& out) const;
    double maxPower() const { return max_[1]; }
    double totalPower() const { return sum_[1]; }
    std::size_t size() const { return count_; }

private:
    // Node `node`'s maximum and sum from its two children's.
    void pull(std::size_t node) {
        const double a = max_[2 * node], b = max_[2 * node + 1];
        max_[node] = a >= b ? a : b;
        sum_[node] = sum_[2 * node] + sum_[2 * node + 1];
    }

    std::size_t count_;
    std::size_t leaves_;
    std::vector<double> max_;
    std::vector<double> sum_;
    std::vector<std::size_t> scratch_;  // setMany's nodes of one level
};

}  // namespace hemibake
