#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/pose3.h"

namespace curvesfm {

// The TUM RGB-D layout of DESIGN.md, as the synthetic scenes write it: what `curvesfm run`
// and `eval` read back without any layout flag.

/// One synthetic sequence: index-aligned images, timestamps and poses (cam_from_world).
struct SyntheticSequence {
  const Camera* camera = nullptr;
  const std::vector<double>* timestamps = nullptr;
  std::vector<cv::Mat> images;  ///< 8-bit grey or BGR; shallow headers of the scene's images.
  const std::vector<Pose3>* true_cam_from_world = nullptr;
  const std::vector<Pose3>* initial_cam_from_world = nullptr;  ///< May stay null (see below).
};

/// Writes `dir`/rgb.txt, rgb/NNNNNN.png (lossless, frame index with 6 digits), camera.yaml,
/// groundtruth.txt (true poses) and init_poses.txt (initial poses; without them, none, and an
/// older one is removed so that `run` starts from the point initialiser), trajectories
/// camera-to-world. Creates `dir` and rgb/ if needed; existing files of the same names are
/// overwritten, others left alone. Throws IoError naming the path that cannot be created or
/// written, CheckError for sizes that do not match.
void writeSyntheticDataset(const std::string& dir, const SyntheticSequence& sequence);

}  // namespace curvesfm
