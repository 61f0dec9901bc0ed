#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "apps/cli/curve_overlays.h"
#include "apps/cli/options_table.h"
#include "core/image_sequence.h"
#include "frontend/image/curve_overlay.h"
#include "frontend/mapping/pipeline.h"
#include "frontend/mapping/point_initialiser.h"
#include "frontend/mapping/start_model.h"

namespace curvesfm {

struct RunInput;

/// `curvesfm run`: the incremental curve SfM pipeline on a dataset in any layout of
/// loadImageSequence (README "Dataset layouts"): takes the initial poses from --init-poses (a TUM
/// file or a COLMAP model), DIR/init_poses.txt, or else from the point-based initialiser run on
/// the images first; feeds the frames with a pose to Pipeline printing one line per keyframe, runs
/// global BA and writes trajectory.txt, trajectory_initial.txt (the keyframes' initial poses),
/// curves.ply, curves.obj, report.json (incl. the undistorted camera and the per-pose ATE that
/// `curvesfm report` draws), config.yaml (the flags in force, for --config) and, with
/// --overlays, the curves reprojected onto each keyframe, coloured by a statistic, and the worst
/// curves one by one (apps/cli/curve_overlays.h). With DIR/groundtruth.txt it prints the
/// ATE (Sim(3)) of the initial and the refined keyframe trajectory. Every PipelineOptions field
/// is a flag (and so a --config key), prefixed by its stage.
class RunCommand {
 public:
  explicit RunCommand(CLI::App* app);
  RunCommand(const RunCommand&) = delete;
  RunCommand& operator=(const RunCommand&) = delete;
  bool selected() const { return command_->parsed(); }
  /// Throws InvalidOptions for an option out of range (main reports it as a usage error).
  void validate() const;
  /// Runs the command; returns the process exit code (1 if nothing was reconstructed or global
  /// BA failed). Bad input files throw IoError or ParseError naming the file and line.
  int run() const;

 private:
  struct Outcome;     ///< The pipeline's result and what decided how it ran.
  struct Evaluation;  ///< The result against the ground truth and the images.
  struct Written;     ///< What the output folder received beyond the fixed files.

  /// The images with their initial poses: read, or found by the point initialiser.
  RunInput loadInput() const;
  std::vector<Pose3> frontendPoses(const RunInput& input) const;
  /// Every option in force, for report.json: the table's and the run's own.
  nlohmann::json runOptionsJson() const;
  /// The pipeline over the input, once more per relift pass.
  Outcome refine(const RunInput& input) const;
  Written writeOutputs(const RunInput& input, const Outcome& outcome) const;
  nlohmann::json reportJson(const RunInput& input, const Outcome& outcome,
                            const Evaluation& evaluation, const Written& written,
                            double seconds) const;
  /// The summary lines after the run.
  void printResults(const RunInput& input, const Outcome& outcome, const Evaluation& evaluation,
                    const Written& written, double seconds) const;

  CLI::App* command_;
  std::string dataset_dir_;
  std::string out_dir_;
  std::string init_poses_path_;
  bool overlays_ = false;
  int export_samples_per_segment_ = 20;
  /// curves.obj and curves.ply hold the curves whose median sample runs at least this far out of
  /// their views' epipolar planes (deg; CurveStatistics::epipolar_angle_deg): the others' depth
  /// along themselves is unobserved. 0 exports every curve.
  double export_min_epipolar_angle_deg_ = 15.0;
  /// Seconds between the progress lines printed during a global BA (0: every iteration).
  double progress_interval_s_ = 5.0;
  /// Largest |t_image - t_pose| of an image matched to an initial pose (s).
  double max_dt_ = 0.02;
  /// With given initial poses, the initialiser's tracks are triangulated at them: points for the
  /// keyframes' depth ranges and for --ba-points, as the initialiser's own run has.
  bool points_at_given_poses_ = true;
  std::string frontend_poses_path_;  // Diagnosis: --diagnose-frontend-poses.
  /// After the run, this many more runs, each lifting and registering the map again at the
  /// previous run's refined keyframe poses while its BA starts from, and its priors tie to, the
  /// initial poses (as --diagnose-frontend-poses does): a map lifted at noisy poses carries
  /// their errors, one lifted at better poses carries less. >= 0.
  int relift_passes_ = 0;
  /// Prepare the next keyframe's image stage on a second thread while this one's BA runs.
  std::string images_ahead_ = "auto";  // auto, true or false: see imagesAhead().
  ImageSequenceOptions sequence_;
  PointInitialiserOptions initialiser_;
  StartModelOptions start_model_;
  PipelineOptions options_;
  CurveOverlayOptions overlay_;
  OverlayColouringOptions overlay_colouring_;
  /// Rows point into the options structs above: the command is not copied.
  OptionsTable table_;
};

}  // namespace curvesfm
