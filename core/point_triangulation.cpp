#include "core/point_triangulation.h"

#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "core/angles.h"

namespace curvesfm {

bool triangulateDlt(const std::vector<Pose3>& cam_from_world,
                    const std::vector<Eigen::Vector2d>& normalized, Eigen::Vector3d* point) {
  const std::size_t n = cam_from_world.size();
  if (n < 2 || normalized.size() != n) return false;
  Eigen::MatrixXd A(2 * n, 4);
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Matrix<double, 3, 4> P;
    P.leftCols<3>() = cam_from_world[i].rotationMatrix();
    P.col(3) = cam_from_world[i].translation();
    A.row(2 * i) = normalized[i].x() * P.row(2) - P.row(0);
    A.row(2 * i + 1) = normalized[i].y() * P.row(2) - P.row(1);
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d X = svd.matrixV().col(3);
  // The system is homogeneous and |X| = 1, so a tiny w means a point at infinity.
  if (std::abs(X(3)) < 1e-12) return false;
  const Eigen::Vector3d result = X.head<3>() / X(3);
  if (!result.allFinite()) return false;
  *point = result;
  return true;
}

bool refinePointAtPoses(const std::vector<Pose3>& cam_from_world,
                        const std::vector<Eigen::Vector2d>& normalized, Eigen::Vector3d* point) {
  const std::size_t n = cam_from_world.size();
  if (n < 2 || normalized.size() != n) return false;
  // From a DLT point Gauss-Newton converges in a few steps (the residuals are small against the
  // depth); the bound only stops a point that runs off along a nearly degenerate ray.
  constexpr int kMaxIterations = 10;
  constexpr double kRelativeStep = 1e-10;
  Eigen::Vector3d x = *point;
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Matrix3d R = cam_from_world[i].rotationMatrix();
      const Eigen::Vector3d c = R * x + cam_from_world[i].translation();
      if (!(c.z() > 0.0)) return false;
      const double inv_z = 1.0 / c.z();
      const Eigen::Vector2d residual(c.x() * inv_z - normalized[i].x(),
                                     c.y() * inv_z - normalized[i].y());
      Eigen::Matrix<double, 2, 3> d_projection;
      d_projection << inv_z, 0.0, -c.x() * inv_z * inv_z, 0.0, inv_z, -c.y() * inv_z * inv_z;
      const Eigen::Matrix<double, 2, 3> J = d_projection * R;
      normal += J.transpose() * J;
      gradient += J.transpose() * residual;
    }
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(normal);
    if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > 1e-14)) return false;
    const Eigen::Vector3d step = -ldlt.solve(gradient);
    if (!step.allFinite()) return false;
    x += step;
    if (step.norm() <= kRelativeStep * x.norm()) break;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!((cam_from_world[i] * x).z() > 0.0)) return false;
  }
  *point = x;
  return true;
}

double triangulationAngleDeg(const Eigen::Vector3d& centre_a, const Eigen::Vector3d& centre_b,
                             const Eigen::Vector3d& point) {
  const Eigen::Vector3d ray_a = centre_a - point;
  const Eigen::Vector3d ray_b = centre_b - point;
  // atan2 of |cross| and dot is accurate also for the small angles the gates compare.
  return kRadToDeg * std::atan2(ray_a.cross(ray_b).norm(), ray_a.dot(ray_b));
}

double maxTriangulationAngleDeg(const std::vector<Eigen::Vector3d>& centres,
                                const Eigen::Vector3d& point) {
  double best = 0.0;
  for (std::size_t i = 0; i < centres.size(); ++i) {
    for (std::size_t j = i + 1; j < centres.size(); ++j) {
      best = std::max(best, triangulationAngleDeg(centres[i], centres[j], point));
    }
  }
  return best;
}

}  // namespace curvesfm
