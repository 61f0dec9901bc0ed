#pragma once

#include <random>

#include "core/pose3.h"
#include "core/so3.h"

namespace curvesfm::testing {

/// A pose with a rotation vector and a translation of standard normal entries: far from the
/// identity, so that Jacobian checks do not sit on a special case.
inline Pose3 randomPose(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Pose3(so3::exp(Eigen::Vector3d(n(rng), n(rng), n(rng))),
               Eigen::Vector3d(n(rng), n(rng), n(rng)));
}

}  // namespace curvesfm::testing
