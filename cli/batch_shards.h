#pragma once
// Splitting a batch over N machines: each scene gets an estimated cost, and the scenes are dealt out greedily
// (longest processing time first) so the shards finish at about the same time. Pure and deterministic: every
// machine running `--shard I/N` on the same manifest and inputs computes the same assignment.
#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace hemibake::cli {

struct ShardSpec {
    int index = 0;  // 0-based, as SLURM_ARRAY_TASK_ID (--array=0-N-1) and JOB_COMPLETION_INDEX count
    int count = 1;
};

// "I/N" with 0 <= I < N; throws std::invalid_argument otherwise.
ShardSpec parseShardSpec(const std::string& text);

// Estimated relative cost of baking a scene: input bytes (a proxy for triangles, which the hemicubes draw) times
// texel density squared relative to the draft floor (texels per m²), times a preset factor for the per-texel
// and shooting work. Only the ratios between scenes matter.
double estimatedBakeCost(double inputBytes, const nlohmann::json& settings);

// shard[i] for every scene i, given costs in manifest order: greedy LPT, scenes by decreasing cost (ties by
// manifest order) each to the least-loaded shard (ties by lowest index).
std::vector<int> assignShards(const std::vector<double>& costs, int shardCount);

}  // namespace hemibake::cli
