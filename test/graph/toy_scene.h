#pragma once

// A small problem over every variable type for the graph layer's solver tests.

#include <random>

#include "core/so3.h"
#include "graph/factor_graph.h"
#include "graph/values.h"
#include "test/graph/test_factors.h"

namespace curvesfm::testing {

struct ToyScene {
  FactorGraph graph;
  Values start;
};

/// `groups` structures (a point, a direction and a scale each) seen through `poses` poses, with
/// targets perturbed by noise of 0.05 (`seed`) so that the optimum keeps a cost, a Huber prior on
/// every point so that the kernel's weights matter, and every structure started off its truth.
/// Poses 1.. are moved by a fixed tangent step times `pose_offset` (0: at the truth).
inline ToyScene makeToyScene(int groups, int poses, unsigned seed, double pose_offset) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.05);
  ToyScene scene;
  for (int i = 0; i < poses; ++i) {
    scene.start.insert(poseKey(i), Pose3(so3::exp(Eigen::Vector3d(0.2 * i, -0.1, 0.3)),
                                         Eigen::Vector3d(i, 0.5 * i, 1.0)));
  }
  const NoiseModel huber{0.1, RobustKernel(RobustKernelType::kHuber, 1.0)};
  for (int g = 0; g < groups; ++g) {
    const Eigen::Vector3d point(g, 1.0 - g, 2.0);
    const Direction direction(Eigen::Vector3d(1.0, 0.2 * g, 0.5).normalized());
    const double scale = 1.0 + 0.1 * g;
    for (int i = 0; i < poses; ++i) {
      const Pose3& pose = scene.start.at<Pose3>(poseKey(i));
      const Eigen::Vector3d target = pose * (point + scale * direction.vector()) +
                                     Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
      scene.graph.emplace<AllTypesFactor>(poseKey(i), pointKey(g), directionKey(g, 0),
                                          startLengthKey(g, 0), target);
    }
    scene.graph.emplace<PointPriorFactor>(pointKey(g), point + Eigen::Vector3d(0.3, 0.0, 0.0),
                                          huber);
    scene.start.insert(pointKey(g), Eigen::Vector3d(point + Eigen::Vector3d(0.2, -0.1, 0.1)));
    scene.start.insert(directionKey(g, 0), direction.retract(Eigen::Vector2d(0.2, -0.1)));
    scene.start.insert(startLengthKey(g, 0), scale * 1.2);
  }
  Vector6d offset;
  offset << 0.02, -0.01, 0.03, 0.05, -0.04, 0.02;
  for (int i = 1; i < poses; ++i) {
    scene.start.update(poseKey(i), scene.start.at<Pose3>(poseKey(i)).retract(pose_offset * offset));
  }
  return scene;
}

}  // namespace curvesfm::testing
