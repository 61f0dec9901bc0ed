#include "core/similarity_alignment.h"

#include <Eigen/SVD>
#include <cmath>

#include "core/check.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

// Relative spread below which points count as one point: far above the rounding of a centroid
// (~1e-16 relative) and far below any real camera motion.
constexpr double kMinRelativeSpread = 1e-9;

}  // namespace

Pose3 Sim3::transformPose(const Pose3& source_from_cam) const {
  return Pose3(Eigen::Matrix3d(rotation * source_from_cam.rotationMatrix()),
               *this * source_from_cam.translation());
}

bool hasSpreadForScale(const Eigen::Matrix3Xd& points) {
  if (points.cols() == 0) return false;
  const Eigen::Vector3d centroid = points.rowwise().mean();
  const double spread =
      std::sqrt((points.colwise() - centroid).squaredNorm() / static_cast<double>(points.cols()));
  return spread > kMinRelativeSpread * (1.0 + centroid.norm());
}

// Umeyama's closed form, written out rather than Eigen::umeyama because that one returns only
// scale * R, which loses R when the target points coincide (scale 0).
Sim3 alignPointSets(const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target,
                    AlignmentKind kind) {
  CURVESFM_CHECK(source.cols() == target.cols())
      << "point sets differ in size: " << source.cols() << " source vs " << target.cols()
      << " target points";
  CURVESFM_CHECK(source.cols() >= 1) << "an alignment needs at least 1 point pair";
  Sim3 target_from_source;
  if (kind == AlignmentKind::kNone) return target_from_source;
  CURVESFM_CHECK(kind != AlignmentKind::kSim3 || hasSpreadForScale(source))
      << "the source points coincide: no scale can be estimated";

  const double count = static_cast<double>(source.cols());
  const Eigen::Vector3d source_mean = source.rowwise().mean();
  const Eigen::Vector3d target_mean = target.rowwise().mean();
  const Eigen::Matrix3Xd source_centred = source.colwise() - source_mean;
  const Eigen::Matrix3Xd target_centred = target.colwise() - target_mean;
  const Eigen::Matrix3d covariance = target_centred * source_centred.transpose() / count;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  // Flipping the weakest axis turns a best reflection into the best rotation (Umeyama eq. 39).
  Eigen::Vector3d signs = Eigen::Vector3d::Ones();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) signs(2) = -1.0;
  target_from_source.rotation = svd.matrixU() * signs.asDiagonal() * svd.matrixV().transpose();
  if (kind == AlignmentKind::kSim3) {
    const double source_variance = source_centred.squaredNorm() / count;
    target_from_source.scale = svd.singularValues().dot(signs) / source_variance;
  }
  target_from_source.translation =
      target_mean - target_from_source.scale * target_from_source.rotation * source_mean;
  return target_from_source;
}

}  // namespace curvesfm
