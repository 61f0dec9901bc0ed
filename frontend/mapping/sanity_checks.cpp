#include "frontend/mapping/sanity_checks.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/check.h"
#include "core/errors.h"
#include "core/median.h"
#include "core/similarity_alignment.h"

namespace curvesfm {

void SanityOptions::validate() const {
  const OptionCheck require("SanityOptions");
  require(extent_percentile >= 0.0 && extent_percentile <= 25.0, "extent_percentile",
          extent_percentile, "in [0, 25]");
  require.nonNegative("extent_margin", extent_margin);
  require(samples_per_segment >= 1 && samples_per_segment <= 1000, "samples_per_segment",
          samples_per_segment, "in [1, 1000]");
  require(max_curve_residual_px >= 0.0 && std::isfinite(max_curve_residual_px),
          "max_curve_residual_px", max_curve_residual_px, "finite and >= 0");
  require(min_chord_ratio >= 0.0 && min_chord_ratio < 1.0, "min_chord_ratio", min_chord_ratio,
          "in [0, 1)");
  require(min_epipolar_angle_deg >= 0.0 && min_epipolar_angle_deg < 90.0, "min_epipolar_angle_deg",
          min_epipolar_angle_deg, "in [0, 90)");
  require(max_implausible_fraction >= 0.0 && max_implausible_fraction <= 1.0,
          "max_implausible_fraction", max_implausible_fraction, "in [0, 1]");
  require.positive("max_pose_move_spacings", max_pose_move_spacings);
  require(min_keyframes >= 0, "min_keyframes", min_keyframes, ">= 0");
  require(min_curves >= 0, "min_curves", min_curves, ">= 0");
}

bool SceneExtent::valid() const {
  const double d = diagonal();
  return d > 0.0 && std::isfinite(d);
}

double SceneExtent::diagonal() const {
  if ((min.array() > max.array()).any()) return 0.0;
  return (max - min).norm();
}

bool SceneExtent::contains(const Eigen::Vector3d& point) const {
  return (point.array() >= min.array()).all() && (point.array() <= max.array()).all();
}

SceneExtent SceneExtent::scaled(double factor) const {
  SceneExtent s = *this;
  s.min *= factor;
  s.max *= factor;
  return s;
}

SceneExtent sceneExtent(const std::vector<Eigen::Vector3d>& camera_centres,
                        const std::vector<Eigen::Vector3d>& points, const std::string& source,
                        const SanityOptions& options) {
  SceneExtent extent;
  const auto include = [&extent](const Eigen::Vector3d& p) {
    if (!p.allFinite()) return;
    if ((extent.min.array() > extent.max.array()).any()) {
      extent.min = extent.max = p;
      return;
    }
    extent.min = extent.min.cwiseMin(p);
    extent.max = extent.max.cwiseMax(p);
  };
  for (const Eigen::Vector3d& c : camera_centres) include(c);
  std::vector<Eigen::Vector3d> finite;
  for (const Eigen::Vector3d& p : points) {
    if (p.allFinite()) finite.push_back(p);
  }
  extent.source = finite.empty() ? "" : source;
  if (!finite.empty()) {
    const double fraction = options.extent_percentile / 100.0;
    const double last = static_cast<double>(finite.size() - 1);
    Eigen::Vector3d low, high;
    std::vector<double> axis(finite.size());
    for (int a = 0; a < 3; ++a) {
      for (std::size_t i = 0; i < finite.size(); ++i) axis[i] = finite[i][a];
      std::sort(axis.begin(), axis.end());
      low[a] = axis[static_cast<std::size_t>(std::floor(fraction * last))];
      high[a] = axis[static_cast<std::size_t>(std::ceil((1.0 - fraction) * last))];
    }
    include(low);
    include(high);
  }
  const double margin = options.extent_margin * extent.diagonal();
  if (extent.diagonal() > 0.0) {
    extent.min.array() -= margin;
    extent.max.array() += margin;
  }
  return extent;
}

CurveCheck checkCurve(const PolyBezier& curve, const SceneExtent& extent, int samples_per_segment) {
  CurveCheck check;
  const std::vector<Eigen::Vector3d> samples = curve.sample(samples_per_segment);
  bool outside = false;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (i > 0) check.length += (samples[i] - samples[i - 1]).norm();
    outside = outside || !samples[i].allFinite() || !extent.contains(samples[i]);
  }
  if (!extent.valid()) return check;
  if (outside) {
    check.reason = CurveImplausibility::kOutsideExtent;
  } else if (!(check.length <= extent.diagonal())) {
    check.reason = CurveImplausibility::kLongerThanExtent;
  }
  return check;
}

PoseMove largestPoseMove(const std::vector<Pose3>& initial_cam_from_world,
                         const std::vector<Pose3>& refined_cam_from_world) {
  CURVESFM_CHECK(initial_cam_from_world.size() == refined_cam_from_world.size())
      << initial_cam_from_world.size() << " initial poses but " << refined_cam_from_world.size()
      << " refined";
  PoseMove move;
  const int n = static_cast<int>(initial_cam_from_world.size());
  if (n < 3) return move;
  Eigen::Matrix3Xd initial(3, n), refined(3, n);
  for (int j = 0; j < n; ++j) {
    initial.col(j) = initial_cam_from_world[j].inverseTranslation();
    refined.col(j) = refined_cam_from_world[j].inverseTranslation();
  }
  if (!initial.allFinite() || !refined.allFinite()) return move;
  std::vector<double> spacings;
  for (int j = 1; j < n; ++j) spacings.push_back((initial.col(j) - initial.col(j - 1)).norm());
  move.spacing = upperMedian(spacings);
  if (!(move.spacing > 0.0) || !hasSpreadForScale(refined) || !hasSpreadForScale(initial)) {
    move.spacing = 0.0;
    return move;
  }
  const Sim3 initial_from_refined = alignPointSets(refined, initial, AlignmentKind::kSim3);
  for (int j = 0; j < n; ++j) {
    const double d =
        (initial.col(j) - initial_from_refined * Eigen::Vector3d(refined.col(j))).norm();
    if (move.keyframe < 0 || d > move.distance) {
      move.keyframe = j;
      move.distance = d;
    }
  }
  return move;
}

int RunSanity::droppedCurves() const {
  return static_cast<int>(std::count_if(implausible_curves.begin(), implausible_curves.end(),
                                        [](const ImplausibleCurve& c) { return c.dropped; }));
}

std::vector<RunVerdict> judgeRun(int keyframes, int curves, int checked, int implausible,
                                 const PoseMove& move, const SanityOptions& options) {
  std::vector<RunVerdict> verdicts;
  const auto add = [&verdicts](RunVerdictKind kind, const std::ostringstream& message) {
    verdicts.push_back({kind, message.str()});
  };
  if (keyframes < options.min_keyframes) {
    std::ostringstream m;
    m << "only " << keyframes << " keyframes (fewer than " << options.min_keyframes
      << "): the trajectory is barely constrained";
    add(RunVerdictKind::kFewKeyframes, m);
  }
  if (curves < options.min_curves) {
    std::ostringstream m;
    m << "only " << curves << " curves in the final map (fewer than " << options.min_curves
      << "): little was reconstructed";
    add(RunVerdictKind::kFewCurves, m);
  }
  if (checked > 0 && implausible > options.max_implausible_fraction * checked) {
    std::ostringstream m;
    m.precision(3);
    m << implausible << " of " << checked << " curves that reached the global map ("
      << 100.0 * implausible / checked << " %, more than "
      << 100.0 * options.max_implausible_fraction
      << " %) were implausible (outside the scene's extent, longer than it, or not fitting their "
         "views): the map is unreliable";
    add(RunVerdictKind::kMostCurvesImplausible, m);
  }
  if (move.keyframe >= 0 && move.spacings() > options.max_pose_move_spacings) {
    std::ostringstream m;
    m.precision(3);
    m << "keyframe " << move.keyframe << " moved " << move.spacings()
      << " keyframe spacings from its initial pose after Sim(3) alignment (more than "
      << options.max_pose_move_spacings << "): the refined trajectory left the start's uncertainty";
    add(RunVerdictKind::kPosesMovedFar, m);
  }
  return verdicts;
}

}  // namespace curvesfm
