#pragma once
// Running a command line from a test: what it printed and how it ended.

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace kdet::test {

struct CommandOutcome {
    int exit_code; ///< -1 when the command did not exit normally
    std::string out;
};

/// @brief Runs @p command_line through the shell and reads its stdout; a caller that wants stderr too
/// redirects it in the line (`2>&1`).
inline CommandOutcome run_command(const std::string& command_line) {
    FILE* pipe = popen(command_line.c_str(), "r");
    if (pipe == nullptr) return CommandOutcome{-1, "cannot run " + command_line};
    std::string out;
    std::array<char, 4096> chunk{};
    while (std::fgets(chunk.data(), static_cast<int>(chunk.size()), pipe)) out += chunk.data();
    const int status = pclose(pipe);
    return CommandOutcome{WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

} // namespace kdet::test
