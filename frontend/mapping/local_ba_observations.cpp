#include "frontend/mapping/local_ba_observations.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <utility>

#include "core/check.h"

namespace curvesfm {
namespace {

// The keyframes to keep of one segment's sorted, distinct keyframes.
std::set<int> keptKeyframes(const std::vector<int>& keyframes, int max_keyframes,
                            int first_window_keyframe) {
  if (static_cast<int>(keyframes.size()) <= max_keyframes) {
    return {keyframes.begin(), keyframes.end()};
  }
  const auto window_begin =
      std::lower_bound(keyframes.begin(), keyframes.end(), first_window_keyframe);
  std::set<int> kept(window_begin, keyframes.end());
  const std::vector<int> older(keyframes.begin(), window_begin);
  const int picks = std::min<int>(max_keyframes - static_cast<int>(kept.size()),
                                  static_cast<int>(older.size()));
  for (int i = 0; i < picks; ++i) {
    const double position =
        picks == 1 ? 0.0 : static_cast<double>(i) * (older.size() - 1) / (picks - 1);
    kept.insert(older[static_cast<std::size_t>(std::lround(position))]);
  }
  return kept;
}

}  // namespace

std::vector<SegmentObservation> thinLocalObservations(
    const std::vector<SegmentObservation>& observations, int max_keyframes, int window,
    int newest_keyframe) {
  if (max_keyframes == 0) return observations;
  CURVESFM_CHECK(max_keyframes > window && window >= 1)
      << "keep more keyframes per curve (" << max_keyframes << ") than the window holds ("
      << window << ")";
  using Segment = std::pair<int, int>;  // (curve, segment)
  std::map<Segment, std::vector<int>> keyframes_of_segment;
  for (const SegmentObservation& o : observations) {
    keyframes_of_segment[{o.curve, o.segment}].push_back(o.keyframe);
  }
  std::map<Segment, std::set<int>> kept;
  for (auto& [segment, keyframes] : keyframes_of_segment) {
    std::sort(keyframes.begin(), keyframes.end());
    keyframes.erase(std::unique(keyframes.begin(), keyframes.end()), keyframes.end());
    kept[segment] = keptKeyframes(keyframes, max_keyframes, newest_keyframe - window + 1);
  }
  std::vector<SegmentObservation> thinned;
  for (const SegmentObservation& o : observations) {
    if (kept[{o.curve, o.segment}].count(o.keyframe) > 0) thinned.push_back(o);
  }
  return thinned;
}

}  // namespace curvesfm
