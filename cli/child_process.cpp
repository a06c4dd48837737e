#include "cli/child_process.h"

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <stdexcept>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace hemibake::cli {

namespace {

// posix_spawn's file actions and attributes as RAII objects.
struct SpawnActions {
    posix_spawn_file_actions_t actions;
    SpawnActions() { posix_spawn_file_actions_init(&actions); }
    ~SpawnActions() { posix_spawn_file_actions_destroy(&actions); }
};

struct SpawnAttributes {
    posix_spawnattr_t attributes;
    SpawnAttributes() { posix_spawnattr_init(&attributes); }
    ~SpawnAttributes() { posix_spawnattr_destroy(&attributes); }
};

}  // namespace

ChildProcess::ChildProcess(const std::string& executable, const std::vector<std::string>& args) {
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("cannot create a pipe: ") + std::strerror(errno));
    SpawnActions fa;
    posix_spawn_file_actions_adddup2(&fa.actions, fds[1], STDERR_FILENO);  // dup2 clears O_CLOEXEC on fd 2
    posix_spawn_file_actions_addopen(&fa.actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&fa.actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    // The child starts with default SIGINT/SIGTERM actions and nothing blocked, whatever the batch has installed.
    SpawnAttributes sa;
    sigset_t defaults, none;
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGINT);
    sigaddset(&defaults, SIGTERM);
    sigemptyset(&none);
    posix_spawnattr_setsigdefault(&sa.attributes, &defaults);
    posix_spawnattr_setsigmask(&sa.attributes, &none);
    posix_spawnattr_setflags(&sa.attributes, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);

    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const int rc = posix_spawn(&pid_, executable.c_str(), &fa.actions, &sa.attributes, argv.data(), environ);
    ::close(fds[1]);
    if (rc != 0) {
        ::close(fds[0]);
        pid_ = -1;
        throw std::runtime_error("cannot start " + executable + ": " + std::strerror(rc));
    }
    stderrFd_ = fds[0];
}

ChildProcess::~ChildProcess() {
    if (pid_ > 0) {
        ::kill(pid_, SIGKILL);
        while (::waitpid(pid_, nullptr, 0) < 0 && errno == EINTR) {
        }
    }
    if (stderrFd_ >= 0) ::close(stderrFd_);
}

ChildOutcome ChildProcess::wait(const std::function<void(const std::string&)>& onLine, const std::function<int()>& pendingSignal) {
    ChildOutcome outcome;
    std::string partial;
    auto flushLine = [&](std::string line) {
        while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
        if (const std::size_t cr = line.rfind('\r'); cr != std::string::npos) line.erase(0, cr + 1);
        if (line.empty()) return;
        outcome.lastLine = line;
        onLine(line);
    };
    int forwarded = 0;
    std::chrono::steady_clock::time_point forwardedAt{};
    bool killed = false;
    char buf[4096];
    while (stderrFd_ >= 0) {
        pollfd p{stderrFd_, POLLIN, 0};
        const int ready = ::poll(&p, 1, 200);
        if (const int sig = pendingSignal(); sig && !forwarded) {
            ::kill(pid_, sig);
            forwarded = sig;
            forwardedAt = std::chrono::steady_clock::now();
        } else if (forwarded && !killed && std::chrono::steady_clock::now() - forwardedAt > std::chrono::seconds(30)) {
            ::kill(pid_, SIGKILL);  // it ignored the polite request
            killed = true;
        }
        if (ready <= 0) continue;  // timeout, or EINTR from the signal we just noted
        const ssize_t n = ::read(stderrFd_, buf, sizeof buf);
        if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
        if (n <= 0) {
            ::close(stderrFd_);
            stderrFd_ = -1;
            break;
        }
        partial.append(buf, std::size_t(n));
        for (std::size_t nl; (nl = partial.find('\n')) != std::string::npos;) {
            flushLine(partial.substr(0, nl));
            partial.erase(0, nl + 1);
        }
    }
    flushLine(partial);
    int status = 0;
    rusage usage{};
    while (::wait4(pid_, &status, 0, &usage) < 0) {
        if (errno != EINTR) throw std::runtime_error(std::string("waiting for a child failed: ") + std::strerror(errno));
        if (const int sig = pendingSignal(); sig && !forwarded) ::kill(pid_, forwarded = sig);
    }
    pid_ = -1;
    outcome.exited = WIFEXITED(status);
    outcome.exitCode = outcome.exited ? WEXITSTATUS(status) : -1;
    outcome.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
    outcome.peakMemoryMiB = double(usage.ru_maxrss) / 1024.0;  // Linux reports kibibytes
    return outcome;
}

}  // namespace hemibake::cli
