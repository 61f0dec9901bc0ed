#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/camera.h"
#include "core/pose3.h"

namespace curvesfm {

// A solid, upright cylinder standing on the plane of a planar scene (sim/planar_scene.h, world
// z up): its two silhouette lines are occluding contours, edges whose 3D position moves over the
// cylinder's surface as the camera moves, in front of a textured background that changes from
// view to view; its top rim is a real 3D circle. The scene a curve-based method must not be
// biased by (issue 14).
struct OccludingCylinder {
  Eigen::Vector2d base_centre = Eigen::Vector2d::Zero();  ///< On the plane z = 0 (m).
  double radius = 0.05;                                   ///< (m); > 0.
  double height = 0.2;                                    ///< Top at z = height (m); > 0.
  /// Colour of a surface facing the light (B, G, R; 0-255); the side is shaded by the cosine
  /// to a fixed light, so the shading varies smoothly around it and forms no edge.
  cv::Scalar colour = cv::Scalar(60, 90, 220);
};

/// Paints the cylinder over `view` (CV_8UC1 or CV_8UC3 of the camera's size, as rendered by
/// renderPlanarView) as `camera` at `cam_from_world` sees it: each pixel is covered by the
/// fraction of 4 x 4 sub-pixel rays that hit the cylinder (anti-aliased silhouettes), blended
/// with what is there. The camera must be distortion-free and see the cylinder from outside.
/// CheckError for a view of another size or type, or a non-positive radius or height.
void paintOccludingCylinder(const OccludingCylinder& cylinder, const Camera& camera,
                            const Pose3& cam_from_world, cv::Mat* view);

}  // namespace curvesfm
