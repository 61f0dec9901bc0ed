#pragma once

// Runs another program from a benchmark harness (the curvesfm executable, COLMAP) and times it:
// fork + execvp, so that arguments need no shell quoting, with the child's stdout and stderr
// written to files for the record.
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/clock.h"

namespace curvesfm::bench {

/// What a finished child did.
struct ProcessResult {
  int exit_code = -1;      ///< Its exit code; 127 if it could not start, -1 if it was killed.
  double seconds = 0.0;    ///< Wall time from fork to exit.
  std::string stdout_log;  ///< The file its stdout went to.
  std::string stderr_log;  ///< The file its stderr went to.
};

/// Runs `argv` (argv[0] looked up on PATH when it has no '/') with stdout into `stdout_log` and
/// stderr into `stderr_log` (truncated first), and waits for it.
inline ProcessResult runProcess(const std::vector<std::string>& argv, const std::string& stdout_log,
                                const std::string& stderr_log) {
  std::vector<std::string> strings = argv;
  std::vector<char*> pointers;
  for (std::string& s : strings) pointers.push_back(s.data());
  pointers.push_back(nullptr);
  ProcessResult result{-1, 0.0, stdout_log, stderr_log};
  // Everything the child needs is prepared before fork: only async-signal-safe calls after it.
  const int out = open(stdout_log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  const int err = open(stderr_log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::fflush(stdout);
  std::fflush(stderr);
  const Clock::time_point start = Clock::now();
  const pid_t pid = (out < 0 || err < 0) ? -1 : fork();
  if (pid == 0) {
    dup2(out, STDOUT_FILENO);
    dup2(err, STDERR_FILENO);
    execvp(pointers[0], pointers.data());
    _exit(127);
  }
  if (out >= 0) close(out);
  if (err >= 0) close(err);
  if (pid < 0) {
    result.exit_code = 127;
    return result;
  }
  int status = 0;
  if (waitpid(pid, &status, 0) >= 0 && WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
  result.seconds = secondsSince(start);
  return result;
}

/// The whole text of `path`; empty if it cannot be read.
inline std::string readTextFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// The last non-empty line of `path`, for a one-line note on why a child failed.
inline std::string lastLine(const std::string& path) {
  std::istringstream lines(readTextFile(path));
  std::string last;
  for (std::string line; std::getline(lines, line);) {
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  }
  return last;
}

/// The full path of `program` on PATH (or `program` itself if it holds a '/' and is
/// executable); empty if there is none.
inline std::string findOnPath(const std::string& program) {
  if (program.find('/') != std::string::npos) {
    return access(program.c_str(), X_OK) == 0 ? program : "";
  }
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    const std::string candidate = (dir.empty() ? "." : dir) + "/" + program;
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return "";
}

}  // namespace curvesfm::bench
