#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/pose3.h"

namespace curvesfm {

// Readers and writers for the dataset files of DESIGN.md "Data contracts" (TUM RGB-D layout and
// ORB-SLAM2-style camera YAML).
//
// Errors, common to every reader:
//   - a file that cannot be opened or read: IoError "<path>: cannot open for reading";
//   - malformed content: ParseError "<path>:<line>: expected <what>, found <what>", with 1-based
//     line numbers (line 0, i.e. no number, for the file as a whole, e.g. an empty file).
// Text files: a line whose first non-blank character is '#' is a comment; blank lines are
// skipped; fields are separated by spaces or tabs; CRLF line ends are accepted. Numbers are
// parsed locale independently and must be finite, with no trailing characters.

/// One line of a TUM `rgb.txt`.
struct ImageEntry {
  double timestamp = 0.0;  ///< Capture time in seconds (as written in the file).
  std::string path;        ///< Image path, resolved relative to the folder holding rgb.txt.
};

/// Reads a TUM image list: lines "timestamp path". Relative paths are resolved against the folder
/// holding `rgb_txt_path`; absolute paths are kept. Entries keep the file's order. Paths must not
/// contain blanks. A list with no entries is a ParseError (line 0).
std::vector<ImageEntry> readImageList(const std::string& rgb_txt_path);

/// Writes a TUM image list: a "# timestamp filename" header, then one line "timestamp path" per
/// entry in the given order, the timestamp with 6 decimals as writeTrajectory() writes it (so the
/// two files of a dataset carry identical timestamps). Paths are written as given: make them
/// relative to the list's folder, as readImageList() resolves them. A path that is empty or
/// holds a blank cannot be read back: CheckError. Throws IoError if the file cannot be written.
void writeImageList(const std::string& rgb_txt_path, const std::vector<ImageEntry>& entries);

/// Reads an image as 8-bit, 3-channel BGR (cv::IMREAD_COLOR: grey is expanded, alpha dropped).
/// Throws IoError "<path>: no such file", "<path>: is a directory" or "<path>: cannot decode as
/// an image ...".
cv::Mat readColorImage(const std::string& path);

/// Writes `image` in the format its file extension names (cv::imwrite; PNG is lossless).
/// Throws IoError naming the path if OpenCV has no writer for the extension or the write fails.
void writeImage(const std::string& path, const cv::Mat& image);

/// A timestamped camera pose.
struct StampedPose {
  double timestamp = 0.0;  ///< Seconds.
  Pose3 world_from_cam;    ///< Camera-to-world: x_world = R x_cam + t (t is the camera centre).
};

/// |norm - 1| above which a trajectory quaternion is rejected instead of normalised. TUM files
/// store ~4-9 decimals (norm error <= 1e-4); a larger error means a broken or misordered column.
inline constexpr double kQuaternionNormTolerance = 1e-2;

/// Reads a TUM trajectory: lines "timestamp tx ty tz qx qy qz qw", camera-to-world. Quaternions
/// are normalised; one whose norm differs from 1 by more than kQuaternionNormTolerance (zero
/// included) is a ParseError. Poses keep the file's order. An empty trajectory is a ParseError
/// (line 0).
std::vector<StampedPose> readTrajectory(const std::string& path);

/// Writes a TUM trajectory with ORB-SLAM2's precision: one line per pose,
/// "timestamp tx ty tz qx qy qz qw", fixed notation, timestamp with 6 decimals and the 7 pose
/// values with 9, space separated, no header. `poses` may be empty (an empty file, which
/// readTrajectory() rejects). Throws IoError if the file cannot be written.
void writeTrajectory(const std::string& path, const std::vector<StampedPose>& poses);

/// Pairs timestamps[k] with cam_from_world[k] as the camera-to-world StampedPose a TUM file
/// holds. CheckError unless both have the same size.
std::vector<StampedPose> stampedPoses(const std::vector<double>& timestamps,
                                      const std::vector<Pose3>& cam_from_world);

/// Reads an OpenCV FileStorage YAML camera file in one of three forms:
///  - ORB-SLAM2's keys. Required: Camera.fx, Camera.fy (> 0), Camera.cx, Camera.cy, Camera.width,
///    Camera.height (positive whole numbers); optional, default 0: Camera.k1, Camera.k2,
///    Camera.p1, Camera.p2, Camera.k3.
///  - What OpenCV's calibration sample and ROS camera_info write (when there is no Camera.fx):
///    camera_matrix (3x3, as !!opencv-matrix or {rows, cols, data}; zero skew), image_width,
///    image_height; optional distortion_coefficients (k1 k2 p1 p2 [k3], or OpenCV's 8, 12 or 14
///    with every coefficient after k3 zero) and distortion_model (plumb_bob).
///  - EuRoC's sensor.yaml (when there is neither): intrinsics [fu, fv, cu, cv], resolution
///    [width, height], optional distortion_coefficients [k1, k2, p1, p2], distortion_model
///    radial-tangential and camera_model pinhole.
/// Other keys are ignored. The "%YAML:1.0" / "%YAML 1.0" header is optional.
/// Errors: IoError if the file cannot be read; ParseError for YAML that OpenCV rejects (with the
/// line OpenCV reports and its message), for a missing required key (line 0), and for a value
/// that is not a finite number or out of range (with the key's line when it can be located).
Camera readCameraYaml(const std::string& path);

/// The numbers of `key` in an OpenCV FileStorage YAML file, a sequence or a matrix
/// ({rows, cols, data} or !!opencv-matrix, in row order). ParseError naming the file (and the
/// key's line) when the key is absent or holds anything else.
std::vector<double> readYamlNumbers(const std::string& path, const std::string& key);

/// Writes `camera` as OpenCV FileStorage YAML ("%YAML:1.0" header) with every key that
/// readCameraYaml() reads, distortion included; numbers with 17 significant digits, so that
/// reading the file back gives the same intrinsics exactly. Throws IoError if the file cannot be
/// written.
void writeCameraYaml(const std::string& path, const Camera& camera);

}  // namespace curvesfm
