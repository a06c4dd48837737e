#include "baker/solve/unshot_queue.h"

#include <algorithm>

namespace hemibake {

UnshotQueue::UnshotQueue(std::size_t count) : count_(count), leaves_(1) {
    while (leaves_ < count) leaves_ *= 2;
    max_.assign(2 * leaves_, 0.0);
    sum_.assign(2 * leaves_, 0.0);
}

void UnshotQueue::set(std::size_t index, double powerWatts) {
    std::size_t node = leaves_ + index;
    max_[node] = powerWatts;
    sum_[node] = powerWatts;
    for (node /= 2; node >= 1; node /= 2) pull(node);
}

void UnshotQueue::setMany(std::span<const std::pair<std::uint32_t, double>> updates) {
    scratch_.clear();
    for (const auto& [index, powerWatts] : updates) {
        const std::size_t node = leaves_ + index;
        max_[node] = powerWatts;
        sum_[node] = powerWatts;
        if (node > 1) scratch_.push_back(node / 2);  // one leaf alone is the root
    }
    // Level by level: every leaf is at the same depth, so a level's parents are the next level's nodes, and a node is
    // a pure function of its two children: recomputing each touched node once, children first, gives what the
    // updates one by one gave.
    std::sort(scratch_.begin(), scratch_.end());
    while (!scratch_.empty()) {
        scratch_.erase(std::unique(scratch_.begin(), scratch_.end()), scratch_.end());
        for (std::size_t& node : scratch_) {
            pull(node);
            node /= 2;  // stays sorted: halving keeps the order
        }
        if (scratch_.front() == 0) scratch_.clear();  // the root's parent
    }
}

std::size_t UnshotQueue::argmax() const {
    std::size_t node = 1;
    while (node < leaves_) node = max_[2 * node] >= max_[2 * node + 1] ? 2 * node : 2 * node + 1;
    return node - leaves_;
}

void UnshotQueue::collectAtLeast(double threshold, std::vector<std::uint32_t>& out) const {
    if (!(threshold > 0.0) || !(max_[1] >= threshold)) return;
    // Depth-first, left before right: only subtrees whose maximum reaches the threshold are entered.
    std::vector<std::size_t> stack{1};
    while (!stack.empty()) {
        const std::size_t node = stack.back();
        stack.pop_back();
        if (node >= leaves_) {
            out.push_back(std::uint32_t(node - leaves_));
            continue;
        }
        if (max_[2 * node + 1] >= threshold) stack.push_back(2 * node + 1);
        if (max_[2 * node] >= threshold) stack.push_back(2 * node);
    }
}

}  // namespace hemibake
