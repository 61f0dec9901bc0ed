#include "factors/centre_precision.h"

#include <Eigen/Dense>
#include <cmath>
#include <limits>

#include "core/check.h"
#include "core/so3.h"

namespace curvesfm {
namespace {

// An orthonormal basis of the centre moves a similarity makes (translation, rotation and scale
// about the centres' mean), 3 rows per centre: fewer than 7 columns where the centres lie on a
// line (a turn about it moves none of them).
Eigen::MatrixXd similarityDirections(const std::vector<Eigen::Vector3d>& centres) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& c : centres) mean += c / static_cast<double>(centres.size());
  Eigen::MatrixXd moves(3 * centres.size(), 7);
  for (std::size_t i = 0; i < centres.size(); ++i) {
    const Eigen::Vector3d r = centres[i] - mean;
    moves.block<3, 3>(3 * i, 0).setIdentity();
    moves.block<3, 3>(3 * i, 3) = -so3::hat(r);
    moves.block<3, 1>(3 * i, 6) = r;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(moves, Eigen::ComputeThinU);
  const Eigen::VectorXd& singular = svd.singularValues();
  const int rank = static_cast<int>((singular.array() > 1e-9 * singular(0)).count());
  return svd.matrixU().leftCols(rank);
}

}  // namespace

double predictedCentreAteFromInformation(const Eigen::MatrixXd& pose_information,
                                         const std::vector<Pose3>& cam_from_world) {
  const int cameras = static_cast<int>(cam_from_world.size());
  CURVESFM_CHECK(pose_information.rows() == 6 * cameras && pose_information.cols() == 6 * cameras)
      << "pose information of " << pose_information.rows() << " x " << pose_information.cols()
      << " for " << cameras << " poses";
  if (cameras < 3) return 0.0;
  // Rotations and translations in one matrix: its unit-free form (unit diagonal) keeps the
  // eigenvalues comparable in any length unit.
  if ((pose_information.diagonal().array() <= 0.0).any()) {
    return std::numeric_limits<double>::infinity();
  }
  const Eigen::VectorXd scale = pose_information.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd unit_free = scale.asDiagonal() * pose_information * scale.asDiagonal();
  // The seven smallest eigenvalues belong to the similarity (the gauge); any further one near
  // zero leaves a direction that the observations do not fix.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(unit_free);
  const Eigen::VectorXd& values = eigen.eigenvalues();
  if (values(7) <= 1e-9 * values(values.size() - 1)) return std::numeric_limits<double>::infinity();
  const Eigen::MatrixXd vectors =
      scale.asDiagonal() * eigen.eigenvectors().rightCols(values.size() - 7);
  const Eigen::VectorXd inverse = values.tail(values.size() - 7).cwiseInverse();
  // A pose's centre -R^T t moves by -R^T u for a retraction (w, u); w leaves it.
  Eigen::MatrixXd centre_from_pose = Eigen::MatrixXd::Zero(3 * cameras, vectors.cols());
  std::vector<Eigen::Vector3d> centres;
  for (int i = 0; i < cameras; ++i) {
    const Pose3& pose = cam_from_world[i];
    centres.push_back(pose.inverseTranslation());
    centre_from_pose.middleRows<3>(3 * i) =
        -pose.rotationMatrix().transpose() * vectors.middleRows<3>(6 * i + 3);
  }
  const Eigen::MatrixXd basis = similarityDirections(centres);
  // Centre errors with the similarity's moves taken out, per unit of each eigen-direction's
  // standard deviation.
  const Eigen::MatrixXd aligned =
      (centre_from_pose - basis * (basis.transpose() * centre_from_pose)) *
      inverse.cwiseSqrt().asDiagonal();
  return std::sqrt(aligned.squaredNorm() / cameras);
}

}  // namespace curvesfm
