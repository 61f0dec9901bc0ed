#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>

#include "apps/cli/options_table.h"
#include "core/image_sequence.h"
#include "frontend/mapping/point_initialiser.h"

namespace curvesfm {

/// `curvesfm init`: initial poses and a sparse point map from the images alone (the point-based
/// initialiser), written as trajectory.txt, points.ply and report.json.
class InitCommand {
 public:
  explicit InitCommand(CLI::App* app);
  InitCommand(const InitCommand&) = delete;
  InitCommand& operator=(const InitCommand&) = delete;
  bool selected() const { return command_->parsed(); }
  /// Throws InvalidOptions for an option out of range (main reports it as a usage error).
  void validate() const { table_.validate(); }
  /// Runs the command; returns the process exit code: 1 when nothing could be reconstructed.
  int run() const;

 private:
  CLI::App* command_;
  std::string dataset_dir_, out_dir_;
  ImageSequenceOptions sequence_;
  PointInitialiserOptions options_;
  OptionsTable table_;
};

}  // namespace curvesfm
