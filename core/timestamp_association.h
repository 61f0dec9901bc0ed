#pragma once

#include <vector>

#include "core/dataset_io.h"

namespace curvesfm {

/// One estimated pose paired with the ground-truth pose nearest in time.
struct TimestampMatch {
  int estimate_index = 0;      ///< Index into the estimated trajectory.
  int ground_truth_index = 0;  ///< Index into the ground-truth trajectory.
};

/// Pairs estimated and ground-truth poses one-to-one by timestamp, as TUM's associate.py: among
/// all pairs with |t_estimate - t_ground_truth| <= max_dt, the closest in time are taken first and
/// each pose is used at most once. Neither trajectory needs to be sorted. Returns the matches in
/// the estimate's time order (ties by file order). max_dt must be finite and >= 0 (CheckError).
std::vector<TimestampMatch> associateByTimestamp(const std::vector<StampedPose>& estimate,
                                                 const std::vector<StampedPose>& ground_truth,
                                                 double max_dt);

}  // namespace curvesfm
