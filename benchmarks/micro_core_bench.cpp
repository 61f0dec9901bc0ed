// micro_core_bench: Google Benchmark timings of the core geometry in bundle adjustment's inner
// loop: Camera::project (with and without its 2x3 Jacobian, with distortion) and
// Pose3::transformPoint (with and without its 3x6 / 3x3 Jacobians).
#include <benchmark/benchmark.h>

#include <Eigen/Core>
#include <random>
#include <vector>

#include "core/camera.h"
#include "core/eigen_types.h"
#include "core/pose3.h"

namespace curvesfm {
namespace {

// Enough distinct inputs that results cannot be constant-folded, few enough to stay in L1.
constexpr int kNumInputs = 256;

// Points in front of the camera, inside the image for the default intrinsics.
std::vector<Eigen::Vector3d> pointsInCamera() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> lateral(-1.0, 1.0);
  std::uniform_real_distribution<double> depth(2.0, 6.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < kNumInputs; ++i) {
    const double z = depth(rng);
    points.emplace_back(0.5 * z * lateral(rng), 0.4 * z * lateral(rng), z);
  }
  return points;
}

// Mild barrel distortion as in sim/point_scene.h, so the full model is timed.
Camera distortedCamera() {
  return Camera(
      CameraIntrinsics{500.0, 500.0, 319.5, 239.5, -0.05, 0.01, 0.001, -0.001, 0.0, 640, 480});
}

void BM_CameraProject(benchmark::State& state) {
  const Camera camera = distortedCamera();
  const std::vector<Eigen::Vector3d> points = pointsInCamera();
  Eigen::Vector2d pixel;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(camera.project(points[i], &pixel));
    benchmark::DoNotOptimize(pixel);
    i = (i + 1) % points.size();
  }
}
BENCHMARK(BM_CameraProject);

void BM_CameraProjectWithJacobian(benchmark::State& state) {
  const Camera camera = distortedCamera();
  const std::vector<Eigen::Vector3d> points = pointsInCamera();
  Eigen::Vector2d pixel;
  Matrix23d H_point;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(camera.project(points[i], &pixel, &H_point));
    benchmark::DoNotOptimize(pixel);
    benchmark::DoNotOptimize(H_point);
    i = (i + 1) % points.size();
  }
}
BENCHMARK(BM_CameraProjectWithJacobian);

void BM_Pose3TransformPoint(benchmark::State& state) {
  const Pose3 cam_from_world(Eigen::Quaterniond(0.9, 0.1, -0.3, 0.2), Eigen::Vector3d(1, -2, 3));
  const std::vector<Eigen::Vector3d> points = pointsInCamera();
  std::size_t i = 0;
  for (auto _ : state) {
    Eigen::Vector3d point_in_cam = cam_from_world.transformPoint(points[i]);
    benchmark::DoNotOptimize(point_in_cam);
    i = (i + 1) % points.size();
  }
}
BENCHMARK(BM_Pose3TransformPoint);

void BM_Pose3TransformPointWithJacobians(benchmark::State& state) {
  const Pose3 cam_from_world(Eigen::Quaterniond(0.9, 0.1, -0.3, 0.2), Eigen::Vector3d(1, -2, 3));
  const std::vector<Eigen::Vector3d> points = pointsInCamera();
  Matrix36d H_pose;
  Eigen::Matrix3d H_point;
  std::size_t i = 0;
  for (auto _ : state) {
    Eigen::Vector3d point_in_cam = cam_from_world.transformPoint(points[i], &H_pose, &H_point);
    benchmark::DoNotOptimize(point_in_cam);
    benchmark::DoNotOptimize(H_pose);
    benchmark::DoNotOptimize(H_point);
    i = (i + 1) % points.size();
  }
}
BENCHMARK(BM_Pose3TransformPointWithJacobians);

}  // namespace
}  // namespace curvesfm

BENCHMARK_MAIN();
