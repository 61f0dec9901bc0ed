#pragma once

#include <vector>

#include "core/pose3.h"
#include "graph/factor_graph.h"

namespace curvesfm {

/// Fixes the monocular scale: a CameraDistanceFactor between poseKey(0) and poseKey(1) at
/// `distance`, or at their starting distance when `distance` <= 0. Throws CheckError with fewer
/// than two poses.
void addScaleGauge(const std::vector<Pose3>& cam_from_world, double distance, double sigma,
                   FactorGraph* graph);

}  // namespace curvesfm
