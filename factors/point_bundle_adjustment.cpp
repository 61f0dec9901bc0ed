#include "factors/point_bundle_adjustment.h"

#include <Eigen/Dense>
#include <cmath>

#include "core/check.h"
#include "core/errors.h"
#include "core/so3.h"
#include "factors/centre_precision.h"
#include "factors/point_reprojection_factor.h"

namespace curvesfm {

void PointBundleAdjustmentOptions::validate() const {
  const OptionCheck require("PointBundleAdjustmentOptions");
  require.positive("pixel_sigma", pixel_sigma);
  require.positive("kernel_width", kernel_width);
  require.positive("scale_sigma", scale_sigma);
}

PointBundleAdjustmentProblem buildPointBundleAdjustment(
    const PointBundleAdjustmentInput& input, const PointBundleAdjustmentOptions& options) {
  options.validate();
  CURVESFM_CHECK(input.camera != nullptr) << "point bundle adjustment needs a camera";
  PointBundleAdjustmentProblem problem;
  for (std::size_t i = 0; i < input.cam_from_world.size(); ++i) {
    problem.values.insert(poseKey(i), input.cam_from_world[i]);
  }
  for (std::size_t p = 0; p < input.points.size(); ++p) {
    problem.values.insert(pointKey(p), input.points[p]);
  }
  if (options.refine_focal) problem.values.insert(focalScaleKey(), 1.0);

  const NoiseModel pixel_noise{options.pixel_sigma,
                               RobustKernel(options.kernel, options.kernel_width)};
  const int num_cameras = static_cast<int>(input.cam_from_world.size());
  const int num_points = static_cast<int>(input.points.size());
  for (const PointObservation& obs : input.observations) {
    CURVESFM_CHECK(obs.camera_index >= 0 && obs.camera_index < num_cameras &&
                   obs.point_index >= 0 && obs.point_index < num_points)
        << "observation of point " << obs.point_index << " in camera " << obs.camera_index
        << " is out of range (" << num_points << " points, " << num_cameras << " cameras)";
    if (options.refine_focal) {
      problem.graph.emplace<FocalPointReprojectionFactor>(
          poseKey(obs.camera_index), pointKey(obs.point_index), focalScaleKey(), obs.pixel,
          input.camera, pixel_noise);
    } else {
      problem.graph.emplace<PointReprojectionFactor>(poseKey(obs.camera_index),
                                                     pointKey(obs.point_index), obs.pixel,
                                                     input.camera, pixel_noise);
    }
  }

  if (options.fix_first_pose && num_cameras > 0) problem.config.setConstant(poseKey(0));
  if (options.fix_scale) {
    addScaleGauge(input.cam_from_world, input.scale_distance, options.scale_sigma, &problem.graph);
  }
  return problem;
}

std::vector<Eigen::Vector3d> extractPoints(const Values& values, std::size_t num_points) {
  std::vector<Eigen::Vector3d> points;
  for (std::size_t p = 0; p < num_points; ++p) {
    points.push_back(values.at<Eigen::Vector3d>(pointKey(p)));
  }
  return points;
}

double extractFocalScale(const Values& values) {
  return values.exists(focalScaleKey()) ? values.at<double>(focalScaleKey()) : 1.0;
}

namespace {

// One point's share of the information on the poses, the point eliminated (Schur complement),
// added to `reduced` (6 per camera: the retraction's rotation then translation, Pose3). A point
// that fewer than two views place, or that they place along a line only, adds nothing.
void addPointInformation(const PointBundleAdjustmentInput& input,
                         const std::vector<const PointObservation*>& seen,
                         Eigen::MatrixXd* reduced) {
  struct Block {
    int camera;
    Matrix6d pose_pose;
    Eigen::Matrix<double, 6, 3> pose_point;
  };
  std::vector<Block> blocks;
  Eigen::Matrix3d point_point = Eigen::Matrix3d::Zero();
  for (const PointObservation* o : seen) {
    const Pose3& pose = input.cam_from_world[o->camera_index];
    const Eigen::Vector3d in_camera = pose * input.points[o->point_index];
    Eigen::Vector2d pixel;
    Matrix23d d_pixel;
    if (!input.camera->project(in_camera, &pixel, &d_pixel)) continue;
    Eigen::Matrix<double, 2, 6> d_pose;
    d_pose << -d_pixel * so3::hat(in_camera), d_pixel;
    const Matrix23d d_point = d_pixel * pose.rotationMatrix();
    point_point += d_point.transpose() * d_point;
    blocks.push_back({o->camera_index, d_pose.transpose() * d_pose, d_pose.transpose() * d_point});
  }
  if (blocks.size() < 2) return;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> point_eigen(point_point);
  const Eigen::Vector3d& lambda = point_eigen.eigenvalues();
  if (lambda(0) <= 1e-8 * lambda(2)) return;
  const Eigen::Matrix3d& v = point_eigen.eigenvectors();
  const Eigen::Matrix3d point_inverse = v * lambda.cwiseInverse().asDiagonal() * v.transpose();
  for (const Block& a : blocks) {
    reduced->block<6, 6>(6 * a.camera, 6 * a.camera) += a.pose_pose;
    for (const Block& b : blocks) {
      reduced->block<6, 6>(6 * a.camera, 6 * b.camera) -=
          a.pose_point * point_inverse * b.pose_point.transpose();
    }
  }
}

// Each point's observations; CheckError for an index out of range.
std::vector<std::vector<const PointObservation*>> observationsByPoint(
    const PointBundleAdjustmentInput& input) {
  const int cameras = static_cast<int>(input.cam_from_world.size());
  std::vector<std::vector<const PointObservation*>> by_point(input.points.size());
  for (const PointObservation& o : input.observations) {
    CURVESFM_CHECK(o.camera_index >= 0 && o.camera_index < cameras && o.point_index >= 0 &&
                   o.point_index < static_cast<int>(input.points.size()))
        << "observation of point " << o.point_index << " in camera " << o.camera_index
        << " is out of range";
    by_point[o.point_index].push_back(&o);
  }
  return by_point;
}

// The information on the poses (6 per camera) that the observations give at std dev
// `pixel_sigma`, the points eliminated.
Eigen::MatrixXd poseInformation(const PointBundleAdjustmentInput& input, double pixel_sigma) {
  const int cameras = static_cast<int>(input.cam_from_world.size());
  Eigen::MatrixXd reduced = Eigen::MatrixXd::Zero(6 * cameras, 6 * cameras);
  for (const auto& seen : observationsByPoint(input)) {
    if (seen.size() >= 2) addPointInformation(input, seen, &reduced);
  }
  return reduced / (pixel_sigma * pixel_sigma);
}

}  // namespace

double estimatedPixelSigma(const PointBundleAdjustmentInput& input, bool poses_fitted) {
  CURVESFM_CHECK(input.camera != nullptr) << "the pixel noise needs a camera";
  double squares = 0.0;
  int observations = 0;
  int points = 0;
  for (const auto& seen : observationsByPoint(input)) {
    int in_front = 0;
    double point_squares = 0.0;
    for (const PointObservation* o : seen) {
      Eigen::Vector2d projected;
      const Pose3& pose = input.cam_from_world[o->camera_index];
      if (!input.camera->project(pose * input.points[o->point_index], &projected)) continue;
      point_squares += (o->pixel - projected).squaredNorm();
      ++in_front;
    }
    if (in_front < 2) continue;  // A point seen once fits its observation exactly.
    squares += point_squares;
    observations += in_front;
    ++points;
  }
  const int cameras = static_cast<int>(input.cam_from_world.size());
  const int fitted = 3 * points + (poses_fitted ? std::max(0, 6 * cameras - 7) : 0);
  const int redundancy = 2 * observations - fitted;
  return redundancy > 0 ? std::sqrt(squares / redundancy) : std::nan("");
}

double predictedCentreAte(const PointBundleAdjustmentInput& input, double pixel_sigma) {
  CURVESFM_CHECK(input.camera != nullptr) << "the centres' precision needs a camera";
  CURVESFM_CHECK(pixel_sigma > 0.0) << "pixel std dev " << pixel_sigma << " must be > 0";
  if (input.cam_from_world.size() < 3) return 0.0;  // A similarity fits two centres exactly.
  return predictedCentreAteFromInformation(poseInformation(input, pixel_sigma),
                                           input.cam_from_world);
}

}  // namespace curvesfm
