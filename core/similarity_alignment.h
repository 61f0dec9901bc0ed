#pragma once

#include <Eigen/Core>
#include <string>

#include "core/enum_names.h"
#include "core/pose3.h"

namespace curvesfm {

/// A similarity transform x_target = scale * rotation * x_source + translation, e.g. the
/// alignment truth_from_estimated of an estimated (gauge-free up to Sim(3)) reconstruction.
struct Sim3 {
  double scale = 1.0;  ///< Unitless, > 0 (0 only from aligning onto coinciding points).
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  ///< A rotation matrix.
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();   ///< In the target frame's unit.

  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return scale * (rotation * point) + translation;
  }

  /// Carries a camera pose source_from_cam into the target frame: target_from_cam, with the
  /// camera centre mapped by this transform and the camera axes rotated by `rotation`. The
  /// camera's own frame is not scaled (a Pose3 is rigid), so relative motions between two
  /// carried poses have their translations multiplied by `scale`.
  Pose3 transformPose(const Pose3& source_from_cam) const;
};

/// Which transform a point-set or trajectory alignment estimates.
enum class AlignmentKind {
  kSim3,  ///< Rotation, translation and scale (7 DoF): monocular estimates.
  kSe3,   ///< Rotation and translation, scale fixed to 1 (6 DoF): metric estimates.
  kNone,  ///< The identity: compare the estimate in its own frame.
};

template <>
struct EnumNames<AlignmentKind> {
  static constexpr std::array<std::pair<AlignmentKind, const char*>, 3> kNames = {{
      {AlignmentKind::kSim3, "sim3"},
      {AlignmentKind::kSe3, "se3"},
      {AlignmentKind::kNone, "none"},
  }};
};

/// The least-squares alignment target_from_source of two corresponding point sets (Umeyama 1991,
/// "Least-squares estimation of transformation parameters between two point patterns"): the
/// transform T of the given kind minimising sum_k |target_k - T * source_k|^2. Columns are
/// corresponding points; both sets need the same number >= 1 (CheckError otherwise).
/// Degenerate sets: with fewer than 3 non-collinear points the rotation about their line is not
/// determined and one minimiser is returned (the residual is the same for all); target points
/// that all coincide give scale 0 under kSim3. kSim3 needs hasSpreadForScale(source) (CheckError
/// otherwise): callers that take points from files test it first and report a user error.
Sim3 alignPointSets(const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target,
                    AlignmentKind kind);

/// False when the points (columns) nearly coincide, so that no scale can be estimated from them:
/// their RMS distance from their centroid is below 1e-9 times (1 + the centroid's norm).
bool hasSpreadForScale(const Eigen::Matrix3Xd& points);

}  // namespace curvesfm
