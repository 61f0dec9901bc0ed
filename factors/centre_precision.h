#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/pose3.h"

namespace curvesfm {

/// The rms error of the camera centres after a Sim(3) alignment (the ATE's metric) that an
/// estimate with information `pose_information` on the poses `cam_from_world` leaves, to first
/// order: the Cramér-Rao bound of the centres. `pose_information` is 6 rows per pose in Pose3's
/// tangent (rotation, then translation: retract), in pixels' information units already divided by
/// the noise variance. It is inverted outside the seven similarity directions (the gauge), and
/// the similarity's centre moves are projected out of what remains. Infinite when it leaves
/// more than the similarity free (a pose nothing observes, poses that share nothing); 0 for fewer
/// than three poses (a similarity fits two centres exactly). In the poses' length unit.
double predictedCentreAteFromInformation(const Eigen::MatrixXd& pose_information,
                                         const std::vector<Pose3>& cam_from_world);

}  // namespace curvesfm
