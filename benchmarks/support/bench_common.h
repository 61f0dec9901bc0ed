#pragma once

// Small helpers shared by the benchmark harnesses: wall-clock timing, medians and the
// `key: value` output lines that docs/benchmarks.md quotes.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <iostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/clock.h"
#include "core/errors.h"
#include "core/heap_policy.h"

namespace curvesfm::bench {

using curvesfm::Clock;
using curvesfm::secondsSince;

/// Median of `samples` (mean of the middle two for an even count); 0 for none.
inline double median(std::vector<double> samples) {
  if (samples.empty()) return 0.0;
  std::sort(samples.begin(), samples.end());
  const std::size_t n = samples.size();
  return n % 2 == 1 ? samples[n / 2] : 0.5 * (samples[n / 2 - 1] + samples[n / 2]);
}

inline void print(const std::string& key, double value) {
  std::printf("%s: %.6g\n", key.c_str(), value);
}
inline void printPrecise(const std::string& key, double value) {
  std::printf("%s: %.12g\n", key.c_str(), value);
}
inline void printInt(const std::string& key, long long value) {
  std::printf("%s: %lld\n", key.c_str(), value);
}
inline void printText(const std::string& key, const std::string& value) {
  std::printf("%s: %s\n", key.c_str(), value.c_str());
}

/// The items of a comma-separated list flag; CLI::ValidationError naming `flag` for an empty
/// item or an empty list.
inline std::vector<std::string> splitAtCommas(const std::string& list, const std::string& flag) {
  std::vector<std::string> items;
  std::stringstream stream(list);
  for (std::string item; std::getline(stream, item, ',');) {
    if (item.empty()) throw CLI::ValidationError(flag, "empty item in '" + list + "'");
    items.push_back(item);
  }
  if (items.empty()) throw CLI::ValidationError(flag, "no item given");
  return items;
}

/// argv joined by spaces, for the command line a summary quotes.
inline std::string commandLine(int argc, char** argv) {
  std::string command;
  for (int i = 0; i < argc; ++i) command += (i == 0 ? "" : " ") + std::string(argv[i]);
  return command;
}

/// Runs `parse` (which fills `app`), then `run`, with freed memory kept in the process as the
/// curvesfm binary keeps it (core/heap_policy.h; printed as `heap:`). Exit codes as the curvesfm
/// binary: 2 for usage errors (CLI::ParseError, or a curvesfm::Error while parsing, e.g. a bad
/// --config file) and invalid options, 1 for any other error (one line on stderr), else run's.
template <class Parse, class Run>
int parseWithAndRun(CLI::App& app, Parse&& parse, Run&& run) {
  keepFreedMemoryInProcess();
  try {
    parse();
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const Error& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
  try {
    printText("heap", describe(heapPolicy()));
    return run();
  } catch (const InvalidOptions& e) {
    std::cerr << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}

/// parseWithAndRun with CLI11's own parse of argv.
template <class Run>
int parseAndRun(CLI::App& app, int argc, char** argv, Run&& run) {
  return parseWithAndRun(
      app, [&] { app.parse(argc, argv); }, std::forward<Run>(run));
}

}  // namespace curvesfm::bench
