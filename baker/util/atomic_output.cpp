#include "baker/util/atomic_output.h"

#include <fstream>
#include <stdexcept>
#include <unistd.h>

namespace hemibake {

void writeAtomically(const std::filesystem::path& path, const std::function<void(const std::filesystem::path&)>& write) {
    namespace fs = std::filesystem;
    if (path.has_parent_path()) fs::create_directories(path.parent_path());
    // The temp name keeps the extension: writers such as OpenImageIO choose the format from it.
    const fs::path temp = path.parent_path() / (".tmp-" + std::to_string(::getpid()) + "-" + path.filename().string());
    try {
        write(temp);
        fs::rename(temp, path);
    } catch (...) {
        std::error_code ec;
        fs::remove(temp, ec);
        throw;
    }
}

void writeTextAtomically(const std::filesystem::path& path, const std::string& text) {
    writeAtomically(path, [&](const std::filesystem::path& temp) {
        std::ofstream out(temp, std::ios::binary);
        out << text;
        out.close();
        if (!out) throw std::runtime_error(path.string() + ": cannot write");
    });
}

}  // namespace hemibake
