#include "apps/synth_command.h"

#include <cmath>
#include <cstdio>

#include "apps/cli/cli_options.h"
#include "apps/cli/option_tables.h"
#include "core/dataset_io.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

// An empty path would only fail later, with a message that names nothing.
const CLI::Validator kNotEmpty(
    [](std::string& value) { return value.empty() ? std::string("must not be empty") : ""; }, "");

void printSummary(const std::string& image_path, const std::string& out_dir,
                  const PlanarSceneOptions& options, const PlanarScene& scene,
                  bool with_initial_poses) {
  const double distance = std::hypot(options.orbit_radius, options.camera_height);
  std::printf("synth planar: %zu frames of %dx%d px (fx %g, fy %g, cx %g, cy %g), 1/30 s apart\n",
              scene.images.size(), options.width, options.height, options.fx, options.fy,
              options.cx, options.cy);
  std::printf("photo: %s, %dx%d px, laid as a %.3f x %.3f m plane at z = 0\n", image_path.c_str(),
              scene.texture.image.cols, scene.texture.image.rows, scene.texture.width_m,
              scene.texture.height_m);
  std::printf("orbit: radius %.3f m at height %.3f m over %g deg, %.3f m from the plane centre\n",
              options.orbit_radius, options.camera_height, options.arc_degrees, distance);
  std::printf("baseline: %.1f mm between frames (%.2f%% of the distance), %.1f mm first to last\n",
              1e3 * scene.meanFrameBaseline(), 100.0 * scene.meanFrameBaseline() / distance,
              1e3 * scene.firstToLastBaseline());
  std::printf("noise: intensity std dev %.2f levels (%g x 255) per pixel and channel, seed %u\n",
              options.intensity_noise * 255.0, options.intensity_noise, options.seed);
  if (with_initial_poses) {
    std::printf("initial poses: %s, std dev %g m and %g deg per axis %s\n",
                options.init_noise_model == InitNoiseModel::kDrift
                    ? "drift (every motion between frames perturbed)"
                    : "every frame perturbed on its own",
                options.init_noise_translation, options.init_noise_rotation_deg,
                options.init_noise_model == InitNoiseModel::kDrift ? "per step" : "per pose");
  } else {
    std::printf("initial poses: none (`run` starts from the point initialiser)\n");
  }
  std::printf("written: %s (rgb.txt, rgb/ with %zu PNG, camera.yaml, groundtruth.txt%s)\n",
              out_dir.c_str(), scene.images.size(), with_initial_poses ? ", init_poses.txt" : "");
}

void printCurveSummary(const std::string& out_dir, const CurveSceneOptions& options,
                       const CurveScene& scene, bool with_initial_poses) {
  const CameraIntrinsics& k = options.intrinsics;
  int segments = 0;
  for (const PolyBezier& curve : scene.true_curves) segments += curve.numSegments();
  std::printf(
      "synth curves: %zu frames of %dx%d px (fx %g, fy %g, cx %g, cy %g, k1 %g, k2 %g), "
      "1/30 s apart\n",
      scene.keyframes.size(), k.width, k.height, k.fx, k.fy, k.cx, k.cy, k.k1, k.k2);
  if (options.camera_path == CameraPath::kOrbit) {
    std::printf("path: orbit of radius %.3f m around the room centre over %g deg\n",
                options.camera_distance, options.arc_degrees);
  } else if (options.camera_path == CameraPath::kForwardWalk) {
    std::printf("path: forward walk of %.3f m ending %.3f m before the room centre\n",
                options.walk_length, options.camera_distance);
  } else {
    std::printf("path: sideways walk of %.3f m along x, %.3f m in front of the room centre\n",
                options.walk_length, options.camera_distance);
  }
  std::printf(
      "curves: %zu (%d segments, %s), %zu segment observations, image noise %g levels, "
      "seed %u\n",
      scene.true_curves.size(), segments, toString(options.curve_kind).c_str(),
      scene.observations.size(), options.pixel_noise, options.seed);
  if (with_initial_poses) {
    std::printf(
        "initial poses: every frame but the first perturbed on its own, std dev %g m and "
        "%g deg per axis (the second frame keeps its distance to the first)\n",
        options.pose_noise_translation, options.pose_noise_rotation_deg);
  } else {
    std::printf("initial poses: none (`run` starts from the point initialiser)\n");
  }
  std::printf(
      "written: %s (rgb.txt, rgb/ with %zu PNG, camera.yaml, groundtruth.txt%s, "
      "gt_curves.obj)\n",
      out_dir.c_str(), scene.keyframes.size(), with_initial_poses ? ", init_poses.txt" : "");
}

// A sequence rather than the unit scene of the curve BA tests: a full orbit in a room whose
// curves each keyframe sees about a third of, and a start like issue 14's noise protocol
// (about 1 % of the camera spacing at 100 frames, 0.1 deg).
CurveSceneOptions defaultCurveSequenceOptions() {
  CurveSceneOptions options;
  options.num_keyframes = 100;
  options.arc_degrees = 360.0;
  options.num_curves = 100;
  options.volume_half_extents = Eigen::Vector3d(6.0, 1.5, 6.0);
  options.pose_noise_translation = 0.002;
  options.pose_noise_rotation_deg = 0.1;
  // `run` detects edges down to 0.8 grey levels / px on noise-free images: a return to the
  // background of 20 grey levels over 48 px (0.42 / px) shows no second edge beside each curve,
  // which the unit scene's 40 over 8 px did (half the map of a walk was such ghosts).
  options.step_contrast = 40.0;
  options.edge_return_length_px = 48.0;
  return options;
}

}  // namespace

SynthCommand::SynthCommand(CLI::App* app) : curve_options_(defaultCurveSequenceOptions()) {
  CLI::App* synth =
      app->add_subcommand("synth",
                          "Write a synthetic dataset (TUM RGB-D layout with groundtruth.txt and "
                          "init_poses.txt); `curvesfm synth <kind> --help` for a kind's flags.");
  synth->require_subcommand(1);
  planar_ = synth->add_subcommand(
      "planar",
      "The paper's planar protocol (4.1): a photograph laid on a plane, a camera orbiting above "
      "it looking at its centre, views rendered by homography with Gaussian intensity noise, "
      "the true trajectory and a perturbed one as starting guess.");
  addConfigFlag(planar_);
  CLI::App* c = planar_;
  c->add_option("--image", image_path_, "The photograph (any format OpenCV reads)")
      ->required()
      ->check(kNotEmpty);
  c->add_option("--out", out_dir_, "Dataset folder to write (created if needed)")
      ->required()
      ->check(kNotEmpty);
  c->add_option("--init-poses", write_init_poses_,
                "Write init_poses.txt, the perturbed truth; false leaves `run` to the point "
                "initialiser")
      ->capture_default_str();
  addPlanarSceneOptions(&table_, &options_, {"", "", "Scene", ""});
  table_.addFlags(c);

  curves_ = synth->add_subcommand(
      "curves",
      "3D curves (lines, arcs, helices) in a room, rendered as blurred step edges on a grey "
      "background from cameras on an orbit, a forward walk or a sideways walk: the true "
      "trajectory, a perturbed "
      "one as starting guess and the true curves (gt_curves.obj) for eval-map.");
  addConfigFlag(curves_);
  curves_->add_option("--out", out_dir_, "Dataset folder to write (created if needed)")
      ->required()
      ->check(kNotEmpty);
  curves_
      ->add_option("--init-poses", write_init_poses_,
                   "Write init_poses.txt, the perturbed truth; false leaves `run` to the point "
                   "initialiser")
      ->capture_default_str();
  addCurveSceneOptions(&curve_table_, &curve_options_, {"", "", "Scene", ""});
  curve_table_.addFlags(curves_);
}

PlanarSceneOptions SynthCommand::planarOptions() const {
  PlanarSceneOptions options = options_;
  options.cx = 0.5 * (options.width - 1);
  options.cy = 0.5 * (options.height - 1);
  return options;
}

void SynthCommand::validate() const {
  if (curves_->parsed()) {
    curve_table_.validate();
    curve_options_.validate();
    return;
  }
  table_.validate();
  planarOptions().validate();
}

int SynthCommand::run() const { return curves_->parsed() ? runCurves() : runPlanar(); }

int SynthCommand::runCurves() const {
  curve_options_.validate();
  const CurveScene scene = makeCurveScene(curve_options_);
  writeCurveDataset(out_dir_, scene, write_init_poses_);
  printCurveSummary(out_dir_, curve_options_, scene, write_init_poses_);
  return 0;
}

int SynthCommand::runPlanar() const {
  const PlanarSceneOptions options = planarOptions();
  options.validate();
  const cv::Mat photo = readColorImage(image_path_);
  const PlanarScene scene = makePlanarScene(photo, options);
  writePlanarDataset(out_dir_, scene, write_init_poses_);
  printSummary(image_path_, out_dir_, options, scene, write_init_poses_);
  return 0;
}

}  // namespace curvesfm
