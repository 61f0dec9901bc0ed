#include "frontend/mapping/local_ba_observations.h"

#include <gtest/gtest.h>

#include <set>
#include <vector>

#include "core/check.h"

namespace curvesfm {
namespace {

std::vector<SegmentObservation> track(int curve, int segment, int first, int last) {
  std::vector<SegmentObservation> observations;
  for (int k = first; k <= last; ++k) observations.push_back({curve, segment, k});
  return observations;
}

std::set<int> keyframesOf(const std::vector<SegmentObservation>& observations, int curve,
                          int segment) {
  std::set<int> keyframes;
  for (const SegmentObservation& o : observations) {
    if (o.curve == curve && o.segment == segment) keyframes.insert(o.keyframe);
  }
  return keyframes;
}

TEST(ThinLocalObservations, KeepsTheWindowAndSpreadsTheRestFromTheOldest) {
  // Segment 0 of curve 3 seen in keyframes 0-29; window 5 ending at keyframe 29.
  const std::vector<SegmentObservation> thinned =
      thinLocalObservations(track(3, 0, 0, 29), 10, 5, 29);
  // The window's five (25-29), then five of the 25 older ones, evenly: 0, 6, 12, 18, 24.
  EXPECT_EQ(keyframesOf(thinned, 3, 0), (std::set<int>{0, 6, 12, 18, 24, 25, 26, 27, 28, 29}));
  EXPECT_EQ(thinned.size(), 10u);
  EXPECT_EQ(thinned.front().keyframe, 0);  // The input's order stays.
  EXPECT_EQ(thinned.back().keyframe, 29);
}

TEST(ThinLocalObservations, ShortTracksAndEverySegmentKeepTheirObservations) {
  std::vector<SegmentObservation> observations = track(1, 0, 20, 29);  // 10 keyframes: all stay.
  const std::vector<SegmentObservation> old_segment = track(1, 1, 0, 12);  // Out of the window.
  observations.insert(observations.end(), old_segment.begin(), old_segment.end());
  const std::vector<SegmentObservation> thinned = thinLocalObservations(observations, 10, 5, 29);
  EXPECT_EQ(keyframesOf(thinned, 1, 0).size(), 10u);
  // Segment 1 has no keyframe in the window: ten of its 13, the first and the last among them.
  const std::set<int> kept = keyframesOf(thinned, 1, 1);
  EXPECT_EQ(kept.size(), 10u);
  EXPECT_EQ(*kept.begin(), 0);
  EXPECT_EQ(*kept.rbegin(), 12);
}

TEST(ThinLocalObservations, ZeroKeepsEverythingAndAWindowAsLargeIsRefused) {
  const std::vector<SegmentObservation> observations = track(0, 0, 0, 99);
  EXPECT_EQ(thinLocalObservations(observations, 0, 5, 99).size(), 100u);
  EXPECT_THROW(thinLocalObservations(observations, 5, 5, 99), CheckError);
}

}  // namespace
}  // namespace curvesfm
