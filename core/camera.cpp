#include "core/camera.h"

#include <cmath>
#include <iomanip>
#include <limits>
#include <locale>
#include <sstream>
#include <string>

#include "core/errors.h"

namespace curvesfm {
namespace {

constexpr int kMaxUndistortIterations = 20;
// Squared residual in normalized units at which undistortion stops: 1e-12, i.e. ~1e-9 pixels.
constexpr double kUndistortToleranceSq = 1e-24;
// Step halvings per iteration before undistortion gives up on a direction.
constexpr int kMaxStepHalvings = 10;
// Below this |det J| the Newton step is meaningless (fold of the model); we fall back to the
// fixed-point step xn <- xn - (distort(xn) - xd), which is J ~= I.
constexpr double kMinJacobianDeterminant = 1e-12;

// The distortion in plain scalars so that project() stays allocation free and branch light.
// J (row-major 2x2, optional) receives d(xd, yd) / d(x, y).
inline void distort(const CameraIntrinsics& c, double x, double y, double* xd, double* yd,
                    double* J) {
  const double xx = x * x;
  const double yy = y * y;
  const double xy = x * y;
  const double r2 = xx + yy;
  const double radial = 1.0 + r2 * (c.k1 + r2 * (c.k2 + r2 * c.k3));
  *xd = x * radial + 2.0 * c.p1 * xy + c.p2 * (r2 + 2.0 * xx);
  *yd = y * radial + c.p1 * (r2 + 2.0 * yy) + 2.0 * c.p2 * xy;
  if (J == nullptr) return;
  // d radial / d r2; d r2 / dx = 2x, d r2 / dy = 2y.
  const double d_radial_d_r2 = c.k1 + r2 * (2.0 * c.k2 + 3.0 * c.k3 * r2);
  J[0] = radial + 2.0 * xx * d_radial_d_r2 + 2.0 * c.p1 * y + 6.0 * c.p2 * x;
  J[1] = 2.0 * xy * d_radial_d_r2 + 2.0 * c.p1 * x + 2.0 * c.p2 * y;
  J[2] = J[1];  // The model's Jacobian is symmetric.
  J[3] = radial + 2.0 * yy * d_radial_d_r2 + 6.0 * c.p1 * y + 2.0 * c.p2 * x;
}

// Solves J step = residual by Cramer's rule (a 2x2 needs no LU module); where J is singular
// (a fold of the model) it falls back to the fixed-point step.
Eigen::Vector2d newtonStep(const Eigen::Matrix2d& J, const Eigen::Vector2d& residual) {
  const double det = J(0, 0) * J(1, 1) - J(0, 1) * J(1, 0);
  if (!(std::abs(det) > kMinJacobianDeterminant)) return residual;
  return Eigen::Vector2d(J(1, 1) * residual.x() - J(0, 1) * residual.y(),
                         J(0, 0) * residual.y() - J(1, 0) * residual.x()) /
         det;
}

}  // namespace

void CameraIntrinsics::validate() const {
  const OptionCheck require("CameraIntrinsics");
  require.positive("fx", fx);
  require.positive("fy", fy);
  for (const auto& [field, value] : {std::pair{"cx", cx},
                                     {"cy", cy},
                                     {"k1", k1},
                                     {"k2", k2},
                                     {"p1", p1},
                                     {"p2", p2},
                                     {"k3", k3}}) {
    require.finite(field, value);
  }
  require(width > 0, "width", width, "must be > 0");
  require(height > 0, "height", height, "must be > 0");
}

Camera::Camera(const CameraIntrinsics& intrinsics) : intrinsics_(intrinsics) {
  intrinsics_.validate();
  distorted_ = hasDistortion();
}

Eigen::Matrix3d Camera::K() const {
  Eigen::Matrix3d K;
  K << intrinsics_.fx, 0.0, intrinsics_.cx, 0.0, intrinsics_.fy, intrinsics_.cy, 0.0, 0.0, 1.0;
  return K;
}

bool Camera::hasDistortion() const {
  const CameraIntrinsics& c = intrinsics_;
  return c.k1 != 0.0 || c.k2 != 0.0 || c.p1 != 0.0 || c.p2 != 0.0 || c.k3 != 0.0;
}

Camera Camera::withFocalScale(double factor) const {
  CameraIntrinsics scaled = intrinsics_;
  scaled.fx *= factor;
  scaled.fy *= factor;
  return Camera(scaled);
}

Camera Camera::withoutDistortion() const {
  CameraIntrinsics pinhole = intrinsics_;
  pinhole.k1 = pinhole.k2 = pinhole.p1 = pinhole.p2 = pinhole.k3 = 0.0;
  return Camera(pinhole);
}

bool Camera::project(const Eigen::Vector3d& point_in_cam, Eigen::Vector2d* pixel,
                     Matrix23d* H_point) const {
  const double z = point_in_cam.z();
  // `!(z > min)` also rejects NaN depth.
  if (!(z > kMinDepth)) {
    pixel->setZero();
    if (H_point) H_point->setZero();
    return false;
  }
  const CameraIntrinsics& c = intrinsics_;
  const double inv_z = 1.0 / z;
  const double x = point_in_cam.x() * inv_z;
  const double y = point_in_cam.y() * inv_z;
  double xd = x;
  double yd = y;
  double J[4] = {1.0, 0.0, 0.0, 1.0};
  // The pipeline's keyframes are undistorted: skipping the model there changes no bit of the
  // result (the identity it computes is exact) and saves about 2.5 % of a curve sample's cost.
  if (distorted_) distort(c, x, y, &xd, &yd, H_point ? J : nullptr);
  (*pixel)(0) = c.fx * xd + c.cx;
  (*pixel)(1) = c.fy * yd + c.cy;
  if (H_point) {
    // pixel = F * D(xn(P)): chain diag(fx, fy) * J * d xn / d P, with
    // d xn / d P = [1/z 0 -x/z; 0 1/z -y/z].
    const double a = c.fx * inv_z;
    const double b = c.fy * inv_z;
    Matrix23d& H = *H_point;
    H(0, 0) = a * J[0];
    H(0, 1) = a * J[1];
    H(0, 2) = -a * (J[0] * x + J[1] * y);
    H(1, 0) = b * J[2];
    H(1, 1) = b * J[3];
    H(1, 2) = -b * (J[2] * x + J[3] * y);
  }
  return true;
}

Eigen::Vector2d Camera::distortNormalized(const Eigen::Vector2d& xn, Eigen::Matrix2d* H) const {
  Eigen::Vector2d xd;
  double J[4];
  distort(intrinsics_, xn.x(), xn.y(), &xd.x(), &xd.y(), H ? J : nullptr);
  if (H) *H << J[0], J[1], J[2], J[3];
  return xd;
}

Eigen::Vector2d Camera::undistortNormalized(const Eigen::Vector2d& xd) const {
  if (!hasDistortion()) return xd;
  // Distortion is a small perturbation of the identity, so the distorted point is a good start.
  Eigen::Vector2d xn = xd;
  Eigen::Matrix2d J;
  Eigen::Vector2d residual = distortNormalized(xn, &J) - xd;
  double cost = residual.squaredNorm();
  for (int iteration = 0; iteration < kMaxUndistortIterations; ++iteration) {
    if (cost <= kUndistortToleranceSq) break;
    const Eigen::Vector2d step = newtonStep(J, residual);
    // Halving until the residual shrinks keeps the iteration monotone near folds of the model,
    // where a full Newton step can jump to another branch or overflow.
    bool improved = false;
    double scale = 1.0;
    for (int halving = 0; halving < kMaxStepHalvings && !improved; ++halving, scale *= 0.5) {
      const Eigen::Vector2d candidate = xn - scale * step;
      Eigen::Matrix2d J_candidate;
      const Eigen::Vector2d r_candidate = distortNormalized(candidate, &J_candidate) - xd;
      const double cost_candidate = r_candidate.squaredNorm();
      if (cost_candidate < cost) {  // False for NaN, so a non-finite candidate is never taken.
        xn = candidate;
        J = J_candidate;
        residual = r_candidate;
        cost = cost_candidate;
        improved = true;
      }
    }
    if (!improved) break;
  }
  return xn;
}

Eigen::Vector2d Camera::pixelToNormalized(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d xd((pixel.x() - intrinsics_.cx) / intrinsics_.fx,
                           (pixel.y() - intrinsics_.cy) / intrinsics_.fy);
  return undistortNormalized(xd);
}

Eigen::Vector3d Camera::unproject(const Eigen::Vector2d& pixel, double depth) const {
  const Eigen::Vector2d xn = pixelToNormalized(pixel);
  return Eigen::Vector3d(xn.x() * depth, xn.y() * depth, depth);
}

Eigen::Vector2d Camera::undistortPixel(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d xn = pixelToNormalized(pixel);
  return Eigen::Vector2d(intrinsics_.fx * xn.x() + intrinsics_.cx,
                         intrinsics_.fy * xn.y() + intrinsics_.cy);
}

bool Camera::isInImage(const Eigen::Vector2d& pixel, double margin) const {
  // Written as positive comparisons so that NaN coordinates fail.
  return pixel.x() >= margin && pixel.x() <= intrinsics_.width - 1 - margin &&
         pixel.y() >= margin && pixel.y() <= intrinsics_.height - 1 - margin;
}

}  // namespace curvesfm
