#pragma once

#include <cmath>

namespace curvesfm {

/// Degrees to radians and back: options and reports speak degrees, the maths radians.
inline constexpr double kDegToRad = M_PI / 180.0;
inline constexpr double kRadToDeg = 180.0 / M_PI;

}  // namespace curvesfm
