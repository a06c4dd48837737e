#pragma once
// Each sub-command registers its options on the shared CLI11 app and returns the function that runs it.
#include <functional>

#include <CLI/CLI.hpp>

namespace hemibake::cli {

using CommandRunner = std::function<int()>;

// Registration functions, one per sub-command file.
CommandRunner addInfoCommand(CLI::App& app);
CommandRunner addBakeCommand(CLI::App& app);
CommandRunner addReferenceCommand(CLI::App& app);
CommandRunner addCompareCommand(CLI::App& app);
CommandRunner addBatchCommand(CLI::App& app);
CommandRunner addSampleVolumeCommand(CLI::App& app);
CommandRunner addRenderCommand(CLI::App& app);

}  // namespace hemibake::cli
