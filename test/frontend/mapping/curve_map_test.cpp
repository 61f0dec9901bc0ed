#include "frontend/mapping/curve_map.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"

namespace curvesfm {
namespace {

// A straight curve of `segments` segments along x.
PolyBezier straightCurve(int segments) {
  std::vector<Eigen::Vector3d> points;
  std::vector<Direction> directions;
  for (int i = 0; i <= segments; ++i) {
    points.emplace_back(0.1 * i, 0.0, 1.0);
    directions.emplace_back(Eigen::Vector3d::UnitX());
  }
  return PolyBezier(points, directions, std::vector<SegmentLengths>(segments, {0.03, 0.03}));
}

ObservedSegmentAppearance seenIn(int keyframe) {
  ObservedSegmentAppearance o;
  o.observation.keyframe = keyframe;
  o.viewing_direction_in_world = Eigen::Vector3d::UnitZ();
  return o;
}

void observeSegments(CurveMap* map, int id, int first, int last, int keyframe) {
  for (int i = first; i <= last; ++i) map->addObservation(id, i, seenIn(keyframe));
}

TEST(CurveMap, PromotesAtThreeObservedKeyframes) {
  CurveMap map;
  const int id = map.addCurve(straightCurve(4), 0);
  observeSegments(&map, id, 0, 3, 0);
  map.endKeyframe(0);
  observeSegments(&map, id, 0, 3, 1);
  map.endKeyframe(1);
  EXPECT_EQ(map.curve(id).state, CurveState::kTemporary);
  observeSegments(&map, id, 0, 3, 2);
  map.endKeyframe(2);
  EXPECT_EQ(map.curve(id).state, CurveState::kGlobal);
  EXPECT_EQ(map.count(CurveState::kGlobal), 1);
  EXPECT_EQ(map.curve(id).observedKeyframes(), 3);
}

TEST(CurveMap, RepeatedObservationInOneKeyframeCountsOnce) {
  CurveMap map;
  const int id = map.addCurve(straightCurve(2), 0);
  observeSegments(&map, id, 0, 1, 0);
  observeSegments(&map, id, 0, 1, 0);
  EXPECT_EQ(map.curve(id).segments[0].observations.size(), 1u);
  EXPECT_THROW(map.addObservation(id, 0, seenIn(-1)), CheckError);
  EXPECT_THROW(map.addObservation(id, 2, seenIn(1)), CheckError);
}

// Re-association after bundle adjustment registers segments in earlier keyframes too.
TEST(CurveMap, KeepsObservationsInKeyframeOrder) {
  CurveMap map;
  const int id = map.addCurve(straightCurve(1), 0);
  for (const int keyframe : {4, 1, 6, 1, 3}) map.addObservation(id, 0, seenIn(keyframe));
  std::vector<int> keyframes;
  for (const auto& o : map.curve(id).segments[0].observations) {
    keyframes.push_back(o.observation.keyframe);
  }
  EXPECT_EQ(keyframes, (std::vector<int>{1, 3, 4, 6}));
}

TEST(CurveMap, DisablesWhenMoreThanHalfUnseenOverThreeKeyframes) {
  CurveMap map;
  const int id = map.addCurve(straightCurve(4), 0);
  for (int k = 0; k < 3; ++k) {
    observeSegments(&map, id, 0, 3, k);
    map.endKeyframe(k);
  }
  ASSERT_EQ(map.curve(id).state, CurveState::kGlobal);
  // Segments 2 and 3 (half) unseen over keyframes 3..5: still enabled.
  for (int k = 3; k < 6; ++k) {
    observeSegments(&map, id, 0, 1, k);
    map.endKeyframe(k);
    EXPECT_EQ(map.curve(id).state, CurveState::kGlobal) << "keyframe " << k;
  }
  // Only segment 0 seen from keyframe 6 on: 1, 2, 3 were last seen at 5, 2, 2. Segment 1 drops
  // out of the window [k - 2, k] at k = 8, making 3 of 4 unseen.
  for (int k = 6; k < 8; ++k) {
    observeSegments(&map, id, 0, 0, k);
    map.endKeyframe(k);
    EXPECT_EQ(map.curve(id).state, CurveState::kGlobal) << "keyframe " << k;
  }
  observeSegments(&map, id, 0, 0, 8);
  map.endKeyframe(8);
  EXPECT_EQ(map.curve(id).state, CurveState::kDisabled);
  EXPECT_TRUE(map.exportCurves(CurveSelection::kGlobal).ids.empty());
  EXPECT_EQ(map.exportCurves(CurveSelection::kPromoted).ids.size(), 1u);
}

TEST(CurveMap, ReactivatesWhenSeenAgain) {
  CurveMap map;
  const int a = map.addCurve(straightCurve(2), 0);  // Stays temporary (seen in 1 keyframe).
  const int b = map.addCurve(straightCurve(2), 0);  // Promoted at keyframe 2.
  for (int k = 0; k < 3; ++k) {
    if (k == 0) observeSegments(&map, a, 0, 1, k);
    observeSegments(&map, b, 0, 1, k);
    map.endKeyframe(k);
  }
  EXPECT_EQ(map.curve(a).state, CurveState::kTemporary);
  EXPECT_EQ(map.curve(b).state, CurveState::kGlobal);
  for (int k = 3; k < 6; ++k) map.endKeyframe(k);
  EXPECT_EQ(map.curve(a).state, CurveState::kDisabled);
  EXPECT_EQ(map.curve(b).state, CurveState::kDisabled);

  observeSegments(&map, a, 0, 0, 6);
  observeSegments(&map, b, 1, 1, 6);
  map.endKeyframe(6);
  EXPECT_EQ(map.curve(a).state, CurveState::kTemporary);
  EXPECT_EQ(map.curve(b).state, CurveState::kGlobal);
  // Seen in 6 only, 1 of 2 segments: not more than half unseen, so it stays.
  map.endKeyframe(7);
  EXPECT_EQ(map.curve(b).state, CurveState::kGlobal);
}

TEST(CurveMap, ExportsObservationsAndTakesUpdates) {
  CurveMap map;
  const int temporary = map.addCurve(straightCurve(2), 0);
  const int global = map.addCurve(straightCurve(3), 0);
  observeSegments(&map, temporary, 0, 1, 0);
  for (int k = 0; k < 3; ++k) {
    observeSegments(&map, global, 1, 2, k);
    map.endKeyframe(k);
  }
  const ExportedCurves input = map.exportCurves(CurveSelection::kGlobal);
  const std::vector<int>& ids = input.ids;
  ASSERT_EQ(ids, std::vector<int>{global});
  ASSERT_EQ(input.curves.size(), 1u);
  ASSERT_EQ(input.observations.size(), 6u);
  EXPECT_EQ(input.observations[0].curve, 0);
  EXPECT_EQ(input.observations[0].segment, 1);
  EXPECT_EQ(input.observations[5].keyframe, 2);

  PolyBezier moved = straightCurve(3);
  moved.setPoint(0, Eigen::Vector3d(0.0, 0.5, 1.0));
  map.updateCurves(ids, {moved});
  EXPECT_EQ(map.curve(global).curve.points()[0].y(), 0.5);
  EXPECT_THROW(map.updateCurves(ids, {straightCurve(2)}), CheckError);
}

TEST(CurveMap, ExtendingAtTheBackAppendsUnobservedSegments) {
  CurveMap map;
  const int id = map.addCurve(straightCurve(2), 0);
  observeSegments(&map, id, 0, 1, 0);
  map.extendCurve(id, straightCurve(5), CurveEnd::kBack);
  const MapCurve& c = map.curve(id);
  ASSERT_EQ(c.segments.size(), 5u);
  EXPECT_TRUE(c.segments[1].observedIn(0));
  EXPECT_TRUE(c.segments[2].observations.empty());
  EXPECT_EQ(c.state, CurveState::kTemporary);
  EXPECT_THROW(map.extendCurve(id, straightCurve(5), CurveEnd::kBack), CheckError);
  EXPECT_THROW(map.extendCurve(7, straightCurve(6), CurveEnd::kBack), CheckError);
}

TEST(CurveMap, ExtendingAtTheFrontMovesObservationsWithTheirSegments) {
  CurveMap map;
  const int id = map.addCurve(straightCurve(2), 0);
  map.addObservation(id, 0, seenIn(0));
  map.addObservation(id, 1, seenIn(1));
  map.extendCurve(id, straightCurve(5), CurveEnd::kFront);
  const MapCurve& c = map.curve(id);
  ASSERT_EQ(c.segments.size(), 5u);
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(c.segments[i].observations.empty()) << i;
  EXPECT_TRUE(c.segments[3].observedIn(0));
  EXPECT_TRUE(c.segments[4].observedIn(1));
  map.addObservation(id, 0, seenIn(1));
  map.addObservation(id, 0, seenIn(2));
  map.endKeyframe(2);
  const ExportedCurves input = map.exportCurves(CurveSelection::kGlobal);
  ASSERT_EQ(input.observations.size(), 4u);
  EXPECT_EQ(input.observations[2].segment, 3);
  EXPECT_EQ(input.observations[3].segment, 4);
  EXPECT_EQ(c.segments[4].observations[0].observation.segment, 4);
}

// Each segment keeps the chord it was created with (E_s1's reference), through geometry updates
// and extensions at either end, so that bundle adjustments cannot shrink it step by step.
TEST(CurveMap, SegmentsKeepTheirChordsAtCreation) {
  CurveMap map;
  const int id = map.addCurve(straightCurve(2), 0);
  PolyBezier shrunk = straightCurve(2);
  shrunk.setPoint(1, Eigen::Vector3d(0.02, 0.0, 1.0));
  map.updateCurves({id}, {shrunk});
  // Extensions whose new segments are longer than the old ones (0.3 instead of 0.1).
  auto extendedBy = [](const PolyBezier& curve, int added, bool front) {
    std::vector<Eigen::Vector3d> points = curve.points();
    for (int k = 1; k <= added; ++k) {
      const Eigen::Vector3d end = front ? points.front() : points.back();
      const Eigen::Vector3d step(front ? -0.3 : 0.3, 0.0, 0.0);
      if (front) {
        points.insert(points.begin(), end + step);
      } else {
        points.push_back(end + step);
      }
    }
    std::vector<Direction> directions(points.size(), Direction(Eigen::Vector3d::UnitX()));
    return PolyBezier(points, directions,
                      std::vector<SegmentLengths>(points.size() - 1, {0.03, 0.03}));
  };
  map.extendCurve(id, extendedBy(map.curve(id).curve, 1, false), CurveEnd::kBack);
  map.extendCurve(id, extendedBy(map.curve(id).curve, 2, true), CurveEnd::kFront);
  std::vector<double> chords;
  for (const MapSegment& s : map.curve(id).segments) chords.push_back(s.initial_chord);
  EXPECT_THAT(chords, testing::Pointwise(testing::DoubleNear(1e-12),
                                         std::vector<double>{0.3, 0.3, 0.1, 0.1, 0.3}));
  for (int k = 0; k < 3; ++k) {
    observeSegments(&map, id, 0, 4, k);
    map.endKeyframe(k);
  }
  const ExportedCurves exported = map.exportCurves(CurveSelection::kGlobal);
  ASSERT_EQ(exported.initial_chords.size(), 1u);
  EXPECT_THAT(exported.initial_chords[0], testing::Pointwise(testing::DoubleNear(1e-12), chords));
}

// A dropped curve leaves every export and stays dropped, whatever the keyframes see.
TEST(CurveMap, DroppedCurveLeavesEveryExportForGood) {
  CurveMap map;
  const int kept = map.addCurve(straightCurve(2), 0);
  const int dropped = map.addCurve(straightCurve(2), 0);
  for (int k = 0; k < 3; ++k) {
    for (const int id : {kept, dropped}) observeSegments(&map, id, 0, 1, k);
    map.endKeyframe(k);
  }
  map.dropImplausible(dropped);
  observeSegments(&map, dropped, 0, 1, 3);
  map.endKeyframe(3);
  EXPECT_EQ(map.curve(dropped).state, CurveState::kImplausible);
  EXPECT_EQ(map.count(CurveState::kGlobal), 1);
  for (const CurveSelection selection : {CurveSelection::kGlobal, CurveSelection::kPromoted}) {
    EXPECT_EQ(map.exportCurves(selection).ids, std::vector<int>{kept});
  }
  EXPECT_THROW(map.dropImplausible(7), CheckError);
}

TEST(CurveMapOptions, ValidateNamesTheField) {
  CurveMapOptions options;
  options.disable_unseen_fraction = 1.0;
  EXPECT_THAT([&] { options.validate(); },
              testing::ThrowsMessage<InvalidOptions>(
                  testing::HasSubstr("CurveMapOptions.disable_unseen_fraction")));
  options = {};
  options.min_keyframe_translation = -1.0;
  EXPECT_THROW(CurveMap{options}, InvalidOptions);
}

}  // namespace
}  // namespace curvesfm
