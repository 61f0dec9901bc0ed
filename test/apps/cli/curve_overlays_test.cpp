#include "apps/cli/curve_overlays.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "core/errors.h"
#include "test/support/cameras.h"
#include "test/support/temp_folder.h"

namespace curvesfm {
namespace {

using ::testing::HasSubstr;

CurveStatistics withResidual(double px) {
  CurveStatistics s;
  s.residual_rms_px = px;
  return s;
}

CurveStatistics withTrack(int keyframes) {
  CurveStatistics s;
  s.keyframes = keyframes;
  return s;
}

CurveStatistics withPullShare(double share) {
  CurveStatistics s;
  s.pose_pull_share = share;
  return s;
}

TEST(CurveColouring, MapsEachStatisticOverItsFixedRangeAndClips) {
  EXPECT_DOUBLE_EQ(colourFraction(CurveColouring::kResidual, withResidual(0.0)), 0.0);
  EXPECT_DOUBLE_EQ(colourFraction(CurveColouring::kResidual, withResidual(1.5)), 0.5);
  EXPECT_DOUBLE_EQ(colourFraction(CurveColouring::kResidual, withResidual(3.0)), 1.0);
  EXPECT_DOUBLE_EQ(colourFraction(CurveColouring::kResidual, withResidual(40.0)), 1.0);
  EXPECT_DOUBLE_EQ(colourFraction(CurveColouring::kResidual, withResidual(std::nan(""))), 0.0);
  EXPECT_DOUBLE_EQ(colourFraction(CurveColouring::kTrack, withTrack(1)), 0.0);
  EXPECT_DOUBLE_EQ(colourFraction(CurveColouring::kTrack, withTrack(2)), 0.0);
  EXPECT_DOUBLE_EQ(colourFraction(CurveColouring::kTrack, withTrack(11)), 0.5);
  EXPECT_DOUBLE_EQ(colourFraction(CurveColouring::kTrack, withTrack(20)), 1.0);
  EXPECT_DOUBLE_EQ(colourFraction(CurveColouring::kTrack, withTrack(300)), 1.0);
  // The pull share on a log scale, 1e-4 to 1e-1: a decade is a third of the bar.
  EXPECT_DOUBLE_EQ(colourFraction(CurveColouring::kPull, withPullShare(0.0)), 0.0);
  EXPECT_DOUBLE_EQ(colourFraction(CurveColouring::kPull, withPullShare(1e-6)), 0.0);
  EXPECT_NEAR(colourFraction(CurveColouring::kPull, withPullShare(1e-4)), 0.0, 1e-12);
  EXPECT_NEAR(colourFraction(CurveColouring::kPull, withPullShare(1e-3)), 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(colourFraction(CurveColouring::kPull, withPullShare(1e-1)), 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(colourFraction(CurveColouring::kPull, withPullShare(0.9)), 1.0);
  EXPECT_DOUBLE_EQ(colourFraction(CurveColouring::kNone, withResidual(2.0)), 0.0);
}

TEST(CurveColouring, LegendsNameTheStatisticAndTheRangesEnds) {
  const ColourLegend residual = colourLegend(CurveColouring::kResidual);
  EXPECT_EQ(residual.title, "residual rms (px)");
  EXPECT_EQ(residual.low_label, "0");
  EXPECT_EQ(residual.high_label, ">=3");
  const ColourLegend track = colourLegend(CurveColouring::kTrack);
  EXPECT_EQ(track.title, "track length (keyframes)");
  EXPECT_EQ(track.low_label, "<=2");
  EXPECT_EQ(track.high_label, ">=20");
  const ColourLegend pull = colourLegend(CurveColouring::kPull);
  EXPECT_THAT(pull.title, HasSubstr("pull"));
  EXPECT_EQ(pull.low_label, "<=0.01%");
  EXPECT_EQ(pull.high_label, ">=10%");
  EXPECT_THROW(colourLegend(CurveColouring::kNone), CheckError);
}

TEST(CurveColouring, CurvesWithDifferentValuesGetDifferentColours) {
  const std::vector<CurveStatistics> stats = {withResidual(0.2), withResidual(2.5),
                                              withResidual(0.2), withResidual(9.0)};
  const cv::Scalar plain(0, 255, 0);
  const std::vector<cv::Scalar> colours = curveColours(CurveColouring::kResidual, stats, plain);
  ASSERT_EQ(colours.size(), 4u);
  EXPECT_NE(colours[0], colours[1]);
  EXPECT_EQ(colours[0], colours[2]);
  EXPECT_EQ(colours[3], colourMapBgr(1.0));
  for (const cv::Scalar& c : curveColours(CurveColouring::kNone, stats, plain)) {
    EXPECT_EQ(c, plain);
  }
}

TEST(CurveColouring, AColourByOutsideTheNamesIsRefused) {
  OverlayColouringOptions options;
  options.validate();
  options.colour_by = static_cast<CurveColouring>(9);
  try {
    options.validate();
    FAIL() << "no InvalidOptions";
  } catch (const InvalidOptions& e) {
    EXPECT_THAT(e.what(), HasSubstr("OverlayColouringOptions.colour_by"));
    EXPECT_THAT(e.what(), HasSubstr("none, residual, track, pull"));
  }
}

TEST(WorstCurves, RanksHighestFirstKeepingTheIndexOrderOfEquals) {
  std::vector<CurveStatistics> stats = {withResidual(1.0), withResidual(3.0), withResidual(1.0),
                                        withResidual(2.0)};
  stats[0].pose_pull_share = 0.5;
  EXPECT_EQ(worstCurves(stats, CurveRanking::kResidual, 10),
            (std::vector<std::size_t>{1, 3, 0, 2}));
  EXPECT_EQ(worstCurves(stats, CurveRanking::kResidual, 2), (std::vector<std::size_t>{1, 3}));
  EXPECT_EQ(worstCurves(stats, CurveRanking::kPull, 2), (std::vector<std::size_t>{0, 1}));
}

// Twelve horizontal lines across three keyframes looking down +z, residual i / 4 px for curve i,
// pull shares the other way round; curve 11 is observed nowhere.
OverlayScene twelveLines() {
  OverlayScene scene{testing::centredPinhole(100.0, 160, 120), {}, {}, {}, {}};
  for (int j = 0; j < 3; ++j) {
    scene.keyframe_images.push_back(cv::Mat(120, 160, CV_8UC3, cv::Scalar(90, 90, 90)));
    scene.keyframe_cam_from_world.push_back(
        Pose3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.05 * j, 0.0, 0.0)));
  }
  for (int i = 0; i < 12; ++i) {
    const double y = -0.5 + 0.09 * i;
    const Eigen::Vector3d a(-0.5, y, 2.0), b(0.5, y, 2.0);
    const Direction v(b - a);
    scene.curves.push_back(PolyBezier({a, b}, {v, v}, {SegmentLengths{0.3, 0.3}}));
    CurveStatistics s = withResidual(0.25 * i);
    s.pose_pull_share = (12 - i) / 78.0;
    s.keyframes = 2;
    s.first_keyframe = i == 11 ? -1 : 0;
    s.last_keyframe = i == 11 ? -1 : 2;
    s.worst_keyframe = i == 11 ? -1 : i % 3;
    scene.statistics.push_back(s);
  }
  return scene;
}

class CurveOverlaysTest : public testing::TempFolderTest {
 protected:
  const OverlayScene scene_ = twelveLines();
};

TEST_F(CurveOverlaysTest, OverlaysCarryTheLegendOnlyWhenColoured) {
  EXPECT_EQ(writeOverlays(path("plain"), scene_, {}, CurveColouring::kNone), 3);
  EXPECT_EQ(writeOverlays(path("residual"), scene_, {}, CurveColouring::kResidual), 3);
  const cv::Mat plain = cv::imread(path("plain/000002.png"));
  const cv::Mat coloured = cv::imread(path("residual/000002.png"));
  ASSERT_EQ(plain.size(), coloured.size());
  // The corner holds the legend's bar, with the map's ends, in the coloured overlay only.
  const cv::Rect corner(0, 0, 120, 40);
  const cv::Vec3b high(colourMapBgr(1.0)[0], colourMapBgr(1.0)[1], colourMapBgr(1.0)[2]);
  int plain_high = 0, coloured_high = 0;
  for (int r = corner.y; r < corner.y + corner.height; ++r) {
    for (int c = corner.x; c < corner.x + corner.width; ++c) {
      plain_high += plain.at<cv::Vec3b>(r, c) == high;
      coloured_high += coloured.at<cv::Vec3b>(r, c) == high;
    }
  }
  EXPECT_EQ(plain_high, 0);
  EXPECT_GT(coloured_high, 0);
}

TEST_F(CurveOverlaysTest, WorstCurvesAreWrittenUnderTheirDocumentedNamesAndIndexed) {
  EXPECT_EQ(writeWorstCurves(path("worst"), scene_, {}), 19);  // Curve 11 has no keyframe.
  // Residual 11 * 0.25 px is the highest, but curve 11 is observed nowhere: listed, no image.
  for (const char* name :
       {"residual_02_curve_0010_kf_0001.png", "residual_03_curve_0009_kf_0000.png",
        "pull_01_curve_0000_kf_0000.png", "pull_10_curve_0009_kf_0000.png"}) {
    EXPECT_TRUE(std::filesystem::exists(path("worst/") + name)) << name;
  }
  std::ifstream in(path("worst/worst_curves.md"));
  std::stringstream index;
  index << in.rdbuf();
  EXPECT_THAT(index.str(), HasSubstr("## Highest residual"));
  EXPECT_THAT(index.str(), HasSubstr("## Most pull on the poses"));
  EXPECT_THAT(index.str(), HasSubstr("| 1 | 11 | 2.75 |"));
  EXPECT_THAT(index.str(), HasSubstr("none (observed in no keyframe)"));
  EXPECT_THAT(index.str(), HasSubstr("[residual_02_curve_0010_kf_0001.png]"
                                     "(residual_02_curve_0010_kf_0001.png) (keyframe 1)"));
  // The highlighted curve is thick magenta on its keyframe: row 59.5 + 100 * y / 2.
  const cv::Mat image = cv::imread(path("worst/residual_02_curve_0010_kf_0001.png"));
  const int row = static_cast<int>(59.5 + 50.0 * (-0.5 + 0.09 * 10));
  const cv::Vec3b centre = image.at<cv::Vec3b>(row, 80);
  EXPECT_GT(centre[0], 200);
  EXPECT_LT(centre[1], 60);
  EXPECT_GT(centre[2], 200);
}

}  // namespace
}  // namespace curvesfm
