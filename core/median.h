#pragma once

#include <algorithm>
#include <vector>

namespace curvesfm {

/// The middle value of `values` (copied; the upper of the middle two for an even count), 0 when
/// empty: a robust typical value (scale, spacing, depth), in linear time by nth_element.
inline double upperMedian(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace curvesfm
