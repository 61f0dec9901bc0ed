#pragma once

#include <Eigen/Core>

#include "core/eigen_types.h"

namespace curvesfm {

/// Intrinsic parameters of a pinhole camera with radial-tangential ("plumb bob", OpenCV)
/// distortion. Plain copyable data; `Camera`'s constructor validates it. The defaults are the
/// nominal TUM RGB-D (ROS default) camera without distortion.
struct CameraIntrinsics {
  double fx = 525.0;  ///< Focal length along x in pixels; finite, > 0.
  double fy = 525.0;  ///< Focal length along y in pixels; finite, > 0.
  double cx = 319.5;  ///< Principal point x in pixels (pixel centres at integers); finite.
  double cy = 239.5;  ///< Principal point y in pixels (pixel centres at integers); finite.
  double k1 = 0.0;    ///< Radial distortion coefficient of r^2; finite, unitless.
  double k2 = 0.0;    ///< Radial distortion coefficient of r^4; finite, unitless.
  double p1 = 0.0;    ///< First tangential distortion coefficient; finite, unitless.
  double p2 = 0.0;    ///< Second tangential distortion coefficient; finite, unitless.
  double k3 = 0.0;    ///< Radial distortion coefficient of r^6; finite, unitless.
  int width = 640;    ///< Image width in pixels; > 0.
  int height = 480;   ///< Image height in pixels; > 0.

  /// Throws InvalidOptions naming the first field outside its documented range.
  void validate() const;
};

/// A pinhole camera with OpenCV's radial-tangential distortion (k1, k2, p1, p2, k3).
///
/// Frames and units: points are in the camera frame (x right, y down, z forward along the
/// principal axis, scene units); normalized coordinates are (x/z, y/z); pixels have their centres
/// at integer coordinates, (0, 0) is the centre of the top-left pixel. Distortion acts on
/// normalized coordinates xn = (x, y), r^2 = x^2 + y^2:
///   radial = 1 + k1 r^2 + k2 r^4 + k3 r^6
///   xd = x radial + 2 p1 x y + p2 (r^2 + 2 x^2)
///   yd = y radial + p1 (r^2 + 2 y^2) + 2 p2 x y
///   pixel = (fx xd + cx, fy yd + cy)
///
/// Degenerate cases: like OpenCV, the polynomial model is only meaningful where it is invertible
/// (it folds back far outside the calibrated field of view); project() does not detect that
/// region, and undistortNormalized() returns its best iterate there.
///
/// Immutable after construction, so one instance can be shared between threads.
class Camera {
 public:
  /// Points with depth z at or below this (scene units) do not project. It guards the division
  /// by z (points behind or on the camera plane); it is not a near clipping plane.
  static constexpr double kMinDepth = 1e-6;

  /// Throws InvalidOptions (via CameraIntrinsics::validate) if `intrinsics` are invalid.
  explicit Camera(const CameraIntrinsics& intrinsics);

  const CameraIntrinsics& intrinsics() const { return intrinsics_; }
  double fx() const { return intrinsics_.fx; }
  double fy() const { return intrinsics_.fy; }
  double cx() const { return intrinsics_.cx; }
  double cy() const { return intrinsics_.cy; }
  int width() const { return intrinsics_.width; }
  int height() const { return intrinsics_.height; }

  /// The 3x3 calibration matrix [fx 0 cx; 0 fy cy; 0 0 1] (distortion not included).
  Eigen::Matrix3d K() const;

  /// True if any of k1, k2, p1, p2, k3 is non-zero.
  bool hasDistortion() const;
  /// The same K and size without distortion: the camera of this one's undistorted images.
  Camera withoutDistortion() const;
  /// The same camera with fx and fy multiplied by `factor` (> 0): a refined focal length.
  Camera withFocalScale(double factor) const;

  /// Projects a point in the camera frame to a (distorted) pixel.
  /// H_point (optional, 2x3): d pixel / d point_in_cam, distortion included.
  /// Returns false if z <= kMinDepth; then `*pixel` and `*H_point` are set to zero.
  /// Allocation free; meant for the inner loop of bundle adjustment.
  bool project(const Eigen::Vector3d& point_in_cam, Eigen::Vector2d* pixel,
               Matrix23d* H_point = nullptr) const;

  /// Applies the distortion to normalized coordinates xn (see class comment).
  /// H (optional, 2x2): d xd / d xn.
  Eigen::Vector2d distortNormalized(const Eigen::Vector2d& xn, Eigen::Matrix2d* H = nullptr) const;

  /// Inverts distortNormalized() by damped Newton iterations (at most 20) started at xd;
  /// converges to ~1e-12 for realistic distortion inside the image. Where the model is not
  /// invertible it returns the best iterate found and never throws or returns NaN for finite xd.
  Eigen::Vector2d undistortNormalized(const Eigen::Vector2d& xd) const;

  /// The undistorted normalized coordinates (x/z, y/z) of the ray through `pixel`.
  Eigen::Vector2d pixelToNormalized(const Eigen::Vector2d& pixel) const;

  /// The point in the camera frame seen at `pixel` with z = `depth` (depth along the principal
  /// axis, not along the ray). Inverse of project() for depth > kMinDepth.
  Eigen::Vector3d unproject(const Eigen::Vector2d& pixel, double depth) const;

  /// Where `pixel` would appear in an ideal pinhole camera with the same K and no distortion.
  Eigen::Vector2d undistortPixel(const Eigen::Vector2d& pixel) const;

  /// True if `pixel` lies in [margin, width - 1 - margin] x [margin, height - 1 - margin]
  /// (pixel centres at integer coordinates). False for NaN coordinates.
  bool isInImage(const Eigen::Vector2d& pixel, double margin = 0.0) const;

 private:
  CameraIntrinsics intrinsics_;
  bool distorted_ = false;  ///< hasDistortion(), once.
};

}  // namespace curvesfm
