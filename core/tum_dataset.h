#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/dataset_io.h"
#include "core/image_sequence.h"

namespace curvesfm {

// A calibrated image sequence in the TUM RGB-D layout (DESIGN.md "Data contracts"), read as
// `curvesfm run` takes it: DIR/camera.yaml, DIR/rgb.txt, the initial poses and, if present,
// DIR/groundtruth.txt.

/// One image of the sequence with the initial pose matched to it.
struct DatasetFrame {
  double timestamp = 0.0;  ///< s, as rgb.txt gives it.
  std::string image_path;  ///< Resolved against rgb.txt's folder.
  Pose3 initial_cam_from_world;
};

/// The files of a dataset folder, every one but the images read and checked.
struct TumDataset {
  std::string camera_path, rgb_path, init_poses_path, ground_truth_path;
  std::optional<Camera> camera;           ///< From camera.yaml.
  int images = 0;                         ///< Entries of rgb.txt.
  std::vector<DatasetFrame> frames;       ///< Images with an initial pose, in rgb.txt order.
  std::vector<StampedPose> ground_truth;  ///< Empty without groundtruth.txt.
};

/// Reads the dataset in `dir` with loadImageSequence()'s TUM reader (camera.yaml is required
/// here: IoError naming it when missing). The initial poses come from `init_poses_path`, or
/// DIR/init_poses.txt when it is empty; each image takes the pose nearest in time within
/// `max_dt` seconds (associateByTimestamp), images without one are left out. Every file but the
/// images is parsed here and every image file checked to exist and have a format OpenCV reads,
/// so that bad input fails before any work. Throws IoError (missing or unreadable file, no
/// initial poses) or ParseError (malformed file, no pose within max_dt of any image), each
/// naming the file.
TumDataset loadTumDataset(const std::string& dir, const std::string& init_poses_path,
                          double max_dt);

/// The images of `sequence` that have an initial pose in `poses` (camera-to-world), each taking
/// the pose nearest in time within `max_dt` seconds (associateByTimestamp), in the sequence's
/// order. ParseError naming `poses_source` when no image has one.
std::vector<DatasetFrame> framesWithPoses(const ImageSequence& sequence,
                                          const std::vector<StampedPose>& poses, double max_dt,
                                          const std::string& poses_source);

/// The initial poses `run` starts from, camera-to-world, and where they came from (`*source`):
/// `path` names a TUM trajectory file or a COLMAP model folder (text or binary; its poses are
/// matched to the images by name and stamped with their timestamps); an empty `path` takes
/// DIR/init_poses.txt when the dataset has one. Empty (and `*source` empty) when there are none:
/// the initialiser must find them. IoError or ParseError naming the file for bad input.
std::vector<StampedPose> readInitialPoses(const std::string& path, const ImageSequence& sequence,
                                          std::string* source);

/// Decodes the image at `path` (8-bit BGR); IoError naming it if it does not load or its size
/// differs from `camera`'s.
cv::Mat loadCameraImage(const std::string& path, const Camera& camera);

/// Decodes `frame`'s image (8-bit BGR); IoError naming it if it does not load or its size differs
/// from `camera`'s.
cv::Mat loadFrameImage(const DatasetFrame& frame, const Camera& camera);

}  // namespace curvesfm
