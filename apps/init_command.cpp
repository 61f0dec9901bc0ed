#include "apps/init_command.h"

#include <cstdio>
#include <filesystem>

#include "apps/cli/cli_options.h"
#include "apps/cli/config_file.h"
#include "apps/cli/initialisation_output.h"
#include "apps/cli/option_tables.h"
#include "apps/cli/report_json.h"
#include "core/clock.h"
#include "core/errors.h"
#include "core/heap_policy.h"

namespace curvesfm {

namespace fs = std::filesystem;

InitCommand::InitCommand(CLI::App* app) {
  command_ = app->add_subcommand(
      "init",
      "Initial poses and a sparse point map from a calibrated image sequence alone (KLT tracks "
      "and descriptor matches, two-view start, PnP registration, point BA): writes "
      "trajectory.txt, points.ply and report.json.");
  addConfigFlag(command_);
  command_->add_option("--dataset", dataset_dir_, "Dataset folder in any layout of the README")
      ->required();
  command_->add_option("--out", out_dir_, "Output folder (created if needed)")->required();
  addImageSequenceOptions(&table_, &sequence_);
  addPointInitialiserOptions(&table_, &options_, "/points");
  table_.addFlags(command_);
}

int InitCommand::run() const {
  validate();
  const Clock::time_point start = Clock::now();
  const ImageSequence sequence = loadImageSequence(dataset_dir_, sequence_);
  createOutputFolder(out_dir_);
  std::printf("init: %s (%s layout), %zu images, camera %dx%d from %s\n", dataset_dir_.c_str(),
              sequence.layout.c_str(), sequence.images.size(), sequence.camera.width(),
              sequence.camera.height(), sequence.camera_source.c_str());
  const PointInitialisation result = initialiseSequence(sequence, options_);
  const nlohmann::json ate = printInitialisationSummary(sequence, result);

  const std::string trajectory = (fs::path(out_dir_) / "trajectory.txt").string();
  const std::string points = (fs::path(out_dir_) / "points.ply").string();
  writeTrajectory(trajectory, initialisedTrajectory(sequence, result));
  writeInitialisedPoints(points, result);
  nlohmann::json report = initialisationToJson(sequence, result);
  report["command"] = "init";
  report["curvesfm"] = versionJson();
  report["heap"] = describe(heapPolicy());
  report["config"] = optionsToJson(*command_);
  report["options"] = table_.toJson();
  report["dataset"] = {{"dir", dataset_dir_},
                       {"layout", sequence.layout},
                       {"camera", sequence.camera_source},
                       {"images", sequence.images.size()},
                       {"groundtruth", sequence.ground_truth_source}};
  // The camera the trajectory and points hold: the dataset's, its focal lengths refined with
  // --points-ba-refine-focal.
  report["camera"] = cameraToJson(sequence.camera.withFocalScale(result.focal_scale));
  report["ate"] = ate;
  report["total_seconds"] = secondsSince(start);
  writeJsonFile((fs::path(out_dir_) / "report.json").string(), report);
  std::printf("written: %s (trajectory.txt, points.ply, report.json)\n", out_dir_.c_str());
  std::fflush(stdout);  // The summary first, then why nothing was reconstructed.
  if (result.registeredFrames() == 0) {
    std::fprintf(stderr, "init: nothing reconstructed: %s\n", result.failure.c_str());
    return 1;
  }
  return 0;
}

}  // namespace curvesfm
