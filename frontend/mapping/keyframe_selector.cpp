#include "frontend/mapping/keyframe_selector.h"

#include <cmath>

#include "core/angles.h"

namespace curvesfm {
namespace {

double rotationAngleDeg(const Pose3& a, const Pose3& b) {
  return a.rotation().angularDistance(b.rotation()) * kRadToDeg;
}

}  // namespace

KeyframeSelector::KeyframeSelector(const CurveMapOptions& options) : options_(options) {
  options_.validate();
}

bool KeyframeSelector::isKeyframe(const Pose3& cam_from_world, double length_unit) {
  const bool every_frame =
      options_.min_keyframe_translation == 0.0 && options_.min_keyframe_rotation_deg == 0.0;
  bool accept = !has_keyframe_ || every_frame;
  if (!accept) {
    accept = cameraCentreDistance(cam_from_world, last_keyframe_) >
                 options_.min_keyframe_translation * length_unit ||
             rotationAngleDeg(cam_from_world, last_keyframe_) > options_.min_keyframe_rotation_deg;
  }
  if (accept) {
    has_keyframe_ = true;
    last_keyframe_ = cam_from_world;
  }
  return accept;
}

}  // namespace curvesfm
