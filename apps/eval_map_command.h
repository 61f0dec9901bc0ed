#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "apps/cli/options_table.h"
#include "core/curve_map_evaluation.h"
#include "core/image_sequence.h"
#include "core/trajectory_evaluation.h"
#include "core/tum_dataset.h"
#include "frontend/image/edge_coverage.h"

namespace curvesfm {

/// The estimate's alignment onto the ground truth, when one was asked for.
struct MapAlignment {
  std::optional<TrajectoryEvaluation> evaluation;  ///< Empty with --align none.
  double frames_axis_length = 0.0;  ///< > 0: fitted to the camera frames, axes this long.
  std::string ground_truth_source;  ///< The ground-truth trajectory's file.
};

/// `curvesfm eval-map`: curve-map precision, recall and F-score at thresholds tau
/// (core/curve_map_evaluation.h) of a run's curves against ground-truth curves (any format of
/// readCurveMap: Pavilion's curve graph, synthcurves, an OBJ). The estimate is carried into the
/// ground truth's frame by the Sim(3) (or SE(3)) that aligns its trajectory onto the ground-truth
/// trajectory (compareTrajectories, as `eval` does), read from the dataset (loadImageSequence) or a
/// TUM file; `--align none` takes the curves as they are. Prints a table per tau and writes every
/// figure and option as JSON. With `--edge-coverage`, also how much of the ground truth the
/// dataset's images show as edges (frontend/image/edge_coverage.h) and the recall on that part.

class EvalMapCommand {
 public:
  explicit EvalMapCommand(CLI::App* app);
  EvalMapCommand(const EvalMapCommand&) = delete;
  EvalMapCommand& operator=(const EvalMapCommand&) = delete;
  bool selected() const { return command_->parsed(); }
  /// Throws InvalidOptions for values out of range and CLI::ValidationError for a missing input
  /// (no curves, or no trajectory or ground truth to align with): usage errors, before any file
  /// is read.
  void validate() const;
  /// Runs the command; returns the process exit code. Bad files throw IoError or ParseError
  /// naming the file and line; trajectories that cannot be aligned TrajectoryEvaluationError.
  int run() const;

 private:
  std::string curvesPath() const;
  std::string trajectoryPath() const;
  /// The dataset, when the alignment or --edge-coverage needs its ground truth; IoError if it
  /// has none.
  std::optional<ImageSequence> sequenceIfNeeded() const;
  /// Aligns the run's trajectory onto the ground truth's and moves `estimate` with it, printing
  /// the alignment; leaves it as it is with --align none.
  MapAlignment alignEstimate(const std::optional<ImageSequence>& sequence,
                             const Polylines3& ground_truth, Polylines3* estimate) const;
  void printEvaluation(const std::string& curves_path, const CurveMapEvaluation& e) const;
  void writeJsonReport(const std::string& curves_path, const CurveMapEvaluation& e,
                       const MapAlignment& alignment, const nlohmann::json& edge_coverage) const;
  nlohmann::json reportEdgeCoverage(const Polylines3& estimate, const Polylines3& ground_truth,
                                    const std::vector<DatasetFrame>& frames,
                                    const ImageSequence& sequence, double spacing) const;

  CLI::App* command_;
  std::string run_dir_;
  std::string curves_path_;
  std::string trajectory_path_;
  std::string dataset_dir_;
  std::string ground_truth_trajectory_path_;
  std::string ground_truth_curves_path_;
  std::string json_path_;
  bool align_frames_ = true;
  bool edge_coverage_ = false;
  int edge_coverage_min_views_ = 2;
  double edge_coverage_min_share_ = 0.5;
  EdgeCoverageOptions edge_coverage_options_;
  ImageSequenceOptions sequence_;
  TrajectoryEvaluationOptions alignment_;
  CurveMapEvaluationOptions options_;
  OptionsTable table_;  ///< Rows point into the options above: the command is not copied.
};

}  // namespace curvesfm
