// Runs a shell command for end-to-end CLI tests: its exit code and its
// stdout and stderr together.
#pragma once

#include <cstdio>
#include <string>

#include <sys/wait.h>

namespace mmvk::test {

struct CommandResult {
  int exit_code = 0;      // the process's exit status; 128 + N when killed by signal N
  std::string output;     // stdout and stderr together
};

inline CommandResult run_command(const std::string& command) {
  CommandResult result;
  std::FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return {-1, "popen failed"};
  char buffer[4096];
  while (std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) result.output.append(buffer, n);
  const int status = ::pclose(pipe);
  if (WIFEXITED(status)) {
    result.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    result.exit_code = 128 + WTERMSIG(status);
  } else {
    result.exit_code = -1;
  }
  return result;
}

}  // namespace mmvk::test
