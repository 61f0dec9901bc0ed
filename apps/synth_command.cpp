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

}  // namespace

SynthCommand::SynthCommand(CLI::App* app) {
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
}

PlanarSceneOptions SynthCommand::planarOptions() const {
  PlanarSceneOptions options = options_;
  options.cx = 0.5 * (options.width - 1);
  options.cy = 0.5 * (options.height - 1);
  return options;
}

void SynthCommand::validate() const {
  table_.validate();
  planarOptions().validate();
}

int SynthCommand::run() const {
  const PlanarSceneOptions options = planarOptions();
  options.validate();
  const cv::Mat photo = readColorImage(image_path_);
  const PlanarScene scene = makePlanarScene(photo, options);
  writePlanarDataset(out_dir_, scene, write_init_poses_);
  printSummary(image_path_, out_dir_, options, scene, write_init_poses_);
  return 0;
}

}  // namespace curvesfm
