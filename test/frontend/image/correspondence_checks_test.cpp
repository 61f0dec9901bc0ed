#include "frontend/image/correspondence_checks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/errors.h"

namespace curvesfm {
namespace {

constexpr int kWidth = 640;
constexpr int kHeight = 480;
constexpr double kFocal = 500.0;
constexpr double kDepth = 2.0;
// The column the test segment projects to when it lies in the plane x = 0.
constexpr int kEdgeColumn = 320;

const cv::Vec3b kRed(0, 0, 255);
const cv::Vec3b kBlue(255, 0, 0);
const cv::Vec3b kGreen(0, 255, 0);
const cv::Vec3b kYellow(0, 255, 255);

Camera testCamera() {
  CameraIntrinsics intrinsics;
  intrinsics.fx = kFocal;
  intrinsics.fy = kFocal;
  intrinsics.cx = kEdgeColumn;
  intrinsics.cy = kHeight / 2;
  intrinsics.width = kWidth;
  intrinsics.height = kHeight;
  return Camera(intrinsics);
}

// A straight vertical segment 0.4 m long at depth z, offset x (m) from the optical axis; seen from
// the identity pose it projects to column kEdgeColumn + kFocal * x / z, rows 190..290 at z = 2.
BezierSegmentParams verticalSegment(double x, double z) {
  BezierSegmentParams segment;
  segment.q0 = Eigen::Vector3d(x, -0.2, z);
  segment.q1 = Eigen::Vector3d(x, 0.2, z);
  segment.v0 = Direction(Eigen::Vector3d::UnitY());
  segment.v1 = Direction(Eigen::Vector3d::UnitY());
  segment.d1 = 0.4 / 3.0;
  segment.d2 = 0.4 / 3.0;
  return segment;
}

BezierSegmentParams segmentOnEdge() { return verticalSegment(0.0, kDepth); }

// The field of a vertical edge along column kEdgeColumn, rows 0..last_row, with gradient (1, 0):
// a constant gradient magnitude gives no sub-pixel shift, so the edge lies exactly on the column.
NearestEdgeField verticalEdgeField(int last_row = kHeight - 1) {
  cv::Mat edges = cv::Mat::zeros(kHeight, kWidth, CV_8UC1);
  edges(cv::Range(0, last_row + 1), cv::Range(kEdgeColumn, kEdgeColumn + 1)).setTo(255);
  const cv::Mat grad_x(kHeight, kWidth, CV_32FC1, cv::Scalar(1.0f));
  const cv::Mat grad_y(kHeight, kWidth, CV_32FC1, cv::Scalar(0.0f));
  return NearestEdgeField::build(edges, grad_x, grad_y, NearestEdgeFieldOptions{});
}

// Left of kEdgeColumn `left`, from it on `right`.
cv::Mat twoColourImage(const cv::Vec3b& left, const cv::Vec3b& right) {
  cv::Mat image(kHeight, kWidth, CV_8UC3, cv::Scalar(right[0], right[1], right[2]));
  image.colRange(0, kEdgeColumn).setTo(cv::Scalar(left[0], left[1], left[2]));
  return image;
}

// The unit vector at `degrees` from +z, rotated about +x.
Eigen::Vector3d directionFromOpticalAxis(double degrees) {
  const double radians = degrees * M_PI / 180.0;
  return Eigen::Vector3d(0.0, std::sin(radians), std::cos(radians));
}

HsvAppearance appearance(double hue_deg, double saturation, double value) {
  HsvAppearance out;
  out.hue_deg = hue_deg;
  out.saturation = saturation;
  out.value = value;
  out.num_pixels = 9;
  return out;
}

TEST(CorrespondenceChecks, DepthAcceptsSegmentInFront) {
  const CheckResult result = checkPositiveDepth(segmentOnEdge(), Pose3(), {});
  EXPECT_TRUE(result.passed);
  EXPECT_NEAR(result.value, kDepth, 1e-12);
}

TEST(CorrespondenceChecks, DepthRejectsSegmentBehind) {
  const CheckResult result = checkPositiveDepth(verticalSegment(0.0, -kDepth), Pose3(), {});
  EXPECT_FALSE(result.passed);
  EXPECT_NEAR(result.value, -kDepth, 1e-12);
}

TEST(CorrespondenceChecks, EdgeDistanceAcceptsSegmentOnEdge) {
  const CheckResult result =
      checkEdgeDistance(segmentOnEdge(), Pose3(), testCamera(), verticalEdgeField(), {});
  EXPECT_TRUE(result.passed);
  EXPECT_NEAR(result.value, 0.0, 1e-9);
}

TEST(CorrespondenceChecks, EdgeDistanceRejectsSegmentEightPixelsAside) {
  const BezierSegmentParams beside = verticalSegment(8.0 * kDepth / kFocal, kDepth);
  const CheckResult result =
      checkEdgeDistance(beside, Pose3(), testCamera(), verticalEdgeField(), {});
  EXPECT_FALSE(result.passed);
  EXPECT_NEAR(result.value, 8.0, 1e-6);
}

TEST(CorrespondenceChecks, EdgeDistanceMeasuresTheGapPastTheEndOfAnEdge) {
  // The edge stops at row 240, the middle of the projected segment (rows 190..290): the five
  // samples below it (rows 245.6 .. 290, 100/9 px apart) measure their gap past the end pixel's
  // piece of edge, each capped at the reach 15; the five above lie on the edge.
  const NearestEdgeField field = verticalEdgeField(240);
  const CheckResult result = checkEdgeDistance(segmentOnEdge(), Pose3(), testCamera(), field, {});
  const double piece = 0.5 * std::sqrt(2.0);
  double expected = 0.0;
  for (int k = 5; k < 10; ++k) {
    const double row = 190.0 + 100.0 * k / 9.0;
    expected += std::min(15.0, std::max(0.0, row - 240.0 - piece));
  }
  EXPECT_FALSE(result.passed);
  EXPECT_NEAR(result.value, expected / 10.0, 1e-6);
}

TEST(CorrespondenceChecks, EdgeDistanceCountsSamplesOffTheImageAsTheReach) {
  const BezierSegmentParams outside = verticalSegment(-10.0, kDepth);
  const NearestEdgeField field = verticalEdgeField();
  const CheckResult result = checkEdgeDistance(outside, Pose3(), testCamera(), field, {});
  EXPECT_FALSE(result.passed);
  EXPECT_DOUBLE_EQ(result.value, field.maxDistance());
}

TEST(CorrespondenceChecks, ViewingDirectionAcceptsThirtyDegrees) {
  const CheckResult result = checkViewingDirection(segmentOnEdge(), Eigen::Vector3d::Zero(),
                                                   directionFromOpticalAxis(30.0), {});
  EXPECT_TRUE(result.passed);
  EXPECT_NEAR(result.value, 30.0, 1e-9);
}

TEST(CorrespondenceChecks, ViewingDirectionRejectsSeventyFiveDegrees) {
  const CheckResult result = checkViewingDirection(segmentOnEdge(), Eigen::Vector3d::Zero(),
                                                   directionFromOpticalAxis(75.0), {});
  EXPECT_FALSE(result.passed);
  EXPECT_NEAR(result.value, 75.0, 1e-9);
}

TEST(CorrespondenceChecks, ViewingDirectionMeanAveragesUnitDirections) {
  ViewingDirectionMean mean;
  EXPECT_TRUE(mean.mean().isZero());
  mean.add(3.0 * directionFromOpticalAxis(20.0));
  mean.add(directionFromOpticalAxis(-20.0));
  EXPECT_EQ(mean.count(), 2);
  EXPECT_NEAR((mean.mean() - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-12);
  // Without earlier observations there is nothing to compare with.
  EXPECT_TRUE(
      checkViewingDirection(segmentOnEdge(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), {})
          .passed);
}

TEST(CorrespondenceChecks, AppearanceAcceptsSameColoursInAnotherImage) {
  const Camera camera = testCamera();
  const HsvAppearance reference =
      appearanceOf(segmentOnEdge(), Pose3(), camera, twoColourImage(kRed, kBlue), {});
  // The segment projects 2 px beside the boundary; the field re-centres the band on its edge.
  const NearestEdgeField field = verticalEdgeField();
  const HsvAppearance candidate =
      appearanceOf(verticalSegment(2.0 * kDepth / kFocal, kDepth), Pose3(), camera,
                   twoColourImage(kRed, kBlue), {}, &field);
  // 10 samples, 9 pixels each.
  EXPECT_EQ(reference.num_pixels, 90);
  EXPECT_NEAR(reference.saturation, 1.0, 1e-12);
  EXPECT_NEAR(reference.value, 1.0, 1e-12);
  const CheckResult result = checkAppearance(reference, candidate, {});
  EXPECT_TRUE(result.passed);
  EXPECT_NEAR(result.value, 0.0, 1e-12);
}

TEST(CorrespondenceChecks, AppearanceRejectsOtherColours) {
  const Camera camera = testCamera();
  const HsvAppearance reference =
      appearanceOf(segmentOnEdge(), Pose3(), camera, twoColourImage(kRed, kBlue), {});
  const HsvAppearance candidate =
      appearanceOf(segmentOnEdge(), Pose3(), camera, twoColourImage(kGreen, kYellow), {});
  const CheckResult result = checkAppearance(reference, candidate, {});
  EXPECT_FALSE(result.passed);
  EXPECT_GT(result.value, 0.5);
}

TEST(CorrespondenceChecks, AppearanceWeightsHueBySaturation) {
  // Grey: the hue is arbitrary and must not count.
  EXPECT_TRUE(checkAppearance(appearance(0.0, 0.0, 0.5), appearance(180.0, 0.0, 0.5), {}).passed);
  // Fully saturated, the same hues are half a turn apart: E = lambda * 1 * 1.
  const CheckResult saturated =
      checkAppearance(appearance(0.0, 1.0, 0.5), appearance(180.0, 1.0, 0.5), {});
  EXPECT_FALSE(saturated.passed);
  EXPECT_NEAR(saturated.value, 1.0, 1e-12);
  // Hand-computed: lambda 2, mean S 0.5, 20 deg across 0 (20 / 180), |dV| 0.1.
  EXPECT_NEAR(appearanceError(appearance(350.0, 0.4, 0.6), appearance(10.0, 0.6, 0.5), 2.0),
              2.0 * 0.5 * (20.0 / 180.0) + 0.1, 1e-12);
}

TEST(CorrespondenceChecks, AppearanceRejectsUnseenRegion) {
  const HsvAppearance unseen = appearanceOf(verticalSegment(0.0, -kDepth), Pose3(), testCamera(),
                                            twoColourImage(kRed, kBlue), {});
  EXPECT_FALSE(unseen.valid());
  const CheckResult result = checkAppearance(appearance(0.0, 0.0, 0.5), unseen, {});
  EXPECT_FALSE(result.passed);
  EXPECT_TRUE(std::isinf(result.value));
}

TEST(CorrespondenceChecks, AppearanceNeedsABgrImage) {
  const cv::Mat grey(kHeight, kWidth, CV_8UC1, cv::Scalar(0));
  EXPECT_THROW(appearanceOf(segmentOnEdge(), Pose3(), testCamera(), grey, {}), CheckError);
}

class RegisterSegmentTest : public ::testing::Test {
 protected:
  RegisterSegmentTest()
      : camera_(testCamera()), field_(verticalEdgeField()), image_(twoColourImage(kRed, kBlue)) {
    history_.reference_appearance =
        appearanceOf(segmentOnEdge(), pose_, camera_, image_, options_, &field_);
    history_.mean_viewing_direction_in_world = directionFromOpticalAxis(10.0);
  }

  CorrespondenceVerdict run(const BezierSegmentParams& segment, const cv::Mat& image) const {
    return registerSegment(segment, KeyframeView{pose_, camera_, field_, image}, history_,
                           options_);
  }

  Pose3 pose_;
  Camera camera_;
  NearestEdgeField field_;
  cv::Mat image_;
  CorrespondenceOptions options_;
  SegmentHistory history_;
};

TEST_F(RegisterSegmentTest, RegistersWhenAllChecksPass) {
  const CorrespondenceVerdict verdict = run(segmentOnEdge(), image_);
  EXPECT_TRUE(verdict.registered);
  EXPECT_EQ(verdict.failed_check, CorrespondenceCheck::kNone);
  EXPECT_NEAR(verdict.viewing_angle_deg, 10.0, 1e-9);
  EXPECT_NEAR(verdict.appearance_error, 0.0, 1e-12);
  EXPECT_TRUE(verdict.appearance.valid());
  EXPECT_NEAR((verdict.viewing_direction_in_world - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-12);
}

TEST_F(RegisterSegmentTest, StopsAtTheFirstFailedCheck) {
  const CorrespondenceVerdict behind = run(verticalSegment(0.0, -kDepth), image_);
  EXPECT_FALSE(behind.registered);
  EXPECT_EQ(behind.failed_check, CorrespondenceCheck::kDepth);
  EXPECT_TRUE(std::isnan(behind.mean_edge_distance_px));

  const CorrespondenceVerdict aside = run(verticalSegment(8.0 * kDepth / kFocal, kDepth), image_);
  EXPECT_EQ(aside.failed_check, CorrespondenceCheck::kEdgeDistance);
  EXPECT_TRUE(std::isnan(aside.viewing_angle_deg));

  history_.mean_viewing_direction_in_world = directionFromOpticalAxis(75.0);
  const CorrespondenceVerdict oblique = run(segmentOnEdge(), image_);
  EXPECT_EQ(oblique.failed_check, CorrespondenceCheck::kViewingDirection);
  EXPECT_TRUE(std::isnan(oblique.appearance_error));

  history_.mean_viewing_direction_in_world = Eigen::Vector3d::UnitZ();
  const CorrespondenceVerdict recoloured = run(segmentOnEdge(), twoColourImage(kGreen, kYellow));
  EXPECT_EQ(recoloured.failed_check, CorrespondenceCheck::kAppearance);
  EXPECT_EQ(toString(recoloured.failed_check), "appearance");
}

TEST(CorrespondenceOptions, DefaultsAreValid) {
  EXPECT_NO_THROW(CorrespondenceOptions{}.validate());
}

TEST(CorrespondenceOptions, BadValuesThrowNamingTheField) {
  const auto expectInvalid = [](CorrespondenceOptions options, const std::string& field) {
    try {
      options.validate();
      ADD_FAILURE() << "no throw for " << field;
    } catch (const InvalidOptions& error) {
      EXPECT_NE(std::string(error.what()).find("CorrespondenceOptions." + field), std::string::npos)
          << error.what();
    }
  };
  CorrespondenceOptions options;
  options.samples_per_segment = 1;
  expectInvalid(options, "samples_per_segment");
  options = {};
  options.min_depth = 0.0;
  expectInvalid(options, "min_depth");
  options = {};
  options.max_mean_edge_distance_px = std::numeric_limits<double>::quiet_NaN();
  expectInvalid(options, "max_mean_edge_distance_px");
  options = {};
  options.appearance_half_width_px = -1;
  expectInvalid(options, "appearance_half_width_px");
  options = {};
  options.hue_weight = -1.0;
  expectInvalid(options, "hue_weight");
  options = {};
  options.max_appearance_error = 0.0;
  expectInvalid(options, "max_appearance_error");
  options = {};
  options.max_viewing_angle_deg = 181.0;
  expectInvalid(options, "max_viewing_angle_deg");
  // The checks validate too.
  EXPECT_THROW(checkPositiveDepth(segmentOnEdge(), Pose3(), options), InvalidOptions);
}

}  // namespace
}  // namespace curvesfm
