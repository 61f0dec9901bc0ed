#include "core/image_sequence.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <sstream>
#include <system_error>

#include "core/errors.h"
#include "core/text_records.h"

namespace curvesfm {
namespace {

namespace fs = std::filesystem;
using Matrix34d = Eigen::Matrix<double, 3, 4>;

constexpr char kCameraFormat[] = "fx,fy,cx,cy[,k1,k2,p1,p2[,k3]]";
// K entries of different frames may differ by this fraction of fx (projection matrices stored
// as floats decompose to K's that differ in the 5th digit); more means different cameras.
constexpr double kIntrinsicsTolerance = 1e-3;
// |R^T R - I| above which a matrix given as a rotation is rejected.
constexpr double kRotationTolerance = 1e-3;

std::string joinPath(const fs::path& dir, const std::string& name) { return (dir / name).string(); }

std::string lowerCase(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

bool endsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

bool isDirectory(const fs::path& path) {
  std::error_code ignored;
  return fs::is_directory(path, ignored);
}

bool isFile(const fs::path& path) {
  std::error_code ignored;
  return fs::is_regular_file(path, ignored);
}

// "img2.png" before "img10.png": runs of digits compare as numbers.
bool naturalLess(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) &&
        std::isdigit(static_cast<unsigned char>(b[j]))) {
      std::size_t i_end = i, j_end = j;
      while (i_end < a.size() && std::isdigit(static_cast<unsigned char>(a[i_end]))) ++i_end;
      while (j_end < b.size() && std::isdigit(static_cast<unsigned char>(b[j_end]))) ++j_end;
      std::string_view x(a.data() + i, i_end - i), y(b.data() + j, j_end - j);
      while (x.size() > 1 && x.front() == '0') x.remove_prefix(1);
      while (y.size() > 1 && y.front() == '0') y.remove_prefix(1);
      if (x.size() != y.size()) return x.size() < y.size();
      if (x != y) return x < y;
      i = i_end;
      j = j_end;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j || (a.size() - i == b.size() - j && a < b);
}

// The regular files of `dir` whose name satisfies `keep`, in natural order of their names.
std::vector<fs::path> listFiles(const fs::path& dir,
                                const std::function<bool(const std::string&)>& keep) {
  std::vector<fs::path> files;
  std::error_code error;
  for (fs::directory_iterator it(dir, error), end; !error && it != end; it.increment(error)) {
    if (isFile(it->path()) && keep(it->path().filename().string())) files.push_back(it->path());
  }
  if (error) throw IoError(dir.string(), "cannot list the folder: " + error.message());
  std::sort(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
    return naturalLess(a.filename().string(), b.filename().string());
  });
  return files;
}

constexpr const char* kImageExtensions[] = {".png", ".jpg", ".jpeg", ".ppm",
                                            ".pgm", ".bmp", ".tif",  ".tiff"};

std::string imageExtensionsText() {
  std::string text;
  for (const char* extension : kImageExtensions)
    text += (text.empty() ? "" : ", ") + std::string(extension);
  return text;
}

bool isImageName(const std::string& name) {
  const std::string lower = lowerCase(name);
  for (const char* extension : kImageExtensions) {
    if (endsWith(lower, extension)) return true;
  }
  return false;
}

std::vector<fs::path> listImages(const fs::path& dir) { return listFiles(dir, isImageName); }

// --- What a layout reader hands to the common part -------------------------------------------

struct LayoutFrame {
  double timestamp = 0.0;
  std::string image_path;
  std::optional<Pose3> world_from_cam;
};

struct LayoutContents {
  std::vector<LayoutFrame> frames;
  std::optional<CameraIntrinsics> intrinsics;  ///< width/height 0: take the first image's.
  std::string camera_source;                   ///< The file the intrinsics came from.
  std::string camera_looked_for;               ///< Without intrinsics: what was looked for.
  std::vector<StampedPose> ground_truth;       ///< TUM, EuRoC, images; the others use frames.
  std::string ground_truth_source;
};

CameraIntrinsics intrinsicsFromK(const Eigen::Matrix3d& K) {
  CameraIntrinsics intrinsics;
  intrinsics.fx = K(0, 0);
  intrinsics.fy = K(1, 1);
  intrinsics.cx = K(0, 2);
  intrinsics.cy = K(1, 2);
  intrinsics.width = intrinsics.height = 0;
  return intrinsics;
}

std::string describeK(const Eigen::Matrix3d& K) {
  return "fx " + formatNumber(K(0, 0)) + ", fy " + formatNumber(K(1, 1)) + ", cx " +
         formatNumber(K(0, 2)) + ", cy " + formatNumber(K(1, 2)) + ", skew " +
         formatNumber(K(0, 1));
}

// Our Camera has one K for the whole sequence and no skew: every frame's K must agree with the
// first within kIntrinsicsTolerance, or the error names the frame's file and line.
class SharedIntrinsics {
 public:
  void add(const Eigen::Matrix3d& K, const std::string& path, int line) {
    const double tolerance = kIntrinsicsTolerance * std::abs(K(0, 0));
    const bool calibration_form = K(0, 0) > 0.0 && K(1, 1) > 0.0 && K(1, 0) == 0.0 &&
                                  K(2, 0) == 0.0 && K(2, 1) == 0.0 && K(2, 2) == 1.0;
    if (!calibration_form || std::abs(K(0, 1)) > tolerance) {
      throw ParseError(path, line,
                       "a calibration matrix K = [fx 0 cx; 0 fy cy; 0 0 1] with fx, fy > 0 and "
                       "zero skew",
                       describeK(K));
    }
    if (!first_) {
      first_ = K;
      first_source_ = path + (line > 0 ? ":" + std::to_string(line) : std::string());
      return;
    }
    if ((K - *first_).cwiseAbs().maxCoeff() > tolerance) {
      throw ParseError(path, line,
                       "the same K as " + first_source_ + " (" + describeK(*first_) + ") within " +
                           formatNumber(kIntrinsicsTolerance) +
                           " fx: one camera for the whole sequence",
                       describeK(K));
    }
  }
  const Eigen::Matrix3d& K() const { return *first_; }
  bool empty() const { return !first_; }

 private:
  std::optional<Eigen::Matrix3d> first_;
  std::string first_source_;
};

// R read from a file must be a rotation; a transposed or mis-scaled matrix fails here, naming
// where it was read.
Eigen::Matrix3d checkedRotation(const Eigen::Matrix3d& R, const std::string& path, int line,
                                const std::string& what) {
  const double error = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(error <= kRotationTolerance) || R.determinant() < 0.0) {
    throw ParseError(
        path, line,
        what + " to be a rotation (|R^T R - I| <= " + formatNumber(kRotationTolerance) +
            ", det R = +1)",
        "|R^T R - I| = " + formatNumber(error) + ", det R = " + formatNumber(R.determinant()));
  }
  return R;
}

// Reads `rows` records of `cols` numbers each from `path` (comments and blank lines skipped).
// A first record that is the single word `header` (PMVS writes "CONTOUR") is skipped.
// `row_format` names the fields of a row for the message.
Eigen::MatrixXd readNumberRows(const std::string& path, int rows, int cols, const char* row_format,
                               const char* what, std::vector<int>* lines = nullptr,
                               const std::string& header = "") {
  Eigen::MatrixXd matrix(rows, cols);
  int row = 0;
  forEachRecord(path, [&](int line, const TextFields& fields) {
    if (row == 0 && !header.empty() && fields.size() == 1 && fields[0] == header) return;
    if (row == rows) {
      throw ParseError(path, line, std::to_string(rows) + " lines of " + what,
                       "more: \"" + std::string(fields[0]) + " ...\"");
    }
    requireFieldCount(path, line, fields, static_cast<std::size_t>(cols), row_format);
    for (int c = 0; c < cols; ++c) {
      matrix(row, c) = numberField(path, line, fields, static_cast<std::size_t>(c), "number");
    }
    if (lines) lines->push_back(line);
    ++row;
  });
  if (row < rows) {
    throw ParseError(path, 0, std::to_string(rows) + " lines of " + what,
                     std::to_string(row) + " lines");
  }
  return matrix;
}

// P = lambda K [R | t] with K upper triangular, positive diagonal, K(2,2) = 1 and R a rotation
// (an RQ decomposition done row by row, Gram-Schmidt from the third row up). P's overall sign
// is chosen so that det(K R) > 0, which makes det R = +1.
struct DecomposedProjection {
  Eigen::Matrix3d K;
  Pose3 cam_from_world;
};

DecomposedProjection decomposeProjection(Matrix34d P, const std::string& path) {
  if (P.leftCols<3>().determinant() < 0.0) P = -P;
  const Eigen::Vector3d m1 = P.block<1, 3>(0, 0).transpose();
  const Eigen::Vector3d m2 = P.block<1, 3>(1, 0).transpose();
  const Eigen::Vector3d m3 = P.block<1, 3>(2, 0).transpose();
  const double lambda = m3.norm();
  const double scale = P.leftCols<3>().cwiseAbs().maxCoeff();
  if (!(std::abs(P.leftCols<3>().determinant()) > 1e-12 * scale * scale * scale)) {
    throw ParseError(path, 0, "a 3x4 projection matrix whose left 3x3 block is invertible",
                     "a singular one");
  }
  const Eigen::Vector3d r3 = m3 / lambda;
  const double cy = m2.dot(r3);
  const Eigen::Vector3d m2_rest = m2 - cy * r3;
  const double fy = m2_rest.norm();
  const Eigen::Vector3d r2 = m2_rest / fy;
  const double cx = m1.dot(r3), skew = m1.dot(r2);
  const Eigen::Vector3d m1_rest = m1 - skew * r2 - cx * r3;
  const double fx = m1_rest.norm();
  const Eigen::Vector3d r1 = m1_rest / fx;
  Eigen::Matrix3d K;
  K << fx, skew, cx, 0.0, fy, cy, 0.0, 0.0, lambda;
  K /= lambda;
  Eigen::Matrix3d R;
  R << r1.transpose(), r2.transpose(), r3.transpose();
  const Eigen::Vector3d t = K.inverse() * P.col(3) / lambda;
  return {K, Pose3(R, t)};
}

// --- TUM RGB-D ---------------------------------------------------------------------------------

// DIR/camera.yaml and DIR/groundtruth.txt (a whole TUM trajectory), where present.
void readCameraYamlAndGroundTruth(const fs::path& dir, LayoutContents* c) {
  const std::string camera_yaml = joinPath(dir, "camera.yaml");
  if (fs::exists(camera_yaml)) {
    c->intrinsics = readCameraYaml(camera_yaml).intrinsics();
    c->camera_source = camera_yaml;
  } else {
    c->camera_looked_for = camera_yaml;
  }
  const std::string ground_truth = joinPath(dir, "groundtruth.txt");
  if (fs::exists(ground_truth)) {
    c->ground_truth = readTrajectory(ground_truth);
    c->ground_truth_source = ground_truth;
  }
}

LayoutContents readTum(const fs::path& dir) {
  LayoutContents c;
  readCameraYamlAndGroundTruth(dir, &c);
  for (const ImageEntry& entry : readImageList(joinPath(dir, "rgb.txt"))) {
    c.frames.push_back({entry.timestamp, entry.path, std::nullopt});
  }
  return c;
}

// --- KITTI odometry ----------------------------------------------------------------------------

// Image folder -> the calib.txt line that projects into it (P0 left grey, P2 left colour).
struct KittiCamera {
  const char* folder;
  int p_index;
};
constexpr KittiCamera kKittiCameras[] = {{"image_0", 0}, {"image_l", 0}, {"image_2", 2}};

// calib.txt: "P0: 12 numbers" lines as KITTI publishes it, or bare lines of 12 numbers, P0 first
// (as some copies have). Other keys (Tr:, R0_rect:) are skipped.
Matrix34d readKittiProjection(const std::string& path, int wanted) {
  std::optional<Matrix34d> found;
  int unnamed = 0;
  forEachRecord(path, [&](int line, const TextFields& fields) {
    TextFields numbers = fields;
    int index = unnamed;
    if (fields[0].back() == ':') {
      const std::string_view key = fields[0];
      if (key.size() != 3 || key[0] != 'P' || !std::isdigit(static_cast<unsigned char>(key[1]))) {
        return;
      }
      index = key[1] - '0';
      numbers.erase(numbers.begin());
    } else {
      ++unnamed;
    }
    if (index != wanted) return;
    requireFieldCount(path, line, numbers, 12, "P row-major: p11 p12 p13 p14 ... p34");
    Matrix34d P;
    for (int k = 0; k < 12; ++k) P(k / 4, k % 4) = numberField(path, line, numbers, k, "P");
    found = P;
  });
  if (!found) {
    throw ParseError(path, 0, "a line P" + std::to_string(wanted) + " (12 numbers)", "none");
  }
  return *found;
}

std::vector<double> readKittiTimes(const std::string& path, std::size_t count) {
  std::vector<double> times;
  forEachRecord(path, [&](int line, const TextFields& fields) {
    requireFieldCount(path, line, fields, 1, "timestamp");
    times.push_back(numberField(path, line, fields, 0, "timestamp"));
  });
  if (times.size() != count) {
    throw ParseError(path, 0, std::to_string(count) + " times, one per image",
                     std::to_string(times.size()));
  }
  return times;
}

std::vector<Pose3> readKittiPoses(const std::string& path, std::size_t count) {
  std::vector<Pose3> poses;
  forEachRecord(path, [&](int line, const TextFields& fields) {
    requireFieldCount(path, line, fields, 12, "r11 r12 r13 tx r21 r22 r23 ty r31 r32 r33 tz");
    Matrix34d T;
    for (int k = 0; k < 12; ++k) T(k / 4, k % 4) = numberField(path, line, fields, k, "pose");
    poses.emplace_back(checkedRotation(T.leftCols<3>(), path, line, "the pose's 3x3 block"),
                       T.col(3));
  });
  if (poses.size() != count) {
    throw ParseError(path, 0, std::to_string(count) + " poses, one per image",
                     std::to_string(poses.size()));
  }
  return poses;
}

LayoutContents readKitti(const fs::path& dir) {
  const KittiCamera* camera = nullptr;
  for (const KittiCamera& candidate : kKittiCameras) {
    if (isDirectory(dir / candidate.folder)) {
      camera = &candidate;
      break;
    }
  }
  if (!camera) {
    throw IoError(dir.string(), "no KITTI image folder: looked for image_0/, image_l/, image_2/");
  }
  const fs::path images_dir = dir / camera->folder;
  const std::vector<fs::path> images = listImages(images_dir);
  if (images.empty()) throw IoError(images_dir.string(), "holds no images");

  LayoutContents c;
  c.camera_source = joinPath(dir, "calib.txt");
  const Matrix34d P = readKittiProjection(c.camera_source, camera->p_index);
  SharedIntrinsics K;
  K.add(P.leftCols<3>(), c.camera_source, 0);
  c.intrinsics = intrinsicsFromK(K.K());
  c.camera_source += " (P" + std::to_string(camera->p_index) + ")";
  // Rectified cameras differ by a translation only: x_cam_i = x_cam_0 + K^-1 P_i(:, 3). The
  // poses are camera 0's, so image_2's are shifted by its offset.
  const Eigen::Vector3d offset = K.K().inverse() * P.col(3);
  const Pose3 cam0_from_cam(Eigen::Quaterniond::Identity(), -offset);

  std::vector<double> times(images.size());
  for (std::size_t i = 0; i < times.size(); ++i) times[i] = static_cast<double>(i);
  if (fs::exists(dir / "times.txt"))
    times = readKittiTimes(joinPath(dir, "times.txt"), images.size());
  // This folder's poses.txt, or the official tree's poses/NN.txt for sequences/NN/.
  std::string poses_path = joinPath(dir, "poses.txt");
  if (!fs::exists(poses_path)) {
    fs::path sequence = fs::absolute(dir).lexically_normal();
    if (!sequence.has_filename()) sequence = sequence.parent_path();  // "sequences/06/"
    poses_path =
        (sequence.parent_path().parent_path() / "poses" / (sequence.filename().string() + ".txt"))
            .string();
  }
  std::vector<Pose3> poses;
  if (fs::exists(poses_path)) {
    poses = readKittiPoses(poses_path, images.size());
    c.ground_truth_source = poses_path;
  }
  for (std::size_t i = 0; i < images.size(); ++i) {
    LayoutFrame frame{times[i], images[i].string(), std::nullopt};
    if (!poses.empty()) frame.world_from_cam = poses[i] * cam0_from_cam;
    c.frames.push_back(frame);
  }
  return c;
}

// --- Middlebury multi-view ---------------------------------------------------------------------

std::vector<fs::path> middleburyParFiles(const fs::path& dir) {
  return listFiles(dir, [](const std::string& name) { return endsWith(name, "_par.txt"); });
}

LayoutContents readMiddlebury(const fs::path& dir) {
  const std::vector<fs::path> par_files = middleburyParFiles(dir);
  if (par_files.size() != 1) {
    std::string names;
    for (const fs::path& p : par_files) names += " " + p.filename().string();
    throw IoError(dir.string(), "expected one *_par.txt, found " +
                                    std::to_string(par_files.size()) +
                                    (names.empty() ? "" : ":" + names));
  }
  const std::string path = par_files[0].string();
  LayoutContents c;
  c.camera_source = c.ground_truth_source = path;
  SharedIntrinsics K;
  int declared = -1, entries = 0;
  forEachRecord(path, [&](int line, const TextFields& fields) {
    if (declared < 0) {
      requireFieldCount(path, line, fields, 1, "number of images");
      const double count = numberField(path, line, fields, 0, "number of images");
      if (count < 0 || count != std::floor(count)) {
        throw ParseError(path, line, "a whole number of images", quoteToken(fields[0]));
      }
      declared = static_cast<int>(count);
      return;
    }
    requireFieldCount(path, line, fields, 22, "name k11..k33 r11..r33 t1 t2 t3");
    double v[21];
    for (int k = 0; k < 21; ++k) v[k] = numberField(path, line, fields, k + 1, "K, R or t");
    const Eigen::Matrix3d Ki = Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(v);
    const Eigen::Matrix3d R = checkedRotation(
        Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(v + 9), path, line, "R");
    K.add(Ki, path, line);
    const Pose3 cam_from_world(R, Eigen::Vector3d(v[18], v[19], v[20]));
    // The par file of a published subset lists every view of the full ring (templeRing ships 19
    // of 47 images): views without their image are skipped, each image keeps its view's index.
    const std::string image = joinPath(dir, std::string(fields[0]));
    if (fs::exists(image)) {
      c.frames.push_back({static_cast<double>(entries), image, cam_from_world.inverse()});
    }
    ++entries;
  });
  if (declared < 0) throw ParseError(path, 0, "the number of images on the first line", "none");
  if (entries != declared) {
    throw ParseError(path, 0, std::to_string(declared) + " camera lines (the first line's count)",
                     std::to_string(entries));
  }
  if (c.frames.empty()) {
    throw IoError(dir.string(), "holds none of the " + std::to_string(entries) + " images that " +
                                    path + " names");
  }
  c.intrinsics = intrinsicsFromK(K.K());
  return c;
}

// --- Images with projection matrices (Pavilion, PMVS) -------------------------------------------

// Folders of one projection matrix file per image: Pavilion's cameras/NNN.projmatrix, PMVS's
// txt/NNNNNNNN.txt ("CONTOUR" then the 3 rows).
constexpr const char* kProjectionFolders[] = {"cameras", "txt"};
constexpr const char* kProjectionImageFolders[] = {"images", "visualize"};

bool isProjectionName(const std::string& name) {
  return endsWith(name, ".projmatrix") || endsWith(name, ".txt") || endsWith(name, ".P");
}

std::optional<fs::path> projectionFolder(const fs::path& dir) {
  for (const char* folder : kProjectionFolders) {
    if (isDirectory(dir / folder) && !listFiles(dir / folder, isProjectionName).empty()) {
      return dir / folder;
    }
  }
  return std::nullopt;
}

// `folder` itself when it holds images, else its one sub-folder that does (Pavilion:
// images/midday/); nothing when there is none, IoError when there are several.
std::optional<fs::path> imagesIn(const fs::path& folder) {
  if (!isDirectory(folder)) return std::nullopt;
  if (!listImages(folder).empty()) return folder;
  std::vector<fs::path> subfolders;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    if (entry.is_directory() && !listImages(entry.path()).empty()) {
      subfolders.push_back(entry.path());
    }
  }
  if (subfolders.size() == 1) return subfolders[0];
  if (subfolders.size() > 1) {
    std::sort(subfolders.begin(), subfolders.end());
    std::string names;
    for (const fs::path& s : subfolders) names += " " + s.filename().string();
    throw IoError(folder.string(), "holds no images but several folders of them (" +
                                       names.substr(1) +
                                       "): keep one (e.g. in a copy of the dataset folder)");
  }
  return std::nullopt;
}

fs::path projectionImageFolder(const fs::path& dir) {
  for (const char* name : kProjectionImageFolders) {
    if (const std::optional<fs::path> folder = imagesIn(dir / name)) return *folder;
  }
  throw IoError(dir.string(), "no image folder: looked for images/ and visualize/");
}

LayoutContents readProjection(const fs::path& dir) {
  const std::optional<fs::path> cameras_dir = projectionFolder(dir);
  if (!cameras_dir) {
    throw IoError(dir.string(), "no projection matrix folder: looked for cameras/ and txt/");
  }
  const std::vector<fs::path> cameras = listFiles(*cameras_dir, isProjectionName);
  const fs::path images_dir = projectionImageFolder(dir);
  const std::vector<fs::path> images = listImages(images_dir);
  // Images and matrices pair in natural order (Pavilion's midday-640x-0001.png and
  // 001.projmatrix have no common name), so the counts must agree.
  if (images.size() != cameras.size()) {
    throw IoError(dir.string(), std::to_string(images.size()) + " images in " +
                                    images_dir.string() + " but " + std::to_string(cameras.size()) +
                                    " projection matrices in " + cameras_dir->string() +
                                    ": expected one matrix per image");
  }
  LayoutContents c;
  c.camera_source = c.ground_truth_source = cameras_dir->string();
  SharedIntrinsics K;
  for (std::size_t i = 0; i < images.size(); ++i) {
    const std::string path = cameras[i].string();
    const Matrix34d P = readNumberRows(path, 3, 4, "p_i1 p_i2 p_i3 p_i4", "a 3x4 projection matrix",
                                       nullptr, "CONTOUR");
    const DecomposedProjection d = decomposeProjection(P, path);
    K.add(d.K, path, 0);
    c.frames.push_back({static_cast<double>(i), images[i].string(), d.cam_from_world.inverse()});
  }
  c.intrinsics = intrinsicsFromK(K.K());
  return c;
}

// --- Strecha / EPFL
// -------------------------------------------------------------------------------

// A Strecha .camera file: K (3 lines), distortion (1 line of 3), R camera-to-world (3 lines),
// the centre C (1 line), "width height".
struct StrechaCamera {
  Eigen::Matrix3d K;
  Pose3 world_from_cam;
  int width = 0, height = 0;
  std::vector<int> lines;  ///< The line of each of the 9 records.
};

StrechaCamera readStrechaCamera(const std::string& path) {
  constexpr char kFormat[] = "K (3 lines), distortion, R (3 lines), C, \"width height\"";
  Eigen::Matrix<double, 8, 3> rows;
  StrechaCamera camera;
  forEachRecord(path, [&](int line, const TextFields& fields) {
    const int record = static_cast<int>(camera.lines.size());
    if (record == 9) throw ParseError(path, line, std::string("9 lines: ") + kFormat, "more");
    camera.lines.push_back(line);
    if (record < 8) {
      requireFieldCount(path, line, fields, 3, "three numbers (a row of K, distortion, R or C)");
      for (int k = 0; k < 3; ++k) rows(record, k) = numberField(path, line, fields, k, "number");
      return;
    }
    requireFieldCount(path, line, fields, 2, "width height");
    const double w = numberField(path, line, fields, 0, "width");
    const double h = numberField(path, line, fields, 1, "height");
    if (!(w >= 1 && h >= 1 && w == std::floor(w) && h == std::floor(h) && w < 1e6 && h < 1e6)) {
      throw ParseError(path, line, "a positive whole width and height in pixels",
                       std::string(fields[0]) + " " + std::string(fields[1]));
    }
    camera.width = static_cast<int>(w);
    camera.height = static_cast<int>(h);
  });
  if (camera.lines.size() < 9) {
    throw ParseError(path, 0, std::string("9 lines: ") + kFormat,
                     std::to_string(camera.lines.size()));
  }
  camera.K = rows.topRows<3>();
  if (!rows.row(3).isZero()) {
    throw ParseError(
        path, camera.lines[3], "distortion \"0 0 0\" (undistorted images)",
        formatNumber(rows(3, 0)) + " " + formatNumber(rows(3, 1)) + " " + formatNumber(rows(3, 2)));
  }
  const Eigen::Matrix3d world_R_cam =
      checkedRotation(rows.middleRows<3>(4), path, camera.lines[4], "R (camera to world)");
  camera.world_from_cam = Pose3(world_R_cam, rows.row(7).transpose());
  return camera;
}

LayoutContents readStrecha(const fs::path& dir) {
  // openMVG's copy: images/NNNN.jpg and gt_dense_cameras/NNNN.jpg.camera; the original: both
  // in one folder.
  const bool split = isDirectory(dir / "images") && isDirectory(dir / "gt_dense_cameras");
  const fs::path images_dir = split ? dir / "images" : dir;
  const fs::path cameras_dir = split ? dir / "gt_dense_cameras" : dir;
  const std::vector<fs::path> images = listImages(images_dir);
  if (images.empty()) throw IoError(images_dir.string(), "holds no images");
  LayoutContents c;
  c.camera_source = c.ground_truth_source = cameras_dir.string();
  SharedIntrinsics K;
  int width = 0, height = 0;
  for (std::size_t i = 0; i < images.size(); ++i) {
    const std::string path = (cameras_dir / (images[i].filename().string() + ".camera")).string();
    if (!fs::exists(path)) {
      throw IoError(path, "no such file: the Strecha camera of " + images[i].string());
    }
    const StrechaCamera camera = readStrechaCamera(path);
    K.add(camera.K, path, camera.lines[0]);
    if (i > 0 && (camera.width != width || camera.height != height)) {
      throw ParseError(path, camera.lines[8],
                       "the image size of the first camera, " + std::to_string(width) + " " +
                           std::to_string(height),
                       std::to_string(camera.width) + " " + std::to_string(camera.height));
    }
    width = camera.width;
    height = camera.height;
    c.frames.push_back({static_cast<double>(i), images[i].string(), camera.world_from_cam});
  }
  c.intrinsics = intrinsicsFromK(K.K());
  c.intrinsics->width = width;
  c.intrinsics->height = height;
  return c;
}

// --- Microsoft 7-Scenes
// ---------------------------------------------------------------------------

bool isSevenScenesPose(const std::string& name) {
  return name.rfind("frame-", 0) == 0 && endsWith(name, ".pose.txt");
}

LayoutContents readSevenScenes(const fs::path& dir) {
  const std::vector<fs::path> poses = listFiles(dir, isSevenScenesPose);
  if (poses.empty()) throw IoError(dir.string(), "holds no frame-*.pose.txt");
  LayoutContents c;
  // 7-Scenes documents only the depth camera (585, 585, 320, 240); some copies add it as
  // camera-intrinsics.txt. Without it the colour camera's intrinsics must come from --camera.
  const std::string intrinsics_path = joinPath(dir, "camera-intrinsics.txt");
  if (fs::exists(intrinsics_path)) {
    std::vector<int> lines;
    SharedIntrinsics K;
    const Eigen::Matrix3d K_read =
        readNumberRows(intrinsics_path, 3, 3, "k_i1 k_i2 k_i3", "a 3x3 K", &lines);
    K.add(K_read, intrinsics_path, lines[0]);
    c.intrinsics = intrinsicsFromK(K.K());
    c.camera_source = intrinsics_path;
  } else {
    c.camera_looked_for = intrinsics_path;
  }
  c.ground_truth_source = dir.string() + "/frame-*.pose.txt";
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const std::string path = poses[i].string();
    const std::string stem = path.substr(0, path.size() - std::string(".pose.txt").size());
    std::string image = stem + ".color.png";
    if (!fs::exists(image) && fs::exists(stem + ".color.jpg")) image = stem + ".color.jpg";
    std::vector<int> lines;
    const Eigen::Matrix4d T =
        readNumberRows(path, 4, 4, "t_i1 t_i2 t_i3 t_i4", "a 4x4 camera-to-world matrix", &lines);
    if ((T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-9) {
      throw ParseError(path, lines[3], "a last row \"0 0 0 1\"", "another");
    }
    const Eigen::Matrix3d R =
        checkedRotation(T.topLeftCorner<3, 3>(), path, lines[0], "the pose's 3x3 block");
    c.frames.push_back({static_cast<double>(i), image, Pose3(R, T.topRightCorner<3, 1>())});
  }
  return c;
}

// --- EuRoC MAV -----------------------------------------------------------------------------------

constexpr const char* kEurocGroundTruthFields[] = {
    "timestamp [ns]", "p_RS_R_x", "p_RS_R_y", "p_RS_R_z", "q_RS_w", "q_RS_x", "q_RS_y", "q_RS_z"};

// The camera folder of a EuRoC sequence given as its root (mav0/cam0 below it), as mav0, or as
// the camera folder itself: the one holding data.csv and sensor.yaml.
std::optional<fs::path> eurocCameraFolder(const fs::path& dir) {
  for (const fs::path& folder : {dir / "mav0" / "cam0", dir / "cam0", dir}) {
    if (isFile(folder / "data.csv") && isFile(folder / "sensor.yaml")) {
      const fs::path normal = fs::absolute(folder).lexically_normal();
      return normal.has_filename() ? normal : normal.parent_path();
    }
  }
  return std::nullopt;
}

// sensor.yaml's T_BS: the camera's pose in the body (IMU) frame, x_body = T_BS x_cam.
Pose3 eurocBodyFromCamera(const std::string& sensor_yaml) {
  const std::vector<double> T = readYamlNumbers(sensor_yaml, "T_BS");
  if (T.size() != 16) {
    throw ParseError(sensor_yaml, 0, "key T_BS (a 4x4 matrix, 16 numbers)",
                     std::to_string(T.size()) + " numbers");
  }
  const Eigen::Matrix4d M =
      Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(T.data());
  const Eigen::Matrix3d R =
      checkedRotation(M.topLeftCorner<3, 3>(), sensor_yaml, 0, "T_BS's 3x3 block");
  return Pose3(R, M.topRightCorner<3, 1>());
}

// state_groundtruth_estimate0/data.csv: per line the body's pose in the world (timestamp [ns],
// p_RS_R, q_RS as w x y z, then velocities and biases), carried to the camera by T_BS.
std::vector<StampedPose> readEurocGroundTruth(const std::string& path, const Pose3& body_from_cam) {
  std::vector<StampedPose> poses;
  forEachRecord(
      path,
      [&](int line, const TextFields& fields) {
        if (fields.size() < 8) {
          requireFieldCount(path, line, fields, 8,
                            "timestamp [ns], p_RS_R (3), q_RS (w x y z), ...");
        }
        double v[8];
        for (std::size_t i = 0; i < 8; ++i) {
          v[i] = numberField(path, line, fields, i, kEurocGroundTruthFields[i]);
        }
        const Eigen::Quaterniond q(v[4], v[5], v[6], v[7]);
        if (!(std::abs(q.norm() - 1.0) <= kQuaternionNormTolerance)) {
          throw ParseError(path, line, "a unit quaternion q_RS (w x y z)",
                           "norm " + formatNumber(q.norm()));
        }
        const Pose3 world_from_body(q.normalized(), Eigen::Vector3d(v[1], v[2], v[3]));
        poses.push_back({v[0] * 1e-9, world_from_body * body_from_cam});
      },
      kCsvSeparators);
  if (poses.empty()) throw ParseError(path, 0, "at least one pose line", "none");
  return poses;
}

// EuRoC MAV: cam0/data.csv ("timestamp [ns],filename") lists the images in cam0/data/,
// cam0/sensor.yaml holds the camera and T_BS, and mav0/state_groundtruth_estimate0/data.csv, if
// present, the body's poses.
LayoutContents readEuroc(const fs::path& dir) {
  const std::optional<fs::path> camera = eurocCameraFolder(dir);
  if (!camera) {
    throw IoError(dir.string(),
                  "no EuRoC camera folder: looked for data.csv and sensor.yaml in mav0/cam0/, "
                  "cam0/ and the folder itself");
  }
  LayoutContents c;
  const std::string sensor = (*camera / "sensor.yaml").string();
  c.intrinsics = readCameraYaml(sensor).intrinsics();
  c.camera_source = sensor;
  const std::string list = (*camera / "data.csv").string();
  forEachRecord(
      list,
      [&](int line, const TextFields& fields) {
        requireFieldCount(list, line, fields, 2, "timestamp [ns],filename");
        const double timestamp = numberField(list, line, fields, 0, "timestamp [ns]") * 1e-9;
        c.frames.push_back(
            {timestamp, joinPath(*camera / "data", std::string(fields[1])), std::nullopt});
      },
      kCsvSeparators);
  const fs::path ground_truth = camera->parent_path() / "state_groundtruth_estimate0" / "data.csv";
  if (isFile(ground_truth)) {
    c.ground_truth = readEurocGroundTruth(ground_truth.string(), eurocBodyFromCamera(sensor));
    c.ground_truth_source = ground_truth.string();
  }
  return c;
}

// --- A plain folder of images -------------------------------------------------------------------

// The images directly in `dir`, or in dir/images/ (or its one sub-folder). Other layouts keep
// their images in such folders too, so detection tries every other layout first.
std::optional<fs::path> plainImageFolder(const fs::path& dir) {
  if (!listImages(dir).empty()) return dir;
  return imagesIn(dir / "images");
}

// What most people have: the images of one calibrated camera in file-name order. The intrinsics
// come from --camera or DIR/camera.yaml; DIR/groundtruth.txt, if present, is a TUM trajectory
// whose times are the images' indices 0, 1, 2, ... (as every layout without times numbers them).
LayoutContents readPlainImages(const fs::path& dir) {
  const std::optional<fs::path> folder = plainImageFolder(dir);
  if (!folder) {
    throw IoError(dir.string(), "holds no images (looked for " + imageExtensionsText() +
                                    " files in it and in images/)");
  }
  LayoutContents c;
  readCameraYamlAndGroundTruth(dir, &c);
  const std::vector<fs::path> images = listImages(*folder);
  for (std::size_t i = 0; i < images.size(); ++i) {
    c.frames.push_back({static_cast<double>(i), images[i].string(), std::nullopt});
  }
  return c;
}

// --- Layout detection ---------------------------------------------------------------------------

struct LayoutSignature {
  DatasetLayout layout;
  const char* looks_for;
  bool (*matches)(const fs::path& dir);
};

bool hasAnyFile(const fs::path& dir, bool (*keep)(const std::string&)) {
  if (!isDirectory(dir)) return false;
  std::error_code error;
  for (fs::directory_iterator it(dir, error), end; !error && it != end; it.increment(error)) {
    if (isFile(it->path()) && keep(it->path().filename().string())) return true;
  }
  return false;
}

const LayoutSignature kSignatures[] = {
    {DatasetLayout::kTum, "rgb.txt (tum)", [](const fs::path& d) { return isFile(d / "rgb.txt"); }},
    {DatasetLayout::kKitti, "calib.txt or image_0/ (kitti)",
     [](const fs::path& d) { return isFile(d / "calib.txt") || isDirectory(d / "image_0"); }},
    {DatasetLayout::kMiddlebury, "*_par.txt (middlebury)",
     [](const fs::path& d) {
       return hasAnyFile(d, [](const std::string& n) { return endsWith(n, "_par.txt"); });
     }},
    {DatasetLayout::kProjection, "cameras/ or txt/ of projection matrix files (projection)",
     [](const fs::path& d) {
       return hasAnyFile(d / "cameras", isProjectionName) ||
              hasAnyFile(d / "txt", isProjectionName);
     }},
    {DatasetLayout::kStrecha, "*.camera or gt_dense_cameras/*.camera (strecha)",
     [](const fs::path& d) {
       const auto is_camera = [](const std::string& n) { return endsWith(n, ".camera"); };
       return hasAnyFile(d, is_camera) || hasAnyFile(d / "gt_dense_cameras", is_camera);
     }},
    {DatasetLayout::kSevenScenes, "frame-*.pose.txt (7scenes)",
     [](const fs::path& d) { return hasAnyFile(d, isSevenScenesPose); }},
    {DatasetLayout::kEuroc, "data.csv and sensor.yaml in mav0/cam0/, cam0/ or the folder (euroc)",
     [](const fs::path& d) { return eurocCameraFolder(d).has_value(); }},
};

std::vector<DatasetLayout> matchingLayouts(const fs::path& dir) {
  std::vector<DatasetLayout> layouts;
  for (const LayoutSignature& s : kSignatures) {
    if (s.matches(dir)) layouts.push_back(s.layout);
  }
  return layouts;
}

std::string layoutNames(const std::vector<DatasetLayout>& layouts) {
  std::string names;
  for (DatasetLayout layout : layouts) names += (names.empty() ? "" : ", ") + toString(layout);
  return names;
}

// --- The common part ----------------------------------------------------------------------------

// A missing file or one whose header names no format OpenCV reads fails here, before any work,
// with readColorImage()'s message.
void checkImageFile(const std::string& path) {
  if (!fs::exists(path) || !cv::haveImageReader(path)) readColorImage(path);
}

Camera resolveCamera(const LayoutContents& c, const ImageSequenceOptions& options,
                     const std::optional<FallbackCamera>& fallback, const std::string& first_image,
                     std::string* source) {
  const auto first_image_size = [&] {
    const cv::Mat image = readColorImage(first_image);
    return std::make_pair(image.cols, image.rows);
  };
  if (!options.camera.empty()) {
    const auto [width, height] = first_image_size();
    *source = "--camera";
    return parseCameraString(options.camera, width, height);
  }
  if (!c.intrinsics && fallback) {
    const auto [width, height] = first_image_size();
    if (width != fallback->camera.width() || height != fallback->camera.height()) {
      throw IoError(first_image, "is " + std::to_string(width) + "x" + std::to_string(height) +
                                     " px, the camera of " + fallback->source + " " +
                                     std::to_string(fallback->camera.width()) + "x" +
                                     std::to_string(fallback->camera.height()));
    }
    *source = fallback->source;
    return fallback->camera;
  }
  if (!c.intrinsics) {
    throw IoError(c.camera_looked_for,
                  std::string("no such file, so the dataset gives no intrinsics: pass --camera ") +
                      kCameraFormat + " (pixels), or a COLMAP model as initial poses");
  }
  CameraIntrinsics intrinsics = *c.intrinsics;
  if (intrinsics.width == 0) std::tie(intrinsics.width, intrinsics.height) = first_image_size();
  *source = c.camera_source;
  return Camera(intrinsics);
}

}  // namespace

void ImageSequenceOptions::validate() const {
  const OptionCheck require("ImageSequenceOptions");
  require(max_frames >= 0, "max_frames", max_frames, ">= 0 (0 = all)");
  require(stride >= 1, "stride", stride, ">= 1");
  if (!camera.empty()) parseCameraString(camera, 1, 1);
}

Camera parseCameraString(const std::string& text, int width, int height) {
  const auto fail = [&](const std::string& problem) {
    throw InvalidOptions("ImageSequenceOptions", "camera", "\"" + text + "\"",
                         std::string("expected ") + kCameraFormat + " in pixels: " + problem);
  };
  std::vector<double> values;
  std::size_t begin = 0;
  while (true) {
    const std::size_t end = std::min(text.find(',', begin), text.size());
    std::string_view token(text.data() + begin, end - begin);
    while (!token.empty() && token.front() == ' ') token.remove_prefix(1);
    while (!token.empty() && token.back() == ' ') token.remove_suffix(1);
    const std::optional<double> value = parseFiniteNumber(token);
    if (!value) fail("value " + std::to_string(values.size() + 1) + " is not a finite number");
    values.push_back(*value);
    if (end == text.size()) break;
    begin = end + 1;
  }
  if (values.size() != 4 && values.size() != 8 && values.size() != 9) {
    fail(std::to_string(values.size()) + " values instead of 4, 8 or 9");
  }
  if (!(values[0] > 0.0 && values[1] > 0.0)) fail("fx and fy must be > 0");
  CameraIntrinsics k;
  double* fields[] = {&k.fx, &k.fy, &k.cx, &k.cy, &k.k1, &k.k2, &k.p1, &k.p2, &k.k3};
  for (std::size_t i = 0; i < values.size(); ++i) *fields[i] = values[i];
  k.width = width;
  k.height = height;
  return Camera(k);
}

std::string formatCameraString(const Camera& camera) {
  const CameraIntrinsics& c = camera.intrinsics();
  std::vector<double> values = {c.fx, c.fy, c.cx, c.cy};
  if (camera.hasDistortion()) values.insert(values.end(), {c.k1, c.k2, c.p1, c.p2, c.k3});
  std::ostringstream text;
  text << std::setprecision(std::numeric_limits<double>::max_digits10);
  for (std::size_t i = 0; i < values.size(); ++i) text << (i ? "," : "") << values[i];
  return text.str();
}

DatasetLayout detectDatasetLayout(const std::string& dir) {
  if (!isDirectory(dir)) throw IoError(dir, "no such folder");
  const std::vector<DatasetLayout> layouts = matchingLayouts(dir);
  if (layouts.size() == 1) return layouts[0];
  if (layouts.size() > 1) {
    throw IoError(dir, "looks like several dataset layouts (" + layoutNames(layouts) +
                           "): pass the layout (one of " + layoutNames(layouts) + ")");
  }
  // Last, since the other layouts hold images too.
  if (plainImageFolder(dir)) return DatasetLayout::kImages;
  std::string looked_for;
  for (const LayoutSignature& s : kSignatures) {
    looked_for += (looked_for.empty() ? "" : ", ") + std::string(s.looks_for);
  }
  looked_for += ", image files in it or in images/ (images)";
  // Published archives often wrap the sequence in a folder (KITTI_sequence_1/, data/).
  std::string hint;
  std::vector<fs::path> subfolders;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    if (entry.is_directory()) subfolders.push_back(entry.path());
  }
  std::sort(subfolders.begin(), subfolders.end());
  for (const fs::path& sub : subfolders) {
    const std::vector<DatasetLayout> inside = matchingLayouts(sub);
    if (!inside.empty()) {
      hint += "; " + sub.string() + " looks like " + layoutNames(inside);
    } else if (!listImages(sub).empty()) {
      hint += "; " + sub.string() + " holds images";
    }
  }
  throw IoError(dir, "no known dataset layout: looked for " + looked_for + hint);
}

ImageSequence loadImageSequence(const std::string& dir, const ImageSequenceOptions& options,
                                const std::optional<FallbackCamera>& fallback) {
  options.validate();
  const DatasetLayout layout =
      options.layout == DatasetLayout::kAuto ? detectDatasetLayout(dir) : options.layout;
  if (!isDirectory(dir)) throw IoError(dir, "no such folder");
  LayoutContents c;
  switch (layout) {
    case DatasetLayout::kTum:
      c = readTum(dir);
      break;
    case DatasetLayout::kKitti:
      c = readKitti(dir);
      break;
    case DatasetLayout::kMiddlebury:
      c = readMiddlebury(dir);
      break;
    case DatasetLayout::kProjection:
      c = readProjection(dir);
      break;
    case DatasetLayout::kStrecha:
      c = readStrecha(dir);
      break;
    case DatasetLayout::kSevenScenes:
      c = readSevenScenes(dir);
      break;
    case DatasetLayout::kEuroc:
      c = readEuroc(dir);
      break;
    case DatasetLayout::kImages:
      c = readPlainImages(dir);
      break;
    case DatasetLayout::kAuto:
      break;
  }
  std::vector<LayoutFrame> selected;
  for (std::size_t i = 0; i < c.frames.size(); i += static_cast<std::size_t>(options.stride)) {
    if (options.max_frames > 0 && static_cast<int>(selected.size()) == options.max_frames) break;
    selected.push_back(c.frames[i]);
  }
  if (selected.empty()) throw IoError(dir, "holds no images");
  for (const LayoutFrame& frame : selected) checkImageFile(frame.image_path);

  ImageSequence s;
  s.dir = dir;
  s.layout = toString(layout);
  s.camera = resolveCamera(c, options, fallback, selected.front().image_path, &s.camera_source);
  s.ground_truth = c.ground_truth;
  s.ground_truth_source = c.ground_truth_source;
  for (const LayoutFrame& frame : selected) {
    s.images.push_back(
        {frame.timestamp, frame.image_path, fs::path(frame.image_path).filename().string()});
    if (frame.world_from_cam) s.ground_truth.push_back({frame.timestamp, *frame.world_from_cam});
  }
  if (s.ground_truth.empty()) s.ground_truth_source.clear();
  return s;
}

}  // namespace curvesfm
