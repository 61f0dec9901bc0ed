#include "apps/cli/config_file.h"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <map>

#include "core/errors.h"

namespace curvesfm {
namespace {

bool isFlag(const CLI::Option& option) { return option.get_items_expected_max() == 0; }

// What the user typed after the program name: "point-ba", or "synth planar" when nested.
std::string commandPath(const CLI::App& command) {
  const CLI::App* parent = command.get_parent();
  if (!parent || !parent->get_parent()) return command.get_name();
  return commandPath(*parent) + " " + command.get_name();
}

// What a YAML node is, for the "found" part of a message.
std::string nodeKind(const YAML::Node& node) {
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a nested mapping";
  return "'" + node.as<std::string>("") + "'";
}

void appendOption(const std::string& path, const std::string& name, const YAML::Node& value,
                  const CLI::Option& option, std::vector<std::string>* args) {
  const int line = value.Mark().line + 1;
  if (value.IsMap() || value.IsSequence()) {
    throw ParseError(path, line, "a single value for flag '" + name + "'", nodeKind(value));
  }
  if (isFlag(option)) {
    bool on = false;
    if (!YAML::convert<bool>::decode(value, on)) {
      throw ParseError(path, line, "true or false for flag '" + name + "'", nodeKind(value));
    }
    if (on) args->push_back("--" + name);
    return;
  }
  args->push_back("--" + name);
  args->push_back(value.as<std::string>(""));
}

}  // namespace

std::vector<std::string> configFileArguments(const std::string& path, const CLI::App& command) {
  std::ifstream file(path);
  if (!file) throw IoError(path, "cannot open config file for reading");
  YAML::Node root;
  try {
    root = YAML::Load(file);
  } catch (const YAML::Exception& e) {
    throw ParseError(path, e.mark.line + 1, "valid YAML", e.msg);
  }
  std::vector<std::string> args;
  if (root.IsNull()) return args;
  if (!root.IsMap()) throw ParseError(path, 1, "a mapping of flag names to values", "no mapping");
  // yaml-cpp keeps every entry of a key given twice (a lookup finds the first, the command line
  // would take the last), so repeated keys are caught here, with the line of each.
  std::map<std::string, int> key_lines;
  for (const auto& entry : root) {
    const int line = entry.first.Mark().line + 1;
    if (!entry.first.IsScalar()) {
      throw ParseError(path, line, "a flag name as key", nodeKind(entry.first));
    }
    const std::string name = entry.first.as<std::string>();
    const CLI::Option* option = command.get_option_no_throw("--" + name);
    if (!option || name == "config" || name == "help") {
      throw ParseError(path, line, "a flag of 'curvesfm " + commandPath(command) + "' (see --help)",
                       "'" + name + "'");
    }
    const auto [first, inserted] = key_lines.emplace(name, line);
    if (!inserted) {
      throw ParseError(
          path, line, "each flag once",
          "'" + name + "' again (first on line " + std::to_string(first->second) + ")");
    }
    appendOption(path, name, entry.second, *option, &args);
  }
  return args;
}

std::vector<std::pair<std::string, std::string>> effectiveOptions(const CLI::App& command) {
  std::vector<std::pair<std::string, std::string>> options;
  for (const CLI::Option* option : command.get_options()) {
    if (option->get_lnames().empty()) continue;
    const std::string& name = option->get_lnames().front();
    if (name == "help" || name == "config") continue;
    std::string value;
    if (isFlag(*option)) {
      value = option->count() > 0 ? "true" : "false";
    } else if (option->count() > 0) {
      // reduced_results() applies the multi-option policy: for a flag given in the config file
      // and again on the command line, the value that won.
      for (const std::string& result : option->reduced_results()) {
        value += (value.empty() ? "" : " ") + result;
      }
    } else {
      value = option->get_default_str();
    }
    options.emplace_back(name, value);
  }
  return options;
}

std::string effectiveOptionsYaml(const CLI::App& command) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  for (const auto& [name, value] : effectiveOptions(command)) {
    out << YAML::Key << name << YAML::Value << value;
  }
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace curvesfm
