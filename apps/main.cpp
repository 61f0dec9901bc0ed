// curvesfm: one executable, one sub-command per job. parse -> validate -> run -> report.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <iostream>
#include <string>
#include <vector>

#include "apps/config_file.h"
#include "apps/point_ba_command.h"
#include "core/errors.h"

namespace {

// The arguments again with the selected sub-command's --config file expanded in front of the
// user's own flags, so that flags override the file; empty if no --config was given.
std::vector<std::string> withConfigFile(const CLI::App& app, int argc, char** argv) {
  for (const CLI::App* command : app.get_subcommands()) {
    const CLI::Option* config = command->get_option_no_throw("--config");
    if (!config || config->count() == 0) continue;
    std::vector<std::string> args(argv + 1, argv + argc);
    const auto position = std::find(args.begin(), args.end(), command->get_name());
    const std::vector<std::string> from_file =
        curvesfm::configFileArguments(config->as<std::string>(), *command);
    args.insert(position + 1, from_file.begin(), from_file.end());
    return args;
  }
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"curvesfm: curve-based structure from motion (poly-Bezier curves + bundle adjustment)"};
  app.require_subcommand(1);
  // A flag given in the config file and again on the command line: the last one wins.
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  curvesfm::PointBaCommand point_ba(&app);

  try {
    app.parse(argc, argv);
    std::vector<std::string> args = withConfigFile(app, argc, argv);
    if (!args.empty()) {
      std::reverse(args.begin(), args.end());  // CLI11 takes a vector in reverse order
      app.clear();
      app.parse(args);
    }
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const curvesfm::Error& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }

  try {
    if (point_ba.selected()) return point_ba.run();
  } catch (const curvesfm::Error& e) {
    std::cerr << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
