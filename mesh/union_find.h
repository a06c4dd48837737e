#pragma once
// Disjoint sets over 0..n-1 with path halving; the smaller index is the root, so grouping does not depend on the
// order of unions. Not thread-safe.
#include <algorithm>
#include <cstdint>
#include <numeric>
#include <vector>

namespace hemibake {

struct UnionFind {
    explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), std::uint32_t(0)); }
    std::uint32_t find(std::uint32_t i) {
        while (parent[i] != i) i = parent[i] = parent[parent[i]];
        return i;
    }
    // Joins the sets of a and b; false when they were one already.
    bool unite(std::uint32_t a, std::uint32_t b) {
        a = find(a), b = find(b);
        if (a == b) return false;
        parent[std::max(a, b)] = std::min(a, b);
        return true;
    }
    std::vector<std::uint32_t> parent;
};

}  // namespace hemibake
