#include "core/curve_map_evaluation.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"

namespace curvesfm {
namespace {

using ::testing::HasSubstr;

// Two curves in the plane z = 0, far apart: a circle of radius 1 as a 200-point polyline and a
// straight line of the same length 2 pi as 7 points.
Polylines3 groundTruth() {
  Polylines3 curves(2);
  for (int k = 0; k <= 200; ++k) {
    const double a = 2.0 * M_PI * k / 200;
    curves[0].emplace_back(std::cos(a), std::sin(a), 0.0);
  }
  for (int k = 0; k <= 6; ++k) curves[1].emplace_back(5.0 + 2.0 * M_PI * k / 6, 0.0, 0.0);
  return curves;
}

Polylines3 shifted(Polylines3 curves, const Eigen::Vector3d& offset) {
  for (auto& curve : curves) {
    for (Eigen::Vector3d& p : curve) p += offset;
  }
  return curves;
}

TEST(CurveMapEvaluation, GroundTruthAsEstimateScoresOne) {
  const CurveMapEvaluation e = evaluateCurveMap(groundTruth(), groundTruth(), {});
  ASSERT_EQ(e.scores.size(), 3u);
  for (const CurveMapScore& s : e.scores) {
    EXPECT_DOUBLE_EQ(s.precision, 1.0) << s.tau;
    EXPECT_DOUBLE_EQ(s.recall, 1.0) << s.tau;
    EXPECT_DOUBLE_EQ(s.f_score, 1.0) << s.tau;
    EXPECT_EQ(s.estimate_samples_within, e.estimate_samples);
    EXPECT_EQ(s.ground_truth_samples_within, e.ground_truth_samples);
  }
  EXPECT_DOUBLE_EQ(e.sample_spacing, 0.001);  // A tenth of the smallest default tau.
  // Each curve is a little shorter than 2 pi (the circle's chords) and sampled every <= 1 mm.
  EXPECT_NEAR(e.ground_truth_length, 4.0 * M_PI, 1e-3);
  EXPECT_GE(e.ground_truth_samples, static_cast<int>(e.ground_truth_length / 0.001));
  EXPECT_EQ(e.estimate_samples_inside, e.estimate_samples);
}

TEST(CurveMapEvaluation, ShiftedEstimateIsWithinOnlyTheThresholdsAboveTheShift) {
  // Every point of the plane curves moved 3 cm off their plane is exactly 3 cm from them.
  const CurveMapEvaluation e =
      evaluateCurveMap(shifted(groundTruth(), {0.0, 0.0, 0.03}), groundTruth(), {});
  const double expected[] = {0.0, 0.0, 1.0};  // tau 1, 2 and 5 cm.
  for (int i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(e.scores[i].precision, expected[i]) << e.scores[i].tau;
    EXPECT_DOUBLE_EQ(e.scores[i].recall, expected[i]) << e.scores[i].tau;
    EXPECT_DOUBLE_EQ(e.scores[i].f_score, expected[i]) << e.scores[i].tau;
  }
}

TEST(CurveMapEvaluation, HalfTheGroundTruthMissingHalvesRecallOnly) {
  const Polylines3 gt = groundTruth();
  const CurveMapEvaluation e = evaluateCurveMap({gt[1]}, gt, {});
  for (const CurveMapScore& s : e.scores) {
    EXPECT_DOUBLE_EQ(s.precision, 1.0);
    // The line is 2 pi long, the circle's polyline a little shorter.
    EXPECT_NEAR(s.recall, 0.5, 1e-3);
    EXPECT_NEAR(s.f_score, 2.0 / 3.0, 1e-3);
  }
}

TEST(CurveMapEvaluation, CropDropsEstimatedSamplesOutsideTheGroundTruthBox) {
  const Polylines3 gt = groundTruth();
  Polylines3 estimate = gt;
  // A curve as long as the line, 1 m above the ground truth's plane: outside the box + 5 cm.
  estimate.push_back(shifted({gt[1]}, {0.0, 0.0, 1.0})[0]);
  const CurveMapEvaluation cropped = evaluateCurveMap(estimate, gt, {});
  EXPECT_DOUBLE_EQ(cropped.scores[0].precision, 1.0);
  EXPECT_DOUBLE_EQ(cropped.scores[0].recall, 1.0);
  EXPECT_LT(cropped.estimate_samples_inside, cropped.estimate_samples);
  EXPECT_EQ(cropped.estimate_samples_inside, cropped.ground_truth_samples);
  EXPECT_NEAR(cropped.crop_min.z(), -0.05, 1e-12);
  EXPECT_NEAR(cropped.crop_max.z(), 0.05, 1e-12);

  CurveMapEvaluationOptions all;
  all.crop = false;
  const CurveMapEvaluation uncropped = evaluateCurveMap(estimate, gt, all);
  EXPECT_EQ(uncropped.estimate_samples_inside, uncropped.estimate_samples);
  EXPECT_NEAR(uncropped.scores[0].precision, 2.0 / 3.0, 1e-3);
  EXPECT_DOUBLE_EQ(uncropped.scores[0].recall, 1.0);
}

TEST(CurveMapEvaluation, FractionsAreOfLengthWhateverTheSegmentLengths) {
  // Ground truth: 1 m as one segment and 1 m as 10000 segments of 0.1 mm; the estimate covers
  // only the long segment, which is half the length although it is few samples.
  Polylines3 gt(2);
  gt[0] = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0)};
  for (int k = 0; k <= 10000; ++k) gt[1].emplace_back(0.0, 1.0, 1e-4 * k);
  const CurveMapEvaluation e = evaluateCurveMap({gt[0]}, gt, {});
  EXPECT_NEAR(e.scores[0].recall, 0.5, 1e-9);
  EXPECT_GT(e.ground_truth_samples, 10000);
}

TEST(CurveMapEvaluation, DistancesToLongSegmentsAreExact) {
  // A 40 m segment spans 800 grid cells of 5 cm; a short estimate 1.5 cm beside its middle.
  const Polylines3 gt = {{Eigen::Vector3d(-20, 0, 0), Eigen::Vector3d(20, 0, 0)}};
  const Polylines3 estimate = {{Eigen::Vector3d(0.3, 0.015, 0), Eigen::Vector3d(0.4, 0.015, 0)}};
  const CurveMapEvaluation e = evaluateCurveMap(estimate, gt, {});
  EXPECT_DOUBLE_EQ(e.scores[0].precision, 0.0);
  EXPECT_DOUBLE_EQ(e.scores[1].precision, 1.0);
  EXPECT_DOUBLE_EQ(e.scores[2].precision, 1.0);
  // The ground truth within 2 cm of the estimate reaches sqrt(2^2 - 1.5^2) cm past its ends.
  EXPECT_NEAR(e.scores[1].recall, (0.1 + 2.0 * std::sqrt(0.02 * 0.02 - 0.015 * 0.015)) / 40.0,
              1e-4);
}

TEST(CurveMapEvaluation, EmptyEstimateScoresZero) {
  const CurveMapEvaluation e = evaluateCurveMap({}, groundTruth(), {});
  EXPECT_EQ(e.estimate_samples, 0);
  for (const CurveMapScore& s : e.scores) {
    EXPECT_EQ(s.precision, 0.0);
    EXPECT_EQ(s.recall, 0.0);
    EXPECT_EQ(s.f_score, 0.0);
  }
}

TEST(CurveMapEvaluationOptions, ValidateNamesTheField) {
  CurveMapEvaluationOptions o;
  o.taus = {0.02, 0.01};
  try {
    o.validate();
    ADD_FAILURE() << "no InvalidOptions";
  } catch (const InvalidOptions& e) {
    EXPECT_THAT(e.what(), HasSubstr("CurveMapEvaluationOptions.taus = 0.01: must be strictly "
                                    "increasing"));
  }
  o.taus = {};
  EXPECT_THROW(o.validate(), InvalidOptions);
  o.taus = {-0.01};
  EXPECT_THROW(o.validate(), InvalidOptions);
  o = {};
  o.sample_spacing = -1.0;
  EXPECT_THROW(o.validate(), InvalidOptions);
  o = {};
  o.crop_margin = NAN;
  EXPECT_THROW(o.validate(), InvalidOptions);
  EXPECT_THROW(evaluateCurveMap({}, {}, o), InvalidOptions);
}

}  // namespace
}  // namespace curvesfm
