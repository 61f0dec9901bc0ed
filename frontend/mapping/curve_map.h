#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/bezier.h"
#include "core/enum_names.h"
#include "core/pose3.h"
#include "core/segment_observation.h"
#include "frontend/image/correspondence_checks.h"

namespace curvesfm {

// The temporary and global curve maps of paper §3.3 (DESIGN.md "Correspondences and maps"). Plain
// data: the map knows keyframes only by index and holds no image, field or graph; the pipeline
// measures, the map keeps the books.

/// Map management and keyframe selection.
struct CurveMapOptions {
  /// A temporary curve moves to the global map once it has been registered in at least this
  /// many distinct keyframes (count, its initialisation keyframe included). In [1, 1000].
  int promotion_observations = 3;
  /// Length W of the window of recent keyframes over which a curve must stay visible
  /// (keyframes, the current one included). In [1, 1000].
  int disable_window_keyframes = 3;
  /// A curve is disabled when more than this fraction of its segments has no observation in the
  /// last disable_window_keyframes keyframes (unitless). In [0, 1); 0.5 is the paper's "more
  /// than half".
  double disable_unseen_fraction = 0.5;
  /// A frame becomes a keyframe when its initial camera centre is more than this far from the
  /// last keyframe's, in the length unit KeyframeSelector::isKeyframe is given: the pose unit
  /// (metres for this default) by default, the scene scale in the pipeline
  /// (PipelineOptions::scene_scale; its default there is defaultPipelineMapOptions()'s). >= 0
  /// and finite.
  double min_keyframe_translation = 0.01;
  /// ... or when its initial orientation differs from the last keyframe's by more than this
  /// angle (deg). In [0, 180]. Both thresholds 0 make every frame a keyframe.
  double min_keyframe_rotation_deg = 2.0;

  /// Throws InvalidOptions naming the field, its value and the constraint.
  void validate() const;
};

/// Where a curve stands (paper §3.3).
enum class CurveState {
  kTemporary,  ///< Newly initialised; registered in new keyframes but constrains no pose.
  kGlobal,     ///< Well observed; takes part in bundle adjustment.
  kDisabled,   ///< Mostly unseen lately; out of bundle adjustment until seen again.
  /// Dropped by the sanity checks (SanityOptions): out of bundle adjustment, re-association and
  /// the result for good.
  kImplausible,
};

template <>
struct EnumNames<CurveState> {
  static constexpr std::array<std::pair<CurveState, const char*>, 4> kNames = {{
      {CurveState::kTemporary, "temporary"},
      {CurveState::kGlobal, "global"},
      {CurveState::kDisabled, "disabled"},
      {CurveState::kImplausible, "implausible"},
  }};
};

/// One segment's registrations and what the checks compare new views against.
struct MapSegment {
  /// Verified observations in increasing keyframe order, at most one per keyframe.
  std::vector<ObservedSegmentAppearance> observations;
  ViewingDirectionMean viewing;  ///< Over all observations.
  /// Chord |Q_{i+1} - Q_i| when the segment was created (curve initialisation or extension):
  /// the segment-length regulariser's reference with
  /// CurveBundleAdjustmentOptions::length_from_creation, and the base of the chord ratio.
  double initial_chord = 0.0;

  /// The reference for the next check: the first observation's appearance (the paper stores
  /// the colour of the original observation) and the mean viewing direction.
  SegmentHistory history() const;
  /// True if the segment was registered in keyframe `keyframe`.
  bool observedIn(int keyframe) const;
  /// True if the segment has an observation in keyframes [first, last].
  bool observedBetween(int first, int last) const;
};

/// One curve of the map with its per-segment bookkeeping.
struct MapCurve {
  PolyBezier curve;                  ///< World frame.
  std::vector<MapSegment> segments;  ///< One per curve segment.
  CurveState state = CurveState::kTemporary;
  /// Reached the global map at some point (a disabled curve returns to this state when seen).
  bool promoted = false;
  int first_keyframe = 0;  ///< Keyframe that initialised it.

  /// Distinct keyframes in which at least one segment was registered.
  int observedKeyframes() const;
  /// True if some segment was registered in `keyframe`.
  bool observedIn(int keyframe) const;
};

/// Curves of the map renumbered 0..n-1 with their observations, as a bundle adjustment builder
/// takes them (SegmentObservation::curve indexes `curves`).
struct ExportedCurves {
  std::vector<int> ids;            ///< Map id of each exported curve, increasing.
  std::vector<PolyBezier> curves;  ///< World frame.
  /// MapSegment::initial_chord per curve and segment.
  std::vector<std::vector<double>> initial_chords;
  std::vector<SegmentObservation> observations;
};

/// Which curves an export takes.
enum class CurveSelection {
  kGlobal,    ///< Curves in the global map now (local BA).
  kPromoted,  ///< Every curve that ever reached the global map, disabled ones too, implausible
              ///< ones not (global BA, the final result).
};

/// The temporary and global maps as one container of curves with a state each (paper §3.3):
/// curves are created temporary, promoted at promotion_observations, disabled when more than
/// disable_unseen_fraction of their segments went unseen over the last disable_window_keyframes
/// keyframes, and reactivated when seen again. Curve ids are indices and stay valid: curves are
/// never removed.
class CurveMap {
 public:
  /// Throws InvalidOptions on bad options.
  explicit CurveMap(const CurveMapOptions& options = {});

  const CurveMapOptions& options() const { return options_; }
  int size() const { return static_cast<int>(curves_.size()); }
  const MapCurve& curve(int id) const;
  /// Number of curves in `state`.
  int count(CurveState state) const;
  /// Ids of the curves in `state`, increasing.
  std::vector<int> curvesIn(CurveState state) const;

  /// Adds a temporary curve initialised in `keyframe`, without observations; returns its id.
  int addCurve(const PolyBezier& curve, int keyframe);
  /// Records that segment `segment` of curve `id` was registered in `observation.keyframe`, with
  /// the appearance and viewing direction measured there. Observations stay in keyframe order
  /// (re-association adds earlier keyframes); a second registration in the same keyframe is
  /// ignored. Throws CheckError on a bad id, segment or a negative keyframe.
  void addObservation(int id, int segment, const ObservedSegmentAppearance& observation);

  /// Replaces curve `id` by `extended`, the same curve continued at `end` by new segments
  /// (extendCurve): the new segments start without observations, and the observations of the
  /// existing ones move with them when the curve grows at the front. The state is kept. Throws
  /// CheckError on a bad id or unless `extended` has more segments than the curve.
  void extendCurve(int id, const PolyBezier& extended, CurveEnd end);

  /// Ends keyframe `keyframe` (all its observations added): disabled curves seen in it are
  /// reactivated (to the global map if they had been promoted), temporary curves with enough
  /// observations promoted, and curves that went mostly unseen disabled. A curve seen in this
  /// keyframe after being disabled is not disabled again before the next keyframe. A curve
  /// younger than the window is judged on the keyframes it has existed for.
  void endKeyframe(int keyframe);

  /// Drops curve `id` from the map for good (CurveState::kImplausible): no export, no
  /// registration, no state change at endKeyframe. Its id stays valid. Throws CheckError on a bad
  /// id.
  void dropImplausible(int id);

  /// The selected curves (renumbered 0..n-1 in increasing id) and their observations.
  ExportedCurves exportCurves(CurveSelection selection) const;
  /// Replaces the geometry of curves `ids` (ExportedCurves::ids) by `curves` (e.g. the curves a
  /// bundle adjustment refined). Throws CheckError on mismatched sizes or segment counts.
  void updateCurves(const std::vector<int>& ids, const std::vector<PolyBezier>& curves);

 private:
  bool mostlyUnseen(const MapCurve& curve, int keyframe) const;

  CurveMapOptions options_;
  std::vector<MapCurve> curves_;
};

}  // namespace curvesfm
