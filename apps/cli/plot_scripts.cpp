#include "apps/cli/plot_scripts.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/errors.h"

namespace curvesfm {
namespace {

constexpr int kCannotStart = 127;  // The shell's code for a command it could not run.

std::string shellQuote(const std::string& text) {
  if (text.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                             "_-./=:,+") == std::string::npos) {
    return text;
  }
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

// Our environment with PYTHONPATH = the scripts folder first, so that this checkout's package
// wins over any other.
std::vector<std::string> childEnvironment() {
  const char* existing = std::getenv("PYTHONPATH");
  std::string python_path = std::string("PYTHONPATH=") + CURVESFM_SCRIPTS_DIR;
  if (existing && *existing) python_path += ":" + std::string(existing);
  std::vector<std::string> environment = {python_path};
  for (char** entry = environ; *entry; ++entry) {
    if (std::string(*entry).rfind("PYTHONPATH=", 0) != 0) environment.push_back(*entry);
  }
  return environment;
}

std::vector<char*> pointers(std::vector<std::string>& strings) {
  std::vector<char*> result;
  for (std::string& s : strings) result.push_back(s.data());
  result.push_back(nullptr);
  return result;
}

// fork + execve rather than system(): no shell, so paths need no quoting. Everything the child
// needs is prepared before fork, since a multithreaded parent's child may only call
// async-signal-safe functions (no malloc, no setenv).
int runPython(const std::vector<std::string>& arguments, bool quiet) {
  std::vector<std::string> argv_strings = {CURVESFM_PYTHON};
  argv_strings.insert(argv_strings.end(), arguments.begin(), arguments.end());
  std::vector<std::string> environment = childEnvironment();
  const std::vector<char*> argv = pointers(argv_strings);
  const std::vector<char*> envp = pointers(environment);
  // Our buffered output would otherwise be written twice, once by the child.
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = fork();
  if (pid < 0) return kCannotStart;
  if (pid == 0) {
    if (quiet) {
      const int null = open("/dev/null", O_WRONLY);
      dup2(null, STDOUT_FILENO);
      dup2(null, STDERR_FILENO);
    }
    execve(argv[0], argv.data(), envp.data());
    _exit(kCannotStart);
  }
  int status = 0;
  if (waitpid(pid, &status, 0) < 0) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

std::string plotCommandLine(const std::vector<std::string>& arguments) {
  std::string line = "PYTHONPATH=" + shellQuote(CURVESFM_SCRIPTS_DIR) + " " +
                     shellQuote(CURVESFM_PYTHON) + " -m curvesfm_plots";
  for (const std::string& argument : arguments) line += " " + shellQuote(argument);
  return line;
}

bool plotPackageUsable() { return runPython({"-c", "import numpy, matplotlib"}, true) == 0; }

int runPlotPackage(const std::vector<std::string>& arguments) {
  std::vector<std::string> module = {"-m", "curvesfm_plots"};
  module.insert(module.end(), arguments.begin(), arguments.end());
  return runPython(module, false);
}

void runPlotPackageOrThrow(const std::string& what, const std::vector<std::string>& arguments) {
  const int code = runPlotPackage(arguments);
  if (code == 0) return;
  const std::string reason = code == kCannotStart ? "could not start " CURVESFM_PYTHON
                                                  : "exit code " + std::to_string(code);
  throw Error(what + ": " + plotCommandLine(arguments) + " failed (" + reason + ")");
}

bool drawFiguresIfPossible(const std::vector<std::string>& arguments) {
  if (!plotPackageUsable()) {
    std::printf(
        "figures: not drawn (%s did not start or lacks numpy or matplotlib); draw them later "
        "with: %s\n",
        CURVESFM_PYTHON, plotCommandLine(arguments).c_str());
    return false;
  }
  const int code = runPlotPackage(arguments);
  if (code != 0) {
    std::printf("figures: %s failed (exit code %d)\n", plotCommandLine(arguments).c_str(), code);
  }
  return code == 0;
}

}  // namespace curvesfm
