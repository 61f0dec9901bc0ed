#pragma once

// Runs the real curvesfm executable, for end-to-end tests of its sub-commands: their output,
// messages and exit codes. CURVESFM_EXECUTABLE (the binary's path) is defined for apps_tests in
// test/CMakeLists.txt.
#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace curvesfm::testing {

struct CommandResult {
  int exit_code = -1;  ///< The process's exit code; -1 if it could not start or was killed.
  std::string output;  ///< stdout and stderr, interleaved.
};

/// Runs `curvesfm <arguments>` through the shell (quote arguments that need it).
inline CommandResult runCurvesfm(const std::string& arguments) {
  const std::string command = std::string(CURVESFM_EXECUTABLE) + " " + arguments + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  char buffer[4096];
  while (std::fgets(buffer, sizeof(buffer), pipe)) result.output += buffer;
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace curvesfm::testing
