// FormFactorRow keeps a row of form factors in about 3 bytes an entry (ids delta-coded, form factors as 16-bit
// floats and one factor restoring the row's sum). Known answers: ids come back exactly, each entry within 2^-11 of
// its own value (2^-12 from its rounding, at most as much from the factor), and the row's sum within double rounding,
// which is what keeps the shooter's power ledger balanced.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <vector>

#include "baker/solve/form_factor_cache.h"

namespace hemibake {
namespace {

struct Entries {
    std::vector<std::uint32_t> ids;
    std::vector<double> formFactors;
};

Entries read(const FormFactorRow& row) {
    Entries out;
    row.forEach([&](std::uint32_t id, double f) {
        out.ids.push_back(id);
        out.formFactors.push_back(f);
    });
    return out;
}

double sum(const std::vector<double>& v) {
    double s = 0.0;
    for (double x : v) s += x;
    return s;
}

TEST(FormFactorRow, IdsComeBackExactlyAndEachEntryWithinItsRounding) {
    // Like a hemicube's row: runs of consecutive ids (a patch's elements) with jumps between patches, form factors
    // from 1e-9 to 0.3 (a far element in a corner pixel to a near wall).
    std::mt19937_64 rng(7);
    Entries in;
    std::uint32_t id = 3;
    for (int k = 0; k < 5000; ++k) {
        id += (rng() % 8 == 0) ? 1 + std::uint32_t(rng() % 1000000) : 1;
        in.ids.push_back(id);
        in.formFactors.push_back(std::pow(10.0, -9.0 + 8.5 * double(rng() % 1000000) / 1e6));
    }
    FormFactorRow row;
    row.assign(in.ids, in.formFactors);
    const Entries out = read(row);
    ASSERT_EQ(row.size(), in.ids.size());  // all above the row's smallest code (2^-31 of its largest)
    ASSERT_EQ(out.ids, in.ids);
    for (std::size_t k = 0; k < in.ids.size(); ++k) {
        // Each entry on its own: a tiny entry beside a large one keeps its relative precision (a sliver's irradiance).
        ASSERT_LE(std::abs(out.formFactors[k] - in.formFactors[k]), std::ldexp(1.0, -11) * in.formFactors[k]) << k;
        ASSERT_GT(out.formFactors[k], 0.0);
    }
    EXPECT_NEAR(sum(out.formFactors), sum(in.formFactors), 1e-13 * sum(in.formFactors));
    // Steps of 1 take one byte, jumps up to 1e6 three: 2 bytes of form factor on top.
    const double bytesPerEntry = double(row.bytes() - sizeof(FormFactorRow)) / double(row.size());
    EXPECT_LE(bytesPerEntry, 3.5);
    EXPECT_GE(bytesPerEntry, 3.0);
}

TEST(FormFactorRow, ValuesBelowTheSmallestCodeAreDroppedButNotTheirPower) {
    // One near element and a thousand that are 1e-12 of it (below 2^-32): they are dropped as entries, and what they
    // held goes to the entry kept.
    Entries in;
    in.ids.push_back(0);
    in.formFactors.push_back(0.5);
    for (std::uint32_t k = 1; k <= 1000; ++k) in.ids.push_back(k), in.formFactors.push_back(0.5e-12);
    FormFactorRow row;
    row.assign(in.ids, in.formFactors);
    const Entries out = read(row);
    EXPECT_EQ(out.ids, std::vector<std::uint32_t>{0});
    // Within the rounding of summing 1001 doubles: 1000 × 2^-53.
    EXPECT_NEAR(out.formFactors[0], 0.5 + 1000 * 0.5e-12, 1000 * std::ldexp(1.0, -53));

    // Zeros are not stored; a row of nothing but zeros, like an empty one, has no entries.
    FormFactorRow zeros;
    zeros.assign(std::vector<std::uint32_t>{4, 9, 11}, std::vector<double>{0.0, 0.25, 0.0});
    EXPECT_EQ(read(zeros).ids, std::vector<std::uint32_t>{9});
    EXPECT_DOUBLE_EQ(read(zeros).formFactors[0], 0.25);
    zeros.assign(std::vector<std::uint32_t>{4, 9}, std::vector<double>{0.0, 0.0});
    EXPECT_EQ(zeros.size(), 0u);
    FormFactorRow empty;
    empty.assign({}, {});
    EXPECT_EQ(empty.size(), 0u);
    EXPECT_TRUE(read(empty).ids.empty());
}

TEST(FormFactorRow, ScalesFollowTheRowNotAFixedRange) {
    // A row of tiny form factors (a far shooter) keeps the same relative precision as a near one.
    for (double scale : {1.0, 1e-6, 1e-20}) {
        const std::vector<std::uint32_t> ids{1, 2, 3};
        const std::vector<double> f{0.3 * scale, 0.2 * scale, 0.1 * scale};
        FormFactorRow row;
        row.assign(ids, f);
        const Entries out = read(row);
        ASSERT_EQ(out.ids, ids);
        for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(out.formFactors[k], f[k], 1e-3 * f[k]) << scale;
        EXPECT_NEAR(sum(out.formFactors), 0.6 * scale, 1e-15 * scale);
    }
}

TEST(FormFactorRow, RejectsUnsortedOrMismatchedInput) {
    FormFactorRow row;
    EXPECT_THROW(row.assign(std::vector<std::uint32_t>{2, 1}, std::vector<double>{0.1, 0.1}), std::invalid_argument);
    EXPECT_THROW(row.assign(std::vector<std::uint32_t>{1, 1}, std::vector<double>{0.1, 0.1}), std::invalid_argument);
    EXPECT_THROW(row.assign(std::vector<std::uint32_t>{1}, std::vector<double>{0.1, 0.1}), std::invalid_argument);
}

}  // namespace
}  // namespace hemibake
