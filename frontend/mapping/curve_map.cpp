#include "frontend/mapping/curve_map.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "core/errors.h"

namespace curvesfm {
void CurveMapOptions::validate() const {
  const OptionCheck require("CurveMapOptions");
  require(promotion_observations >= 1 && promotion_observations <= 1000, "promotion_observations",
          promotion_observations, "in [1, 1000]");
  require(disable_window_keyframes >= 1 && disable_window_keyframes <= 1000,
          "disable_window_keyframes", disable_window_keyframes, "in [1, 1000]");
  require(disable_unseen_fraction >= 0.0 && disable_unseen_fraction < 1.0,
          "disable_unseen_fraction", disable_unseen_fraction, "in [0, 1)");
  require(std::isfinite(min_keyframe_translation) && min_keyframe_translation >= 0.0,
          "min_keyframe_translation", min_keyframe_translation, "must be finite and >= 0");
  require(min_keyframe_rotation_deg >= 0.0 && min_keyframe_rotation_deg <= 180.0,
          "min_keyframe_rotation_deg", min_keyframe_rotation_deg, "in [0, 180]");
}

SegmentHistory MapSegment::history() const {
  SegmentHistory history;
  if (!observations.empty()) history.reference_appearance = observations.front().appearance;
  history.mean_viewing_direction_in_world = viewing.mean();
  return history;
}

bool MapSegment::observedIn(int keyframe) const { return observedBetween(keyframe, keyframe); }

bool MapSegment::observedBetween(int first, int last) const {
  // Observations are in keyframe order, and recent keyframes are what callers ask about.
  for (auto it = observations.rbegin(); it != observations.rend(); ++it) {
    const int k = it->observation.keyframe;
    if (k < first) return false;
    if (k <= last) return true;
  }
  return false;
}

int MapCurve::observedKeyframes() const {
  std::vector<int> keyframes;
  for (const MapSegment& segment : segments) {
    for (const ObservedSegmentAppearance& o : segment.observations) {
      keyframes.push_back(o.observation.keyframe);
    }
  }
  std::sort(keyframes.begin(), keyframes.end());
  return static_cast<int>(std::unique(keyframes.begin(), keyframes.end()) - keyframes.begin());
}

bool MapCurve::observedIn(int keyframe) const {
  return std::any_of(segments.begin(), segments.end(),
                     [keyframe](const MapSegment& s) { return s.observedIn(keyframe); });
}

CurveMap::CurveMap(const CurveMapOptions& options) : options_(options) { options_.validate(); }

const MapCurve& CurveMap::curve(int id) const {
  CURVESFM_CHECK(id >= 0 && id < size())
      << "curve id " << id << " out of range (" << size() << " curves)";
  return curves_[id];
}

int CurveMap::count(CurveState state) const {
  return static_cast<int>(std::count_if(curves_.begin(), curves_.end(),
                                        [state](const MapCurve& c) { return c.state == state; }));
}

std::vector<int> CurveMap::curvesIn(CurveState state) const {
  std::vector<int> ids;
  for (int id = 0; id < size(); ++id) {
    if (curves_[id].state == state) ids.push_back(id);
  }
  return ids;
}

namespace {

// Segments without observations, with the chords of `curve`'s segments [first, first + count).
std::vector<MapSegment> newSegments(const PolyBezier& curve, int first, int count) {
  std::vector<MapSegment> segments(count);
  for (int i = 0; i < count; ++i) {
    segments[i].initial_chord = (curve.points()[first + i + 1] - curve.points()[first + i]).norm();
  }
  return segments;
}

}  // namespace

int CurveMap::addCurve(const PolyBezier& curve, int keyframe) {
  curves_.push_back(MapCurve{curve, newSegments(curve, 0, curve.numSegments()),
                             CurveState::kTemporary, false, keyframe});
  return size() - 1;
}

void CurveMap::addObservation(int id, int segment, const ObservedSegmentAppearance& observation) {
  curve(id);
  MapCurve& c = curves_[id];
  CURVESFM_CHECK(segment >= 0 && segment < c.curve.numSegments())
      << "segment " << segment << " of curve " << id << " out of range (" << c.curve.numSegments()
      << " segments)";
  MapSegment& s = c.segments[segment];
  const int keyframe = observation.observation.keyframe;
  CURVESFM_CHECK(keyframe >= 0) << "observation of curve " << id << " segment " << segment
                                << " in keyframe " << keyframe;
  // Usually the newest keyframe; re-association after bundle adjustment adds earlier ones.
  const auto at = std::lower_bound(
      s.observations.begin(), s.observations.end(), keyframe,
      [](const ObservedSegmentAppearance& o, int k) { return o.observation.keyframe < k; });
  if (at != s.observations.end() && at->observation.keyframe == keyframe) return;
  ObservedSegmentAppearance stored = observation;
  stored.observation.curve = id;
  stored.observation.segment = segment;
  s.observations.insert(at, stored);
  s.viewing.add(observation.viewing_direction_in_world);
}

void CurveMap::extendCurve(int id, const PolyBezier& extended, CurveEnd end) {
  curve(id);
  MapCurve& c = curves_[id];
  const int added = extended.numSegments() - c.curve.numSegments();
  CURVESFM_CHECK(added > 0) << "extending curve " << id << " of " << c.curve.numSegments()
                            << " segments to " << extended.numSegments() << " segments";
  const bool front = end == CurveEnd::kFront;
  const std::vector<MapSegment> segments =
      newSegments(extended, front ? 0 : c.curve.numSegments(), added);
  c.segments.insert(front ? c.segments.begin() : c.segments.end(), segments.begin(),
                    segments.end());
  c.curve = extended;
  if (end == CurveEnd::kBack) return;
  for (int i = added; i < c.curve.numSegments(); ++i) {
    for (ObservedSegmentAppearance& o : c.segments[i].observations) o.observation.segment = i;
  }
}

void CurveMap::dropImplausible(int id) {
  curve(id);
  curves_[id].state = CurveState::kImplausible;
}

bool CurveMap::mostlyUnseen(const MapCurve& curve, int keyframe) const {
  const int first =
      std::max(curve.first_keyframe, keyframe - options_.disable_window_keyframes + 1);
  int unseen = 0;
  for (const MapSegment& s : curve.segments) unseen += !s.observedBetween(first, keyframe);
  return unseen > options_.disable_unseen_fraction * curve.curve.numSegments();
}

void CurveMap::endKeyframe(int keyframe) {
  for (MapCurve& c : curves_) {
    if (c.state == CurveState::kImplausible) continue;
    if (c.state == CurveState::kDisabled) {
      if (c.observedIn(keyframe))
        c.state = c.promoted ? CurveState::kGlobal : CurveState::kTemporary;
      continue;
    }
    if (c.state == CurveState::kTemporary &&
        c.observedKeyframes() >= options_.promotion_observations) {
      c.state = CurveState::kGlobal;
      c.promoted = true;
    }
    if (mostlyUnseen(c, keyframe)) c.state = CurveState::kDisabled;
  }
}

ExportedCurves CurveMap::exportCurves(CurveSelection selection) const {
  ExportedCurves exported;
  for (int id = 0; id < size(); ++id) {
    const MapCurve& c = curves_[id];
    const bool selected = selection == CurveSelection::kGlobal
                              ? c.state == CurveState::kGlobal
                              : c.promoted && c.state != CurveState::kImplausible;
    if (!selected) continue;
    const int index = static_cast<int>(exported.ids.size());
    exported.ids.push_back(id);
    exported.curves.push_back(c.curve);
    std::vector<double>& chords = exported.initial_chords.emplace_back();
    for (const MapSegment& s : c.segments) chords.push_back(s.initial_chord);
    for (int i = 0; i < c.curve.numSegments(); ++i) {
      for (const ObservedSegmentAppearance& o : c.segments[i].observations) {
        exported.observations.push_back({index, i, o.observation.keyframe});
      }
    }
  }
  return exported;
}

void CurveMap::updateCurves(const std::vector<int>& ids, const std::vector<PolyBezier>& curves) {
  CURVESFM_CHECK(ids.size() == curves.size())
      << ids.size() << " curve ids but " << curves.size() << " curves";
  for (std::size_t i = 0; i < ids.size(); ++i) {
    curve(ids[i]);
    MapCurve& c = curves_[ids[i]];
    CURVESFM_CHECK(c.curve.numSegments() == curves[i].numSegments())
        << "curve " << ids[i] << " has " << c.curve.numSegments() << " segments, its update "
        << curves[i].numSegments();
    c.curve = curves[i];
  }
}

}  // namespace curvesfm
