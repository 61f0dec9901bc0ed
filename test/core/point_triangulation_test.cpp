#include "core/point_triangulation.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/so3.h"

namespace curvesfm {
namespace {

Pose3 cameraAt(const Eigen::Vector3d& centre, const Eigen::Vector3d& turn) {
  const Eigen::Matrix3d R = so3::exp(turn).toRotationMatrix();
  return Pose3(R, -R * centre);
}

Eigen::Vector2d normalizedOf(const Pose3& cam_from_world, const Eigen::Vector3d& point) {
  return (cam_from_world * point).hnormalized();
}

TEST(TriangulateDlt, RecoversAPointSeenByThreeCameras) {
  const Eigen::Vector3d point(0.3, -0.2, 4.0);
  const std::vector<Pose3> cameras = {cameraAt({0, 0, 0}, {0, 0, 0}),
                                      cameraAt({1, 0, 0}, {0, -0.1, 0}),
                                      cameraAt({0, 0.5, 0.2}, {0.05, 0, 0.02})};
  std::vector<Eigen::Vector2d> normalized;
  for (const Pose3& c : cameras) normalized.push_back(normalizedOf(c, point));
  Eigen::Vector3d estimate;
  ASSERT_TRUE(triangulateDlt(cameras, normalized, &estimate));
  EXPECT_LT((estimate - point).norm(), 1e-9);
}

TEST(TriangulateDlt, RefusesOneViewAndParallelRays) {
  const Pose3 a = cameraAt({0, 0, 0}, {0, 0, 0});
  const Pose3 b = cameraAt({1, 0, 0}, {0, 0, 0});
  Eigen::Vector3d estimate(7, 7, 7);
  EXPECT_FALSE(triangulateDlt({a}, {Eigen::Vector2d(0, 0)}, &estimate));
  // The same normalized coordinates from two parallel cameras: the rays meet at infinity.
  EXPECT_FALSE(
      triangulateDlt({a, b}, {Eigen::Vector2d(0.1, 0), Eigen::Vector2d(0.1, 0)}, &estimate));
  EXPECT_EQ(estimate, Eigen::Vector3d(7, 7, 7));
}

double squaredReprojection(const std::vector<Pose3>& cameras,
                           const std::vector<Eigen::Vector2d>& normalized,
                           const Eigen::Vector3d& point) {
  double sum = 0.0;
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    sum += (normalizedOf(cameras[i], point) - normalized[i]).squaredNorm();
  }
  return sum;
}

std::vector<Pose3> fourCameras() {
  return {cameraAt({0, 0, 0}, {0, 0, 0}), cameraAt({1, 0, 0}, {0, -0.1, 0}),
          cameraAt({0, 0.5, 0.2}, {0.05, 0, 0.02}), cameraAt({-0.8, 0.2, 0.1}, {0, 0.08, 0})};
}

TEST(RefinePointAtPoses, RecoversAPointFromAStartOffItsRays) {
  const Eigen::Vector3d point(0.3, -0.2, 4.0);
  const std::vector<Pose3> cameras = fourCameras();
  std::vector<Eigen::Vector2d> normalized;
  for (const Pose3& c : cameras) normalized.push_back(normalizedOf(c, point));
  Eigen::Vector3d estimate = point + Eigen::Vector3d(0.05, -0.03, 0.4);
  ASSERT_TRUE(refinePointAtPoses(cameras, normalized, &estimate));
  EXPECT_LT((estimate - point).norm(), 1e-9);
}

TEST(RefinePointAtPoses, ReachesTheLeastSquaresPointOfNoisyViewsWhereTheDltDoesNot) {
  const Eigen::Vector3d point(0.3, -0.2, 4.0);
  const std::vector<Pose3> cameras = fourCameras();
  const std::vector<Eigen::Vector2d> noise = {
      {2e-3, -1e-3}, {-1.5e-3, 0.5e-3}, {1e-3, 2e-3}, {-0.5e-3, -2e-3}};
  std::vector<Eigen::Vector2d> normalized;
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    normalized.push_back(normalizedOf(cameras[i], point) + noise[i]);
  }
  Eigen::Vector3d dlt;
  ASSERT_TRUE(triangulateDlt(cameras, normalized, &dlt));
  Eigen::Vector3d refined = dlt;
  ASSERT_TRUE(refinePointAtPoses(cameras, normalized, &refined));
  const double cost = squaredReprojection(cameras, normalized, refined);
  EXPECT_LT(cost, squaredReprojection(cameras, normalized, dlt) * (1.0 - 1e-6));
  // A minimum: no small move along any axis lowers the cost.
  for (int axis = 0; axis < 3; ++axis) {
    for (double sign : {-1.0, 1.0}) {
      const Eigen::Vector3d moved = refined + sign * 1e-4 * Eigen::Vector3d::Unit(axis);
      EXPECT_GT(squaredReprojection(cameras, normalized, moved), cost);
    }
  }
}

TEST(RefinePointAtPoses, RefusesOneViewAndAPointBehindACamera) {
  const std::vector<Pose3> cameras = fourCameras();
  Eigen::Vector3d estimate(0.3, -0.2, 4.0);
  EXPECT_FALSE(refinePointAtPoses({cameras[0]}, {Eigen::Vector2d(0, 0)}, &estimate));
  estimate = Eigen::Vector3d(0.3, -0.2, -4.0);
  std::vector<Eigen::Vector2d> normalized(cameras.size(), Eigen::Vector2d::Zero());
  EXPECT_FALSE(refinePointAtPoses(cameras, normalized, &estimate));
  EXPECT_EQ(estimate, Eigen::Vector3d(0.3, -0.2, -4.0));
}

TEST(TriangulationAngle, IsTheAngleBetweenTheRays) {
  const Eigen::Vector3d point(0, 0, 1);
  EXPECT_NEAR(triangulationAngleDeg({-1, 0, 0}, {1, 0, 0}, point), 90.0, 1e-12);
  EXPECT_NEAR(maxTriangulationAngleDeg({{0, 0, 0}, {-1, 0, 0}, {1, 0, 0}}, point), 90.0, 1e-12);
  EXPECT_EQ(maxTriangulationAngleDeg({{0, 0, 0}}, point), 0.0);
}

}  // namespace
}  // namespace curvesfm
