#pragma once
// A shooter's form factors to every element it sees depend only on geometry, not on what it shoots, so a patch
// that shoots again (progressive refinement re-shoots the same patches many times: 4,264 shots from 942 patches
// on the medium Cornell box) reuses its row instead of rendering its hemicubes again. Rows are stored compactly
// (about 3 bytes an entry, FormFactorRow) up to a memory budget; past it, patches simply render every time.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <vector>

namespace hemibake {

// A row of area-averaged form factors F(shooter → element), one entry per element the shooter sees, held in about
// 3 bytes an entry instead of 8 (id + float): a level's cache keeps 2–3× the rows in the same memory, and every row
// kept is a hemicube (or 16) not rendered again. Ids ascend and are delta-coded as LEB128 varints (a patch's elements
// are numbered together, so most steps are 1 and take one byte); each form factor is a 16-bit unsigned float (5-bit
// exponent, 11-bit mantissa, rounded to nearest) relative to a power of two above the row's largest, and the row is
// read back times one double that restores its exact sum. So an entry is within 2⁻¹¹ of its own value (no rounding
// is pushed onto a neighbour, where a sliver's tiny area would magnify it into irradiance), and the row sums to what
// was encoded within double rounding (the power ledger stays balanced). Entries under 2⁻³² of the largest are
// dropped and their share goes to the rest through that factor.
class FormFactorRow {
public:
    double skyFraction = 0.0;       // weight of the shooter's hemisphere that saw nothing
    double backfaceFraction = 0.0;  // weight that saw the back of a surface
    std::uint32_t hemicubes = 0;    // how many hemicubes the row cost to render
    double sampleShare = 0.0;       // rows by rays: the most one ray carries (1/rays); 0 for hemicube rows

    // Replaces the entries by ids[k] → formFactors[k]. Ids strictly ascending, form factors ≥ 0 (negative ones count
    // as 0; zeros are not stored); throws std::invalid_argument otherwise. Keeps skyFraction, backfaceFraction,
    // hemicubes and sampleShare.
    void assign(std::span<const std::uint32_t> ids, std::span<const double> formFactors);
    // Empties the entries (keeps the buffer's capacity for the next assign).
    void clearEntries();
    // visit(element id, form factor as double) for each entry, ids ascending; every form factor read is > 0, and
    // they sum to the assigned ones' sum within double rounding.
    template <class Visit>
    void forEach(Visit&& visit) const {
        const std::uint8_t* p = bytes_.data();
        const std::uint8_t* const end = p + bytes_.size();
        std::uint32_t id = 0;
        while (p < end) {
            std::uint32_t step = 0;
            for (int shift = 0;; shift += 7) {
                const std::uint8_t b = *p++;
                step |= std::uint32_t(b & 0x7fu) << shift;
                if (!(b & 0x80u)) break;
            }
            id += step;
            const auto code = std::uint16_t(p[0] | (p[1] << 8));
            p += 2;
            visit(id, decode(code, bias_) * sumFactor_);
        }
    }
    std::size_t size() const { return count_; }  // entries
    // Memory held (the object and its buffer's capacity), as the cache counts it.
    std::size_t bytes() const { return sizeof(FormFactorRow) + bytes_.capacity(); }
    void shrinkToFit() { bytes_.shrink_to_fit(); }

    // The value of a 16-bit code in a row whose exponent bias is `bias` (bits (code << 12) + bias form the float).
    static double decode(std::uint16_t code, std::uint32_t bias) {
        if (code == 0) return 0.0;
        const std::uint32_t bits = (std::uint32_t(code) << 12) + bias;
        float value;
        std::memcpy(&value, &bits, sizeof value);
        return double(value);
    }

private:
    std::vector<std::uint8_t> bytes_;  // per entry: varint id step, then the 16-bit code
    std::uint32_t count_ = 0;
    std::uint32_t bias_ = 0;  // float exponent bits that scale the codes: (95 + k) << 23 for the row's scale 2^k
    double sumFactor_ = 1.0;  // Σ assigned / Σ decoded codes: restores the row's exact sum
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
