#include "baker/solve/unshot_queue.h"

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
    for (node /= 2; node >= 1; node /= 2) {
        const double a = max_[2 * node], b = max_[2 * node + 1];
        max_[node] = a >= b ? a : b;
        sum_[node] = sum_[2 * node] + sum_[2 * node + 1];
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
