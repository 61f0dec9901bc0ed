#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <utility>
#include <vector>

namespace curvesfm {

/// Reads a YAML config file for `command` and turns it into command-line arguments, so that
/// every flag can be set from the file: each top-level key is a long flag name without dashes
/// (`max-iterations: 20`, `kernel: cauchy`, `verbose: true`) and takes one scalar value. No flag
/// of curvesfm or of the benchmarks takes several values (a list such as planar_bench's
/// `--photos` is one comma-separated value, `photos: a.jpg,b.jpg`), so a YAML list is an error.
/// Put the returned arguments before the user's own so that flags override the file.
/// Throws IoError (unreadable file) or ParseError naming path:line and the key (malformed YAML,
/// a key that is not a flag of `command`, a key given twice, a list (flow `[a, b]` or block
/// sequence) or nested mapping as a value, a switch that is not true or false).
std::vector<std::string> configFileArguments(const std::string& path, const CLI::App& command);

/// Every option of `command` with a long name (except help and config) and its effective value:
/// the value in force (the command line over the config file, else the default), in declaration
/// order.
std::vector<std::pair<std::string, std::string>> effectiveOptions(const CLI::App& command);

/// effectiveOptions() as YAML that configFileArguments() reads back.
std::string effectiveOptionsYaml(const CLI::App& command);

}  // namespace curvesfm
