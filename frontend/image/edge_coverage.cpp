#include "frontend/image/edge_coverage.h"

#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "core/check.h"
#include "core/errors.h"
#include "core/nearest_edge_field.h"

namespace curvesfm {

void EdgeCoverageOptions::validate() const {
  const OptionCheck require("EdgeCoverageOptions");
  require(max_edge_distance_px > 0.0 && max_edge_distance_px <= 100.0, "max_edge_distance_px",
          max_edge_distance_px, "in (0, 100]");
  require(max_normal_angle_deg > 0.0 && max_normal_angle_deg <= 90.0, "max_normal_angle_deg",
          max_normal_angle_deg, "in (0, 90]");
  edges.validate();
}

EdgeCoverageCounter::EdgeCoverageCounter(std::vector<Eigen::Vector3d> points,
                                         std::vector<Eigen::Vector3d> directions,
                                         const EdgeCoverageOptions& options)
    : points_(std::move(points)),
      directions_(std::move(directions)),
      options_(options),
      views_(points_.size()) {
  options_.validate();
  CURVESFM_CHECK(points_.size() == directions_.size())
      << "edge coverage: " << points_.size() << " points, " << directions_.size() << " directions";
}

namespace {

// Distance of every pixel centre to the nearest pixel the curves' projections cross (px); +inf
// everywhere without curves.
cv::Mat distanceToCurves(const Polylines3& curves, const Pose3& cam_from_world,
                         const Camera& camera) {
  constexpr int kShift = 4;  // Sub-pixel bits of cv::line.
  const auto fixed = [](const Eigen::Vector2d& p) {
    return cv::Point(static_cast<int>(std::lround(p.x() * (1 << kShift))),
                     static_cast<int>(std::lround(p.y() * (1 << kShift))));
  };
  // Far outside the image a segment is not drawn: cv::line's fixed point would overflow.
  const double limit = 4.0 * (camera.width() + camera.height());
  cv::Mat crossed(camera.height(), camera.width(), CV_8UC1, cv::Scalar(0));
  bool any = false;
  for (const auto& polyline : curves) {
    for (std::size_t i = 0; i + 1 < polyline.size(); ++i) {
      Eigen::Vector2d a, b;
      if (!camera.project(cam_from_world * polyline[i], &a) ||
          !camera.project(cam_from_world * polyline[i + 1], &b)) {
        continue;
      }
      if (a.cwiseAbs().maxCoeff() > limit || b.cwiseAbs().maxCoeff() > limit) continue;
      cv::line(crossed, fixed(a), fixed(b), cv::Scalar(255), 1, cv::LINE_8, kShift);
      any = true;
    }
  }
  cv::Mat distance;
  if (!any)
    return cv::Mat(crossed.size(), CV_32F, cv::Scalar(std::numeric_limits<float>::infinity()));
  cv::distanceTransform(crossed == 0, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  return distance;
}

}  // namespace

void EdgeCoverageCounter::addView(const cv::Mat& image, const Pose3& cam_from_world,
                                  const Camera& camera) {
  CURVESFM_CHECK(image.cols == camera.width() && image.rows == camera.height())
      << "edge coverage: a " << image.cols << "x" << image.rows << " image for a "
      << camera.width() << "x" << camera.height() << " camera";
  const EdgeImage edges = detectEdges(image, options_.edges);
  NearestEdgeFieldOptions reach;
  reach.max_distance_px = static_cast<int>(std::ceil(options_.max_edge_distance_px));
  const NearestEdgeField field =
      NearestEdgeField::build(edges.edges, edges.grad_x, edges.grad_y, reach);
  const double sin_max_angle = std::sin(options_.max_normal_angle_deg * M_PI / 180.0);
  const Eigen::Matrix3d R = cam_from_world.rotationMatrix();
  const cv::Mat curve_distance = distanceToCurves(nearby_curves_, cam_from_world, camera);
  for (std::size_t i = 0; i < points_.size(); ++i) {
    Eigen::Vector2d pixel;
    Matrix23d d_pixel;
    if (!camera.project(cam_from_world * points_[i], &pixel, &d_pixel)) continue;
    if (!field.contains(pixel.x(), pixel.y())) continue;
    ++views_[i].in_image;
    // The pixel whose centre is nearest, as the field rounds (contains() keeps it inside).
    const int column = static_cast<int>(pixel.x() + 0.5);
    const int row = static_cast<int>(pixel.y() + 0.5);
    if (curve_distance.at<float>(row, column) <= options_.max_edge_distance_px) {
      ++views_[i].near_curve;
    }
    const EdgePixel* edge = field.nearestToPixel(column, row);
    if (!edge || (edge->pixel.cast<double>() - Eigen::Vector2d(column, row)).norm() >
                     options_.max_edge_distance_px) {
      continue;
    }
    // The edge normal must be nearly normal to the projected curve: |n . t| <= sin(angle) |t|.
    const Eigen::Vector2d tangent = d_pixel * (R * directions_[i]);
    if (std::abs(edge->normal.cast<double>().dot(tangent)) <= sin_max_angle * tangent.norm()) {
      ++views_[i].on_edge;
    }
  }
  ++num_views_;
}

}  // namespace curvesfm
