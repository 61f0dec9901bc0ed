#include "apps/report_command.h"

#include <string>
#include <vector>

#include "apps/cli/cli_options.h"
#include "apps/cli/plot_scripts.h"

namespace curvesfm {

ReportCommand::ReportCommand(CLI::App* app) {
  command_ = app->add_subcommand(
      "report",
      "Interactive HTML report of a `curvesfm run` output folder (plotly, self-contained): the 3D "
      "curve map with keyframe frusta, trajectories against the ground truth, ATE over time, "
      "per-stage timings, costs per factor type and overlay thumbnails.");
  addConfigFlag(command_);
  command_->add_option("run_dir", run_dir_, "Output folder of `curvesfm run` (report.json, ...)")
      ->required();
  command_->add_option("--out", out_path_, "HTML file to write (default RUN_DIR/report.html)");
}

int ReportCommand::run() const {
  std::vector<std::string> arguments = {"report", run_dir_};
  if (!out_path_.empty()) arguments.insert(arguments.end(), {"--out", out_path_});
  runPlotPackageOrThrow("report", arguments);
  return 0;
}

}  // namespace curvesfm
