#include "baker/solve/form_factor_cache.h"

namespace hemibake {

bool FormFactorCache::store(std::uint32_t slot, FormFactorRow& row) {
    row.elements.shrink_to_fit();
    row.formFactors.shrink_to_fit();
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
