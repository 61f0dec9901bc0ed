#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/trajectory_evaluation.h"

namespace curvesfm {

/// The two world axes (0 = x, 1 = y, 2 = z) a top view shows, horizontal < vertical.
struct TopViewAxes {
  int horizontal = 0;
  int vertical = 2;
};

/// The plane of largest spread: drops the axis along which `positions` extend least (max - min),
/// keeping the other two in x, y, z order. Ties drop y first, then x, so that a flat or empty
/// trajectory gets the x-z plane, the top view of a camera-convention (y down) world.
TopViewAxes chooseTopViewAxes(const std::vector<Eigen::Vector3d>& positions);

/// Looks of the evaluation figure.
struct TrajectoryPlotOptions {
  int panel_width = 800;   ///< Width of each of the two panels (px); [240, 8000].
  int panel_height = 600;  ///< Height of the figure (px); [180, 8000].

  /// Throws InvalidOptions naming the field, its value and the constraint.
  void validate() const;
};

/// The evaluation as one figure of two panels side by side:
///   left:  top view of the matched ground-truth and aligned estimated camera centres, in the
///          plane chosen by chooseTopViewAxes() on the ground truth (named in the title), with
///          the same metres per pixel on both axes;
///   right: ATE (position error, m) of every matched pose against time since the first match
///          (s), with the rmse as a horizontal line.
/// Returns a panel_height x (2 * panel_width) CV_8UC3 image.
cv::Mat renderTrajectoryEvaluation(const TrajectoryEvaluation& evaluation,
                                   const TrajectoryPlotOptions& options = {});

/// Writes renderTrajectoryEvaluation() as a PNG at `png_path`; IoError naming it on failure.
void saveTrajectoryEvaluationPlot(const std::string& png_path,
                                  const TrajectoryEvaluation& evaluation,
                                  const TrajectoryPlotOptions& options = {});

}  // namespace curvesfm
