#include "cli/huge_page_heap.h"

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include <unistd.h>

namespace hemibake::cli {

namespace {

constexpr const char* kTunable = "glibc.malloc.hugetlb";

// "always" or "madvise" selected (glibc's tunable asks by madvise; "never" refuses it).
bool kernelGivesHugePages() {
    std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string line;
    if (!std::getline(in, line)) return false;
    return line.find("[always]") != std::string::npos || line.find("[madvise]") != std::string::npos;
}

}  // namespace

void restartWithHugePageHeap(char** argv) {
    const char* current = std::getenv("GLIBC_TUNABLES");
    if (current != nullptr && std::strstr(current, kTunable) != nullptr) return;  // set by the user, or by the restart
    if (!kernelGivesHugePages()) return;
    const bool had = current != nullptr;
    const std::string before = had ? current : "";
    const std::string tunables = (before.empty() ? "" : before + ":") + kTunable + "=1";
    if (setenv("GLIBC_TUNABLES", tunables.c_str(), 1) != 0) return;
    execv("/proc/self/exe", argv);
    // The exec failed (no /proc, the binary replaced on disk): this run goes on in small pages, and says so
    // (bake.json hugePageHeap reads the variable); child processes (batch) restart themselves.
    if (had) setenv("GLIBC_TUNABLES", before.c_str(), 1);
    else unsetenv("GLIBC_TUNABLES");
}

}  // namespace hemibake::cli
