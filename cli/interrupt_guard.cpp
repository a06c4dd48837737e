#include "cli/interrupt_guard.h"

#include <csignal>

namespace hemibake::cli {

namespace {

volatile std::sig_atomic_t gPendingSignal = 0;
struct sigaction gPreviousInt {}, gPreviousTerm {};

extern "C" void noteSignal(int signal) { gPendingSignal = signal; }

}  // namespace

InterruptGuard::InterruptGuard() {
    gPendingSignal = 0;
    struct sigaction action {};
    action.sa_handler = noteSignal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = 0;
    sigaction(SIGINT, &action, &gPreviousInt);
    sigaction(SIGTERM, &action, &gPreviousTerm);
}

InterruptGuard::~InterruptGuard() {
    sigaction(SIGINT, &gPreviousInt, nullptr);
    sigaction(SIGTERM, &gPreviousTerm, nullptr);
}

int InterruptGuard::pending() { return gPendingSignal; }

}  // namespace hemibake::cli
