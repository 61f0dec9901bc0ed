#pragma once

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/camera.h"
#include "core/dataset_io.h"
#include "core/enum_names.h"

namespace curvesfm {

// A calibrated image sequence read in the layout it comes in (DESIGN.md "Data contracts"), so
// that nobody writes a converter. README.md "Dataset layouts" shows each layout's files.
//
// Errors: as every reader of dataset_io.h, one exception naming the file and, for content, the
// line: IoError for a missing or unreadable file or image, or a folder in no (or more than one)
// known layout; ParseError for malformed content or frames that disagree (e.g. different K);
// InvalidOptions for bad options (a malformed camera string).

/// How the files of a dataset folder are laid out.
enum class DatasetLayout {
  kAuto,         ///< Detected from the files present (detectDatasetLayout).
  kTum,          ///< TUM RGB-D: rgb.txt, groundtruth.txt, camera.yaml.
  kKitti,        ///< KITTI odometry: image_0/ (or image_2/, image_l/), calib.txt, poses.txt.
  kMiddlebury,   ///< Middlebury multi-view: *_par.txt and the images it names.
  kProjection,   ///< Images with one 3x4 projection matrix file each (Pavilion, PMVS).
  kStrecha,      ///< Strecha / EPFL: images/*.jpg and gt_dense_cameras/*.camera.
  kSevenScenes,  ///< Microsoft 7-Scenes: frame-*.color.png|jpg and frame-*.pose.txt.
  kEuroc,        ///< EuRoC MAV: mav0/cam0/data.csv, data/, sensor.yaml, the ground truth's csv.
  kImages,       ///< A plain folder of images (or its images/), camera.yaml or --camera.
};

template <>
struct EnumNames<DatasetLayout> {
  static constexpr std::array<std::pair<DatasetLayout, const char*>, 9> kNames = {
      {{DatasetLayout::kAuto, "auto"},
       {DatasetLayout::kTum, "tum"},
       {DatasetLayout::kKitti, "kitti"},
       {DatasetLayout::kMiddlebury, "middlebury"},
       {DatasetLayout::kProjection, "projection"},
       {DatasetLayout::kStrecha, "strecha"},
       {DatasetLayout::kSevenScenes, "7scenes"},
       {DatasetLayout::kEuroc, "euroc"},
       {DatasetLayout::kImages, "images"}}};
};

/// What to read from a dataset folder.
struct ImageSequenceOptions {
  DatasetLayout layout = DatasetLayout::kAuto;  ///< The folder's layout; auto detects it.
  /// Intrinsics in pixels, "fx,fy,cx,cy[,k1,k2,p1,p2[,k3]]" (OpenCV radial-tangential model,
  /// pixel centres at integers), overriding the dataset's own; the image size comes from the
  /// first image. Empty: the dataset's own intrinsics.
  std::string camera;
  int max_frames = 0;  ///< At most this many images after the stride; 0 = all; >= 0.
  int stride = 1;      ///< Every stride-th image, starting with the first; >= 1.

  /// Throws InvalidOptions naming the field (a malformed camera string included).
  void validate() const;
};

/// One image of a sequence.
struct SequenceImage {
  /// Seconds. From the dataset where it has times (TUM rgb.txt, KITTI times.txt, EuRoC data.csv
  /// in nanoseconds); otherwise the
  /// image's 0-based index in the dataset's own order before stride and max_frames, so that the
  /// images and ground truth of a subsampled sequence keep their times.
  double timestamp = 0.0;
  std::string image_path;  ///< The image file, as a path usable from the working folder.
  std::string name;        ///< Its file name (e.g. "000012.png"), for matching by name (COLMAP).
};

/// A calibrated image sequence and, where the dataset has it, its ground-truth trajectory.
struct ImageSequence {
  std::string dir;     ///< The folder read.
  std::string layout;  ///< Its layout's name (toString(DatasetLayout)), never "auto".
  Camera camera{CameraIntrinsics{}};  ///< Intrinsics and image size in pixels.
  std::string camera_source;          ///< Where the intrinsics came from: a file, or "--camera".
  std::vector<SequenceImage> images;  ///< In the layout's order, after stride and max_frames.
  /// Camera-to-world poses (x_world = R x_cam + t, as TUM trajectories) in the dataset's own
  /// world frame and unit (metres for TUM, KITTI, Middlebury, Strecha, 7-Scenes, EuRoC; Blender
  /// units for Pavilion), stamped with the images' timestamps. TUM and images: the whole
  /// groundtruth.txt; EuRoC: the whole ground-truth csv, carried from the body to the camera;
  /// every other layout: one pose per entry of `images`, in the same order. Empty without
  /// ground truth.
  std::vector<StampedPose> ground_truth;
  std::string ground_truth_source;  ///< The file(s) it came from; empty without ground truth.
};

/// Intrinsics for a sequence whose dataset gives none and for which no --camera was given: the
/// camera of a COLMAP model given as initial poses.
struct FallbackCamera {
  Camera camera;
  std::string source;  ///< Where it came from (ImageSequence::camera_source).
};

/// Reads the sequence in `dir`: the image list, the camera, the ground truth if present. Every
/// file but the images is parsed and every selected image checked to exist and be in a format
/// OpenCV reads (the first one is decoded for its size where the layout does not give it), so
/// that bad input fails before any work. The camera is options.camera's, else the dataset's,
/// else `fallback`'s (whose size must be the first image's). Throws as the comment at the top of
/// this file says.
ImageSequence loadImageSequence(const std::string& dir, const ImageSequenceOptions& options,
                                const std::optional<FallbackCamera>& fallback = std::nullopt);

/// The layout of `dir` from the files present: rgb.txt -> tum; calib.txt or image_0/ -> kitti;
/// *_par.txt -> middlebury; *.camera (in dir or gt_dense_cameras/) -> strecha; cameras/ or txt/
/// of projection matrix files -> projection; frame-*.pose.txt -> 7scenes; data.csv and
/// sensor.yaml in mav0/cam0/, cam0/ or dir -> euroc; and when none of
/// these matches, image files in dir or in dir/images/ (or its one sub-folder) -> images. IoError
/// naming the folder and listing the layouts looked for when none or several match (and the
/// sub-folders that do match one, if any).
DatasetLayout detectDatasetLayout(const std::string& dir);

/// Parses the camera string of ImageSequenceOptions::camera for an image of width x height
/// pixels. InvalidOptions "ImageSequenceOptions.camera = ..." naming what is wrong.
Camera parseCameraString(const std::string& text, int width, int height);
/// The camera as parseCameraString() reads it: "fx,fy,cx,cy", and the five distortion
/// coefficients when it has any, every number in as many digits as it takes to read back the
/// same double (the image size is not part of it).
std::string formatCameraString(const Camera& camera);

}  // namespace curvesfm
