#include "frontend/image/point_tracks.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <iostream>
#include <opencv2/imgproc.hpp>
#include <set>

#include "core/errors.h"
#include "sim/planar_scene.h"
#include "test/support/textures.h"

namespace curvesfm {
namespace {

using ::testing::HasSubstr;

// Eight 640x480 views at half the default orbit's spacing, with a little sensor noise: about 6 px
// of motion and 1.5 deg of roll per frame (45 deg/s at 30 Hz, a brisk hand-held pan). Built once:
// rendering is the slow part.
const PlanarScene& scene() {
  static const PlanarScene kScene = [] {
    PlanarSceneOptions options;
    options.num_frames = 8;
    options.arc_degrees = 90.0 / 29 * 7 / 2;
    options.intensity_noise = 0.01;
    return makePlanarScene(testing::denseTexture(), options);
  }();
  return kScene;
}

Eigen::Vector2d mapPixel(const Eigen::Matrix3d& h, const Eigen::Vector2d& p) {
  return (h * p.homogeneous()).hnormalized();
}

std::vector<PointFrame> trackAll(const std::vector<cv::Mat>& images,
                                 const PointTrackerOptions& options = {}) {
  PointTracker tracker(options);
  std::vector<PointFrame> frames;
  for (const cv::Mat& image : images) frames.push_back(tracker.track(image));
  return frames;
}

bool sameOutput(const PointFrame& a, const PointFrame& b) {
  if (a.frame != b.frame || a.tracked != b.tracked || a.detected != b.detected ||
      a.lost.total() != b.lost.total() || a.points.size() != b.points.size()) {
    return false;
  }
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    if (a.points[i].track != b.points[i].track || a.points[i].pixel != b.points[i].pixel) {
      return false;
    }
  }
  return true;
}

TEST(PointTracker, FollowsPlanarViewsWithinAPixelOfTheHomography) {
  const PlanarScene& s = scene();
  PointTracker tracker;
  PointTracks tracks;
  const auto start = std::chrono::steady_clock::now();
  for (const cv::Mat& image : s.images) tracks.add(tracker.track(image));
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::cout << "PointTracker: " << ms / s.images.size() << " ms per 640x480 frame\n";

  const int last = static_cast<int>(s.images.size()) - 1;
  int checked = 0, within_1px = 0, within_half_px = 0, from_first_frame = 0;
  for (const auto& [id, observations] : tracks.tracks()) {
    if (observations.back().frame != last) continue;
    const TrackObservation& birth = observations.front();
    const Eigen::Matrix3d last_from_birth = s.pixelMap(birth.frame, last);
    const double error =
        (mapPixel(last_from_birth, birth.pixel) - observations.back().pixel).norm();
    ++checked;
    within_1px += error < 1.0;
    within_half_px += error < 0.5;
    from_first_frame += birth.frame == 0;
  }
  std::cout << "PointTracker: " << checked << " tracks in frame " << last << ", "
            << from_first_frame << " from frame 0, " << within_half_px << " within 0.5 px, "
            << within_1px << " within 1 px\n";
  EXPECT_GE(from_first_frame, 200);  // Most of frame 0's tracks (about 280) live through 7 steps.
  // Translation-only KLT drifts under roll (see window_size_px): about 0.08 px a frame here.
  EXPECT_GT(within_1px, 0.9 * checked);
  EXPECT_GT(within_half_px, 0.25 * checked);
}

TEST(PointTracker, KeepsIdsStableAndCountsEveryTrack) {
  const std::vector<PointFrame> frames = trackAll(scene().images);
  std::set<int> previous;
  int next_new_id = 0;
  for (const PointFrame& frame : frames) {
    ASSERT_EQ(frame.tracked + frame.lost.total(), static_cast<int>(previous.size()));
    ASSERT_EQ(frame.tracked + frame.detected, static_cast<int>(frame.points.size()));
    std::set<int> current;
    for (int i = 0; i < static_cast<int>(frame.points.size()); ++i) {
      const int id = frame.points[i].track;
      if (i > 0) {
        EXPECT_LT(frame.points[i - 1].track, id);  // Ascending.
      }
      if (i < frame.tracked) {
        EXPECT_EQ(previous.count(id), 1u) << "followed track " << id << " is not an earlier one";
      } else {
        EXPECT_GE(id, next_new_id) << "a new track reuses an id";
      }
      current.insert(id);
    }
    if (!current.empty()) next_new_id = std::max(next_new_id, *current.rbegin() + 1);
    previous = current;
  }
}

TEST(PointTracker, SpreadsCornersOverTheGrid) {
  const PointTrackerOptions options;
  PointTracker tracker(options);
  const PointFrame first = tracker.track(scene().images[0]);
  std::vector<int> count(options.grid_cols * options.grid_rows, 0);
  for (const TrackedPoint& p : first.points) {
    const int col = static_cast<int>(p.pixel.x() * options.grid_cols / 640);
    const int row = static_cast<int>(p.pixel.y() * options.grid_rows / 480);
    ++count[row * options.grid_cols + col];
  }
  const auto filled = std::count_if(count.begin(), count.end(), [](int n) { return n > 0; });
  EXPECT_GE(filled, 0.9 * count.size());
  EXPECT_LE(*std::max_element(count.begin(), count.end()), options.corners_per_cell);
  EXPECT_TRUE(first.detection_ran);
  EXPECT_EQ(first.detected, static_cast<int>(first.points.size()));
}

TEST(PointTracker, AnIdenticalFrameKeepsEveryTrackInPlace) {
  PointTracker tracker;
  const PointFrame first = tracker.track(scene().images[0]);
  const PointFrame again = tracker.track(scene().images[0].clone());
  ASSERT_GT(first.points.size(), 100u);
  EXPECT_EQ(again.tracked, static_cast<int>(first.points.size()));
  EXPECT_EQ(again.lost.total(), 0);
  EXPECT_EQ(again.detected, 0);
  for (std::size_t i = 0; i < first.points.size(); ++i) {
    EXPECT_EQ(again.points[i].track, first.points[i].track);
    EXPECT_LT((again.points[i].pixel - first.points[i].pixel).norm(), 1e-3);
  }
}

TEST(PointTracker, ABlackFrameLosesEveryTrackAndTrackingRestartsAfterIt) {
  PointTracker tracker;
  const PointFrame first = tracker.track(scene().images[0]);
  const cv::Mat black(480, 640, CV_8UC1, cv::Scalar(0));
  PointFrame dark;
  ASSERT_NO_THROW(dark = tracker.track(black));
  EXPECT_TRUE(dark.points.empty());
  EXPECT_EQ(dark.lost.total(), static_cast<int>(first.points.size()));
  EXPECT_EQ(dark.detected, 0);
  const PointFrame after = tracker.track(scene().images[1]);
  EXPECT_EQ(after.tracked, 0);
  EXPECT_GT(after.detected, 100);
  EXPECT_GT(after.points.front().track, first.points.back().track);  // Fresh ids.
}

TEST(PointTracker, TrackingTheSameFramesTwiceGivesTheSameTracks) {
  const std::vector<cv::Mat> images(scene().images.begin(), scene().images.begin() + 4);
  const std::vector<PointFrame> once = trackAll(images), twice = trackAll(images);
  ASSERT_EQ(once.size(), twice.size());
  for (std::size_t i = 0; i < once.size(); ++i) EXPECT_TRUE(sameOutput(once[i], twice[i])) << i;
}

TEST(PointTracker, TakesBgrImagesAsTheirGrey) {
  const cv::Mat& grey = scene().images[0];
  cv::Mat bgr;
  cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
  EXPECT_TRUE(sameOutput(PointTracker().track(grey), PointTracker().track(bgr)));
}

TEST(PointTracker, RejectsOtherImageTypesAndASizeChange) {
  PointTracker tracker;
  EXPECT_THAT([&] { tracker.track(cv::Mat(480, 640, CV_32FC1, cv::Scalar(0))); },
              ::testing::ThrowsMessage<CheckError>(HasSubstr("8-bit grey (CV_8UC1) or BGR")));
  EXPECT_THROW(tracker.track(cv::Mat()), CheckError);
  tracker.track(cv::Mat(480, 640, CV_8UC1, cv::Scalar(0)));
  EXPECT_THAT([&] { tracker.track(cv::Mat(240, 320, CV_8UC1, cv::Scalar(0))); },
              ::testing::ThrowsMessage<CheckError>(HasSubstr("frame 1 is 320x240 px")));
}

TEST(PointTrackerOptions, ValidateNamesTheField) {
  EXPECT_NO_THROW(PointTrackerOptions().validate());
  const auto expectRejects = [](PointTrackerOptions options, const std::string& message) {
    EXPECT_THAT([&] { PointTracker tracker(options); },
                ::testing::ThrowsMessage<InvalidOptions>(HasSubstr(message)));
  };
  PointTrackerOptions o;
  o.grid_cols = 0;
  expectRejects(o, "PointTrackerOptions.grid_cols = 0: in [1, 64]");
  o = {};
  o.window_size_px = 20;
  expectRejects(o, "PointTrackerOptions.window_size_px = 20: odd, in [5, 101]");
  o = {};
  o.quality_level = 1.0;
  expectRejects(o, "PointTrackerOptions.quality_level = 1");
  o = {};
  o.max_forward_backward_px = std::nan("");
  expectRejects(o, "PointTrackerOptions.max_forward_backward_px = nan");
  o = {};
  o.min_live_tracks = -1;
  expectRejects(o, "PointTrackerOptions.min_live_tracks = -1");
}

PointFrame frameOf(int index, std::vector<std::pair<int, double>> points) {
  PointFrame frame;
  frame.frame = index;
  for (const auto& [id, x] : points) frame.points.push_back({id, Eigen::Vector2d(x, 10.0 * index)});
  return frame;
}

TEST(PointTracks, CorrespondencesPairTheTracksSeenInBothFrames) {
  PointTracks tracks;
  tracks.add(frameOf(0, {{0, 1.0}, {1, 2.0}, {2, 3.0}}));
  tracks.add(frameOf(1, {{0, 1.5}, {2, 3.5}, {3, 4.5}}));
  tracks.add(frameOf(3, {{2, 3.9}, {3, 4.9}}));
  EXPECT_EQ(tracks.numTracks(), 4);
  const std::vector<PointCorrespondence> pairs = tracks.correspondences(0, 3);
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0].track, 2);
  EXPECT_EQ(pairs[0].pixel_a, Eigen::Vector2d(3.0, 0.0));
  EXPECT_EQ(pairs[0].pixel_b, Eigen::Vector2d(3.9, 30.0));
  const std::vector<PointCorrespondence> neighbours = tracks.correspondences(1, 0);
  ASSERT_EQ(neighbours.size(), 2u);
  EXPECT_EQ(neighbours[0].track, 0);
  EXPECT_EQ(neighbours[0].pixel_a, Eigen::Vector2d(1.5, 10.0));
  EXPECT_EQ(neighbours[1].track, 2);
  EXPECT_TRUE(tracks.correspondences(0, 2).empty());  // Frame 2 was never added.
  EXPECT_EQ(tracks.observations(3).size(), 2u);
  EXPECT_TRUE(tracks.observations(42).empty());
}

TEST(PointTracks, TakesFramesInIncreasingOrderOnly) {
  PointTracks tracks;
  tracks.add(frameOf(2, {{0, 1.0}}));
  EXPECT_THROW(tracks.add(frameOf(2, {{0, 1.0}})), CheckError);
  EXPECT_THROW(tracks.add(frameOf(1, {{0, 1.0}})), CheckError);
}

TEST(PointTracks, CorrespondencesOfTrackedPlanarViewsAreTrueMatches) {
  const PlanarScene& s = scene();
  PointTracks tracks;
  PointTracker tracker;
  for (int k = 0; k < 4; ++k) tracks.add(tracker.track(s.images[k]));
  const std::vector<PointCorrespondence> pairs = tracks.correspondences(0, 3);
  ASSERT_GT(pairs.size(), 150u);
  const Eigen::Matrix3d h = s.pixelMap(0, 3);
  int good = 0;
  for (const PointCorrespondence& c : pairs)
    good += (mapPixel(h, c.pixel_a) - c.pixel_b).norm() < 1.0;
  EXPECT_GT(good, 0.95 * pairs.size());
}

}  // namespace
}  // namespace curvesfm
