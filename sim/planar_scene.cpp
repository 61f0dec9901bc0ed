#include "sim/planar_scene.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>

#include "core/angles.h"
#include "core/check.h"
#include "core/errors.h"
#include "sim/synthetic_dataset.h"

namespace curvesfm {
namespace {

// Far beyond any real camera; it keeps a mistyped size from allocating gigabytes per frame.
constexpr int kMaxImageSide = 16384;

void checkTexture(const cv::Mat& texture) {
  CURVESFM_CHECK(!texture.empty() && texture.depth() == CV_8U &&
                 (texture.channels() == 1 || texture.channels() == 3))
      << "the planar texture must be a non-empty 8-bit grey or BGR image, got " << texture.cols
      << "x" << texture.rows << " of OpenCV type " << texture.type();
}

// Camera at `centre` looking at the origin, its image x axis horizontal and its image y axis
// pointing down the slope of the view, as a person looking down at a table.
Pose3 lookAtPlaneCentre(const Eigen::Vector3d& centre) {
  const Eigen::Vector3d z = -centre.normalized();
  const Eigen::Vector3d down = -Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d y = (down - down.dot(z) * z).normalized();
  Eigen::Matrix3d world_from_cam_rotation;
  world_from_cam_rotation << y.cross(z), y, z;
  return Pose3(world_from_cam_rotation, centre).inverse();
}

Pose3 orbitPose(const PlanarSceneOptions& options, int frame) {
  const double arc = options.arc_degrees * kDegToRad;
  const double azimuth = -0.5 * M_PI + arc * (double(frame) / (options.num_frames - 1) - 0.5);
  return lookAtPlaneCentre(Eigen::Vector3d(options.orbit_radius * std::cos(azimuth),
                                           options.orbit_radius * std::sin(azimuth),
                                           options.camera_height));
}

// An isotropic rotation error (so applying it in the world frame is the same as in the camera
// frame) and a shift of the camera centre in the world.
Vector6d poseNoise(const PlanarSceneOptions& options, std::mt19937& rng) {
  std::normal_distribution<double> rotation(0.0, options.init_noise_rotation_deg * kDegToRad);
  std::normal_distribution<double> translation(0.0, options.init_noise_translation);
  Vector6d delta;
  for (int k = 0; k < 3; ++k) delta(k) = rotation(rng);
  for (int k = 3; k < 6; ++k) delta(k) = translation(rng);
  return delta;
}

Pose3 perturb(const Pose3& cam_from_world, const Vector6d& delta) {
  return perturbCamera(cam_from_world.inverse(), delta).inverse();
}

// The starting guess of every frame (see InitNoiseModel).
std::vector<Pose3> initialPoses(const std::vector<Pose3>& truth, const PlanarSceneOptions& options,
                                std::mt19937& rng) {
  std::vector<Pose3> initial;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const Vector6d delta = poseNoise(options, rng);
    if (options.init_noise_model == InitNoiseModel::kIndependent || i == 0) {
      initial.push_back(perturb(truth[i], delta));
      continue;
    }
    // The true motion from frame i-1 to i, perturbed, applied to the previous guess.
    const Pose3 true_step = truth[i] * truth[i - 1].inverse();
    initial.push_back(perturb(true_step * initial.back(), delta));
  }
  return initial;
}

void addIntensityNoise(double sigma, cv::RNG& rng, cv::Mat* image) {
  if (sigma <= 0.0) return;
  cv::Mat noisy;
  image->convertTo(noisy, CV_32F);
  cv::Mat noise(noisy.size(), noisy.type());
  rng.fill(noise, cv::RNG::NORMAL, cv::Scalar::all(0.0), cv::Scalar::all(sigma));
  noisy += noise;
  noisy.convertTo(*image, CV_8U);  // rounds and clips to [0, 255]
}

// A homography cannot tell the two sides of the camera apart: warpPerspective also paints the
// pixels whose ray meets the plane behind the camera. `inverse_depth` is the row of
// texture_from_image that gives 1 / depth of a pixel's plane point.
void fillBehindCamera(const Eigen::RowVector3d& inverse_depth, const cv::Scalar& fill,
                      cv::Mat* view) {
  cv::Mat behind(view->size(), CV_8U);
  for (int y = 0; y < view->rows; ++y) {
    auto* row = behind.ptr<unsigned char>(y);
    for (int x = 0; x < view->cols; ++x) {
      row[x] = inverse_depth.dot(Eigen::Vector3d(x, y, 1.0)) > 0.0 ? 0 : 255;
    }
  }
  view->setTo(fill, behind);
}

}  // namespace

CameraIntrinsics PlanarSceneOptions::intrinsics() const {
  CameraIntrinsics intrinsics;
  intrinsics.fx = fx;
  intrinsics.fy = fy;
  intrinsics.cx = cx;
  intrinsics.cy = cy;
  intrinsics.width = width;
  intrinsics.height = height;
  return intrinsics;
}

int maxPlanarFrames(int width, int height) {
  const std::int64_t frame_bytes = std::int64_t{width} * height * 3;
  return static_cast<int>(std::min<std::int64_t>(
      kMaxPlanarFrames, kMaxPlanarSceneBytes / std::max<std::int64_t>(frame_bytes, 1)));
}

void PlanarSceneOptions::validate() const {
  const OptionCheck require("PlanarSceneOptions");
  require(num_frames >= 2, "num_frames", num_frames, "must be >= 2");
  require(intensity_noise >= 0.0 && intensity_noise <= 1.0, "intensity_noise", intensity_noise,
          "must be in [0, 1] (a fraction of 255)");
  require(std::isfinite(init_noise_translation) && init_noise_translation >= 0.0,
          "init_noise_translation", init_noise_translation, "must be finite and >= 0");
  require(std::isfinite(init_noise_rotation_deg) && init_noise_rotation_deg >= 0.0,
          "init_noise_rotation_deg", init_noise_rotation_deg, "must be finite and >= 0");
  require(width >= 1 && width <= kMaxImageSide, "width", width, "must be in [1, 16384]");
  require(height >= 1 && height <= kMaxImageSide, "height", height, "must be in [1, 16384]");
  const int max_frames = maxPlanarFrames(width, height);
  require(num_frames <= max_frames, "num_frames", num_frames,
          "must be <= " + std::to_string(max_frames) + " for " + std::to_string(width) + "x" +
              std::to_string(height) + " views (at most " + std::to_string(kMaxPlanarFrames) +
              ", and the views held in memory, frames x width x height x 3 bytes, within 4 GiB)");
  require(std::isfinite(fx) && fx > 0.0, "fx", fx, "must be finite and > 0");
  require(std::isfinite(fy) && fy > 0.0, "fy", fy, "must be finite and > 0");
  require(std::isfinite(cx), "cx", cx, "must be finite");
  require(std::isfinite(cy), "cy", cy, "must be finite");
  require(std::isfinite(plane_width) && plane_width > 0.0, "plane_width", plane_width,
          "must be finite and > 0");
  require(std::isfinite(orbit_radius) && orbit_radius > 0.0, "orbit_radius", orbit_radius,
          "must be finite and > 0");
  require(std::isfinite(camera_height) && camera_height > 0.0, "camera_height", camera_height,
          "must be finite and > 0");
  require(arc_degrees > 0.0 && arc_degrees < 360.0, "arc_degrees", arc_degrees,
          "must be in (0, 360)");
}

Eigen::Matrix3d PlanarTexture::planeFromTexture() const {
  const double sx = width_m / image.cols;
  const double sy = height_m / image.rows;
  Eigen::Matrix3d plane_from_texture;
  plane_from_texture << sx, 0.0, 0.5 * (sx - width_m),  //
      0.0, -sy, 0.5 * (height_m - sy),                  //
      0.0, 0.0, 1.0;
  return plane_from_texture;
}

PlanarTexture makePlanarTexture(const cv::Mat& image, double plane_width_m) {
  checkTexture(image);
  CURVESFM_CHECK(std::isfinite(plane_width_m) && plane_width_m > 0.0)
      << "plane width " << plane_width_m << " m";
  const double metres_per_pixel = plane_width_m / std::max(image.cols, image.rows);
  return {image, image.cols * metres_per_pixel, image.rows * metres_per_pixel};
}

Eigen::Matrix3d PlanarScene::pixelMap(int from, int to) const {
  const int frames = static_cast<int>(true_cam_from_world.size());
  CURVESFM_CHECK(from >= 0 && from < frames && to >= 0 && to < frames)
      << "frames " << from << " and " << to << " of " << frames;
  return pixelFromPlane(*camera, true_cam_from_world[to]) *
         pixelFromPlane(*camera, true_cam_from_world[from]).inverse();
}

Eigen::Matrix3d pixelFromPlane(const Camera& camera, const Pose3& cam_from_world) {
  const Eigen::Matrix3d rotation = cam_from_world.rotationMatrix();
  Eigen::Matrix3d cam_from_plane;
  cam_from_plane << rotation.col(0), rotation.col(1), cam_from_world.translation();
  return camera.K() * cam_from_plane;
}

cv::Mat renderPlanarView(const cv::Mat& texture_bgr, double plane_width_m, const Camera& camera,
                         const Pose3& cam_from_world, int background) {
  CURVESFM_CHECK(!camera.hasDistortion()) << "a homography cannot render lens distortion";
  CURVESFM_CHECK(background >= 0 && background <= 255) << "background " << background;
  const PlanarTexture texture = makePlanarTexture(texture_bgr, plane_width_m);
  const cv::Size size(camera.width(), camera.height());
  const cv::Scalar fill = cv::Scalar::all(background);

  const Eigen::Matrix3d pixel_from_plane = pixelFromPlane(camera, cam_from_world);
  // The determinant is minus the camera's height times det K: a camera in the plane sees it
  // edge-on.
  if (!(std::abs(pixel_from_plane.determinant() / camera.K().determinant()) > 1e-12)) {
    return cv::Mat(size, texture_bgr.type(), fill);
  }
  // Inverted here, unscaled, so that its last row stays the pixel's inverse depth.
  const Eigen::Matrix3d texture_from_image =
      (pixel_from_plane * texture.planeFromTexture()).inverse();
  cv::Matx33d map;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) map(r, c) = texture_from_image(r, c);
  }
  cv::Mat view;
  cv::warpPerspective(texture_bgr, view, map, size, cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                      cv::BORDER_CONSTANT, fill);
  fillBehindCamera(texture_from_image.row(2), fill, &view);
  return view;
}

double PlanarScene::meanFrameBaseline() const { return meanCameraStep(true_cam_from_world); }

double PlanarScene::firstToLastBaseline() const {
  if (true_cam_from_world.empty()) return 0.0;
  return cameraCentreDistance(true_cam_from_world.back(), true_cam_from_world.front());
}

PlanarScene makePlanarScene(const cv::Mat& texture_bgr, const PlanarSceneOptions& options) {
  options.validate();
  PlanarScene scene;
  scene.camera = std::make_shared<const Camera>(options.intrinsics());
  scene.texture = makePlanarTexture(texture_bgr, options.plane_width);
  // Separate streams: the noise level does not change the initial poses, nor the reverse.
  std::mt19937 pose_rng(options.seed);
  cv::RNG noise_rng(options.seed);
  for (int i = 0; i < options.num_frames; ++i) {
    scene.timestamps.push_back(i * kPlanarFramePeriod);
    scene.true_cam_from_world.push_back(orbitPose(options, i));
  }
  scene.initial_cam_from_world = initialPoses(scene.true_cam_from_world, options, pose_rng);
  for (const Pose3& truth : scene.true_cam_from_world) {
    cv::Mat image = renderPlanarView(texture_bgr, options.plane_width, *scene.camera, truth);
    addIntensityNoise(options.intensity_noise * 255.0, noise_rng, &image);
    scene.images.push_back(image);
  }
  return scene;
}

void writePlanarDataset(const std::string& dir, const PlanarScene& scene, bool with_initial_poses) {
  CURVESFM_CHECK(scene.camera) << "a planar scene needs a camera";
  SyntheticSequence sequence;
  sequence.camera = scene.camera.get();
  sequence.timestamps = &scene.timestamps;
  sequence.images = scene.images;
  sequence.true_cam_from_world = &scene.true_cam_from_world;
  if (with_initial_poses) sequence.initial_cam_from_world = &scene.initial_cam_from_world;
  writeSyntheticDataset(dir, sequence);
}

}  // namespace curvesfm
