#include "apps/cli/cli_options.h"

#include <algorithm>
#include <filesystem>

#include "apps/cli/config_file.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

// The selected (possibly nested) sub-command's --config file, or empty when none was given.
std::string configPath(const CLI::App& app, const CLI::App** selected) {
  const CLI::Option* config = app.get_option_no_throw("--config");
  if (config && config->count() > 0) {
    *selected = &app;
    return config->as<std::string>();
  }
  for (const CLI::App* command : app.get_subcommands()) {
    const std::string nested = configPath(*command, selected);
    if (!nested.empty()) return nested;
  }
  return "";
}

// Where `command`'s own flags begin in `args`: after its name, which for a nested sub-command
// is looked up after its parent's (a flag value may spell a command name too).
std::vector<std::string>::iterator afterCommandName(const CLI::App& command,
                                                    std::vector<std::string>* args) {
  auto begin = args->begin();
  const CLI::App* parent = command.get_parent();
  if (!parent) return begin;  // A program without sub-commands: its flags start at once.
  if (parent && parent->get_parent()) begin = afterCommandName(*parent, args);
  return std::find(begin, args->end(), command.get_name()) + 1;
}

}  // namespace

CLI::Option* addBoolFlag(CLI::App* command, const std::string& name, bool* target,
                         const std::string& description) {
  // Normalised so that the echoed configuration reads true or false whatever was typed.
  const CLI::Validator spellings(
      [](std::string& value) -> std::string {
        const std::string lower = CLI::detail::to_lower(value);
        if (lower == "true" || lower == "yes" || lower == "on" || lower == "1") {
          value = "true";
        } else if (lower == "false" || lower == "no" || lower == "off" || lower == "0") {
          value = "false";
        } else {
          return "expected true or false (or yes/no, on/off, 1/0), found '" + value + "'";
        }
        return "";
      },
      "");
  return command->add_option("--" + name, *target, description)
      ->transform(spellings)
      ->type_name("BOOL")
      ->default_str(*target ? "true" : "false");
}

void parseCommandLine(CLI::App* app, const std::vector<std::string>& args) {
  const CLI::App* command = nullptr;
  try {
    // CLI11 takes a vector in reverse order.
    app->parse(std::vector<std::string>(args.rbegin(), args.rend()));
  } catch (const CLI::RequiredError&) {
    // A required flag may come from the config file. CLI11 checks requirements after reading
    // every argument, so --config is known here; the second parse checks again.
    if (configPath(*app, &command).empty()) throw;
  }
  const std::string path = configPath(*app, &command);
  if (path.empty()) return;
  std::vector<std::string> expanded = args;
  const auto position = afterCommandName(*command, &expanded);
  const std::vector<std::string> from_file = configFileArguments(path, *command);
  expanded.insert(position, from_file.begin(), from_file.end());
  app->clear();
  app->parse(std::vector<std::string>(expanded.rbegin(), expanded.rend()));
}

void addConfigFlag(CLI::App* command) {
  command->add_option("--config",
                      "YAML file of options (keys are long flag names); flags given "
                      "on the command line override it");
}

nlohmann::json optionsToJson(const CLI::App& command) {
  nlohmann::json json = nlohmann::json::object();
  for (const auto& [name, value] : effectiveOptions(command)) json[name] = value;
  return json;
}

void createOutputFolder(const std::string& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw IoError(dir, "cannot create the output folder: " + error.message());
}

}  // namespace curvesfm
