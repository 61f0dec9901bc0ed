#pragma once

// A factor over every variable type, so the graph layer is tested without concrete factors:
//   e = pose * (point + scale * direction) - target      (3 rows)

#include "core/so3.h"
#include "graph/factor.h"

namespace curvesfm::testing {

class AllTypesFactor : public NoiseModelFactorN<3, Pose3, Eigen::Vector3d, Direction, double> {
  using Base = NoiseModelFactorN<3, Pose3, Eigen::Vector3d, Direction, double>;

 public:
  AllTypesFactor(Key pose, Key point, Key direction, Key scale, const Eigen::Vector3d& target,
                 NoiseModel noise = {})
      : Base({pose, point, direction, scale}, noise), target_(target) {}

  Error evaluateError(const Pose3& pose, const Eigen::Vector3d& point, const Direction& direction,
                      const double& scale, Jacobian<Pose3>* H_pose,
                      Jacobian<Eigen::Vector3d>* H_point, Jacobian<Direction>* H_direction,
                      Jacobian<double>* H_scale) const override {
    const Eigen::Matrix3d R = pose.rotationMatrix();
    const Eigen::Vector3d local = point + scale * direction.vector();
    if (H_pose) {
      H_pose->leftCols<3>() = -so3::hat(R * local + pose.translation());
      H_pose->rightCols<3>().setIdentity();
    }
    if (H_point) *H_point = R;
    if (H_direction) *H_direction = scale * R * direction.basis();
    if (H_scale) *H_scale = R * direction.vector();
    return R * local + pose.translation() - target_;
  }
  const char* typeName() const override { return "all_types"; }
  const Eigen::Vector3d& target() const { return target_; }

 private:
  Eigen::Vector3d target_;
};

/// e = point - target (3 rows): a prior that pins a point.
class PointPriorFactor : public NoiseModelFactorN<3, Eigen::Vector3d> {
  using Base = NoiseModelFactorN<3, Eigen::Vector3d>;

 public:
  PointPriorFactor(Key point, const Eigen::Vector3d& target, NoiseModel noise = {})
      : Base({point}, noise), target_(target) {}
  Error evaluateError(const Eigen::Vector3d& point, Jacobian<Eigen::Vector3d>* H) const override {
    if (H) H->setIdentity();
    return point - target_;
  }
  const char* typeName() const override { return "point_prior"; }

 private:
  Eigen::Vector3d target_;
};

/// e = t_a - t_b - target (3 rows): a factor over two poses only (their translations).
class TranslationDifferenceFactor : public NoiseModelFactorN<3, Pose3, Pose3> {
  using Base = NoiseModelFactorN<3, Pose3, Pose3>;

 public:
  TranslationDifferenceFactor(Key a, Key b, const Eigen::Vector3d& target, NoiseModel noise = {})
      : Base({a, b}, noise), target_(target) {}
  Error evaluateError(const Pose3& a, const Pose3& b, Jacobian<Pose3>* H_a,
                      Jacobian<Pose3>* H_b) const override {
    // Pose3's chart moves the translation to exp(w) t + u.
    if (H_a) *H_a << -so3::hat(a.translation()), Eigen::Matrix3d::Identity();
    if (H_b) *H_b << so3::hat(b.translation()), -Eigen::Matrix3d::Identity();
    return a.translation() - b.translation() - target_;
  }
  const char* typeName() const override { return "translation_difference"; }

 private:
  Eigen::Vector3d target_;
};

}  // namespace curvesfm::testing
