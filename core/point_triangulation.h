#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/pose3.h"

namespace curvesfm {

// Triangulation of one 3D point from its observations in two or more calibrated views, and the
// measures the initialiser gates it by (COLMAP's triangulator: angle, cheirality, reprojection;
// ../shared/reviews/initialiser_anchors.md A.5 item 7).
//
// Units: normalized image coordinates (x / z, y / z of the undistorted ray) in, points in the
// world frame of the poses out.

/// The linear (DLT) point minimising the algebraic error of x_i ~ P_i X over every view, with
/// P_i = [R_i | t_i] = cam_from_world[i]: the right singular vector of the stacked 2n x 4 system.
/// Returns false (and leaves `point` alone) with fewer than two views, when the sizes differ or
/// when the solution is at infinity (its homogeneous w is ~0: the rays are parallel).
bool triangulateDlt(const std::vector<Pose3>& cam_from_world,
                    const std::vector<Eigen::Vector2d>& normalized, Eigen::Vector3d* point);

/// Gauss-Newton on `point` alone, the poses held: minimises the sum of squared normalized
/// reprojection errors (x / z - u, y / z - v) over every view, from `point` as the start (a DLT
/// point, say). A point the given poses place from two of its views only carries those two
/// views' errors; the least squares over all of them averages every view's (the structure-only
/// step of COLMAP's and ORB-SLAM's triangulation at known poses). Returns false (and leaves
/// `point` alone) with fewer than two views, when the sizes differ, when a view would see the
/// point behind it or the normal equations are singular (parallel rays).
bool refinePointAtPoses(const std::vector<Pose3>& cam_from_world,
                        const std::vector<Eigen::Vector2d>& normalized, Eigen::Vector3d* point);

/// The largest angle at `point` between the rays from any two of the camera centres (deg): the
/// best baseline the observations offer. 0 with fewer than two centres.
double maxTriangulationAngleDeg(const std::vector<Eigen::Vector3d>& centres,
                                const Eigen::Vector3d& point);

/// The angle at `point` between the rays from centres a and b (deg), in [0, 180].
double triangulationAngleDeg(const Eigen::Vector3d& centre_a, const Eigen::Vector3d& centre_b,
                             const Eigen::Vector3d& point);

}  // namespace curvesfm
