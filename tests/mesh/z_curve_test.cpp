// mesh/z_curve.h: the Morton order of points, its inverse, and its independence of where the points lie.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include "mesh/z_curve.h"

namespace hemibake {
namespace {

// Interleaves x, y, z bits (x lowest) by hand, one bit at a time: the oracle for the Morton code.
std::uint64_t mortonByHand(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
    std::uint64_t code = 0;
    for (int bit = 0; bit < 21; ++bit) {
        code |= std::uint64_t((x >> bit) & 1u) << (3 * bit);
        code |= std::uint64_t((y >> bit) & 1u) << (3 * bit + 1);
        code |= std::uint64_t((z >> bit) & 1u) << (3 * bit + 2);
    }
    return code;
}

// The 8 × 8 × 8 lattice's points, shuffled: their Z-curve order is their hand-made Morton codes' order. The lattice
// spans the bounding box, so coordinate x lands in cell x · (2²¹ − 1) / 7 = x repeated in each 3-bit group: its
// three bits lead the 21, and the order is decided there.
TEST(ZCurve, OrdersALatticeAsItsMortonCodes) {
    std::vector<glm::dvec3> points;
    std::vector<std::uint64_t> code;
    for (std::uint32_t z = 0; z < 8; ++z)
        for (std::uint32_t y = 0; y < 8; ++y)
            for (std::uint32_t x = 0; x < 8; ++x) {
                points.emplace_back(x, y, z);
                code.push_back(mortonByHand(x, y, z));
            }
    std::vector<std::size_t> shuffle(points.size());
    std::iota(shuffle.begin(), shuffle.end(), 0);
    std::shuffle(shuffle.begin(), shuffle.end(), std::mt19937(3));
    std::vector<glm::dvec3> shuffled;
    std::vector<std::uint64_t> shuffledCode;
    for (std::size_t k : shuffle) shuffled.push_back(points[k]), shuffledCode.push_back(code[k]);
    const std::vector<std::uint32_t> order = zCurveOrder(shuffled);
    ASSERT_EQ(order.size(), shuffled.size());
    for (std::size_t k = 0; k < order.size(); ++k) EXPECT_EQ(shuffledCode[order[k]], std::uint64_t(k)) << "place " << k;
}

TEST(ZCurve, RanksAreTheInverseOfTheOrderAndTiesKeepIndexOrder) {
    std::mt19937 rng(11);
    std::uniform_int_distribution<int> cell(0, 3);
    std::vector<glm::dvec3> points(500);
    for (glm::dvec3& p : points) p = glm::dvec3(cell(rng), cell(rng), cell(rng));  // many equal points
    const std::vector<std::uint32_t> order = zCurveOrder(points), rank = zCurveRanks(points);
    for (std::uint32_t k = 0; k < order.size(); ++k) EXPECT_EQ(rank[order[k]], k);
    for (std::size_t k = 1; k < order.size(); ++k)
        if (points[order[k]] == points[order[k - 1]]) {
            EXPECT_LT(order[k - 1], order[k]) << "equal points keep index order";
        }
}

// Relative to the points' bounds: a level 1 mm across or 100 km from the origin gets the same order. Coordinates on
// a 2⁻²⁰ m grid and a power-of-two scale keep every step exact, so any difference would be the method's.
TEST(ZCurve, OrderIsTheSameScaledAndFarFromTheOrigin) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.0, 30.0);
    std::vector<glm::dvec3> points(2000);
    const auto onGrid = [](double v) { return std::floor(v * 0x1.0p20) * 0x1.0p-20; };
    for (glm::dvec3& p : points) p = glm::dvec3(onGrid(u(rng)), onGrid(0.25 * u(rng)), onGrid(u(rng)));
    std::vector<glm::dvec3> small, far;
    for (const glm::dvec3& p : points) {
        small.push_back(p * 0x1.0p-15);  // 30 m → 0.9 mm
        far.push_back(p + glm::dvec3(1e5, -1e5, 1e5));
    }
    const std::vector<std::uint32_t> order = zCurveOrder(points);
    EXPECT_EQ(zCurveOrder(small), order);
    EXPECT_EQ(zCurveOrder(far), order);
}

TEST(ZCurve, EmptyFlatAndNonFiniteInputsGiveAPermutation) {
    EXPECT_TRUE(zCurveOrder({}).empty());
    const std::vector<glm::dvec3> flat(5, glm::dvec3(2.0));
    EXPECT_EQ(zCurveOrder(flat), (std::vector<std::uint32_t>{0, 1, 2, 3, 4}));
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    const std::vector<glm::dvec3> odd = {{1, 1, 1}, {nan, 0, 0}, {0, inf, 0}, {0, 0, 0}};
    std::vector<std::uint32_t> order = zCurveOrder(odd);
    std::sort(order.begin(), order.end());
    EXPECT_EQ(order, (std::vector<std::uint32_t>{0, 1, 2, 3}));
}

}  // namespace
}  // namespace hemibake
