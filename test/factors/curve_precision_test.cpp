#include "factors/curve_precision.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <map>

#include "factors/centre_precision.h"
#include "factors/curve_reprojection_factor.h"
#include "sim/curve_scene.h"
#include "sim/curve_scene_input.h"

namespace curvesfm {
namespace {

CurveBundleAdjustmentInput sceneInput(int keyframes) {
  CurveSceneOptions options;
  options.num_keyframes = keyframes;
  return makeCurveBundleAdjustmentInput(makeCurveScene(options), SceneStart::kTruth);
}

// Segment lengths relative to their own size, so that the objective does not change with the
// scene's unit.
CurveBundleAdjustmentOptions unitFreeOptions() {
  CurveBundleAdjustmentOptions options;
  options.length_sigma_rel = 0.1;
  return options;
}

bool isPose(Key key) { return categoryOf(key) == VariableCategory::kPose; }

// The same information by brute force: every variable in one dense system, each edge
// observation's samples weighed by the inverse of their AR(1) covariance rho^|i - j| (every
// sample live), the structure eliminated by one pseudo-inverse.
Eigen::MatrixXd denseInformation(const CurveBundleAdjustmentProblem& problem, int keyframes,
                                 double correlation = 0.0) {
  std::map<Key, int> offset;
  int dimension = 6 * keyframes;
  for (int j = 0; j < keyframes; ++j) offset[poseKey(j)] = 6 * j;
  std::vector<const Factor*> counted;
  for (const auto& factor : problem.graph) {
    const bool edge = dynamic_cast<const CurveReprojectionFactor*>(factor.get()) != nullptr;
    bool touches_pose = false;
    for (Key key : factor->keys()) touches_pose |= isPose(key);
    if (!edge && touches_pose) continue;  // the gauge
    counted.push_back(factor.get());
    for (Key key : factor->keys()) {
      if (offset.count(key) == 0) {
        offset[key] = dimension;
        dimension += tangentDim(problem.values.type(key));
      }
    }
  }
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(dimension, dimension);
  for (const Factor* factor : counted) {
    const Linearization lin = factor->linearize(problem.values);
    Eigen::MatrixXd rows = Eigen::MatrixXd::Zero(lin.error.size(), dimension);
    for (std::size_t i = 0; i < factor->keys().size(); ++i) {
      rows.middleCols(offset.at(factor->keys()[i]), lin.jacobians[i].cols()) = lin.jacobians[i];
    }
    const double sigma = factor->noiseModel().sigma;
    const int n = static_cast<int>(lin.error.size());
    Eigen::MatrixXd covariance = Eigen::MatrixXd::Identity(n, n);
    if (dynamic_cast<const CurveReprojectionFactor*>(factor) != nullptr) {
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) covariance(i, j) = std::pow(correlation, std::abs(i - j));
      }
    }
    h += rows.transpose() * covariance.inverse() * rows / (sigma * sigma);
  }
  const int poses = 6 * keyframes;
  const int structure = dimension - poses;
  const Eigen::MatrixXd hss = h.bottomRightCorner(structure, structure);
  const Eigen::MatrixXd hps = h.topRightCorner(poses, structure);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(hss);
  const double floor = 1e-10 * eigen.eigenvalues().maxCoeff();
  const Eigen::VectorXd inverse =
      eigen.eigenvalues().unaryExpr([floor](double l) { return l > floor ? 1.0 / l : 0.0; });
  const Eigen::MatrixXd pseudo =
      eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose();
  return h.topLeftCorner(poses, poses) - hps * pseudo * hps.transpose();
}

TEST(CurvePrecision, EliminatesEachCurveAsTheDenseSystemDoes) {
  const CurveBundleAdjustmentInput input = sceneInput(4);
  // Without a kernel and at the truth, where no sample of this scene is capped, every row
  // counts at its plain weight: the dense sum of every factor is the reference.
  CurveBundleAdjustmentOptions options = unitFreeOptions();
  options.kernel = RobustKernelType::kNone;
  const CurveBundleAdjustmentProblem problem = buildCurveBundleAdjustment(input, options);
  const CurveSampleCounts samples = countCurveSamples(problem.graph, problem.values);
  ASSERT_EQ(samples.capped(), 0);
  for (const double correlation : {0.0, 0.6}) {
    const Eigen::MatrixXd ours = curvePoseInformation(problem, 4, 1.0, correlation);
    const Eigen::MatrixXd dense = denseInformation(problem, 4, correlation);
    EXPECT_LT((ours - dense).norm(), 1e-6 * dense.norm()) << "correlation " << correlation;
  }
}

TEST(CurvePrecision, FollowsTheSceneUnitAndTheNoise) {
  const CurveBundleAdjustmentInput input = sceneInput(6);
  const CurveBundleAdjustmentProblem problem = buildCurveBundleAdjustment(input, unitFreeOptions());
  const double base = predictedCentreAteFromInformation(curvePoseInformation(problem, 6, 0.5, 0.0),
                                                        input.cam_from_world);
  ASSERT_TRUE(std::isfinite(base));
  ASSERT_GT(base, 0.0);
  EXPECT_NEAR(predictedCentreAteFromInformation(curvePoseInformation(problem, 6, 1.0, 0.0),
                                                input.cam_from_world),
              2.0 * base, 1e-9 * base);

  // The same scene in millimetres: the same pixels, a thousand times the centres' error.
  const double s = 1000.0;
  CurveBundleAdjustmentInput scaled = input;
  for (Pose3& pose : scaled.cam_from_world) pose = Pose3(pose.rotation(), s * pose.translation());
  for (PolyBezier& curve : scaled.curves) {
    std::vector<Eigen::Vector3d> points = curve.points();
    std::vector<SegmentLengths> lengths = curve.lengths();
    for (Eigen::Vector3d& p : points) p *= s;
    for (SegmentLengths& d : lengths) d = {s * d.d1, s * d.d2};
    curve = PolyBezier(points, curve.directions(), lengths);
  }
  for (auto& chords : scaled.segment_reference_lengths) {
    for (double& chord : chords) chord *= s;
  }
  scaled.scale_distance *= s;
  const CurveBundleAdjustmentProblem scaled_problem =
      buildCurveBundleAdjustment(scaled, unitFreeOptions());
  EXPECT_NEAR(predictedCentreAteFromInformation(curvePoseInformation(scaled_problem, 6, 0.5, 0.0),
                                                scaled.cam_from_world),
              s * base, 1e-4 * s * base);
}

TEST(CurvePrecision, CorrelatedSamplesCarryLess) {
  const CurveBundleAdjustmentInput input = sceneInput(6);
  const CurveBundleAdjustmentProblem problem = buildCurveBundleAdjustment(input, unitFreeOptions());
  const auto ate = [&](double correlation) {
    return predictedCentreAteFromInformation(curvePoseInformation(problem, 6, 1.0, correlation),
                                             input.cam_from_world);
  };
  EXPECT_LT(ate(0.0), ate(0.5));
  EXPECT_LT(ate(0.5), ate(0.9));
}

TEST(CurvePrecision, AKeyframeNoCurveSeesLeavesTheCentresFree) {
  CurveBundleAdjustmentInput input = sceneInput(6);
  std::vector<SegmentObservation> kept;
  for (const SegmentObservation& o : input.observations) {
    if (o.keyframe != 3) kept.push_back(o);
  }
  input.observations = kept;
  const CurveBundleAdjustmentProblem problem = buildCurveBundleAdjustment(input, unitFreeOptions());
  const CurveCentrePrecision precision = curveCentrePrecision(problem, 6);
  EXPECT_TRUE(std::isinf(precision.predicted_centre_ate));
  EXPECT_TRUE(std::isinf(precision.predicted_centre_ate_correlated));
}

TEST(CurvePrecision, ReadsTheNoiseFromTheResiduals) {
  CurveBundleAdjustmentInput input = sceneInput(6);
  const CurveBundleAdjustmentProblem truth = buildCurveBundleAdjustment(input, unitFreeOptions());
  const CurveCentrePrecision at_truth = curveCentrePrecision(truth, 6);
  EXPECT_GT(at_truth.observations, 0);
  EXPECT_GT(at_truth.samples, at_truth.observations);
  EXPECT_LT(at_truth.pixel_sigma, 0.5);  // rendered edges: sub-pixel at the truth
  // Every keyframe but the first a few pixels off: the residuals, and the figure, say so.
  for (std::size_t j = 1; j < input.cam_from_world.size(); ++j) {
    const Pose3& pose = input.cam_from_world[j];
    input.cam_from_world[j] =
        Pose3(pose.rotation(), pose.translation() + Eigen::Vector3d(0.004, -0.003, 0.0));
  }
  const CurveCentrePrecision off =
      curveCentrePrecision(buildCurveBundleAdjustment(input, unitFreeOptions()), 6);
  EXPECT_GT(off.pixel_sigma, 2.0 * at_truth.pixel_sigma);
  EXPECT_GT(off.predicted_centre_ate, at_truth.predicted_centre_ate);
}

}  // namespace
}  // namespace curvesfm
