#pragma once

namespace curvesfm {

/// Segment `segment` of curve `curve` is seen in keyframe `keyframe`: the pair gets one curve
/// reprojection term (paper §3.1, the indicator 1_ij of E_geo).
struct SegmentObservation {
  int curve = 0;
  int segment = 0;
  int keyframe = 0;
};

}  // namespace curvesfm
