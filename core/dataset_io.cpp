#include "core/dataset_io.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <limits>
#include <locale>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <regex>
#include <sstream>
#include <string_view>
#include <system_error>

#include "core/check.h"
#include "core/errors.h"
#include "core/text_records.h"

namespace curvesfm {
namespace {

using Fields = TextFields;

constexpr char kImageListFormat[] = "timestamp path";
constexpr char kTrajectoryFormat[] = "timestamp tx ty tz qx qy qz qw";
constexpr const char* kTrajectoryFieldNames[] = {"timestamp", "tx", "ty", "tz",
                                                 "qx",        "qy", "qz", "qw"};

// Opens `path`, lets write(out) fill it and reports a failed open or write as IoError.
template <class Write>
void writeTextFile(const std::string& path, Write&& write) {
  std::ofstream out(path);
  if (!out) throw IoError(path, "cannot open for writing");
  // The global locale could otherwise turn the decimal point into a comma.
  out.imbue(std::locale::classic());
  write(out);
  out.close();
  if (!out) throw IoError(path, "write failed");
}

std::string readWholeFile(const std::string& path) {
  std::ifstream in = openForReading(path);
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) throw IoError(path, "read error");
  text.erase(0, text.size() - withoutByteOrderMark(text).size());
  return text;
}

// OpenCV recognises YAML only by a "%YAML" directive in the very first bytes (even a comment
// before it fails), yet hand-written camera files often omit it. So OpenCV always parses our own
// directive, and the file's directive, if any, is blanked in place: every line number OpenCV
// reports is then exactly one more than the file's.
constexpr char kOpenCvYamlDirective[] = "%YAML:1.0\n";
constexpr int kDirectiveLines = 1;

std::string withOwnYamlDirective(std::string text) {
  std::size_t begin = 0;
  while (begin < text.size()) {
    const std::size_t end = std::min(text.find('\n', begin), text.size());
    const std::string_view line(text.data() + begin, end - begin);
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first != std::string_view::npos && line[first] != '#') {
      if (line.substr(first, 5) == "%YAML") text.erase(begin, end - begin);
      break;
    }
    begin = end + 1;
  }
  return kOpenCvYamlDirective + text;
}

// OpenCV's parser errors carry "<file>(<line>): <message>" in cv::Exception::func.
[[noreturn]] void throwYamlError(const std::string& path, const cv::Exception& e) {
  static const std::regex kLocated(R"(\((\d+)\): (.*)$)");
  std::smatch match;
  if (std::regex_search(e.func, match, kLocated)) {
    const int line = std::max(0, std::stoi(match[1].str()) - kDirectiveLines);
    throw ParseError(path, line, "OpenCV FileStorage YAML",
                     "\"" + match[2].str() + "\" (OpenCV YAML parser)");
  }
  throw ParseError(path, 0, "OpenCV FileStorage YAML", "\"" + std::string(e.what()) + "\"");
}

void openYaml(const std::string& path, const std::string& text, cv::FileStorage* storage) {
  try {
    const int flags =
        cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML;
    if (storage->open(withOwnYamlDirective(text), flags)) return;
  } catch (const cv::Exception& e) {
    throwYamlError(path, e);
  }
  throw ParseError(path, 0, "OpenCV FileStorage YAML", "content OpenCV cannot open");
}

// 1-based line of a top-level "key:" in `text`, 0 if not found; OpenCV's nodes do not keep it.
int lineOfKey(const std::string& text, const std::string& key) {
  std::istringstream in(text);
  std::string line;
  for (int line_number = 1; std::getline(in, line); ++line_number) {
    const std::size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line.compare(first, key.size(), key) != 0) continue;
    const std::size_t colon = line.find_first_not_of(" \t", first + key.size());
    if (colon != std::string::npos && line[colon] == ':') return line_number;
  }
  return 0;
}

std::string describeNode(const cv::FileNode& node) {
  if (node.isString()) return quoteToken(node.string());
  if (node.isSeq()) return "a sequence";
  if (node.isMap()) return "a mapping";
  return "a value of OpenCV node type " + std::to_string(node.type());
}

// The camera file's text and parsed tree, so that errors can name the key's line.
struct YamlFile {
  const std::string& path;
  const std::string& text;
  const cv::FileStorage& storage;

  // The key's finite number, or `fallback` if the key is absent and fallback is given.
  double number(const std::string& key, std::optional<double> fallback = std::nullopt) const {
    const cv::FileNode node = storage[key];
    if (node.isNone()) {
      if (fallback) return *fallback;
      throw ParseError(path, 0, "key " + key + " (a number)", "no such key");
    }
    const int line = lineOfKey(text, key);
    if (!node.isInt() && !node.isReal()) {
      throw ParseError(path, line, "key " + key + " (a number)", describeNode(node));
    }
    const double value = node.real();
    if (!std::isfinite(value)) {
      throw ParseError(path, line, "key " + key + " (a finite number)", formatNumber(value));
    }
    return value;
  }

  double positiveNumber(const std::string& key) const {
    const double value = number(key);
    if (value <= 0.0) {
      throw ParseError(path, lineOfKey(text, key), "key " + key + " > 0", formatNumber(value));
    }
    return value;
  }

  int pixelCount(const std::string& key) const {
    const double value = number(key);
    if (value < 1.0 || value > std::numeric_limits<int>::max() || value != std::floor(value)) {
      throw ParseError(path, lineOfKey(text, key),
                       "key " + key + " (a positive whole number of pixels)", formatNumber(value));
    }
    return static_cast<int>(value);
  }

  // The numbers of a key that is a sequence, or a matrix as OpenCV writes it (!!opencv-matrix)
  // or ROS camera_info does ({rows, cols, data}): its data in row order; `counts` lists the
  // accepted sizes (empty: any).
  std::vector<double> matrixData(const std::string& key, std::initializer_list<int> counts) const {
    const cv::FileNode node = storage[key];
    const cv::FileNode data = node.isMap() ? node["data"] : node;
    std::string sizes;
    for (const int count : counts) sizes += (sizes.empty() ? "" : " or ") + std::to_string(count);
    const std::string expected = "key " + key + " (" +
                                 (sizes.empty() ? "numbers" : "a matrix of " + sizes + " numbers") +
                                 ": data)";
    const int line = lineOfKey(text, key);
    if (!data.isSeq()) throw ParseError(path, line, expected, describeNode(storage[key]));
    std::vector<double> values;
    for (const cv::FileNode& value : data) {
      if (!value.isInt() && !value.isReal()) {
        throw ParseError(path, line, expected, "an entry " + describeNode(value));
      }
      if (!std::isfinite(value.real())) {
        throw ParseError(path, line, expected, "an entry " + formatNumber(value.real()));
      }
      values.push_back(value.real());
    }
    if (counts.size() > 0 &&
        std::find(counts.begin(), counts.end(), static_cast<int>(values.size())) == counts.end()) {
      throw ParseError(path, line, expected, std::to_string(values.size()) + " numbers");
    }
    return values;
  }
};

// ORB-SLAM2's keys: Camera.fx ... Camera.k3, Camera.width, Camera.height.
CameraIntrinsics orbSlamIntrinsics(const YamlFile& file) {
  if (file.storage["Camera.fx"].isNone()) {
    throw ParseError(file.path, 0,
                     "key Camera.fx (a number; or camera_matrix, image_width and image_height as "
                     "OpenCV's calibration and ROS camera_info write them; or intrinsics and "
                     "resolution as EuRoC's sensor.yaml)",
                     "no such key");
  }
  CameraIntrinsics intrinsics;
  intrinsics.fx = file.positiveNumber("Camera.fx");
  intrinsics.fy = file.positiveNumber("Camera.fy");
  intrinsics.cx = file.number("Camera.cx");
  intrinsics.cy = file.number("Camera.cy");
  intrinsics.k1 = file.number("Camera.k1", 0.0);
  intrinsics.k2 = file.number("Camera.k2", 0.0);
  intrinsics.p1 = file.number("Camera.p1", 0.0);
  intrinsics.p2 = file.number("Camera.p2", 0.0);
  intrinsics.k3 = file.number("Camera.k3", 0.0);
  intrinsics.width = file.pixelCount("Camera.width");
  intrinsics.height = file.pixelCount("Camera.height");
  return intrinsics;
}

// camera_matrix, 3x3 with zero skew: fx, fy, cx, cy.
std::array<double, 4> calibrationMatrix(const YamlFile& file) {
  const std::vector<double> K = file.matrixData("camera_matrix", {9});
  if (!(K[0] > 0.0 && K[4] > 0.0) || K[1] != 0.0 || K[3] != 0.0 || K[6] != 0.0 || K[7] != 0.0 ||
      K[8] != 1.0) {
    std::string found = "[";
    for (int i = 0; i < 9; ++i)
      found += formatNumber(K[i]) + (i == 8 ? "]" : i % 3 == 2 ? "; " : " ");
    throw ParseError(file.path, lineOfKey(file.text, "camera_matrix"),
                     "key camera_matrix = [fx 0 cx; 0 fy cy; 0 0 1] with fx, fy > 0 and zero skew",
                     found);
  }
  return {K[0], K[4], K[2], K[5]};
}

// distortion_coefficients (k1 k2 p1 p2 k3; zeros when absent). OpenCV's rational and thin-prism
// terms (coefficients 6 to 14) are accepted only as zeros, since our camera model stops at k3.
std::array<double, 5> calibrationDistortion(const YamlFile& file) {
  const cv::FileNode model = file.storage["distortion_model"];
  if (model.isString() && model.string() != "plumb_bob" &&
      model.string() != "rational_polynomial") {
    throw ParseError(file.path, lineOfKey(file.text, "distortion_model"),
                     "key distortion_model plumb_bob (radial-tangential, OpenCV's model)",
                     quoteToken(model.string()));
  }
  std::array<double, 5> k1_k2_p1_p2_k3{};
  if (file.storage["distortion_coefficients"].isNone()) return k1_k2_p1_p2_k3;
  const std::vector<double> d = file.matrixData("distortion_coefficients", {0, 4, 5, 8, 12, 14});
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (i < k1_k2_p1_p2_k3.size()) {
      k1_k2_p1_p2_k3[i] = d[i];
    } else if (d[i] != 0.0) {
      throw ParseError(file.path, lineOfKey(file.text, "distortion_coefficients"),
                       "key distortion_coefficients with k1 k2 p1 p2 k3 only (any further "
                       "coefficient 0: the camera model is radial-tangential)",
                       "coefficient " + std::to_string(i + 1) + " = " + formatNumber(d[i]));
    }
  }
  return k1_k2_p1_p2_k3;
}

// A pinhole camera with radial-tangential distortion from its parameters.
CameraIntrinsics pinholeIntrinsics(const std::array<double, 4>& fx_fy_cx_cy,
                                   const std::array<double, 5>& k1_k2_p1_p2_k3, int width,
                                   int height) {
  CameraIntrinsics intrinsics;
  intrinsics.fx = fx_fy_cx_cy[0];
  intrinsics.fy = fx_fy_cx_cy[1];
  intrinsics.cx = fx_fy_cx_cy[2];
  intrinsics.cy = fx_fy_cx_cy[3];
  intrinsics.k1 = k1_k2_p1_p2_k3[0];
  intrinsics.k2 = k1_k2_p1_p2_k3[1];
  intrinsics.p1 = k1_k2_p1_p2_k3[2];
  intrinsics.p2 = k1_k2_p1_p2_k3[3];
  intrinsics.k3 = k1_k2_p1_p2_k3[4];
  intrinsics.width = width;
  intrinsics.height = height;
  return intrinsics;
}

// EuRoC's camera_model and distortion_model, where given, must be ours.
void checkEurocModels(const YamlFile& file) {
  for (const auto& [key, allowed] :
       {std::pair<const char*, std::vector<std::string>>{"camera_model", {"pinhole"}},
        {"distortion_model", {"radial-tangential", "radtan", "plumb_bob", "none"}}}) {
    const cv::FileNode node = file.storage[key];
    if (node.isNone()) continue;
    const std::string value = node.isString() ? node.string() : describeNode(node);
    if (std::find(allowed.begin(), allowed.end(), value) == allowed.end()) {
      throw ParseError(file.path, lineOfKey(file.text, key),
                       std::string("key ") + key + " " + allowed.front() +
                           " (the camera model is a pinhole with radial-tangential distortion)",
                       quoteToken(value));
    }
  }
}

// What EuRoC's sensor.yaml (and a Kalibr camera) holds: intrinsics [fu fv cu cv], resolution
// [width height], distortion_coefficients [k1 k2 p1 p2] of the radial-tangential model.
CameraIntrinsics eurocIntrinsics(const YamlFile& file) {
  checkEurocModels(file);
  const std::vector<double> k = file.matrixData("intrinsics", {4});
  const std::vector<double> size = file.matrixData("resolution", {2});
  std::array<double, 5> d{};
  if (!file.storage["distortion_coefficients"].isNone()) {
    const std::vector<double> given = file.matrixData("distortion_coefficients", {0, 4, 5});
    std::copy(given.begin(), given.end(), d.begin());
  }
  if (!(k[0] > 0.0 && k[1] > 0.0) || size[0] < 1.0 || size[1] < 1.0 ||
      size[0] != std::floor(size[0]) || size[1] != std::floor(size[1])) {
    throw ParseError(file.path, lineOfKey(file.text, "intrinsics"),
                     "intrinsics with fu, fv > 0 and a resolution of whole pixels",
                     "fu " + formatNumber(k[0]) + ", fv " + formatNumber(k[1]) + ", resolution " +
                         formatNumber(size[0]) + " x " + formatNumber(size[1]));
  }
  return pinholeIntrinsics({k[0], k[1], k[2], k[3]}, d, static_cast<int>(size[0]),
                           static_cast<int>(size[1]));
}

// What OpenCV's calibration sample and ROS camera_info write: camera_matrix,
// distortion_coefficients (optional), image_width, image_height.
CameraIntrinsics calibrationIntrinsics(const YamlFile& file) {
  // One after the other, so that the first problem in the file is the one reported.
  const std::array<double, 4> K = calibrationMatrix(file);
  const std::array<double, 5> d = calibrationDistortion(file);
  const int width = file.pixelCount("image_width");
  return pinholeIntrinsics(K, d, width, file.pixelCount("image_height"));
}

}  // namespace

std::vector<ImageEntry> readImageList(const std::string& rgb_txt_path) {
  const std::filesystem::path folder = std::filesystem::path(rgb_txt_path).parent_path();
  std::vector<ImageEntry> entries;
  forEachRecord(rgb_txt_path, [&](int line, const Fields& fields) {
    requireFieldCount(rgb_txt_path, line, fields, 2, kImageListFormat);
    const double timestamp = numberField(rgb_txt_path, line, fields, 0, "timestamp");
    // operator/ keeps an absolute right-hand side as it is.
    entries.push_back({timestamp, (folder / std::string(fields[1])).string()});
  });
  if (entries.empty()) {
    throw ParseError(rgb_txt_path, 0,
                     std::string("at least one image line \"") + kImageListFormat + "\"", "none");
  }
  return entries;
}

std::vector<StampedPose> readTrajectory(const std::string& path) {
  std::vector<StampedPose> poses;
  forEachRecord(path, [&](int line, const Fields& fields) {
    requireFieldCount(path, line, fields, 8, kTrajectoryFormat);
    double v[8];
    for (std::size_t i = 0; i < 8; ++i) {
      v[i] = numberField(path, line, fields, i, kTrajectoryFieldNames[i]);
    }
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    const double norm = q.norm();
    if (!(std::abs(norm - 1.0) <= kQuaternionNormTolerance)) {
      throw ParseError(path, line,
                       "a unit quaternion \"qx qy qz qw\" (|norm - 1| <= " +
                           formatNumber(kQuaternionNormTolerance) + ")",
                       "norm " + formatNumber(norm));
    }
    poses.push_back({v[0], Pose3(q, Eigen::Vector3d(v[1], v[2], v[3]))});
  });
  if (poses.empty()) {
    throw ParseError(path, 0, std::string("at least one pose line \"") + kTrajectoryFormat + "\"",
                     "none");
  }
  return poses;
}

void writeImageList(const std::string& rgb_txt_path, const std::vector<ImageEntry>& entries) {
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const std::string& path = entries[i].path;
    // readImageList() splits at blanks and skips lines that start with '#'.
    CURVESFM_CHECK(std::isfinite(entries[i].timestamp) && !path.empty() && path.front() != '#' &&
                   path.find_first_of(" \t\r\n\v\f") == std::string::npos)
        << "entry " << i << " of the image list for " << rgb_txt_path << " (\"" << path
        << "\") cannot be read back";
  }
  writeTextFile(rgb_txt_path, [&](std::ostream& out) {
    out << "# color images\n# timestamp filename\n" << std::fixed << std::setprecision(6);
    for (const ImageEntry& entry : entries) out << entry.timestamp << ' ' << entry.path << '\n';
  });
}

cv::Mat readColorImage(const std::string& path) {
  std::error_code ignored;
  const std::filesystem::file_status status = std::filesystem::status(path, ignored);
  if (!std::filesystem::exists(status)) throw IoError(path, "no such file");
  if (std::filesystem::is_directory(status)) throw IoError(path, "is a directory");
  cv::Mat image;
  try {
    image = cv::imread(path, cv::IMREAD_COLOR);
  } catch (const cv::Exception& e) {
    throw IoError(path, "cannot decode as an image: " + e.err);
  }
  if (image.empty()) {
    throw IoError(path,
                  "cannot decode as an image (unreadable, corrupt or not a format OpenCV "
                  "reads)");
  }
  return image;
}

void writeImage(const std::string& path, const cv::Mat& image) {
  bool written = false;
  try {
    written = cv::imwrite(path, image);
  } catch (const cv::Exception& e) {
    throw IoError(path, "cannot write the image: " + e.err);
  }
  if (!written) throw IoError(path, "cannot write the image");
}

void writeTrajectory(const std::string& path, const std::vector<StampedPose>& poses) {
  writeTextFile(path, [&](std::ostream& out) {
    out << std::fixed;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      const StampedPose& pose = poses[i];
      const Eigen::Vector3d& t = pose.world_from_cam.translation();
      const Eigen::Quaterniond& q = pose.world_from_cam.rotation();
      // "nan" would be written silently and then rejected by every reader.
      CURVESFM_CHECK(std::isfinite(pose.timestamp) && t.allFinite() && q.coeffs().allFinite())
          << "pose " << i << " of the trajectory for " << path << " is not finite";
      out << std::setprecision(6) << pose.timestamp << std::setprecision(9) << ' ' << t.x() << ' '
          << t.y() << ' ' << t.z() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << q.w()
          << '\n';
    }
  });
}

Camera readCameraYaml(const std::string& path) {
  const std::string text = readWholeFile(path);
  cv::FileStorage storage;
  openYaml(path, text, &storage);
  const cv::FileNode root = storage.root();
  // OpenCV asserts (throws) on key lookups in a non-mapping root.
  if (!root.isNone() && !root.isMap()) {
    throw ParseError(path, 0, "a YAML mapping of Camera.* keys", describeNode(root));
  }
  const YamlFile file{path, text, storage};
  const auto has = [&](const char* key) { return !root.isNone() && !storage[key].isNone(); };
  if (!has("Camera.fx") && has("camera_matrix")) return Camera(calibrationIntrinsics(file));
  if (!has("Camera.fx") && has("intrinsics")) return Camera(eurocIntrinsics(file));
  return Camera(orbSlamIntrinsics(file));
}

std::vector<double> readYamlNumbers(const std::string& path, const std::string& key) {
  const std::string text = readWholeFile(path);
  cv::FileStorage storage;
  openYaml(path, text, &storage);
  if (!storage.root().isMap() || storage[key].isNone()) {
    throw ParseError(path, 0, "key " + key + " (numbers)", "no such key");
  }
  return YamlFile{path, text, storage}.matrixData(key, {});
}

void writeCameraYaml(const std::string& path, const Camera& camera) {
  const CameraIntrinsics& c = camera.intrinsics();
  writeTextFile(path, [&](std::ostream& out) {
    // max_digits10 makes every double round-trip; whole numbers print without a point, which
    // OpenCV reads as integers and readCameraYaml() accepts as numbers.
    out << std::setprecision(std::numeric_limits<double>::max_digits10);
    out << "%YAML:1.0\n\n# Pinhole camera with radial-tangential distortion (OpenCV model)\n"
        << "Camera.fx: " << c.fx << "\nCamera.fy: " << c.fy << "\nCamera.cx: " << c.cx
        << "\nCamera.cy: " << c.cy << "\n\nCamera.k1: " << c.k1 << "\nCamera.k2: " << c.k2
        << "\nCamera.p1: " << c.p1 << "\nCamera.p2: " << c.p2 << "\nCamera.k3: " << c.k3
        << "\n\nCamera.width: " << c.width << "\nCamera.height: " << c.height << "\n";
  });
}

std::vector<StampedPose> stampedPoses(const std::vector<double>& timestamps,
                                      const std::vector<Pose3>& cam_from_world) {
  CURVESFM_CHECK(timestamps.size() == cam_from_world.size())
      << timestamps.size() << " timestamps for " << cam_from_world.size() << " poses";
  std::vector<StampedPose> poses(timestamps.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    poses[k] = {timestamps[k], cam_from_world[k].inverse()};
  }
  return poses;
}

}  // namespace curvesfm
