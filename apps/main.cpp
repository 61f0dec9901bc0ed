// curvesfm: one executable, one sub-command per job. parse -> validate -> run -> report.
#include <CLI/CLI.hpp>
#include <iostream>
#include <string>
#include <vector>

#include "apps/cli/cli_options.h"
#include "apps/cli/report_json.h"
#include "apps/curve_ba_command.h"
#include "apps/eval_command.h"
#include "apps/eval_map_command.h"
#include "apps/init_command.h"
#include "apps/point_ba_command.h"
#include "apps/report_command.h"
#include "apps/run_command.h"
#include "apps/synth_command.h"
#include "core/errors.h"
#include "core/heap_policy.h"

int main(int argc, char** argv) {
  // Before any thread starts: see core/heap_policy.h (a page fault per page of every image's
  // scale space, otherwise).
  curvesfm::keepFreedMemoryInProcess();
  CLI::App app{
      "curvesfm: curve-based structure from motion (poly-Bezier curves + bundle adjustment)"};
  app.name("curvesfm");  // for the usage line; parsing a vector does not read argv[0]
  app.require_subcommand(1);
  // `curvesfm --version` prints "curvesfm <version> (<git commit>)" and exits 0.
  const nlohmann::json version = curvesfm::versionJson();
  app.set_version_flag("--version", "curvesfm " + version["version"].get<std::string>() + " (" +
                                        version["commit"].get<std::string>() + ")");
  // A flag given in the config file and again on the command line: the last one wins.
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  curvesfm::PointBaCommand point_ba(&app);
  curvesfm::CurveBaCommand curve_ba(&app);
  curvesfm::EvalCommand eval(&app);
  curvesfm::EvalMapCommand eval_map(&app);
  curvesfm::SynthCommand synth(&app);
  curvesfm::InitCommand init(&app);
  curvesfm::RunCommand run(&app);
  curvesfm::ReportCommand report(&app);

  try {
    curvesfm::parseCommandLine(&app, std::vector<std::string>(argv + 1, argv + argc));
    // Options out of range are usage errors too; validating here keeps them apart from a run
    // that fails.
    if (point_ba.selected()) point_ba.validate();
    if (curve_ba.selected()) curve_ba.validate();
    if (eval.selected()) eval.validate();
    if (eval_map.selected()) eval_map.validate();
    if (synth.selected()) synth.validate();
    if (init.selected()) init.validate();
    if (run.selected()) run.validate();
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const curvesfm::Error& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }

  try {
    if (point_ba.selected()) return point_ba.run();
    if (curve_ba.selected()) return curve_ba.run();
    if (eval.selected()) return eval.run();
    if (eval_map.selected()) return eval_map.run();
    if (synth.selected()) return synth.run();
    if (init.selected()) return init.run();
    if (run.selected()) return run.run();
    if (report.selected()) return report.run();
  } catch (const curvesfm::Error& e) {
    std::cerr << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
