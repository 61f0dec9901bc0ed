#include "sim/synthetic_dataset.h"

#include <cstdio>
#include <filesystem>
#include <system_error>

#include "core/check.h"
#include "core/dataset_io.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

std::string imageName(std::size_t frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "rgb/%06zu.png", frame);
  return name;
}

// Creates `folder` and its parents; throws IoError naming it if that fails or a file is there.
void createDatasetFolder(const std::string& folder) {
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error) throw IoError(folder, "cannot create the folder: " + error.message());
  if (!std::filesystem::is_directory(folder, error)) {
    throw IoError(folder, "cannot create the folder: a file of that name exists");
  }
}

}  // namespace

void writeSyntheticDataset(const std::string& dir, const SyntheticSequence& sequence) {
  CURVESFM_CHECK(sequence.camera && sequence.timestamps && sequence.true_cam_from_world)
      << "a synthetic sequence needs a camera, timestamps and true poses";
  const std::vector<double>& timestamps = *sequence.timestamps;
  const std::size_t frames = timestamps.size();
  CURVESFM_CHECK(sequence.images.size() == frames &&
                 sequence.true_cam_from_world->size() == frames &&
                 (!sequence.initial_cam_from_world ||
                  sequence.initial_cam_from_world->size() == frames))
      << "a synthetic sequence needs one image and one pose of each kind per timestamp";
  CURVESFM_CHECK(!dir.empty()) << "the dataset folder must be named";
  const std::filesystem::path root(dir);
  createDatasetFolder(root.string());
  createDatasetFolder((root / "rgb").string());
  std::vector<ImageEntry> entries;
  for (std::size_t i = 0; i < frames; ++i) {
    entries.push_back({timestamps[i], imageName(i)});
    writeImage((root / entries.back().path).string(), sequence.images[i]);
  }
  writeImageList((root / "rgb.txt").string(), entries);
  writeCameraYaml((root / "camera.yaml").string(), *sequence.camera);
  writeTrajectory((root / "groundtruth.txt").string(),
                  stampedPoses(timestamps, *sequence.true_cam_from_world));
  const std::filesystem::path init_poses = root / "init_poses.txt";
  if (!sequence.initial_cam_from_world) {
    std::error_code ignored;  // A missing file is what we want.
    std::filesystem::remove(init_poses, ignored);
    return;
  }
  writeTrajectory(init_poses.string(), stampedPoses(timestamps, *sequence.initial_cam_from_world));
}

}  // namespace curvesfm
