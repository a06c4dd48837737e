#pragma once
// Outputs are written to a temporary name beside their destination and renamed into place
// (baker/atomic_output: ".tmp-<pid>-<file name>"). A process killed outright (SIGKILL, the OOM killer, a power
// cut) cannot remove its temporary file, and nothing else would: the next run into the same output sweeps them.
#include <cstddef>
#include <filesystem>

namespace CLI {
class App;
}

namespace hemibake::cli {

// Removes the temporary files of processes that no longer run: under `output` (two folder levels deep) when it is
// a directory, else beside it (those named after it). Files of running processes are left alone (two runs may share
// a folder). Returns how many were removed; never throws.
std::size_t removeStaleTemporaries(const std::filesystem::path& output);

// The same for a parsed sub-command's -o/--output, if it has one: called before the command writes anything.
std::size_t removeStaleTemporaries(const CLI::App& command);

}  // namespace hemibake::cli
