#include "baker/solve/form_factor_cache.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hemibake {

namespace {

constexpr std::uint16_t kLargestCode = 0xFFFF;  // exponent 31, mantissa all ones: just under the row's scale

// The code nearest x in a row scaled by 2^k (0 below half the smallest code, 2^(k−31); the largest code at and
// above the scale).
std::uint16_t nearestCode(double x, int k) {
    const double y = std::ldexp(x, -k);
    if (!(y >= std::ldexp(1.0, -32))) return 0;
    if (y < std::ldexp(1.0, -31)) return std::uint16_t(1u << 11);
    int e = 0;
    const double f = std::frexp(y, &e);  // y = f·2^e, f in [0.5, 1): exponent e − 1, mantissa 2f
    int exponent = e + 31;                // 1 … 31 for y in [2^−31, 1)
    auto mantissa = std::uint32_t(std::lround((2.0 * f - 1.0) * 2048.0));
    if (mantissa == 2048u) mantissa = 0u, ++exponent;
    if (exponent > 31) return kLargestCode;
    return std::uint16_t((std::uint32_t(exponent) << 11) | mantissa);
}

}  // namespace

void FormFactorRow::clearEntries() {
    bytes_.clear();
    count_ = 0;
    bias_ = 0;
    sumFactor_ = 1.0;
}

void FormFactorRow::assign(std::span<const std::uint32_t> ids, std::span<const double> formFactors) {
    if (ids.size() != formFactors.size())
        throw std::invalid_argument("FormFactorRow::assign: " + std::to_string(ids.size()) + " ids but " +
                                    std::to_string(formFactors.size()) + " form factors");
    for (std::size_t i = 1; i < ids.size(); ++i)
        if (ids[i] <= ids[i - 1])
            throw std::invalid_argument("FormFactorRow::assign: ids not strictly ascending at entry " + std::to_string(i));
    clearEntries();
    double largest = 0.0;
    for (double f : formFactors) largest = std::max(largest, f);
    if (!(largest > 0.0)) return;
    // The scale 2^k puts the largest form factor in [2^(k−1), 2^k): codes then reach down 2^31 below it.
    int k = 0;
    std::frexp(largest, &k);
    k = std::clamp(k, -95, 128);
    bias_ = std::uint32_t(95 + k) << 23;
    double assigned = 0.0, decoded = 0.0;
    std::uint32_t previous = 0;
    for (std::size_t i = 0; i < ids.size(); ++i) {
        const double x = std::max(0.0, formFactors[i]);
        assigned += x;
        const std::uint16_t code = nearestCode(x, k);
        if (code == 0) continue;
        decoded += decode(code, bias_);
        for (std::uint32_t step = ids[i] - previous;; step >>= 7) {
            if (step < 0x80u) {
                bytes_.push_back(std::uint8_t(step));
                break;
            }
            bytes_.push_back(std::uint8_t(0x80u | (step & 0x7fu)));
        }
        previous = ids[i];
        bytes_.push_back(std::uint8_t(code & 0xffu));
        bytes_.push_back(std::uint8_t(code >> 8));
        ++count_;
    }
    // decoded > 0: the largest entry is coded (it lies in the top octave).
    sumFactor_ = assigned / decoded;
}

bool FormFactorCache::store(std::uint32_t slot, FormFactorRow& row) {
    row.shrinkToFit();
    const std::size_t bytes = row.bytes();
    std::size_t used = used_.load(std::memory_order_relaxed);
    do {
        if (used + bytes > budget_) return false;
    } while (!used_.compare_exchange_weak(used, used + bytes, std::memory_order_relaxed));
    rows_[slot] = std::make_unique<const FormFactorRow>(std::move(row));
    return true;
}

bool FormFactorCache::replace(std::uint32_t slot, FormFactorRow& row) {
    if (rows_[slot]) {
        used_.fetch_sub(rows_[slot]->bytes(), std::memory_order_relaxed);
        rows_[slot].reset();
    }
    return store(slot, row);
}

}  // namespace hemibake
