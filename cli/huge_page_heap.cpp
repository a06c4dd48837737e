#include "cli/huge_page_heap.h"

#include <cstdlib>
#include <cstring>
#include <string>

#include <unistd.h>

#include "baker/pipeline/bake_report.h"

namespace hemibake::cli {

void restartWithHugePageHeap(char** argv) {
    const char* current = std::getenv("GLIBC_TUNABLES");
    // Set by the user, or by the restart.
    if (current != nullptr && std::strstr(current, kGlibcHugePageTunable) != nullptr) return;
    if (!transparentHugePagesAvailable()) return;  // glibc asks by madvise; "never" refuses it
    const bool had = current != nullptr;
    const std::string before = had ? current : "";
    std::string tunables = (before.empty() ? "" : before + ":") + kGlibcHugePageTunable + "=1";
    // glibc madvises its main heap only: the arenas it opens for other threads (64 MiB each) stay in 4 KiB pages, and
    // they hold what worker threads allocate (every form-factor row a shot makes). One arena for all threads.
    if (before.find(kGlibcArenaCountTunable) == std::string::npos)
        tunables += std::string(":") + kGlibcArenaCountTunable + "=1";
    if (setenv("GLIBC_TUNABLES", tunables.c_str(), 1) != 0) return;
    execv("/proc/self/exe", argv);
    // The exec failed (no /proc, the binary replaced on disk): this run goes on in small pages, and says so
    // (bake.json hugePageHeap reads the variable); child processes (batch) restart themselves.
    if (had) setenv("GLIBC_TUNABLES", before.c_str(), 1);
    else unsetenv("GLIBC_TUNABLES");
}

}  // namespace hemibake::cli
