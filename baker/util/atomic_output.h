#pragma once
// Outputs appear whole or not at all: everything is written to a temporary name beside its destination and
// renamed into place (rename is atomic within a filesystem), so an interrupted bake never leaves half a file.
#include <filesystem>
#include <functional>
#include <string>

namespace hemibake {

// Calls write(tempPath), then renames tempPath to `path`. On any exception the temp file is removed and the
// exception propagates; `path` is untouched.
void writeAtomically(const std::filesystem::path& path, const std::function<void(const std::filesystem::path&)>& write);
void writeTextAtomically(const std::filesystem::path& path, const std::string& text);

}  // namespace hemibake
