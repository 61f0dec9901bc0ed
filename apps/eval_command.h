#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "apps/cli/options_table.h"
#include "core/trajectory_evaluation.h"

namespace curvesfm {

/// `curvesfm eval`: compares an estimated TUM trajectory with the ground truth: associates the
/// poses by timestamp, aligns the estimate (sim3, se3 or none) and prints the ATE and RPE
/// statistics; optionally writes them as JSON and draws the trajectories and the error as a PNG
/// or PDF (`--plot`, by `python3 -m curvesfm_plots eval` from that JSON: apps/cli/plot_scripts.h),
/// and writes the aligned estimate as a TUM trajectory (`--aligned-out`), which can be given back
/// to `run` as initial poses in the ground truth's frame.
class EvalCommand {
 public:
  explicit EvalCommand(CLI::App* app);
  EvalCommand(const EvalCommand&) = delete;
  EvalCommand& operator=(const EvalCommand&) = delete;
  bool selected() const { return command_->parsed(); }
  /// Throws InvalidOptions for flag values out of range (a usage error, before any file is read).
  void validate() const { table_.validate(); }
  /// Runs the command; returns the process exit code. Bad files and options throw curvesfm
  /// errors (IoError, ParseError, InvalidOptions, TrajectoryEvaluationError).
  int run() const;

 private:
  CLI::App* command_;
  std::string estimate_path_;
  std::string ground_truth_path_;
  TrajectoryEvaluationOptions options_;
  OptionsTable table_;  ///< Rows point into options_: the command is not copied.
  std::string json_path_;
  std::string plot_path_;
  std::string aligned_path_;
};

}  // namespace curvesfm
