#include "cli/stale_temporaries.h"

#include <cerrno>
#include <csignal>
#include <string>
#include <string_view>
#include <sys/types.h>
#include <vector>

#include <CLI/CLI.hpp>

namespace hemibake::cli {

namespace {

namespace fs = std::filesystem;

// The pid in ".tmp-<pid>-<rest>" (baker/atomic_output's temporary names) and the rest, or pid 0 when `name` is
// not one.
pid_t temporaryOwner(const std::string& name, std::string* rest) {
    constexpr std::string_view kPrefix = ".tmp-";
    if (name.rfind(kPrefix, 0) != 0) return 0;
    std::size_t at = kPrefix.size();
    long long pid = 0;
    while (at < name.size() && name[at] >= '0' && name[at] <= '9' && pid < (1ll << 31)) pid = pid * 10 + (name[at++] - '0');
    if (at == kPrefix.size() || at >= name.size() || name[at] != '-' || pid <= 0 || pid >= (1ll << 31)) return 0;
    if (rest) *rest = name.substr(at + 1);
    return pid_t(pid);
}

bool running(pid_t pid) { return ::kill(pid, 0) == 0 || errno == EPERM; }

bool removeIfStale(const fs::path& path, const std::string& restPrefix) {
    std::string rest;
    const pid_t owner = temporaryOwner(path.filename().string(), &rest);
    if (owner == 0 || rest.rfind(restPrefix, 0) != 0 || running(owner)) return false;
    std::error_code ec;
    return fs::remove_all(path, ec) > 0 && !ec;
}

}  // namespace

std::size_t removeStaleTemporaries(const fs::path& output) {
    std::size_t removed = 0;
    std::error_code ec;
    if (fs::is_directory(fs::symlink_status(output, ec))) {
        std::vector<fs::path> stale;  // collected first: removing while iterating invalidates the iterator
        // Outputs nest at most two folders deep (OUT/lightmaps/…); a user's -o . should not walk a whole tree.
        constexpr int kMaxDepth = 2;
        for (auto it = fs::recursive_directory_iterator(output, fs::directory_options::skip_permission_denied, ec);
             !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
            if (it.depth() >= kMaxDepth) it.disable_recursion_pending();
            if (temporaryOwner(it->path().filename().string(), nullptr) != 0) {
                stale.push_back(it->path());
                it.disable_recursion_pending();
            }
        }
        for (const fs::path& p : stale) removed += removeIfStale(p, "") ? 1 : 0;
        return removed;
    }
    // A file output: its temporaries sit beside it, named after it (or after its stem: a PNG preview beside an EXR).
    const fs::path parent = output.has_parent_path() ? output.parent_path() : fs::path(".");
    if (!fs::is_directory(parent, ec) || output.filename().empty()) return 0;
    const std::string stem = output.stem().string();
    for (const auto& entry : fs::directory_iterator(parent, ec))
        removed += removeIfStale(entry.path(), stem) ? 1 : 0;
    return removed;
}

std::size_t removeStaleTemporaries(const CLI::App& command) {
    const CLI::Option* output = command.get_option_no_throw("--output");
    if (!output || output->count() == 0) return 0;
    try {
        return removeStaleTemporaries(fs::path(output->as<std::string>()));
    } catch (const std::exception&) {
        return 0;
    }
}

}  // namespace hemibake::cli
