#include "core/trajectory_evaluation.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "core/errors.h"

namespace curvesfm {
namespace {

// A camera on a rising helix looking at its axis, 10 poses per second.
std::vector<StampedPose> helix(int count, double start_time = 100.0) {
  std::vector<StampedPose> poses;
  for (int k = 0; k < count; ++k) {
    const double angle = 0.05 * k;
    const Eigen::Vector3d centre(2.0 * std::cos(angle), 0.02 * k, 2.0 * std::sin(angle));
    const Eigen::Quaterniond rotation(
        Eigen::AngleAxisd(-angle, Eigen::Vector3d::UnitY()) *
        Eigen::AngleAxisd(0.1 * std::sin(angle), Eigen::Vector3d::UnitX()));
    poses.push_back({start_time + 0.1 * k, Pose3(rotation, centre)});
  }
  return poses;
}

Sim3 exampleSim3() {
  Sim3 transform;
  transform.scale = 0.4;
  transform.rotation =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.3, 1.0, -0.2).normalized()).toRotationMatrix();
  transform.translation = Eigen::Vector3d(-4.0, 1.5, 7.0);
  return transform;
}

std::vector<StampedPose> transformed(const Sim3& transform, std::vector<StampedPose> poses) {
  for (StampedPose& pose : poses)
    pose.world_from_cam = transform.transformPose(pose.world_from_cam);
  return poses;
}

TrajectoryEvaluationOptions withAlignment(AlignmentKind kind) {
  TrajectoryEvaluationOptions options;
  options.alignment = kind;
  return options;
}

std::string messageOf(const std::vector<StampedPose>& estimate,
                      const std::vector<StampedPose>& ground_truth,
                      const TrajectoryEvaluationOptions& options) {
  try {
    compareTrajectories(estimate, ground_truth, options, "est.txt", "gt.txt");
  } catch (const TrajectoryEvaluationError& e) {
    return e.what();
  }
  return "no error";
}

TEST(ErrorStatistics, MatchesHandComputedValues) {
  const ErrorStatistics s = computeErrorStatistics({4.0, 1.0, 3.0, 2.0});
  EXPECT_EQ(s.count, 4);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(computeErrorStatistics({5.0, 1.0, 3.0}).median, 3.0);
  const ErrorStatistics none = computeErrorStatistics({});
  EXPECT_EQ(none.count, 0);
  EXPECT_EQ(none.rmse, 0.0);
  EXPECT_EQ(none.max, 0.0);
}

TEST(TrajectoryEvaluation, RecoversAKnownSim3WithZeroError) {
  const std::vector<StampedPose> truth = helix(80);
  const Sim3 estimate_from_truth = exampleSim3();
  const TrajectoryEvaluation e = compareTrajectories(transformed(estimate_from_truth, truth), truth,
                                                     withAlignment(AlignmentKind::kSim3));
  ASSERT_EQ(e.matches.size(), 80u);
  EXPECT_LT(e.ate.rmse, 1e-9);
  EXPECT_LT(e.ate.max, 1e-9);
  EXPECT_NEAR(e.ground_truth_from_estimate.scale, 1.0 / estimate_from_truth.scale, 1e-9);
  EXPECT_LT(
      (e.ground_truth_from_estimate.rotation - estimate_from_truth.rotation.transpose()).norm(),
      1e-9);
  EXPECT_LT(e.rpe_translation_stats.max, 1e-9);
  EXPECT_LT(e.rpe_rotation_stats.max, 1e-6);
  EXPECT_EQ(e.rpe_translation_stats.count, 79);
}

TEST(TrajectoryEvaluation, KnownOffsetsGiveTheirRmse) {
  // Every centre displaced by 5 cm in a varying direction; no alignment: every error is 5 cm.
  const std::vector<StampedPose> truth = helix(50);
  std::vector<StampedPose> estimate = truth;
  for (std::size_t k = 0; k < estimate.size(); ++k) {
    const Eigen::Vector3d direction =
        Eigen::Vector3d(std::cos(1.3 * k), std::sin(1.3 * k), std::cos(0.7 * k)).normalized();
    const Pose3& pose = estimate[k].world_from_cam;
    estimate[k].world_from_cam = Pose3(pose.rotation(), pose.translation() + 0.05 * direction);
  }
  const TrajectoryEvaluation e =
      compareTrajectories(estimate, truth, withAlignment(AlignmentKind::kNone));
  EXPECT_NEAR(e.ate.rmse, 0.05, 1e-12);
  EXPECT_NEAR(e.ate.mean, 0.05, 1e-12);
  EXPECT_NEAR(e.ate.std, 0.0, 1e-9);
  EXPECT_EQ(e.ate.count, 50);
}

TEST(TrajectoryEvaluation, GaussianNoiseGivesSigmaRootThreeAfterAlignment) {
  const std::vector<StampedPose> truth = helix(3000);
  std::mt19937 rng(42);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<StampedPose> estimate = transformed(exampleSim3(), truth);
  const double estimate_scale = exampleSim3().scale;
  for (StampedPose& pose : estimate) {
    const Eigen::Vector3d offset(noise(rng), noise(rng), noise(rng));
    pose.world_from_cam = Pose3(pose.world_from_cam.rotation(),
                                pose.world_from_cam.translation() + estimate_scale * offset);
  }
  const TrajectoryEvaluation e =
      compareTrajectories(estimate, truth, withAlignment(AlignmentKind::kSim3));
  // E|n|^2 = 3 sigma^2; the alignment's 7 parameters absorb a negligible share of 9000 values.
  EXPECT_NEAR(e.ate.rmse, 0.01 * std::sqrt(3.0), 0.0005);
  EXPECT_NEAR(e.ground_truth_from_estimate.scale, 1.0 / estimate_scale, 1e-3);
}

TEST(TrajectoryEvaluation, Se3DoesNotFixTheScale) {
  const std::vector<StampedPose> truth = helix(60);
  Sim3 doubled;
  doubled.scale = 2.0;
  const std::vector<StampedPose> estimate = transformed(doubled, truth);
  const TrajectoryEvaluation rigid =
      compareTrajectories(estimate, truth, withAlignment(AlignmentKind::kSe3));
  EXPECT_EQ(rigid.ground_truth_from_estimate.scale, 1.0);
  EXPECT_GT(rigid.ate.rmse, 0.5);
  EXPECT_GT(rigid.rpe_translation_stats.mean, 0.05);  // Steps are twice as long.
  const TrajectoryEvaluation similar =
      compareTrajectories(estimate, truth, withAlignment(AlignmentKind::kSim3));
  EXPECT_NEAR(similar.ground_truth_from_estimate.scale, 0.5, 1e-12);
  EXPECT_LT(similar.ate.rmse, 1e-9);
}

TEST(TrajectoryEvaluation, RpeOfAConstantOffsetIsZero) {
  const std::vector<StampedPose> truth = helix(40);
  std::vector<StampedPose> estimate = truth;
  const Eigen::Vector3d offset(0.3, -0.2, 0.1);
  for (StampedPose& pose : estimate) {
    pose.world_from_cam =
        Pose3(pose.world_from_cam.rotation(), pose.world_from_cam.translation() + offset);
  }
  TrajectoryEvaluationOptions options = withAlignment(AlignmentKind::kNone);
  options.rpe_delta = 5;
  const TrajectoryEvaluation e = compareTrajectories(estimate, truth, options);
  EXPECT_NEAR(e.ate.rmse, offset.norm(), 1e-12);
  EXPECT_EQ(e.rpe_translation_stats.count, 35);
  EXPECT_LT(e.rpe_translation_stats.max, 1e-12);
  EXPECT_LT(e.rpe_rotation_stats.max, 1e-6);
}

TEST(TrajectoryEvaluation, RpeSeesALocalJump) {
  // One pose 10 cm off: the two motions touching it are wrong, the others are not.
  const std::vector<StampedPose> truth = helix(20);
  std::vector<StampedPose> estimate = truth;
  const Pose3& pose = estimate[10].world_from_cam;
  estimate[10].world_from_cam =
      Pose3(pose.rotation(), pose.translation() + Eigen::Vector3d(0.1, 0.0, 0.0));
  const TrajectoryEvaluation e =
      compareTrajectories(estimate, truth, withAlignment(AlignmentKind::kNone));
  ASSERT_EQ(e.rpe_translation.size(), 19u);
  EXPECT_NEAR(e.rpe_translation[9], 0.1, 1e-12);
  EXPECT_NEAR(e.rpe_translation[10], 0.1, 1e-12);
  EXPECT_NEAR(e.rpe_translation_stats.median, 0.0, 1e-12);
}

TEST(TimestampAssociation, DropsStampsFartherThanMaxDt) {
  const std::vector<StampedPose> truth = helix(10);  // 100.0, 100.1, ..., 100.9
  std::vector<StampedPose> estimate = truth;
  estimate[2].timestamp += 0.015;  // Within 0.02 s: kept.
  estimate[5].timestamp += 0.03;   // Too far from 100.5 and 100.6: dropped.
  estimate[8].timestamp -= 0.05;   // Halfway between two stamps: dropped.
  const std::vector<TimestampMatch> matches = associateByTimestamp(estimate, truth, 0.02);
  ASSERT_EQ(matches.size(), 8u);
  for (const TimestampMatch& m : matches) {
    EXPECT_EQ(m.estimate_index, m.ground_truth_index);
    EXPECT_NE(m.estimate_index, 5);
    EXPECT_NE(m.estimate_index, 8);
  }
  EXPECT_EQ(associateByTimestamp(estimate, truth, 0.0).size(), 7u);
}

TEST(TimestampAssociation, IsOneToOneClosestFirstAndInTimeOrder) {
  std::vector<StampedPose> truth(2), estimate(3);
  truth[0].timestamp = 1.00;
  truth[1].timestamp = 0.50;
  estimate[0].timestamp = 1.01;   // Closer to 1.00 than estimate 1: takes it.
  estimate[1].timestamp = 0.985;  // Would also match 1.00, which is taken.
  estimate[2].timestamp = 0.49;
  const std::vector<TimestampMatch> matches = associateByTimestamp(estimate, truth, 0.02);
  ASSERT_EQ(matches.size(), 2u);
  EXPECT_EQ(matches[0].estimate_index, 2);  // 0.49 comes first in time.
  EXPECT_EQ(matches[0].ground_truth_index, 1);
  EXPECT_EQ(matches[1].estimate_index, 0);
  EXPECT_EQ(matches[1].ground_truth_index, 0);
}

TEST(TrajectoryEvaluation, MatchesATrajectoryWithADifferentRate) {
  // Ground truth at 100 Hz, estimate at 10 Hz with 4 ms jitter.
  std::vector<StampedPose> truth;
  for (int k = 0; k < 500; ++k) {
    truth.push_back({100.0 + 0.01 * k, Pose3(Eigen::Quaterniond::Identity(),
                                             Eigen::Vector3d(0.1 * k, std::sin(0.05 * k), 0.0))});
  }
  std::vector<StampedPose> estimate;
  for (int k = 0; k < 500; k += 10) {
    StampedPose pose = truth[k];
    pose.timestamp += 0.004;
    estimate.push_back(pose);
  }
  const TrajectoryEvaluation e =
      compareTrajectories(estimate, truth, withAlignment(AlignmentKind::kSe3));
  ASSERT_EQ(e.matches.size(), 50u);
  EXPECT_LT(e.ate.max, 1e-9);
  EXPECT_EQ(e.ground_truth_poses, 500);
  EXPECT_EQ(e.estimate_poses, 50);
}

TEST(TrajectoryEvaluation, TooFewMatchesNameBothTrajectoriesAndCounts) {
  const std::vector<StampedPose> truth = helix(10);
  const std::vector<StampedPose> estimate = helix(4, 100.805);  // 2 stamps within 100.0..100.9.
  EXPECT_THAT(messageOf(estimate, truth, withAlignment(AlignmentKind::kSim3)),
              testing::StrEq("TrajectoryEvaluationError: est.txt vs gt.txt: matched 2 of 4 "
                             "estimated poses (10 ground-truth) within max_dt 0.02 s; sim3 "
                             "alignment needs at least 3"));
  EXPECT_THAT(messageOf(helix(3, 500.0), truth, withAlignment(AlignmentKind::kNone)),
              testing::HasSubstr("matched 0 of 3 estimated poses (10 ground-truth)"));
  EXPECT_EQ(compareTrajectories(estimate, truth, withAlignment(AlignmentKind::kNone)).ate.count, 2);
  EXPECT_THAT(messageOf({}, truth, withAlignment(AlignmentKind::kSe3)),
              testing::HasSubstr("matched 0 of 0"));
}

TEST(TrajectoryEvaluation, CoincidingEstimatedCentresCannotBeScaled) {
  const std::vector<StampedPose> truth = helix(10);
  std::vector<StampedPose> estimate = truth;
  for (StampedPose& pose : estimate) {
    pose.world_from_cam = Pose3(pose.world_from_cam.rotation(), Eigen::Vector3d(1.0, 2.0, 3.0));
  }
  EXPECT_THAT(messageOf(estimate, truth, withAlignment(AlignmentKind::kSim3)),
              testing::HasSubstr("the 10 matched estimated camera centres coincide"));
  EXPECT_GT(compareTrajectories(estimate, truth, withAlignment(AlignmentKind::kSe3)).ate.rmse, 0.1);
}

TEST(TrajectoryEvaluationOptions, RejectsInvalidValues) {
  TrajectoryEvaluationOptions options;
  EXPECT_NO_THROW(options.validate());
  options.max_dt = -0.01;
  EXPECT_THROW(options.validate(), InvalidOptions);
  options.max_dt = std::nan("");
  EXPECT_THROW(options.validate(), InvalidOptions);
  options = {};
  options.rpe_delta = 0;
  try {
    options.validate();
    FAIL() << "expected InvalidOptions";
  } catch (const InvalidOptions& e) {
    EXPECT_STREQ(e.what(),
                 "InvalidOptions: TrajectoryEvaluationOptions.rpe_delta = 0: must be >= 1 "
                 "(frames)");
  }
  EXPECT_THROW(compareTrajectories(helix(5), helix(5), options), InvalidOptions);
}

// The index-matched entry of synthetic scenes: the same ATE as compareTrajectories on the same
// poses, a similarity of the truth scores zero, and the unaligned figures see the similarity.
TEST(EvaluateTrajectory, IsTheAteOfCompareTrajectoriesMatchedByIndex) {
  const std::vector<StampedPose> truth = helix(20);
  std::vector<StampedPose> estimate = transformed(exampleSim3(), truth);
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (StampedPose& pose : estimate) {
    pose.world_from_cam = Pose3(pose.world_from_cam.rotation(),
                                pose.world_from_cam.translation() +
                                    Eigen::Vector3d(noise(random), noise(random), noise(random)));
  }
  std::vector<Pose3> true_cam_from_world, estimated_cam_from_world;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    true_cam_from_world.push_back(truth[k].world_from_cam.inverse());
    estimated_cam_from_world.push_back(estimate[k].world_from_cam.inverse());
  }
  const TrajectoryErrors errors = evaluateTrajectory(true_cam_from_world, estimated_cam_from_world);
  const TrajectoryEvaluation by_time = compareTrajectories(estimate, truth, {});
  // Equal up to the rounding of inverting the poses.
  EXPECT_NEAR(errors.position_ate_sim3, by_time.ate.rmse, 1e-12);
  EXPECT_GT(errors.position_rmse, 1.0);

  const TrajectoryErrors exact = evaluateTrajectory(
      true_cam_from_world,
      std::vector<Pose3>(true_cam_from_world.begin(), true_cam_from_world.end()));
  EXPECT_LT(exact.position_ate_sim3, 1e-12);
  EXPECT_LT(exact.rotation_mean_deg, 1e-9);
  EXPECT_THROW(evaluateTrajectory(true_cam_from_world, {}), CheckError);
}

}  // namespace
}  // namespace curvesfm
