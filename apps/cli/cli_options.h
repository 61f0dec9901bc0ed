#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/enum_names.h"
#include "core/errors.h"

namespace curvesfm {

/// Registers `--<name>` taking an enum by name (EnumNames). An unknown name is a usage error
/// naming the flag and listing the accepted names. The option keeps the name the user gave, so
/// the echoed configuration shows names; the default shown is `toString(*target)`.
template <class Enum>
CLI::Option* addEnumFlag(CLI::App* command, const std::string& name, Enum* target,
                         const std::string& description) {
  return command
      ->add_option_function<std::string>(
          "--" + name,
          // The validator below has already accepted the name.
          [target](const std::string& value) { *target = *findEnumName<Enum>(value); }, description)
      ->check(CLI::Validator(
          [](std::string& value) -> std::string {
            if (findEnumName<Enum>(value)) return "";
            return "\"" + value + "\": expected one of " + enumNameList<Enum>();
          },
          "NAME"))
      ->default_str(toString(*target));
}

/// Registers `--<name> BOOL` (true/false, yes/no, on/off, 1/0; echoed as true or false): a
/// switch whose default is on needs a value, since a YAML `false` cannot switch a bare flag off.
CLI::Option* addBoolFlag(CLI::App* command, const std::string& name, bool* target,
                         const std::string& description);

/// Parses `args` (without the program name) into `app`; if `app` itself or the selected
/// sub-command (nested ones included, e.g. `synth planar`) got `--config FILE`, parses again with
/// the file's flags in front of the user's own so that flags given on the command line win, and
/// required flags may come from the file; that needs options that keep the last value given
/// (`app->option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast)` before the
/// sub-commands are added). Throws CLI::ParseError (unknown flag, bad value) and what
/// configFileArguments() throws (unreadable or malformed config file).
void parseCommandLine(CLI::App* app, const std::vector<std::string>& args);

/// Adds `--config FILE.yaml` (YAML keys are long flag names) to `command`.
void addConfigFlag(CLI::App* command);

/// The effective options of `command` as a JSON object (for report.json).
nlohmann::json optionsToJson(const CLI::App& command);

/// Creates a command's --out folder (and its parents) if needed; IoError naming it otherwise.
void createOutputFolder(const std::string& dir);

}  // namespace curvesfm
