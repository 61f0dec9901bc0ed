#include "sim/point_scene.h"

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "core/angles.h"
#include "core/errors.h"
#include "core/so3.h"
#include "core/trajectory_evaluation.h"

namespace curvesfm {
namespace {

// Camera at `centre` looking at the origin, image y pointing along world +y ("down").
Pose3 lookAtOrigin(const Eigen::Vector3d& centre) {
  const Eigen::Vector3d z = (-centre).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized();
  Eigen::Matrix3d world_from_cam_rotation;
  world_from_cam_rotation << x, z.cross(x), z;
  return Pose3(world_from_cam_rotation, centre).inverse();
}

Eigen::Vector3d gaussian3(std::mt19937& rng, double sigma) {
  std::normal_distribution<double> noise(0.0, sigma);
  return Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
}

// Rotation about the camera's own axes and a shift of its centre in the world.
Pose3 perturb(const Pose3& cam_from_world, double rotation_sigma, double centre_sigma,
              std::mt19937& rng) {
  const Pose3 world_from_cam = cam_from_world.inverse();
  const Eigen::Quaterniond rotation =
      world_from_cam.rotation() * so3::exp(gaussian3(rng, rotation_sigma));
  return Pose3(rotation, world_from_cam.translation() + gaussian3(rng, centre_sigma)).inverse();
}

}  // namespace

void PointSceneOptions::validate() const {
  const OptionCheck require("PointSceneOptions");
  require(num_cameras >= 2, "num_cameras", num_cameras, "must be >= 2");
  require(num_points >= 1, "num_points", num_points, "must be >= 1");
  require(track_length >= 1 && track_length <= num_cameras, "track_length", track_length,
          "must be in [1, num_cameras]");
  require(orbit_radius > 0.0, "orbit_radius", orbit_radius, "must be > 0");
  require(arc_degrees > 0.0 && arc_degrees <= 360.0, "arc_degrees", arc_degrees,
          "must be in (0, 360]");
  require(cube_half_size > 0.0 && cube_half_size < 0.5 * orbit_radius, "cube_half_size",
          cube_half_size, "must be in (0, orbit_radius / 2)");
  require(pixel_noise >= 0.0, "pixel_noise", pixel_noise, "must be >= 0");
  require(pose_noise_translation >= 0.0, "pose_noise_translation", pose_noise_translation,
          "must be >= 0");
  require(pose_noise_rotation_deg >= 0.0, "pose_noise_rotation_deg", pose_noise_rotation_deg,
          "must be >= 0");
  require(point_noise >= 0.0, "point_noise", point_noise, "must be >= 0");
  intrinsics.validate();
}

PointScene makePointScene(const PointSceneOptions& options) {
  options.validate();
  std::mt19937 rng(options.seed);
  PointScene scene;
  scene.camera = std::make_shared<const Camera>(options.intrinsics);

  const double arc = options.arc_degrees * kDegToRad;
  for (int i = 0; i < options.num_cameras; ++i) {
    const double angle = -0.5 * arc + arc * i / (options.num_cameras - 1);
    // A gentle height wave keeps the cameras off one plane.
    const Eigen::Vector3d centre(options.orbit_radius * std::sin(angle),
                                 -0.1 * options.orbit_radius * std::cos(3.0 * angle),
                                 -options.orbit_radius * std::cos(angle));
    scene.true_cam_from_world.push_back(lookAtOrigin(centre));
  }
  scene.initial_cam_from_world = scene.true_cam_from_world;
  for (int i = 1; i < options.num_cameras; ++i) {
    scene.initial_cam_from_world[i] =
        perturb(scene.true_cam_from_world[i], options.pose_noise_rotation_deg * kDegToRad,
                options.pose_noise_translation, rng);
  }

  std::uniform_real_distribution<double> in_cube(-options.cube_half_size, options.cube_half_size);
  std::uniform_int_distribution<int> first_camera(0, options.num_cameras - options.track_length);
  std::normal_distribution<double> pixel_noise(0.0, options.pixel_noise);
  for (int p = 0; p < options.num_points; ++p) {
    const Eigen::Vector3d point(in_cube(rng), in_cube(rng), in_cube(rng));
    scene.true_points.push_back(point);
    scene.initial_points.push_back(point + gaussian3(rng, options.point_noise));
    const int first = first_camera(rng);
    for (int c = first; c < first + options.track_length; ++c) {
      Eigen::Vector2d pixel;
      if (!scene.camera->project(scene.true_cam_from_world[c] * point, &pixel)) continue;
      pixel += Eigen::Vector2d(pixel_noise(rng), pixel_noise(rng));
      if (!scene.camera->isInImage(pixel)) continue;
      scene.observations.push_back({c, p, pixel});
    }
  }
  return scene;
}

double PointScene::trueScaleDistance() const {
  return cameraCentreDistance(true_cam_from_world[1], true_cam_from_world[0]);
}

PointSceneErrors evaluatePointScene(const PointScene& scene,
                                    const std::vector<Pose3>& cam_from_world,
                                    const std::vector<Eigen::Vector3d>& points) {
  const TrajectoryErrors trajectory = evaluateTrajectory(scene.true_cam_from_world, cam_from_world);
  PointSceneErrors errors;
  errors.position_rmse = trajectory.position_rmse;
  errors.position_ate_sim3 = trajectory.position_ate_sim3;
  errors.rotation_mean_deg = trajectory.rotation_mean_deg;
  for (std::size_t p = 0; p < points.size(); ++p) {
    errors.point_rmse += (points[p] - scene.true_points[p]).squaredNorm();
  }
  errors.point_rmse = std::sqrt(errors.point_rmse / std::max<std::size_t>(points.size(), 1));
  for (const PointObservation& obs : scene.observations) {
    Eigen::Vector2d pixel;
    scene.camera->project(cam_from_world[obs.camera_index] * points[obs.point_index], &pixel);
    errors.reprojection_rmse_px += (pixel - obs.pixel).squaredNorm();
  }
  errors.reprojection_rmse_px =
      std::sqrt(errors.reprojection_rmse_px / std::max<std::size_t>(scene.observations.size(), 1));
  return errors;
}

}  // namespace curvesfm
