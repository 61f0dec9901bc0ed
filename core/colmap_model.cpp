#include "core/colmap_model.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>

#include "core/errors.h"
#include "core/text_records.h"

namespace curvesfm {
namespace {

namespace fs = std::filesystem;

// COLMAP's camera models (src/colmap/sensor/models.h): id, name, parameter count.
struct ColmapCameraModel {
  int id;
  const char* name;
  int parameters;
};
constexpr ColmapCameraModel kColmapModels[] = {{0, "SIMPLE_PINHOLE", 3},
                                               {1, "PINHOLE", 4},
                                               {2, "SIMPLE_RADIAL", 4},
                                               {3, "RADIAL", 5},
                                               {4, "OPENCV", 8},
                                               {5, "OPENCV_FISHEYE", 8},
                                               {6, "FULL_OPENCV", 12},
                                               {7, "FOV", 5},
                                               {8, "SIMPLE_RADIAL_FISHEYE", 4},
                                               {9, "RADIAL_FISHEYE", 5},
                                               {10, "THIN_PRISM_FISHEYE", 12},
                                               {11, "RAD_TAN_THIN_PRISM_FISHEYE", 16}};

constexpr char kSupportedModels[] =
    "SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV or FULL_OPENCV with k4 = k5 = k6 = 0";

const ColmapCameraModel* modelById(int id) {
  for (const ColmapCameraModel& m : kColmapModels) {
    if (m.id == id) return &m;
  }
  return nullptr;
}

const ColmapCameraModel* modelByName(std::string_view name) {
  for (const ColmapCameraModel& m : kColmapModels) {
    if (name == m.name) return &m;
  }
  return nullptr;
}

// Maps COLMAP's parameters onto Camera (pixel centres moved from 0.5 to 0, see the header);
// nullopt for a model our radial-tangential camera cannot represent.
std::optional<CameraIntrinsics> intrinsicsOf(const ColmapCameraModel& model,
                                             const std::vector<double>& p, int width, int height) {
  CameraIntrinsics k;
  k.width = width;
  k.height = height;
  switch (model.id) {
    case 0:  // SIMPLE_PINHOLE: f, cx, cy
    case 2:  // SIMPLE_RADIAL: f, cx, cy, k
    case 3:  // RADIAL: f, cx, cy, k1, k2
      k.fx = k.fy = p[0];
      k.cx = p[1];
      k.cy = p[2];
      if (model.id >= 2) k.k1 = p[3];
      if (model.id == 3) k.k2 = p[4];
      break;
    case 1:  // PINHOLE: fx, fy, cx, cy
    case 4:  // OPENCV: fx, fy, cx, cy, k1, k2, p1, p2
    case 6:  // FULL_OPENCV: ... k3, k4, k5, k6 (rational model; ours when k4..k6 are zero)
      k.fx = p[0];
      k.fy = p[1];
      k.cx = p[2];
      k.cy = p[3];
      if (model.id >= 4) {
        k.k1 = p[4];
        k.k2 = p[5];
        k.p1 = p[6];
        k.p2 = p[7];
      }
      if (model.id == 6) {
        if (p[9] != 0.0 || p[10] != 0.0 || p[11] != 0.0) return std::nullopt;
        k.k3 = p[8];
      }
      break;
    default:
      return std::nullopt;
  }
  k.cx -= 0.5;
  k.cy -= 0.5;
  return k;
}

Camera makeCamera(const ColmapCameraModel& model, const std::vector<double>& params, int width,
                  int height, const std::string& path, int line) {
  const std::optional<CameraIntrinsics> k = intrinsicsOf(model, params, width, height);
  if (!k)
    throw ParseError(path, line, std::string("a camera model ") + kSupportedModels, model.name);
  try {
    return Camera(*k);
  } catch (const InvalidOptions& e) {
    throw ParseError(path, line, "valid intrinsics", e.what());
  }
}

Pose3 poseFromQt(const double* q, const double* t, const std::string& path, int line) {
  const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
  if (!(std::abs(rotation.norm() - 1.0) <= kQuaternionNormTolerance)) {
    throw ParseError(path, line, "a unit quaternion \"QW QX QY QZ\"",
                     "norm " + formatNumber(rotation.norm()));
  }
  return Pose3(rotation, Eigen::Vector3d(t[0], t[1], t[2]));
}

int wholeNumber(const std::string& path, int line, const TextFields& fields, std::size_t index,
                const char* name) {
  const double value = numberField(path, line, fields, index, name);
  if (value < 0 || value > 2147483647.0 || value != std::floor(value)) {
    throw ParseError(path, line, std::string("a whole number >= 0 for ") + name,
                     quoteToken(fields[index]));
  }
  return static_cast<int>(value);
}

void checkCameraId(const ColmapModel& model, int camera_id, const std::string& path, int line) {
  if (model.cameras.count(camera_id) == 0) {
    throw ParseError(path, line, "a CAMERA_ID of the cameras file", std::to_string(camera_id));
  }
}

// --- Text ---------------------------------------------------------------------------------------

void readCamerasText(const std::string& path, ColmapModel* model) {
  forEachRecord(path, [&](int line, const TextFields& fields) {
    if (fields.size() < 4) {
      throw ParseError(path, line, "\"CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]\"",
                       std::to_string(fields.size()) + " fields");
    }
    const ColmapCameraModel* camera_model = modelByName(fields[1]);
    if (!camera_model) {
      throw ParseError(path, line, std::string("a COLMAP camera model (") + kSupportedModels + ")",
                       quoteToken(fields[1]));
    }
    const std::string format = "CAMERA_ID MODEL WIDTH HEIGHT and " +
                               std::to_string(camera_model->parameters) + " " + camera_model->name +
                               " parameters";
    requireFieldCount(path, line, fields, 4 + camera_model->parameters, format.c_str());
    const int id = wholeNumber(path, line, fields, 0, "CAMERA_ID");
    const int width = wholeNumber(path, line, fields, 2, "WIDTH");
    const int height = wholeNumber(path, line, fields, 3, "HEIGHT");
    std::vector<double> params;
    for (std::size_t i = 4; i < fields.size(); ++i) {
      params.push_back(numberField(path, line, fields, i, "PARAMS"));
    }
    model->cameras.insert_or_assign(id,
                                    makeCamera(*camera_model, params, width, height, path, line));
  });
}

// Two lines per image; the second (its 2D points) may be empty, so it is consumed as it is, as
// COLMAP's own reader does, instead of skipping blank lines.
void readImagesText(const std::string& path, ColmapModel* model) {
  std::ifstream in = openForReading(path);
  std::string text;
  int line = 0;
  while (std::getline(in, text)) {
    ++line;
    const TextFields fields = splitFields(line == 1 ? withoutByteOrderMark(text) : text);
    if (fields.empty() || fields.front().front() == '#') continue;
    requireFieldCount(path, line, fields, 10, "IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME");
    ColmapImage image;
    image.image_id = wholeNumber(path, line, fields, 0, "IMAGE_ID");
    double v[7];
    for (int k = 0; k < 7; ++k) v[k] = numberField(path, line, fields, k + 1, "QW..TZ");
    image.cam_from_world = poseFromQt(v, v + 4, path, line);
    image.camera_id = wholeNumber(path, line, fields, 8, "CAMERA_ID");
    checkCameraId(*model, image.camera_id, path, line);
    image.name = std::string(fields[9]);
    model->images.push_back(image);
    if (std::getline(in, text)) ++line;
  }
  if (in.bad()) throw IoError(path, "read error");
}

// --- Binary (little endian, as COLMAP writes it on every platform it runs on)
// ---------------------

class BinaryReader {
 public:
  explicit BinaryReader(const std::string& path) : path_(path), in_(path, std::ios::binary) {
    if (!in_) throw IoError(path, "cannot open for reading");
    size_ = static_cast<std::uint64_t>(fs::file_size(path));
  }
  template <class T>
  T read(const char* what) {
    T value;
    need(sizeof(T), what);
    in_.read(reinterpret_cast<char*>(&value), sizeof(T));
    offset_ += sizeof(T);
    return value;
  }
  std::string readName() {
    std::string name;
    for (char c; (c = read<char>("a NUL-terminated image name")) != '\0';) name += c;
    return name;
  }
  void skip(std::uint64_t count, std::uint64_t bytes_each, const char* what) {
    if (count > (size_ - offset_) / bytes_each) need(count * bytes_each, what);
    in_.seekg(static_cast<std::streamoff>(count * bytes_each), std::ios::cur);
    offset_ += count * bytes_each;
  }
  [[noreturn]] void fail(const std::string& expected, const std::string& found) const {
    throw ParseError(path_, 0, expected + " at byte " + std::to_string(offset_), found);
  }
  const std::string& path() const { return path_; }

 private:
  void need(std::uint64_t bytes, const char* what) const {
    if (bytes > size_ - offset_) {
      fail(std::to_string(bytes) + " bytes of " + what,
           "the end of the file (" + std::to_string(size_) + " bytes)");
    }
  }
  std::string path_;
  std::ifstream in_;
  std::uint64_t size_ = 0, offset_ = 0;
};

void readCamerasBinary(const std::string& path, ColmapModel* model) {
  BinaryReader in(path);
  const auto count = in.read<std::uint64_t>("the camera count");
  for (std::uint64_t i = 0; i < count; ++i) {
    const auto id = in.read<std::uint32_t>("camera_id");
    const auto model_id = in.read<std::int32_t>("model_id");
    const ColmapCameraModel* camera_model = modelById(model_id);
    if (!camera_model) {
      in.fail("a COLMAP camera model id 0..11", "model id " + std::to_string(model_id));
    }
    const auto width = in.read<std::uint64_t>("width");
    const auto height = in.read<std::uint64_t>("height");
    std::vector<double> params;
    for (int p = 0; p < camera_model->parameters; ++p) params.push_back(in.read<double>("params"));
    if (width > 1000000 || height > 1000000)
      in.fail("an image size in pixels",
              "width " + std::to_string(width) + ", height " + std::to_string(height));
    model->cameras.insert_or_assign(static_cast<int>(id),
                                    makeCamera(*camera_model, params, static_cast<int>(width),
                                               static_cast<int>(height), path, 0));
  }
}

void readImagesBinary(const std::string& path, ColmapModel* model) {
  BinaryReader in(path);
  const auto count = in.read<std::uint64_t>("the image count");
  for (std::uint64_t i = 0; i < count; ++i) {
    ColmapImage image;
    image.image_id = static_cast<int>(in.read<std::uint32_t>("image_id"));
    double v[7];
    for (double& value : v) value = in.read<double>("qvec and tvec");
    image.camera_id = static_cast<int>(in.read<std::uint32_t>("camera_id"));
    image.name = in.readName();
    try {
      image.cam_from_world = poseFromQt(v, v + 4, path, 0);
      checkCameraId(*model, image.camera_id, path, 0);
    } catch (const ParseError& e) {
      in.fail("image " + image.name + " with a unit qvec and a known camera_id", e.what());
    }
    const auto points = in.read<std::uint64_t>("the 2D point count");
    in.skip(points, 24, "2D points (x, y, point3D_id)");
    model->images.push_back(image);
  }
}

std::string baseName(const std::string& path) { return fs::path(path).filename().string(); }

// The model's cameras, from cameras.txt or else cameras.bin; true when they were text.
bool readCameras(const std::string& dir, ColmapModel* model) {
  const fs::path folder(dir);
  if (fs::exists(folder / "cameras.txt")) {
    readCamerasText((folder / "cameras.txt").string(), model);
    return true;
  }
  if (fs::exists(folder / "cameras.bin")) {
    readCamerasBinary((folder / "cameras.bin").string(), model);
    return false;
  }
  throw IoError(dir,
                "no COLMAP model: looked for cameras.txt + images.txt and cameras.bin + "
                "images.bin");
}

}  // namespace

ColmapModel readColmapModel(const std::string& dir) {
  ColmapModel model;
  model.dir = dir;
  const fs::path folder(dir);
  if (readCameras(dir, &model)) {
    readImagesText((folder / "images.txt").string(), &model);
  } else {
    const std::string images = (folder / "images.bin").string();
    if (!fs::exists(images)) throw IoError(images, "no such file");
    readImagesBinary(images, &model);
  }
  return model;
}

std::optional<FallbackCamera> colmapModelCamera(const std::string& dir) {
  // The cameras file alone: the images, which can be long, are read with the poses.
  ColmapModel model;
  readCameras(dir, &model);
  if (model.cameras.size() != 1) return std::nullopt;
  return FallbackCamera{model.cameras.begin()->second, "the COLMAP model " + dir};
}

std::vector<StampedPose> colmapPosesForSequence(const ColmapModel& model,
                                                const ImageSequence& sequence) {
  std::map<std::string, const ColmapImage*> by_name;
  std::map<std::string, std::vector<const ColmapImage*>> by_file_name;
  for (const ColmapImage& image : model.images) {
    by_name[image.name] = &image;
    by_file_name[baseName(image.name)].push_back(&image);
  }
  std::vector<StampedPose> poses;
  for (const SequenceImage& image : sequence.images) {
    const ColmapImage* match = nullptr;
    if (const auto it = by_name.find(image.name); it != by_name.end()) {
      match = it->second;
    } else if (const auto it = by_file_name.find(image.name);
               it != by_file_name.end() && it->second.size() == 1) {
      match = it->second.front();
    }
    if (match) poses.push_back({image.timestamp, match->cam_from_world.inverse()});
  }
  if (poses.empty()) {
    throw ParseError(model.dir, 0,
                     "images named as those of " + sequence.dir + " (e.g. " +
                         (sequence.images.empty() ? std::string("none") : sequence.images[0].name) +
                         ")",
                     "none of its " + std::to_string(model.images.size()) + " images" +
                         (model.images.empty() ? "" : " (e.g. " + model.images[0].name + ")"));
  }
  return poses;
}

}  // namespace curvesfm
