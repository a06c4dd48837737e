#include "cli/progress.h"

#include <cstdio>
#include <unistd.h>

namespace hemibake::cli {

ProgressLine::ProgressLine(bool forced) : enabled_(forced || ::isatty(STDERR_FILENO)), terminal_(::isatty(STDERR_FILENO)) {}

ProgressLine::~ProgressLine() {
    if (dirty_ && terminal_) std::fputc('\n', stderr);
}

void ProgressLine::update(const std::string& text, bool force) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    // Several lines a second on a terminal; a line a second when piped to a log.
    const auto interval = terminal_ ? std::chrono::milliseconds(200) : std::chrono::milliseconds(1000);
    if (!force && now - last_ < interval) return;
    last_ = now;
    if (terminal_)
        std::fprintf(stderr, "\r\033[K%s", text.c_str());
    else
        std::fprintf(stderr, "%s\n", text.c_str());
    std::fflush(stderr);
    dirty_ = terminal_;
}

void ProgressLine::finish(const std::string& text) {
    if (!enabled_) return;
    if (terminal_) std::fprintf(stderr, "\r\033[K");
    std::fprintf(stderr, "%s\n", text.c_str());
    std::fflush(stderr);
    dirty_ = false;
}

}  // namespace hemibake::cli
