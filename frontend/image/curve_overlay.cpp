#include "frontend/image/curve_overlay.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <string>

#include "core/check.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

// Sub-pixel drawing: OpenCV takes fixed-point coordinates with this many fractional bits.
constexpr int kShiftBits = 4;
constexpr double kShiftScale = 1 << kShiftBits;

cv::Point toFixedPoint(const Eigen::Vector2d& pixel) {
  return {cvRound(pixel.x() * kShiftScale), cvRound(pixel.y() * kShiftScale)};
}

// Far outside the image a projection is numerically meaningless (near the camera plane it grows
// without bound) and would overflow OpenCV's fixed-point coordinates.
bool nearImage(const Camera& camera, const Eigen::Vector2d& pixel) {
  return camera.isInImage(pixel, -std::max(camera.width(), camera.height()));
}

// Splits one curve's projected samples into runs that can be drawn as polylines.
std::vector<std::vector<cv::Point>> projectRuns(const std::vector<Eigen::Vector3d>& samples,
                                                const Camera& camera, const Pose3& cam_from_world,
                                                CurveOverlayCounts* counts) {
  std::vector<std::vector<cv::Point>> runs(1);
  for (const Eigen::Vector3d& x_in_world : samples) {
    Eigen::Vector2d pixel;
    const bool in_front = camera.project(cam_from_world * x_in_world, &pixel);
    if (!in_front || !nearImage(camera, pixel)) {
      ++(in_front ? counts->far_outside : counts->behind_camera);
      if (!runs.back().empty()) runs.emplace_back();
      continue;
    }
    ++counts->drawn_samples;
    runs.back().push_back(toFixedPoint(pixel));
  }
  return runs;
}

void drawPoints(cv::Mat* image, const PolyBezier& curve, const cv::Scalar& colour,
                const Camera& camera, const Pose3& cam_from_world,
                const CurveOverlayOptions& options) {
  for (const Eigen::Vector3d& q : curve.points()) {
    Eigen::Vector2d pixel;
    if (!camera.project(cam_from_world * q, &pixel) || !camera.isInImage(pixel)) continue;
    cv::circle(*image, toFixedPoint(pixel), static_cast<int>(options.point_radius_px * kShiftScale),
               colour, 1, cv::LINE_AA, kShiftBits);
  }
}

}  // namespace

void CurveOverlayOptions::validate() const {
  const OptionCheck require("CurveOverlayOptions");
  require(samples_per_segment >= 1 && samples_per_segment <= 1000, "samples_per_segment",
          samples_per_segment, "in [1, 1000]");
  require(thickness_px >= 1 && thickness_px <= 50, "thickness_px", thickness_px, "in [1, 50]");
  require(point_radius_px >= 0 && point_radius_px <= 50, "point_radius_px", point_radius_px,
          "in [0, 50]");
}

CurveOverlayCounts drawCurves(cv::Mat* image_bgr, const std::vector<PolyBezier>& curves,
                              const Camera& camera, const Pose3& cam_from_world,
                              const CurveOverlayOptions& options) {
  return drawCurves(image_bgr, curves, std::vector<cv::Scalar>(curves.size(), options.colour),
                    camera, cam_from_world, options);
}

CurveOverlayCounts drawCurves(cv::Mat* image_bgr, const std::vector<PolyBezier>& curves,
                              const std::vector<cv::Scalar>& colours_bgr, const Camera& camera,
                              const Pose3& cam_from_world, const CurveOverlayOptions& options) {
  options.validate();
  CURVESFM_CHECK(image_bgr && image_bgr->type() == CV_8UC3 && image_bgr->cols == camera.width() &&
                 image_bgr->rows == camera.height())
      << "expected a CV_8UC3 image of " << camera.width() << "x" << camera.height();
  CURVESFM_CHECK(colours_bgr.size() == curves.size())
      << colours_bgr.size() << " colours for " << curves.size() << " curves";
  CurveOverlayCounts counts;
  for (std::size_t c = 0; c < curves.size(); ++c) {
    const auto runs =
        projectRuns(curves[c].sample(options.samples_per_segment), camera, cam_from_world, &counts);
    for (const std::vector<cv::Point>& run : runs) {
      if (run.size() < 2) continue;
      cv::polylines(*image_bgr, run, false, colours_bgr[c], options.thickness_px, cv::LINE_AA,
                    kShiftBits);
    }
    if (options.point_radius_px > 0) {
      drawPoints(image_bgr, curves[c], colours_bgr[c], camera, cam_from_world, options);
    }
  }
  return counts;
}

}  // namespace curvesfm
