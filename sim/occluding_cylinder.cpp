#include "sim/occluding_cylinder.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/check.h"

namespace curvesfm {
namespace {

constexpr int kSubsamples = 4;  // Per pixel side.

// Brightness of a surface with outward normal n: ambient plus a Lambertian term.
double shade(const Eigen::Vector3d& normal) {
  const Eigen::Vector3d light = Eigen::Vector3d(0.6, -0.5, 0.8).normalized();
  return 0.35 + 0.65 * std::max(0.0, normal.dot(light));
}

// The brightness seen along the ray centre + s * direction (world frame), or none if it misses:
// the nearest hit on the side or on the top disk.
std::optional<double> traceRay(const OccludingCylinder& c, const Eigen::Vector3d& centre,
                               const Eigen::Vector3d& direction) {
  const Eigen::Vector2d o = centre.head<2>() - c.base_centre;
  const Eigen::Vector2d d = direction.head<2>();
  const double a = d.squaredNorm();
  const double b = 2.0 * o.dot(d);
  const double k = o.squaredNorm() - c.radius * c.radius;
  const double discriminant = b * b - 4.0 * a * k;
  if (a > 0.0 && discriminant >= 0.0) {
    const double s = (-b - std::sqrt(discriminant)) / (2.0 * a);
    const double z = centre.z() + s * direction.z();
    if (s > 0.0 && z >= 0.0 && z <= c.height) {
      const Eigen::Vector2d radial = (o + s * d) / c.radius;
      return shade(Eigen::Vector3d(radial.x(), radial.y(), 0.0));
    }
  }
  if (direction.z() >= 0.0) return std::nullopt;
  const double s = (c.height - centre.z()) / direction.z();
  if (s <= 0.0 || (o + s * d).norm() > c.radius) return std::nullopt;
  return shade(Eigen::Vector3d::UnitZ());
}

}  // namespace

void paintOccludingCylinder(const OccludingCylinder& cylinder, const Camera& camera,
                            const Pose3& cam_from_world, cv::Mat* view) {
  CURVESFM_CHECK(view && view->cols == camera.width() && view->rows == camera.height() &&
                 (view->type() == CV_8UC1 || view->type() == CV_8UC3))
      << "the view must be an 8-bit grey or BGR image of the camera's size";
  CURVESFM_CHECK(cylinder.radius > 0.0 && cylinder.height > 0.0)
      << "the cylinder needs a positive radius and height";
  const Pose3 world_from_cam = cam_from_world.inverse();
  const Eigen::Vector3d centre = world_from_cam.translation();
  const double grey = (cylinder.colour[0] + cylinder.colour[1] + cylinder.colour[2]) / 3.0;
  for (int y = 0; y < view->rows; ++y) {
    for (int x = 0; x < view->cols; ++x) {
      double coverage = 0.0, brightness = 0.0;
      for (int i = 0; i < kSubsamples * kSubsamples; ++i) {
        const Eigen::Vector2d pixel(x + ((i % kSubsamples) + 0.5) / kSubsamples - 0.5,
                                    y + ((i / kSubsamples) + 0.5) / kSubsamples - 0.5);
        const Eigen::Vector3d ray = world_from_cam.rotation() * camera.unproject(pixel, 1.0);
        if (const std::optional<double> hit = traceRay(cylinder, centre, ray)) {
          coverage += 1.0;
          brightness += *hit;
        }
      }
      if (coverage == 0.0) continue;
      brightness /= coverage;
      coverage /= kSubsamples * kSubsamples;
      const auto blend = [&](uchar* value, double surface) {
        *value = cv::saturate_cast<uchar>((1.0 - coverage) * *value + coverage * surface);
      };
      if (view->channels() == 1) {
        blend(&view->at<uchar>(y, x), grey * brightness);
      } else {
        cv::Vec3b& pixel = view->at<cv::Vec3b>(y, x);
        for (int ch = 0; ch < 3; ++ch) blend(&pixel[ch], cylinder.colour[ch] * brightness);
      }
    }
  }
}

}  // namespace curvesfm
