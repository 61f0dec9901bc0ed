#pragma once

#include <cstddef>
#include <vector>

#include "core/pose3.h"
#include "graph/factor_graph.h"
#include "graph/values.h"

namespace curvesfm {

// The camera poses of a bundle-adjustment graph, poseKey(0..n-1), as every builder lays them out.

/// Fixes the monocular scale: a CameraDistanceFactor between poseKey(0) and poseKey(1) at
/// `distance`, or at their starting distance when `distance` <= 0. Throws CheckError with fewer
/// than two poses.
void addScaleGauge(const std::vector<Pose3>& cam_from_world, double distance, double sigma,
                   FactorGraph* graph);

/// poseKey(0) .. poseKey(num_poses - 1) of `values`, in order.
std::vector<Pose3> extractPoses(const Values& values, std::size_t num_poses);

}  // namespace curvesfm
