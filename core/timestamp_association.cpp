#include "core/timestamp_association.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>

#include "core/check.h"

namespace curvesfm {
namespace {

struct Candidate {
  double dt;
  int estimate_index;
  int ground_truth_index;
};

// Every (estimate, ground truth) pair within max_dt, found by a binary search in the
// ground-truth stamps so that long trajectories do not cost |estimate| * |ground truth|.
std::vector<Candidate> candidatePairs(const std::vector<StampedPose>& estimate,
                                      const std::vector<StampedPose>& ground_truth, double max_dt) {
  std::vector<int> by_time(ground_truth.size());
  std::iota(by_time.begin(), by_time.end(), 0);
  const auto earlier = [&](int a, int b) {
    return ground_truth[a].timestamp < ground_truth[b].timestamp;
  };
  std::stable_sort(by_time.begin(), by_time.end(), earlier);
  std::vector<Candidate> candidates;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const double t = estimate[i].timestamp;
    auto it =
        std::lower_bound(by_time.begin(), by_time.end(), t - max_dt,
                         [&](int g, double value) { return ground_truth[g].timestamp < value; });
    for (; it != by_time.end() && ground_truth[*it].timestamp <= t + max_dt; ++it) {
      const double dt = std::abs(ground_truth[*it].timestamp - t);
      if (dt <= max_dt) candidates.push_back({dt, static_cast<int>(i), *it});
    }
  }
  return candidates;
}

}  // namespace

std::vector<TimestampMatch> associateByTimestamp(const std::vector<StampedPose>& estimate,
                                                 const std::vector<StampedPose>& ground_truth,
                                                 double max_dt) {
  CURVESFM_CHECK(std::isfinite(max_dt) && max_dt >= 0.0) << "max_dt = " << max_dt;
  std::vector<Candidate> candidates = candidatePairs(estimate, ground_truth, max_dt);
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return std::tie(a.dt, a.estimate_index, a.ground_truth_index) <
           std::tie(b.dt, b.estimate_index, b.ground_truth_index);
  });
  std::vector<bool> estimate_used(estimate.size(), false);
  std::vector<bool> ground_truth_used(ground_truth.size(), false);
  std::vector<TimestampMatch> matches;
  for (const Candidate& c : candidates) {
    if (estimate_used[c.estimate_index] || ground_truth_used[c.ground_truth_index]) continue;
    estimate_used[c.estimate_index] = true;
    ground_truth_used[c.ground_truth_index] = true;
    matches.push_back({c.estimate_index, c.ground_truth_index});
  }
  std::sort(matches.begin(), matches.end(), [&](const TimestampMatch& a, const TimestampMatch& b) {
    return std::make_pair(estimate[a.estimate_index].timestamp, a.estimate_index) <
           std::make_pair(estimate[b.estimate_index].timestamp, b.estimate_index);
  });
  return matches;
}

}  // namespace curvesfm
