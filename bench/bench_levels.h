#pragma once
// The levels a level benchmark runs on: HEMIBAKE_BENCH_TILED, a comma-separated list of glTF files (e.g. tiled levels
// from examples/generate_level.py --tiles N). Empty when the variable is not set.
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace hemibake {

inline std::vector<std::string> benchTiledLevels() {
    std::vector<std::string> files;
    const char* list = std::getenv("HEMIBAKE_BENCH_TILED");
    if (list == nullptr) return files;
    std::stringstream in(list);
    for (std::string file; std::getline(in, file, ',');)
        if (!file.empty()) files.push_back(file);
    return files;
}

}  // namespace hemibake
