#pragma once
// A folder of one fuzzing process's own (the loader reads paths, so every input goes through a file), removed when
// the process ends.
#include <filesystem>
#include <string>
#include <system_error>
#include <unistd.h>

namespace hemibake::fuzz {

class ScratchDir {
public:
    explicit ScratchDir(const std::string& name)
        : dir_(std::filesystem::temp_directory_path() / (name + "-" + std::to_string(::getpid()))) {
        std::filesystem::create_directories(dir_);
    }
    ~ScratchDir() {
        std::error_code ec;
        std::filesystem::remove_all(dir_, ec);
    }
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;
    const std::filesystem::path& path() const { return dir_; }

private:
    std::filesystem::path dir_;
};

}  // namespace hemibake::fuzz
