#pragma once
// Errors that cross layer boundaries. The CLI turns InputError into "hemibake: <message>" and exit code 1.
#include <stdexcept>
#include <string>

namespace hemibake {

// Bad input: a file that is missing, malformed or describes something hemibake cannot bake.
// The message always names the file first: "<path>: <problem>".
class InputError : public std::runtime_error {
public:
    InputError(const std::string& path, const std::string& problem)
        : std::runtime_error(path + ": " + problem), path_(path) {}
    const std::string& path() const { return path_; }

private:
    std::string path_;
};

}  // namespace hemibake
