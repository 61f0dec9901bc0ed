#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "apps/cli/options_table.h"
#include "sim/curve_scene.h"
#include "sim/planar_scene.h"

namespace curvesfm {

/// `curvesfm synth <kind>`: writes synthetic datasets in the TUM RGB-D layout of DESIGN.md.
/// `synth planar` is the paper's planar protocol (§4.1): a photograph laid on a plane, a camera
/// orbiting above it, views rendered by homography with Gaussian intensity noise, the true
/// trajectory (groundtruth.txt) and a perturbed one (init_poses.txt). `synth curves` renders
/// sim/curve_scene.h's 3D curves (step edges on a grey background) along an orbit or a walk of
/// any length, and writes the true curves beside the dataset for `eval-map`.
class SynthCommand {
 public:
  explicit SynthCommand(CLI::App* app);
  SynthCommand(const SynthCommand&) = delete;
  SynthCommand& operator=(const SynthCommand&) = delete;
  bool selected() const { return planar_->parsed() || curves_->parsed(); }
  /// Throws InvalidOptions for an option out of range (main reports it as a usage error).
  void validate() const;
  /// Renders and writes the selected kind's dataset, prints a summary; returns the exit code.
  /// Throws what validate() throws, IoError for a photo that does not load or a dataset that
  /// cannot be written.
  int run() const;

 private:
  /// The scene options as run: the principal point is the centre of the chosen image size.
  PlanarSceneOptions planarOptions() const;

  int runPlanar() const;
  int runCurves() const;

  CLI::App* planar_;
  CLI::App* curves_;
  PlanarSceneOptions options_;
  OptionsTable table_;  ///< Rows point into options_: the command is not copied.
  CurveSceneOptions curve_options_;
  OptionsTable curve_table_;  ///< Rows point into curve_options_.
  std::string image_path_;
  std::string out_dir_;
  bool write_init_poses_ = true;
};

}  // namespace curvesfm
