#pragma once

#include <vector>

#include "core/segment_observation.h"

namespace curvesfm {

/// Bounds what one local BA costs per curve on a long sequence. With the poses held, a curve's
/// old observations add little to one more refinement, but every one of them is evaluated in
/// every LM iteration, so without a bound a keyframe's local BA grows with the track lengths
/// (a 1,000-frame orbit whose curves stay in view over 300 keyframes reached 2.4 s a keyframe
/// at keyframe 200). Keeps, per curve segment seen in more than `max_keyframes` keyframes, its
/// observations in the window's keyframes (index > newest_keyframe - window) and in
/// max_keyframes minus that many of its older keyframes spread evenly over them, the oldest
/// among them, so that the kept baseline stays as wide as the track's; per segment, so that
/// every segment keeps observations. The input's order stays. max_keyframes 0 keeps everything;
/// otherwise it must exceed `window` (CheckError).
std::vector<SegmentObservation> thinLocalObservations(
    const std::vector<SegmentObservation>& observations, int max_keyframes, int window,
    int newest_keyframe);

}  // namespace curvesfm
