#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace curvesfm {

/// `curvesfm report RUN_DIR [--out FILE.html]`: the self-contained interactive HTML report of one
/// `curvesfm run` output folder (3D curve map with keyframe frusta, trajectories against the
/// ground truth, ATE over time, per-stage timings, costs per factor type, overlay thumbnails),
/// drawn by `python3 -m curvesfm_plots report` (apps/cli/plot_scripts.h). Default output
/// RUN_DIR/report.html.
class ReportCommand {
 public:
  explicit ReportCommand(CLI::App* app);
  bool selected() const { return command_->parsed(); }
  /// Runs the package; returns 0. A missing or malformed report.json or curves.obj, or a Python
  /// without the package's dependencies, throws Error after the package's own message.
  int run() const;

 private:
  CLI::App* command_;
  std::string run_dir_;
  std::string out_path_;
};

}  // namespace curvesfm
