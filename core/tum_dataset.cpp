#include "core/tum_dataset.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "core/colmap_model.h"
#include "core/errors.h"
#include "core/image_sequence.h"
#include "core/timestamp_association.h"

namespace curvesfm {
namespace {

namespace fs = std::filesystem;

std::string joinPath(const std::string& dir, const std::string& name) {
  return (fs::path(dir) / name).string();
}

// DIR/init_poses.txt unless --init-poses names a file; until an automatic initialiser exists
// a run cannot start without one.
std::string initPosesPath(const std::string& dataset_dir, const std::string& flag) {
  if (!flag.empty()) return flag;
  const std::string fallback = joinPath(dataset_dir, "init_poses.txt");
  if (fs::exists(fallback)) return fallback;
  throw IoError(fallback,
                "no such file and no --init-poses given; an automatic initialiser is not "
                "available yet: pass --init-poses FILE, a TUM trajectory "
                "'timestamp tx ty tz qx qy qz qw' (camera-to-world) covering the images");
}

std::string timeSpan(const std::vector<double>& times) {
  char text[64];
  const auto [low, high] = std::minmax_element(times.begin(), times.end());
  std::snprintf(text, sizeof(text), "%.6f .. %.6f s", *low, *high);
  return text;
}

}  // namespace

// The TUM reader of loadImageSequence() reads camera.yaml, rgb.txt and groundtruth.txt and checks
// every image, so that bad input fails before any work; the initial poses are this function's.
TumDataset loadTumDataset(const std::string& dir, const std::string& init_poses_flag,
                          double max_dt) {
  TumDataset d;
  d.camera_path = joinPath(dir, "camera.yaml");
  d.rgb_path = joinPath(dir, "rgb.txt");
  ImageSequenceOptions options;
  options.layout = DatasetLayout::kTum;
  const ImageSequence sequence = loadImageSequence(dir, options);
  d.camera.emplace(sequence.camera);
  d.images = static_cast<int>(sequence.images.size());
  d.init_poses_path = initPosesPath(dir, init_poses_flag);
  d.frames =
      framesWithPoses(sequence, readTrajectory(d.init_poses_path), max_dt, d.init_poses_path);
  d.ground_truth_path = sequence.ground_truth_source;
  d.ground_truth = sequence.ground_truth;
  return d;
}

std::vector<DatasetFrame> framesWithPoses(const ImageSequence& sequence,
                                          const std::vector<StampedPose>& poses, double max_dt,
                                          const std::string& poses_source) {
  std::vector<StampedPose> image_times(sequence.images.size());
  std::vector<double> image_stamps, pose_stamps;
  for (std::size_t i = 0; i < sequence.images.size(); ++i) {
    image_times[i].timestamp = sequence.images[i].timestamp;
    image_stamps.push_back(sequence.images[i].timestamp);
  }
  for (const StampedPose& pose : poses) pose_stamps.push_back(pose.timestamp);
  std::vector<DatasetFrame> frames;
  for (const TimestampMatch& m : associateByTimestamp(image_times, poses, max_dt)) {
    const SequenceImage& image = sequence.images[m.estimate_index];
    frames.push_back(
        {image.timestamp, image.image_path, poses[m.ground_truth_index].world_from_cam.inverse()});
  }
  if (frames.empty()) {
    char within[32];
    std::snprintf(within, sizeof(within), "%g", max_dt);
    throw ParseError(
        poses_source, 0,
        "poses within " + std::string(within) + " s of the images of " + sequence.dir + " (" +
            timeSpan(image_stamps) + ")",
        "none of its " + std::to_string(poses.size()) + " poses (" + timeSpan(pose_stamps) + ")");
  }
  return frames;
}

std::vector<StampedPose> readInitialPoses(const std::string& path, const ImageSequence& sequence,
                                          std::string* source) {
  source->clear();
  std::string file = path;
  if (file.empty()) {
    const std::string fallback = joinPath(sequence.dir, "init_poses.txt");
    if (!fs::exists(fallback)) return {};
    file = fallback;
  }
  *source = file;
  if (fs::is_directory(file)) return colmapPosesForSequence(readColmapModel(file), sequence);
  return readTrajectory(file);
}

cv::Mat loadCameraImage(const std::string& path, const Camera& camera) {
  cv::Mat image = readColorImage(path);
  if (image.cols != camera.width() || image.rows != camera.height()) {
    throw IoError(path, "is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                            " px, the camera says " + std::to_string(camera.width()) + "x" +
                            std::to_string(camera.height()));
  }
  return image;
}

cv::Mat loadFrameImage(const DatasetFrame& frame, const Camera& camera) {
  return loadCameraImage(frame.image_path, camera);
}

}  // namespace curvesfm
