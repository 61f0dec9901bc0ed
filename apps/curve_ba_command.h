#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "apps/cli/options_table.h"
#include "factors/curve_bundle_adjustment.h"
#include "graph/scheduler.h"
#include "sim/curve_scene.h"

namespace curvesfm {

/// `curvesfm curve-ba`: builds a synthetic curve scene (rendered images, Canny edges, a perturbed
/// start), solves its curve bundle adjustment with the scheduler and prints the camera and curve
/// errors and the sample counts before and after. Every weight of the objective, the sampling,
/// the robust kernel, the gauge and the schedule is a flag (and so a --config key), and
/// `--report FILE` echoes all of them with the results.
class CurveBaCommand {
 public:
  explicit CurveBaCommand(CLI::App* app);
  CurveBaCommand(const CurveBaCommand&) = delete;
  CurveBaCommand& operator=(const CurveBaCommand&) = delete;
  bool selected() const { return command_->parsed(); }
  /// Throws InvalidOptions for an option out of range (main reports it as a usage error).
  void validate() const;
  /// Runs the command; returns the process exit code (1 if a solve failed). Throws what
  /// validate() throws and IoError if the report cannot be written.
  int run() const;

 private:
  /// The scheduler options as run: the gauge switch is the graph builder's.
  SchedulerOptions schedulerOptions() const;

  CLI::App* command_;
  CurveSceneOptions scene_;
  CurveBundleAdjustmentOptions ba_;
  SchedulerOptions scheduler_;
  OptionsTable table_;  ///< Rows point into the members above: the command is not copied.
  std::string report_path_;
};

}  // namespace curvesfm
