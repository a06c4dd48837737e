#pragma once
// SIGINT/SIGTERM while a batch runs: instead of dying with a child half-way through a bake, the batch notes the
// signal, forwards it to the child, waits for it, cleans up and exits non-zero. The note is a process-wide flag
// because a signal handler can reach nothing else (the one global the project allows).
namespace hemibake::cli {

class InterruptGuard {
public:
    InterruptGuard();   // installs the handlers (no SA_RESTART, so blocking calls wake up)
    ~InterruptGuard();  // restores the previous ones
    InterruptGuard(const InterruptGuard&) = delete;
    InterruptGuard& operator=(const InterruptGuard&) = delete;

    // The signal received since construction (SIGINT or SIGTERM), or 0.
    static int pending();
};

}  // namespace hemibake::cli
