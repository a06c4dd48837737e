// UnshotQueue: the tree's maximum, argmax and total under point updates, and the bulk's sweep query.
#include <algorithm>
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

TEST(UnshotQueue, SetManyLeavesTheSameTreeBitForBitAsSettingEachInTurn) {
    // Two queues under the same updates: one by set(), one by setMany() in batches like a shot's (runs of neighbouring
    // indices, unsorted, repeats within a batch, a batch of one, the last index, an empty batch). Every query agrees
    // exactly, and the totals are equal bit for bit, not within a tolerance: the pairwise sums must be the same sums.
    for (std::size_t n : {std::size_t(1), std::size_t(2), std::size_t(1000), std::size_t(1024), std::size_t(4099)}) {
        UnshotQueue one(n), many(n);
        std::mt19937 rng{std::uint32_t(n)};
        std::uniform_real_distribution<double> watts(0.0, 10.0);
        std::uniform_int_distribution<std::size_t> start(0, n - 1);
        for (int batch = 0; batch < 200; ++batch) {
            std::vector<std::pair<std::uint32_t, double>> updates;
            const std::size_t first = start(rng), size = batch % 17 == 0 ? 0 : batch % 13 == 0 ? 1 : 1 + batch % 40;
            for (std::size_t k = 0; k < size; ++k) {
                const std::size_t index = k % 5 == 4 ? start(rng) : std::min(first + k, n - 1);  // mostly a run
                updates.emplace_back(std::uint32_t(index), k % 7 == 3 ? 0.0 : watts(rng));
            }
            if (size > 3) updates.emplace_back(updates[1].first, watts(rng));  // a repeat: the later value wins
            if (batch == 5) updates.emplace_back(std::uint32_t(n - 1), 3.5);
            for (const auto& [index, power] : updates) one.set(index, power);
            many.setMany(updates);
            ASSERT_EQ(many.totalPower(), one.totalPower()) << "n " << n << ", batch " << batch;
            ASSERT_EQ(many.maxPower(), one.maxPower()) << "n " << n << ", batch " << batch;
            ASSERT_EQ(many.argmax(), one.argmax()) << "n " << n << ", batch " << batch;
        }
        for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(many.get(i), one.get(i)) << "n " << n << ", index " << i;
        for (double threshold : {1e-9, 5.0, 9.0}) {
            std::vector<std::uint32_t> a, b;
            one.collectAtLeast(threshold, a);
            many.collectAtLeast(threshold, b);
            EXPECT_EQ(b, a) << "n " << n << ", threshold " << threshold;
        }
        EXPECT_GT(one.totalPower(), 0.0) << "n " << n;  // the batches left something to compare
    }
}

}  // namespace
}  // namespace hemibake
