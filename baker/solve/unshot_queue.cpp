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

}  // namespace hemibake
