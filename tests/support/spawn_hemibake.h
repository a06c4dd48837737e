#pragma once
// Starts the hemibake binary without waiting for it (tests that interrupt a run: cli_batch_test, cli_interrupt_test).
#include <fcntl.h>
#include <spawn.h>
#include <string>
#include <unistd.h>
#include <vector>

extern char** environ;

namespace hemibake::test {

// Runs HEMIBAKE_BINARY with `args` (without argv[0]), stdout to /dev/null, stderr into `stderrPath`. Returns the
// pid, or -1 when it could not be started.
inline pid_t spawnHemibake(const std::vector<std::string>& args, const std::string& stderrPath) {
    std::vector<std::string> all = {"hemibake"};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, STDERR_FILENO, stderrPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    pid_t pid = -1;
    const int rc = posix_spawn(&pid, HEMIBAKE_BINARY, &fa, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    return rc == 0 ? pid : -1;
}

}  // namespace hemibake::test
