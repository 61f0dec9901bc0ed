#include "frontend/image/feature_tracks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "sim/planar_scene.h"
#include "test/support/textures.h"

namespace curvesfm {
namespace {

// Ten views of the textured plane, 3 deg of orbit apart.
const PlanarScene& scene() {
  static const PlanarScene kScene = [] {
    PlanarSceneOptions options;
    options.num_frames = 10;
    options.arc_degrees = 27.0;
    options.intensity_noise = 0.01;
    return makePlanarScene(testing::denseTexture(), options);
  }();
  return kScene;
}

Eigen::Vector2d mapPixel(const Eigen::Matrix3d& h, const Eigen::Vector2d& p) {
  return (h * p.homogeneous()).hnormalized();
}

// Feeds `frames` (scene frame indices; -1 is an all-black frame) and returns the tracks.
FeatureTracks build(const std::vector<int>& frames, const FeatureTrackOptions& options = {}) {
  FeatureTrackBuilder builder(options, {}, {});
  const cv::Mat black = cv::Mat::zeros(scene().images[0].size(), scene().images[0].type());
  for (int f : frames) builder.addFrame(f < 0 ? black : scene().images[f]);
  return builder.finish();
}

// The fraction of tracks whose every observation lies within 2 px of where the true homography
// carries its first one.
double consistentFraction(const FeatureTracks& tracks, const std::vector<int>& frames) {
  int consistent = 0;
  for (const FeatureTrack& track : tracks.tracks) {
    const TrackObservation& first = track.observations.front();
    bool ok = true;
    for (const TrackObservation& o : track.observations) {
      const Eigen::Matrix3d h = scene().pixelMap(frames[first.frame], frames[o.frame]);
      ok = ok && (mapPixel(h, first.pixel) - o.pixel).norm() < 3.0;
    }
    consistent += ok;
  }
  return tracks.tracks.empty() ? 0.0 : double(consistent) / tracks.tracks.size();
}

TEST(FeatureTracks, JoinKltAndDescriptorsIntoConsistentTracks) {
  const std::vector<int> frames = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
  const FeatureTracks tracks = build(frames);
  ASSERT_EQ(tracks.num_frames, 10);
  EXPECT_GT(tracks.tracks.size(), 300u);
  EXPECT_GT(consistentFraction(tracks, frames), 0.97);
  FeatureTrackOptions klt_only;
  klt_only.match_overlap = 0;
  EXPECT_GT(consistentFraction(build(frames, klt_only), frames), 0.97);
  // Matching frames: every fifth and the last.
  EXPECT_TRUE(tracks.frames[0].matching_frame);
  EXPECT_FALSE(tracks.frames[1].matching_frame);
  EXPECT_TRUE(tracks.frames[5].matching_frame);
  EXPECT_TRUE(tracks.frames[9].matching_frame);
  for (int f = 0; f < 10; ++f) {
    for (int t : tracks.frame_tracks[f]) ASSERT_NE(tracks.pixel(t, f), nullptr);
  }
}

TEST(FeatureTracks, DescriptorsBridgeAFrameWhereKltLosesEverything) {
  // Frame 4 of the sequence is black: KLT loses every track there and starts afresh after it.
  const std::vector<int> frames = {0, 1, 2, 3, -1, 4, 5, 6};
  const FeatureTracks bridged = build(frames);
  EXPECT_GT(bridged.sharedTracks(3, 5).size(), 100u);
  FeatureTrackOptions klt_only;
  klt_only.match_overlap = 0;
  EXPECT_TRUE(build(frames, klt_only).sharedTracks(3, 5).empty());
}

// A keypoint observation is one a descriptor detected in its frame, not one KLT followed there:
// its pixel is one of that matching frame's keypoints, and KLT alone makes none.
TEST(FeatureTracks, MarkTheObservationsThatAreDescriptorKeypoints) {
  const std::vector<int> frames = {0, 1, 2, 3, -1, 4, 5, 6};
  const FeatureTracks tracks = build(frames);
  std::vector<const FeatureSet*> features_of(frames.size(), nullptr);
  for (const MatchingFrameFeatures& m : tracks.matching_frames) features_of[m.frame] = &m.features;
  int keypoints = 0;
  for (const FeatureTrack& track : tracks.tracks) {
    for (const TrackObservation& o : track.observations) {
      if (!o.keypoint) continue;
      ++keypoints;
      ASSERT_NE(features_of[o.frame], nullptr) << "keypoint in frame " << o.frame;
      const std::vector<Eigen::Vector2d>& pixels = features_of[o.frame]->pixels;
      const auto found = std::find(pixels.begin(), pixels.end(), o.pixel);
      ASSERT_NE(found, pixels.end());
      // It keeps the scale its keypoint was detected at.
      EXPECT_EQ(o.keypoint_size, features_of[o.frame]->sizes[found - pixels.begin()]);
      EXPECT_EQ(tracks.observation(&track - tracks.tracks.data(), o.frame), &o);
    }
  }
  EXPECT_GT(keypoints, 20);
  FeatureTrackOptions klt_only;
  klt_only.match_overlap = 0;
  for (const FeatureTrack& track : build(frames, klt_only).tracks) {
    for (const TrackObservation& o : track.observations) {
      EXPECT_FALSE(o.keypoint);
      EXPECT_EQ(o.keypoint_size, 0.0);
    }
  }
}

TEST(FeatureTracks, ShortSequenceMatchesEveryPairOfMatchingFrames) {
  // Two black frames part frames 0 and 3 (consecutive matching frames without a match: out of
  // order); the window (one earlier matching frame) never pairs them, the exhaustive matching of
  // a short sequence does.
  const std::vector<int> frames = {0, -1, -1, 1};
  FeatureTrackOptions window_only;
  window_only.match_overlap = 1;
  window_only.exhaustive_max_frames = 0;
  EXPECT_TRUE(build(frames, window_only).sharedTracks(0, 3).empty());
  FeatureTrackOptions exhaustive = window_only;
  exhaustive.exhaustive_max_frames = 4;
  EXPECT_GT(build(frames, exhaustive).sharedTracks(0, 3).size(), 100u);
  // One frame too many for the bound: the window alone again.
  exhaustive.exhaustive_max_frames = 3;
  EXPECT_TRUE(build(frames, exhaustive).sharedTracks(0, 3).empty());
}

// The matching frames' descriptors stay available for loop matches, each keypoint with the track
// that observes it at its pixel, and the pairs the window matched are listed.
TEST(FeatureTracks, KeepMatchingFramesWithTheTrackOfEachKeypoint) {
  const std::vector<int> frames = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 8, 7, 6};
  const FeatureTracks tracks = build(frames);
  std::vector<int> matching;
  for (const MatchingFrameFeatures& m : tracks.matching_frames) matching.push_back(m.frame);
  EXPECT_EQ(matching, (std::vector<int>{0, 5, 10, 12}));
  const std::set<std::pair<int, int>> window = {{0, 5}, {0, 10}, {5, 10}, {5, 12}, {10, 12}};
  EXPECT_EQ(tracks.matched_pairs, window);
  for (const MatchingFrameFeatures& m : tracks.matching_frames) {
    ASSERT_EQ(static_cast<int>(m.track_of_keypoint.size()), m.features.size());
    int tracked = 0;
    for (int k = 0; k < m.features.size(); ++k) {
      const int t = m.track_of_keypoint[k];
      if (t < 0) continue;
      ++tracked;
      ASSERT_NE(tracks.pixel(t, m.frame), nullptr);
      EXPECT_LE((*tracks.pixel(t, m.frame) - m.features.pixels[k]).norm(),
                FeatureTrackOptions{}.merge_radius_px);
    }
    EXPECT_GT(tracked, m.features.size() / 4) << "matching frame " << m.frame;
  }
}

TEST(FeatureTracks, RejectsBadOptions) {
  FeatureTrackOptions options;
  options.match_interval = 0;
  EXPECT_THROW(FeatureTrackBuilder(options, {}, {}), InvalidOptions);
}

}  // namespace
}  // namespace curvesfm
