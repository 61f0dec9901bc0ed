#include "core/similarity_alignment.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "core/errors.h"

namespace curvesfm {
namespace {

Sim3 exampleSim3() {
  Sim3 transform;
  transform.scale = 2.5;
  transform.rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  transform.translation = Eigen::Vector3d(3.0, -1.0, 0.25);
  return transform;
}

Eigen::Matrix3Xd randomPoints(int count) {
  std::srand(7);
  return Eigen::Matrix3Xd::Random(3, count) * 4.0;
}

Eigen::Matrix3Xd transformed(const Sim3& transform, const Eigen::Matrix3Xd& points) {
  Eigen::Matrix3Xd result(3, points.cols());
  for (Eigen::Index k = 0; k < points.cols(); ++k) result.col(k) = transform * points.col(k);
  return result;
}

TEST(SimilarityAlignment, RecoversAnExactSimilarity) {
  const Sim3 truth = exampleSim3();
  const Eigen::Matrix3Xd source = randomPoints(20);
  const Sim3 found = alignPointSets(source, transformed(truth, source), AlignmentKind::kSim3);
  EXPECT_NEAR(found.scale, truth.scale, 1e-12);
  EXPECT_LT((found.rotation - truth.rotation).norm(), 1e-12);
  EXPECT_LT((found.translation - truth.translation).norm(), 1e-12);
}

TEST(SimilarityAlignment, Se3KeepsUnitScaleAndNoneIsTheIdentity) {
  Sim3 rigid = exampleSim3();
  rigid.scale = 1.0;
  const Eigen::Matrix3Xd source = randomPoints(10);
  const Sim3 found = alignPointSets(source, transformed(rigid, source), AlignmentKind::kSe3);
  EXPECT_EQ(found.scale, 1.0);
  EXPECT_LT((found.rotation - rigid.rotation).norm(), 1e-12);
  EXPECT_LT((found.translation - rigid.translation).norm(), 1e-12);

  const Sim3 scaled =
      alignPointSets(source, transformed(exampleSim3(), source), AlignmentKind::kSe3);
  EXPECT_EQ(scaled.scale, 1.0);  // The scale difference stays in the residual.

  const Sim3 none = alignPointSets(source, transformed(rigid, source), AlignmentKind::kNone);
  EXPECT_EQ(none.scale, 1.0);
  EXPECT_TRUE(none.rotation.isIdentity());
  EXPECT_TRUE(none.translation.isZero());
}

TEST(SimilarityAlignment, NeverReturnsAReflection) {
  // A mirrored target: the best proper rotation, not the reflection.
  const Eigen::Matrix3Xd source = randomPoints(12);
  Eigen::Matrix3Xd target = source;
  target.row(2) *= -1.0;
  const Sim3 found = alignPointSets(source, target, AlignmentKind::kSim3);
  EXPECT_NEAR(found.rotation.determinant(), 1.0, 1e-12);
  EXPECT_TRUE(std::isfinite(found.scale));
}

TEST(SimilarityAlignment, TransformPoseMovesTheCentreAndRotatesTheAxes) {
  const Sim3 transform = exampleSim3();
  const Pose3 source_from_cam(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY())),
                              Eigen::Vector3d(1.0, 2.0, 3.0));
  const Pose3 target_from_cam = transform.transformPose(source_from_cam);
  EXPECT_LT((target_from_cam.translation() - transform * source_from_cam.translation()).norm(),
            1e-12);
  EXPECT_LT(
      (target_from_cam.rotationMatrix() - transform.rotation * source_from_cam.rotationMatrix())
          .norm(),
      1e-12);
}

TEST(SimilarityAlignment, DegenerateInputs) {
  const Eigen::Matrix3Xd same = Eigen::Vector3d(0.1, 0.2, 0.3).replicate(1, 5);
  EXPECT_FALSE(hasSpreadForScale(same));
  EXPECT_FALSE(hasSpreadForScale(Eigen::Matrix3Xd(3, 0)));
  EXPECT_TRUE(hasSpreadForScale(randomPoints(2)));
  EXPECT_THROW(alignPointSets(same, randomPoints(5), AlignmentKind::kSim3), CheckError);
  EXPECT_THROW(alignPointSets(randomPoints(4), randomPoints(5), AlignmentKind::kSe3), CheckError);
  EXPECT_THROW(alignPointSets(Eigen::Matrix3Xd(3, 0), Eigen::Matrix3Xd(3, 0), AlignmentKind::kNone),
               CheckError);
  // Coinciding targets: scale 0, every source point maps onto the target point, no NaN.
  const Sim3 collapsed = alignPointSets(randomPoints(5), same, AlignmentKind::kSim3);
  EXPECT_EQ(collapsed.scale, 0.0);
  EXPECT_LT((collapsed * Eigen::Vector3d(5.0, 6.0, 7.0) - same.col(0)).norm(), 1e-12);
  EXPECT_NEAR(collapsed.rotation.determinant(), 1.0, 1e-12);
}

TEST(SimilarityAlignment, KindNamesRoundTrip) {
  for (auto kind : {AlignmentKind::kSim3, AlignmentKind::kSe3, AlignmentKind::kNone}) {
    EXPECT_EQ(parseEnumName<AlignmentKind>(toString(kind), "Options", "alignment"), kind);
  }
  try {
    parseEnumName<AlignmentKind>("sim2", "Options", "alignment");
    FAIL() << "expected InvalidOptions";
  } catch (const InvalidOptions& e) {
    EXPECT_STREQ(e.what(),
                 "InvalidOptions: Options.alignment = \"sim2\": expected one of sim3, se3, none");
  }
}

}  // namespace
}  // namespace curvesfm
