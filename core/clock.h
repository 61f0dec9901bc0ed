#pragma once

#include <chrono>

namespace curvesfm {

/// The clock of every timing curvesfm reports: monotonic, so a wall-clock change cannot make a
/// stage take negative time.
using Clock = std::chrono::steady_clock;

/// Seconds elapsed since `start` (a Clock::now() taken earlier).
inline double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace curvesfm
