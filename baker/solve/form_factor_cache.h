#pragma once
// A shooter's form factors to every element it sees depend only on geometry, not on what it shoots, so a patch
// that shoots again (progressive refinement re-shoots the same patches many times: 4,264 shots from 942 patches
// on the medium Cornell box) reuses its row instead of rendering its hemicubes again. Rows are stored compactly
// (element id + float form factor) up to a memory budget; past it, patches simply render every time.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace hemibake {

struct FormFactorRow {
    std::vector<std::uint32_t> elements;
    std::vector<float> formFactors;  // area-averaged F(patch → element); float keeps 1e-7 of a row's sum
    double skyFraction = 0.0;
    double backfaceFraction = 0.0;
    std::uint32_t hemicubes = 0;     // how many hemicubes the row cost to render

    std::size_t bytes() const {
        return sizeof(FormFactorRow) + elements.capacity() * sizeof(std::uint32_t) + formFactors.capacity() * sizeof(float);
    }
};

class FormFactorCache {
public:
    // `slots` rows at most (the shooter keeps patches' rows and single elements'); `budgetBytes` = 0 disables it.
    FormFactorCache(std::size_t slots, std::size_t budgetBytes) : rows_(slots), budget_(budgetBytes) {}

    // Safe to call concurrently for different slots (each slot is touched by one thread at a time).
    const FormFactorRow* find(std::uint32_t slot) const { return rows_[slot].get(); }
    // Moves `row` into the cache when it fits the budget and returns true; otherwise returns false and leaves `row`
    // as it was (the caller shoots with it). Thread-safe for different slots.
    bool store(std::uint32_t slot, FormFactorRow& row);
    // As store, but the slot's previous row (if any) is released first; when `row` does not fit, the slot is left
    // empty. Invalidates pointers to the previous row. Thread-safe for different slots.
    bool replace(std::uint32_t slot, FormFactorRow& row);

    std::size_t bytesUsed() const { return used_.load(std::memory_order_relaxed); }
    std::size_t budgetBytes() const { return budget_; }
    std::uint64_t hits() const { return hits_.load(std::memory_order_relaxed); }
    void countHit() { hits_.fetch_add(1, std::memory_order_relaxed); }

private:
    std::vector<std::unique_ptr<const FormFactorRow>> rows_;
    std::size_t budget_;
    std::atomic<std::size_t> used_{0};
    std::atomic<std::uint64_t> hits_{0};
};

}  // namespace hemibake
