#include "factors/curve_statistics.h"

#include <gtest/gtest.h>

#include <numeric>

#include "sim/curve_scene.h"
#include "sim/curve_scene_input.h"

namespace curvesfm {
namespace {

CurveScene smallScene() {
  CurveSceneOptions options;
  options.num_keyframes = 4;
  return makeCurveScene(options);
}

TEST(CurveStatistics, DescribesEveryCurveAndSharesThePull) {
  const CurveScene scene = smallScene();
  CurveBundleAdjustmentInput input = makeCurveBundleAdjustmentInput(scene, SceneStart::kTruth);
  // One curve moved 5 cm across: it alone is off its edges, so it must have the largest residual
  // and pull the poses hardest.
  const int moved = 0;
  std::vector<Eigen::Vector3d> points = input.curves[moved].points();
  for (Eigen::Vector3d& p : points) p += Eigen::Vector3d(0.0, 0.05, 0.0);
  input.curves[moved] =
      PolyBezier(points, input.curves[moved].directions(), input.curves[moved].lengths());
  const std::vector<CurveStatistics> stats = curveStatistics(input, {});
  ASSERT_EQ(stats.size(), input.curves.size());
  double shares = 0.0;
  for (std::size_t c = 0; c < stats.size(); ++c) {
    const CurveStatistics& s = stats[c];
    shares += s.pose_pull_share;
    EXPECT_GE(s.keyframes, 1);
    EXPECT_GE(s.observations, s.keyframes);
    EXPECT_GT(s.length, 0.0);
    EXPECT_GT(s.median_camera_distance, 0.0);
    if (static_cast<int>(c) == moved) continue;
    EXPECT_LT(s.residual_rms_px, stats[moved].residual_rms_px) << "curve " << c;
    EXPECT_LT(s.pose_pull, stats[moved].pose_pull) << "curve " << c;
  }
  EXPECT_NEAR(shares, 1.0, 1e-9);
}

TEST(CurveStatistics, GivesTheTrackOfEachCurveFromItsObservations) {
  const CurveScene scene = smallScene();
  const CurveBundleAdjustmentInput input =
      makeCurveBundleAdjustmentInput(scene, SceneStart::kTruth);
  const std::vector<CurveStatistics> stats = curveStatistics(input, {});
  std::vector<int> observations(input.curves.size(), 0);
  std::vector<int> first(input.curves.size(), 1 << 30);
  std::vector<int> last(input.curves.size(), -1);
  for (const SegmentObservation& o : input.observations) {
    ++observations[o.curve];
    first[o.curve] = std::min(first[o.curve], o.keyframe);
    last[o.curve] = std::max(last[o.curve], o.keyframe);
  }
  for (std::size_t c = 0; c < stats.size(); ++c) {
    EXPECT_EQ(stats[c].observations, observations[c]);
    EXPECT_EQ(stats[c].first_keyframe, observations[c] > 0 ? first[c] : -1);
    EXPECT_EQ(stats[c].last_keyframe, last[c]);
    EXPECT_LE(stats[c].keyframes, 4);
    EXPECT_GE(stats[c].triangulation_angle_deg, 0.0);
    EXPECT_LT(stats[c].triangulation_angle_deg, 180.0);
  }
}

TEST(CurveStatistics, FindsTheKeyframeWhereEachCurveIsWorst) {
  const CurveScene scene = smallScene();
  CurveBundleAdjustmentInput input = makeCurveBundleAdjustmentInput(scene, SceneStart::kTruth);
  // Keyframe 2 moved 5 cm sideways: every curve it observes is furthest off its edges there.
  const int moved = 2;
  const Pose3& pose = input.cam_from_world[moved];
  input.cam_from_world[moved] =
      Pose3(pose.rotation(), pose.translation() + Eigen::Vector3d(0.05, 0.0, 0.0));
  std::vector<bool> seen_by_moved(input.curves.size(), false);
  for (const SegmentObservation& o : input.observations) {
    if (o.keyframe == moved) seen_by_moved[o.curve] = true;
  }
  const std::vector<CurveStatistics> stats = curveStatistics(input, {});
  int checked = 0;
  for (std::size_t c = 0; c < stats.size(); ++c) {
    if (stats[c].observations == 0) {
      EXPECT_EQ(stats[c].worst_keyframe, -1) << "curve " << c;
      continue;
    }
    EXPECT_GE(stats[c].worst_keyframe, stats[c].first_keyframe) << "curve " << c;
    EXPECT_LE(stats[c].worst_keyframe, stats[c].last_keyframe) << "curve " << c;
    if (!seen_by_moved[c]) continue;
    EXPECT_EQ(stats[c].worst_keyframe, moved) << "curve " << c;
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

// A straight curve of `segments` equal segments from `from` along `direction` (unit), `length`
// long.
PolyBezier straightCurve(const Eigen::Vector3d& from, const Eigen::Vector3d& direction,
                         double length, int segments) {
  const double step = length / segments;
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i <= segments; ++i) points.push_back(from + i * step * direction);
  return PolyBezier(points, std::vector<Direction>(points.size(), Direction(direction)),
                    std::vector<SegmentLengths>(segments, {step / 3.0, step / 3.0}));
}

TEST(CurveStatistics, MeasuresHowFarACurveRunsOutOfItsEpipolarPlanes) {
  const CurveScene scene = smallScene();
  CurveBundleAdjustmentInput input = makeCurveBundleAdjustmentInput(scene, SceneStart::kTruth);
  // The orbit's centres lie in one plane: every epipolar plane through a point of that plane is
  // the plane itself, so a line in it runs along every epipolar line it is seen on (0 deg). A
  // line rising across it from the same point is 90 deg out at its foot and a little less above
  // it, where the epipolar planes tilt towards it.
  std::vector<Eigen::Vector3d> centres;
  for (const Pose3& pose : input.cam_from_world) centres.push_back(pose.inverseTranslation());
  ASSERT_GE(centres.size(), 3u);
  const Eigen::Vector3d normal =
      (centres[1] - centres[0]).cross(centres[2] - centres[0]).normalized();
  const Eigen::Vector3d middle = input.curves[0].evaluate(0, 0.5);
  const Eigen::Vector3d in_plane = middle - normal.dot(middle - centres[0]) * normal;
  const Eigen::Vector3d along = normal.cross(in_plane - centres[0]).normalized();
  input.curves[0] = straightCurve(in_plane, along, 0.3, input.curves[0].numSegments());
  input.curves[1] = straightCurve(in_plane, normal, 0.3, input.curves[1].numSegments());
  const std::vector<CurveStatistics> stats = curveStatistics(input, {});
  ASSERT_GE(stats[0].keyframes, 2);
  ASSERT_GE(stats[1].keyframes, 2);
  EXPECT_LT(stats[0].epipolar_angle_deg, 1.0);
  EXPECT_GT(stats[1].epipolar_angle_deg, 80.0);
}

}  // namespace
}  // namespace curvesfm
