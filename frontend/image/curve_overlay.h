#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "core/bezier.h"
#include "core/camera.h"
#include "core/pose3.h"

namespace curvesfm {

/// How drawCurves() renders the reprojected curves.
struct CurveOverlayOptions {
  /// Samples per cubic segment of the drawn polyline (PolyBezier::sample); more give smoother
  /// curves on screen. In [1, 1000].
  int samples_per_segment = 16;
  /// Line colour (B, G, R; 0-255 each) when every curve takes the same one.
  cv::Scalar colour = cv::Scalar(0, 255, 0);
  /// Line thickness (px). In [1, 50].
  int thickness_px = 1;
  /// Also mark every shared point Q_i with a small circle of this radius (px), so segment
  /// boundaries are visible; 0 draws none. In [0, 50].
  int point_radius_px = 2;

  /// Throws InvalidOptions naming the field, its value and the constraint.
  void validate() const;
};

/// What drawCurves() did with the samples.
struct CurveOverlayCounts {
  int drawn_samples = 0;  ///< Samples that projected in front of the camera.
  int behind_camera = 0;  ///< Samples at depth <= Camera::kMinDepth: skipped, line broken.
  int far_outside = 0;    ///< Samples projecting far outside the image: skipped, line broken.
};

/// Draws `curves` (world frame) as seen from `cam_from_world` through `camera` onto `image_bgr`
/// (CV_8UC3 of the camera's size; CheckError otherwise): each curve is sampled densely, the
/// samples are projected (distortion included, so use the camera the image was taken with) and
/// consecutive projected samples are joined by anti-aliased lines. A sample behind the camera,
/// or projecting more than one image size outside the image, breaks the polyline there instead
/// of drawing a line across the image. Throws InvalidOptions for bad options.
CurveOverlayCounts drawCurves(cv::Mat* image_bgr, const std::vector<PolyBezier>& curves,
                              const Camera& camera, const Pose3& cam_from_world,
                              const CurveOverlayOptions& options = {});

/// As above, each curve in its own colour: `colours_bgr[c]` for `curves[c]` (one per curve;
/// CheckError otherwise), e.g. a statistic of the curve through colourMapBgr (colour_map.h);
/// options.colour is not used.
CurveOverlayCounts drawCurves(cv::Mat* image_bgr, const std::vector<PolyBezier>& curves,
                              const std::vector<cv::Scalar>& colours_bgr, const Camera& camera,
                              const Pose3& cam_from_world, const CurveOverlayOptions& options = {});

}  // namespace curvesfm
