#pragma once

#include "core/pose3.h"
#include "frontend/mapping/curve_map.h"

namespace curvesfm {

/// Decides which frames become keyframes, from their initial poses: CurveMapOptions'
/// min_keyframe_translation and min_keyframe_rotation_deg (the map's options, so that the flags
/// `--map-keyframe-*` keep their names).
class KeyframeSelector {
 public:
  /// Throws InvalidOptions on bad options.
  explicit KeyframeSelector(const CurveMapOptions& options = {});

  /// True for the first frame and for every frame that moved or turned enough since the last
  /// keyframe; a true answer makes `cam_from_world` the new reference. The translation threshold
  /// is min_keyframe_translation * length_unit (the unit of the poses; length_unit > 0).
  bool isKeyframe(const Pose3& cam_from_world, double length_unit = 1.0);

 private:
  CurveMapOptions options_;
  bool has_keyframe_ = false;
  Pose3 last_keyframe_;
};

}  // namespace curvesfm
