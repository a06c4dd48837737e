#include "cli/batch_shards.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace hemibake::cli {

ShardSpec parseShardSpec(const std::string& text) {
    const std::size_t slash = text.find('/');
    auto number = [&](const std::string& part) {
        if (part.empty() || part.size() > 6 || !std::all_of(part.begin(), part.end(), [](char c) { return c >= '0' && c <= '9'; }))
            throw std::invalid_argument("--shard must be I/N with 0 <= I < N (e.g. 0/4), got '" + text + "'");
        return std::stoi(part);
    };
    if (slash == std::string::npos) number("");
    ShardSpec s{number(text.substr(0, slash)), number(text.substr(slash + 1))};
    if (s.count < 1 || s.index >= s.count)
        throw std::invalid_argument("--shard must be I/N with 0 <= I < N (e.g. 0/4), got '" + text + "'");
    return s;
}

double estimatedBakeCost(double inputBytes, const nlohmann::json& settings) {
    const std::string preset = settings.value("preset", std::string("medium"));
    // The per-metre texel floors of the presets (baker/bake_layout.cpp) and rough relative per-texel work.
    double texelsPerUnit = 16, work = 4;
    if (preset == "draft") texelsPerUnit = 8, work = 1;
    else if (preset == "high") texelsPerUnit = 32, work = 8;
    else if (preset == "ultra") texelsPerUnit = 64, work = 16;
    if (settings.contains("texels-per-unit") && settings["texels-per-unit"].is_number())
        texelsPerUnit = settings["texels-per-unit"].get<double>();
    const double density = (texelsPerUnit / 8.0) * (texelsPerUnit / 8.0);
    // A floor so empty or missing files still count as a scene to hand out.
    return std::max(inputBytes, 1024.0) * work * density;
}

std::vector<int> assignShards(const std::vector<double>& costs, int shardCount) {
    std::vector<std::size_t> order(costs.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return costs[a] > costs[b]; });
    std::vector<double> load(std::size_t(std::max(shardCount, 1)), 0.0);
    std::vector<int> shard(costs.size(), 0);
    for (std::size_t i : order) {
        const auto least = std::min_element(load.begin(), load.end());  // first minimum: lowest index wins ties
        shard[i] = int(least - load.begin());
        *least += costs[i];
    }
    return shard;
}

}  // namespace hemibake::cli
