// UnshotQueue: the tree's maximum, argmax and total under point updates, and the bulk's sweep query.
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "baker/solve/unshot_queue.h"

namespace hemibake {
namespace {

TEST(UnshotQueue, CollectAtLeastFindsExactlyThePowersAtOrAboveTheThresholdInIndexOrder) {
    // 1,000 entries (not a power of two: the tree's padding leaves hold 0), a third of them 0, the rest random.
    const std::size_t n = 1000;
    UnshotQueue queue(n);
    std::vector<double> power(n, 0.0);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> watts(0.0, 10.0);
    for (std::size_t i = 0; i < n; ++i) {
        power[i] = i % 3 == 0 ? 0.0 : watts(rng);
        queue.set(i, power[i]);
    }
    queue.set(17, 0.0), power[17] = 0.0;  // a later update wins
    for (double threshold : {1e-9, 2.5, 7.0, 9.99}) {
        std::vector<std::uint32_t> expected;
        for (std::uint32_t i = 0; i < n; ++i)
            if (power[i] >= threshold) expected.push_back(i);
        std::vector<std::uint32_t> found{123456};  // appended to, not cleared
        queue.collectAtLeast(threshold, found);
        ASSERT_EQ(found.size(), expected.size() + 1) << "threshold " << threshold;
        EXPECT_EQ(found.front(), 123456u);
        EXPECT_EQ(std::vector<std::uint32_t>(found.begin() + 1, found.end()), expected) << "threshold " << threshold;
    }
    // The largest power itself is found alone at its own value; nothing above it, and a threshold of 0 (which
    // would list the padding) finds nothing.
    const std::size_t top = queue.argmax();
    std::vector<std::uint32_t> found;
    queue.collectAtLeast(queue.maxPower(), found);
    ASSERT_EQ(found.size(), 1u);
    EXPECT_EQ(found[0], top);
    found.clear();
    queue.collectAtLeast(std::nextafter(queue.maxPower(), 1e300), found);
    queue.collectAtLeast(0.0, found);
    EXPECT_TRUE(found.empty());
}

}  // namespace
}  // namespace hemibake
