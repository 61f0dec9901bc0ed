#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "factors/point_bundle_adjustment.h"
#include "graph/optimizer.h"
#include "sim/point_scene.h"

namespace curvesfm {

/// `curvesfm point-ba`: builds a synthetic point scene, solves its bundle adjustment through the
/// factor-graph layer and prints the errors before and after (the proof of the graph layer).
class PointBaCommand {
 public:
  explicit PointBaCommand(CLI::App* app);
  bool selected() const { return command_->parsed(); }
  /// Throws InvalidOptions for an option out of range (main reports it as a usage error).
  void validate() const;
  /// Runs the command; returns the process exit code.
  int run() const;

 private:
  CLI::App* command_;
  PointSceneOptions scene_;
  PointBundleAdjustmentOptions ba_;
  OptimizerOptions optimizer_;
  std::string report_path_;
};

}  // namespace curvesfm
