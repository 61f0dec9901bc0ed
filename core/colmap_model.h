#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/dataset_io.h"
#include "core/image_sequence.h"
#include "core/pose3.h"

namespace curvesfm {

// A COLMAP sparse model (https://colmap.github.io/format.html) read as initial poses and camera:
// cameras.txt + images.txt, or cameras.bin + images.bin (points3D is not needed and not read).
//
// Conventions: COLMAP stores world-to-camera poses (qvec = w, x, y, z; tvec), which become
// `cam_from_world` here; its pixel coordinates put the centre of the top-left pixel at
// (0.5, 0.5), ours at (0, 0), so cx and cy are 0.5 smaller than COLMAP's.
// Camera models: SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, and FULL_OPENCV with
// k4 = k5 = k6 = 0 map onto Camera; any other model is a ParseError naming it.

/// One registered image of the model.
struct ColmapImage {
  int image_id = 0;
  int camera_id = 0;
  std::string name;      ///< As COLMAP stores it: the path relative to its image folder.
  Pose3 cam_from_world;  ///< In the model's world frame and (arbitrary) unit.
};

/// The cameras and registered images of a COLMAP model.
struct ColmapModel {
  std::string dir;
  std::map<int, Camera> cameras;    ///< By camera_id.
  std::vector<ColmapImage> images;  ///< In the file's order.
};

/// Reads the model in `dir`: the text files if cameras.txt is there, else the binary ones.
/// IoError if neither cameras.txt nor cameras.bin exists (or its images file is missing);
/// ParseError naming file and line (text) or file and byte offset (binary, as "line 0" with the
/// offset in the message) for malformed content, an unknown or unsupported camera model, or an
/// image whose camera_id is not in the cameras file.
ColmapModel readColmapModel(const std::string& dir);

/// The camera of the COLMAP model in `dir`, when it has exactly one (a sequence's intrinsics);
/// nothing when it has several. Throws as readColmapModel().
std::optional<FallbackCamera> colmapModelCamera(const std::string& dir);

/// The model's poses of `sequence`'s images as camera-to-world StampedPose (the images'
/// timestamps), in the sequence's order: an image matches the model image of the same name
/// (COLMAP's relative path), or, failing that, the one model image with the same file name.
/// Images the model did not register are left out. ParseError naming the model folder if no
/// image matches at all.
std::vector<StampedPose> colmapPosesForSequence(const ColmapModel& model,
                                                const ImageSequence& sequence);

}  // namespace curvesfm
