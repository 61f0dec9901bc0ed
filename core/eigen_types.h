#pragma once

#include <Eigen/Core>

namespace curvesfm {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix23d = Eigen::Matrix<double, 2, 3>;
using Matrix26d = Eigen::Matrix<double, 2, 6>;
using Matrix32d = Eigen::Matrix<double, 3, 2>;
using Matrix36d = Eigen::Matrix<double, 3, 6>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

}  // namespace curvesfm
