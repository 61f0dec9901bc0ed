#pragma once

// Runs real executables, for end-to-end tests of their output, messages and exit codes:
// curvesfm's sub-commands (CURVESFM_EXECUTABLE, defined for apps_tests) and the benchmarks'
// command lines (defined for benchmarks_tests), both in test/CMakeLists.txt.
#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace curvesfm::testing {

struct CommandResult {
  int exit_code = -1;  ///< The process's exit code; -1 if it could not start or was killed.
  std::string output;  ///< stdout and stderr, interleaved.
};

/// Runs `<executable> <arguments>` through the shell (quote arguments that need it).
inline CommandResult runCommand(const std::string& executable, const std::string& arguments) {
  const std::string command = executable + " " + arguments + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  char buffer[4096];
  while (std::fgets(buffer, sizeof(buffer), pipe)) result.output += buffer;
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

#ifdef CURVESFM_EXECUTABLE
/// Runs `curvesfm <arguments>`.
inline CommandResult runCurvesfm(const std::string& arguments) {
  return runCommand(CURVESFM_EXECUTABLE, arguments);
}
#endif

}  // namespace curvesfm::testing
