#pragma once
// One child process (here: `hemibake bake` for one batch scene), so a crash or an out-of-memory kill in a scene
// cannot take the batch down, and so each scene's peak memory is the child's own (wait4's ru_maxrss).
#include <functional>
#include <string>
#include <sys/types.h>
#include <vector>

namespace hemibake::cli {

struct ChildOutcome {
    bool exited = false;        // exited normally (else killed by `signal`)
    int exitCode = -1;
    int signal = 0;
    double peakMemoryMiB = 0.0;  // maximum resident set size
    std::string lastLine;        // the last non-empty line it wrote to stderr
};

class ChildProcess {
public:
    // Starts `executable` with `args` (args[0] is argv[0]); its stdout goes to /dev/null, its stderr to a pipe
    // that wait() reads. Throws std::runtime_error when it cannot be started.
    ChildProcess(const std::string& executable, const std::vector<std::string>& args);
    ~ChildProcess();  // a child still running is killed and reaped: no orphans, no zombies
    ChildProcess(const ChildProcess&) = delete;
    ChildProcess& operator=(const ChildProcess&) = delete;

    // Reads the child's stderr line by line (onLine for each) until it exits. Every ~200 ms asks pendingSignal();
    // a non-zero answer is sent to the child once (and SIGKILL if it is still alive 30 s later).
    ChildOutcome wait(const std::function<void(const std::string&)>& onLine, const std::function<int()>& pendingSignal);

private:
    pid_t pid_ = -1;
    int stderrFd_ = -1;
};

}  // namespace hemibake::cli
