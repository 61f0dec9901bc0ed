#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/enum_names.h"
#include "core/pose3.h"

namespace curvesfm {

// The paper's planar protocol (§4.1): a real photograph laid on a plane, a camera orbiting above
// it, every view rendered exactly by the plane's homography, per-pixel Gaussian intensity noise,
// and the true trajectory perturbed as a starting guess. Real image content, exact ground truth,
// no correspondence problem.
//
// World frame: the photo lies on the plane z = 0, centred at the origin, its columns along +x
// and its rows along -y (the photo's top edge is at +y), so z points up out of the photo's face
// and a camera above the plane (z > 0) sees it unmirrored. Units: metres, pixels (centres at
// integers, as Camera::project), 8-bit intensities.

/// Colour of the image pixels that do not see the photo (outside it or above the horizon).
inline constexpr int kPlanarBackground = 0;

/// Frame period of the rendered sequence: timestamps are i / 30 s, a TUM RGB-D camera's rate.
inline constexpr double kPlanarFramePeriod = 1.0 / 30.0;

/// The most views a planar scene may have, whatever their size: 10000 views are 5.6 minutes at
/// 30 Hz, twice the longest TUM RGB-D sequences (about 3000 frames), and as many PNG files.
inline constexpr int kMaxPlanarFrames = 10000;

/// The most bytes of rendered views a planar scene holds in memory (4 GiB). makePlanarScene()
/// keeps every view (width x height x 3 bytes for a colour photo) until the dataset is written,
/// and writePlanarDataset() writes each as a PNG of about that size (the added noise leaves
/// little to compress); 4 GiB leaves most of a 16 GB machine to the rest of the process and to
/// whatever else runs on it.
inline constexpr std::int64_t kMaxPlanarSceneBytes = std::int64_t{4} << 30;

/// The most views a scene of width x height (>= 1 px) colour views may have: the smaller of
/// kMaxPlanarFrames and kMaxPlanarSceneBytes / (width x height x 3), e.g. 4660 at 640x480
/// (4,294,967,296 / 921,600 B), 1165 at 1280x960, 5 at the largest 16384x16384 (805 MB each).
int maxPlanarFrames(int width, int height);

/// How the starting guess departs from the true trajectory.
enum class InitNoiseModel {
  /// Every pose perturbed on its own: errors of neighbouring frames are unrelated.
  kIndependent,
  /// The errors of a visual odometry: the starting trajectory integrates the true motion between
  /// consecutive frames, each motion perturbed, so errors accumulate as a random walk (drift)
  /// while neighbouring frames stay consistent. Frame 0 is perturbed like one step.
  kDrift,
};

template <>
struct EnumNames<InitNoiseModel> {
  static constexpr std::array<std::pair<InitNoiseModel, const char*>, 2> kNames = {{
      {InitNoiseModel::kIndependent, "independent"},
      {InitNoiseModel::kDrift, "drift"},
  }};
};

/// Options of makePlanarScene(). The default orbit (height 0.6 m, radius 0.25 m, 90 deg arc)
/// keeps the camera 0.65 m from the photo's centre, 23 deg off the vertical: a default 4:3 photo
/// (1.0 x 0.75 m) then fills at least 90% of every 640x480 view, the views are 13.5 mm apart
/// (2% of the viewing distance, 11 px of parallax at the plane) and the first and last are 0.35 m
/// apart and see the plane's centre from directions 32 deg apart, enough to triangulate well
/// without a strong perspective change between neighbours.
struct PlanarSceneOptions {
  /// Views along the orbit; in [2, maxPlanarFrames(width, height)] (4660 at the default
  /// 640x480): every view is held in memory until written.
  int num_frames = 30;
  /// P: std dev of the Gaussian noise added to every pixel and channel, as a fraction of 255
  /// (0.05 gives a std dev of 12.75 levels), before rounding and clipping to [0, 255]; [0, 1].
  double intensity_noise = 0.0;
  /// Seed of the image noise and of the pose perturbation (independent streams); the same
  /// options and photo give bit-identical scenes.
  unsigned seed = 1;
  /// The default stands for the paper's starting point, ORB-SLAM's poses (a visual odometry's
  /// drift; about 1-2 mm of error on its textured planar sequences, Table 1).
  InitNoiseModel init_noise_model = InitNoiseModel::kDrift;
  /// Std dev per axis of the camera-centre error (m): of every step between consecutive frames
  /// (kDrift; 7% of the default 13.5 mm step) or of every initial pose (kIndependent); finite,
  /// >= 0.
  double init_noise_translation = 0.001;
  /// Std dev per axis of the rotation-vector error (deg), per step or per pose as above; the
  /// rms angle is sqrt(3) times this; finite, >= 0.
  double init_noise_rotation_deg = 0.05;
  int width = 640;    ///< Image width (px); in [1, 16384].
  int height = 480;   ///< Image height (px); in [1, 16384].
  double fx = 525.0;  ///< Focal length along x (px); > 0. No distortion: views are homographies.
  double fy = 525.0;  ///< Focal length along y (px); > 0.
  double cx = 319.5;  ///< Principal point x (px, pixel centres at integers); finite.
  double cy = 239.5;  ///< Principal point y (px); finite.
  /// Extent of the photo's longer side on the plane (m); > 0. The shorter side follows the
  /// photo's aspect ratio (square pixels).
  double plane_width = 1.0;
  /// Horizontal distance of every camera centre from the photo's centre (m); > 0 (a camera
  /// straight above the centre has no defined "up" and the orbit no baseline).
  double orbit_radius = 0.25;
  double camera_height = 0.6;  ///< Height of the orbit above the plane (m); > 0.
  /// Angle of the orbit arc that the views span, evenly spaced and centred on the view from the
  /// side of the photo's bottom edge (-y), which sees the photo upright (deg); in (0, 360): a
  /// closed circle would repeat the first view.
  double arc_degrees = 90.0;

  /// The camera these options describe (no distortion).
  CameraIntrinsics intrinsics() const;

  /// Throws InvalidOptions naming the field, its value and the constraint.
  void validate() const;
};

/// A photo on the plane z = 0 (see the frame convention above). Texture pixel (u, v) (centres at
/// integers) is the rectangle of size width_m / cols x height_m / rows centred at
///   x = (u + 0.5) width_m / cols - width_m / 2,   y = height_m / 2 - (v + 0.5) height_m / rows.
struct PlanarTexture {
  cv::Mat image;          ///< The photo, CV_8UC1 or CV_8UC3 (BGR).
  double width_m = 0.0;   ///< Extent along world x (m); > 0.
  double height_m = 0.0;  ///< Extent along world y (m); > 0.

  /// The 3x3 homogeneous map from texture pixel (u, v, 1) to plane point (x, y, 1).
  Eigen::Matrix3d planeFromTexture() const;
};

/// `image` laid on the plane with its longer side spanning plane_width_m (> 0), square pixels.
/// The image is shared, not copied. CheckError for an empty image or a non-positive width.
PlanarTexture makePlanarTexture(const cv::Mat& image, double plane_width_m);

/// The homography K [r1 r2 t] from a point (x, y, 1) of the plane z = 0 (world frame) to the
/// homogeneous pixel of `camera` at `cam_from_world`: every planar view is this map of the plane,
/// so two views are related by pixelFromPlane(b) * pixelFromPlane(a)^-1.
Eigen::Matrix3d pixelFromPlane(const Camera& camera, const Pose3& cam_from_world);

/// Renders what `camera` at `cam_from_world` sees of the photo `texture_bgr` (CV_8UC1 or
/// CV_8UC3) laid on the plane with its longer side spanning plane_width_m: the homography
/// K [r1 r2 t] planeFromTexture() applied by cv::warpPerspective with bilinear interpolation
/// (OpenCV's 1/32 px sub-pixel grid). Pixels whose ray misses the photo, or meets the plane
/// behind the camera, are `background` (0..255, every channel); the photo's border pixels blend
/// with it. Returns an image of the camera's size and the texture's type; an all-background
/// image if the camera centre lies in the plane. CheckError for a camera with distortion (a
/// homography cannot render it), an empty or non-8-bit texture, or plane_width_m <= 0.
cv::Mat renderPlanarView(const cv::Mat& texture_bgr, double plane_width_m, const Camera& camera,
                         const Pose3& cam_from_world, int background = kPlanarBackground);

/// A rendered planar sequence. All vectors are index-aligned, one entry per frame.
struct PlanarScene {
  std::shared_ptr<const Camera> camera;
  PlanarTexture texture;                   ///< The photo as laid on the plane.
  std::vector<double> timestamps;          ///< i * kPlanarFramePeriod (s).
  std::vector<Pose3> true_cam_from_world;  ///< The orbit (see PlanarSceneOptions).
  /// The starting guess: every pose perturbed, the first one included. A solver that fixes its
  /// first pose as the gauge then works in a frame slightly off the truth, as with any real
  /// initialiser (the paper used ORB-SLAM's poses), so evaluate with a Sim(3) (or SE(3))
  /// alignment to the ground truth (`curvesfm eval` does by default).
  std::vector<Pose3> initial_cam_from_world;
  std::vector<cv::Mat> images;  ///< Rendered views with noise, the texture's type.

  /// Mean distance between consecutive true camera centres (m); 0 for fewer than 2 frames.
  double meanFrameBaseline() const;
  /// The true homography from homogeneous pixels of frame `from` to those of frame `to`.
  Eigen::Matrix3d pixelMap(int from, int to) const;
  /// Distance between the first and the last true camera centres (m).
  double firstToLastBaseline() const;
};

/// Builds the scene from the photo `texture_bgr` (CV_8UC1 or CV_8UC3): cameras evenly spaced on
/// the orbit arc (see PlanarSceneOptions), each looking at the photo's centre with its image x
/// axis horizontal, renderPlanarView() views with Gaussian noise (cv::RNG, `seed`) added per
/// pixel and channel, and perturbed initial poses (per pose or per step, see InitNoiseModel: an
/// isotropic Gaussian rotation-vector error and a Gaussian shift of the camera centre in the
/// world; std::mt19937, `seed`). All images are
/// held in memory (width x height x channels bytes each). Throws InvalidOptions for invalid
/// options, CheckError for an empty or non-8-bit texture.
PlanarScene makePlanarScene(const cv::Mat& texture_bgr, const PlanarSceneOptions& options);

/// Writes the scene as a dataset in DESIGN.md's TUM RGB-D layout: `dir`/rgb.txt, rgb/NNNNNN.png
/// (lossless, frame index with 6 digits), camera.yaml, groundtruth.txt (true poses) and
/// init_poses.txt (initial poses; without `with_initial_poses`, none, and an older one is
/// removed so that `run` starts from the point initialiser), trajectories camera-to-world.
/// Creates `dir` and rgb/ if needed; existing files of the same names are overwritten, others
/// left alone. Throws IoError naming the path that cannot be created or written.
void writePlanarDataset(const std::string& dir, const PlanarScene& scene,
                        bool with_initial_poses = true);

}  // namespace curvesfm
