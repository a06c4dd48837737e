#pragma once
// Progress on stderr, rewritten in place on a terminal, at most a few times a second; silent unless stderr is
// a terminal or --progress was given (CONVENTIONS.md).
#include <chrono>
#include <string>

namespace hemibake::cli {

class ProgressLine {
public:
    explicit ProgressLine(bool forced);
    ~ProgressLine();
    bool enabled() const { return enabled_; }
    void update(const std::string& text, bool force = false);
    void finish(const std::string& text);  // a final line that stays

private:
    bool enabled_;
    bool terminal_;
    bool dirty_ = false;
    std::chrono::steady_clock::time_point last_{};
};

}  // namespace hemibake::cli
