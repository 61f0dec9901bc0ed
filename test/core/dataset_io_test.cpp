#include "core/dataset_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <random>
#include <sstream>
#include <string>

#include "core/errors.h"
#include "test/support/cameras.h"

namespace curvesfm {
namespace {

using ::testing::HasSubstr;

// Each test gets its own folder; the pid keeps concurrent runs from different build trees apart.
class DatasetIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    folder_ =
        std::filesystem::path(::testing::TempDir()) /
        ("curvesfm_dataset_io_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(folder_);
    std::filesystem::create_directories(folder_);
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  std::string write(const std::string& name, const std::string& content) const {
    const std::string path = (folder_ / name).string();
    std::ofstream(path, std::ios::binary) << content;
    return path;
  }

  std::string read(const std::string& path) const {
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  }

  std::filesystem::path folder_;
};

template <class E, class F>
std::string errorMessage(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "wrong exception type: " << e.what();
    return "";
  }
  ADD_FAILURE() << "nothing thrown";
  return "";
}

constexpr char kOrbSlamCamera[] =
    "%YAML:1.0\n"
    "\n"
    "# Camera calibration and distortion parameters (OpenCV)\n"
    "Camera.fx: 517.306408\n"
    "Camera.fy: 516.469215\n"
    "Camera.cx: 318.643040\n"
    "Camera.cy: 255.313989\n"
    "\n"
    "Camera.k1: 0.262383\n"
    "Camera.k2: -0.953104\n"
    "Camera.p1: -0.005358\n"
    "Camera.p2: 0.002628\n"
    "Camera.k3: 1.163314\n"
    "\n"
    "Camera.width: 640\n"
    "Camera.height: 480\n"
    "Camera.fps: 30.0\n"
    "Camera.RGB: 1\n"
    "ORBextractor.nFeatures: 1000\n";

// ---------------------------------------------------------------------------------------------
// rgb.txt

TEST_F(DatasetIoTest, ReadImageListResolvesPathsAgainstItsFolder) {
  const std::string path = write("rgb.txt",
                                 "# color images\n"
                                 "# file: 'rgbd_dataset_freiburg1_xyz.bag'\n"
                                 "# timestamp filename\n"
                                 "1305031102.175304 rgb/1305031102.175304.png\n"
                                 "\n"
                                 "  1305031102.211214\trgb/1305031102.211214.png\r\n"
                                 "1305031102.243211 /abs/image.png\n");
  const std::vector<ImageEntry> entries = readImageList(path);
  ASSERT_EQ(entries.size(), 3u);
  EXPECT_DOUBLE_EQ(entries[0].timestamp, 1305031102.175304);
  EXPECT_EQ(entries[0].path, (folder_ / "rgb/1305031102.175304.png").string());
  EXPECT_DOUBLE_EQ(entries[1].timestamp, 1305031102.211214);
  EXPECT_EQ(entries[1].path, (folder_ / "rgb/1305031102.211214.png").string());
  EXPECT_EQ(entries[2].path, "/abs/image.png");
}

TEST_F(DatasetIoTest, ReadImageListMissingFileIsIoError) {
  const std::string path = (folder_ / "missing" / "rgb.txt").string();
  EXPECT_EQ(errorMessage<IoError>([&] { readImageList(path); }),
            "IoError: " + path + ": cannot open for reading");
}

TEST_F(DatasetIoTest, ReadImageListWrongFieldCountNamesFileAndLine) {
  const std::string path = write("rgb.txt", "# header\n1.0 a.png\n2.0 b.png extra\n");
  EXPECT_EQ(errorMessage<ParseError>([&] { readImageList(path); }),
            "ParseError: " + path + ":3: expected 2 fields \"timestamp path\", found 3");
}

TEST_F(DatasetIoTest, ReadImageListNonNumericTimestampNamesFileAndLine) {
  const std::string path = write("rgb.txt", "1.0 a.png\nnan b.png\n");
  EXPECT_EQ(errorMessage<ParseError>([&] { readImageList(path); }),
            "ParseError: " + path + ":2: expected a number in field 1 (timestamp), found \"nan\"");
}

TEST_F(DatasetIoTest, ReadImageListWithoutEntriesIsParseError) {
  const std::string path = write("rgb.txt", "# only a comment\n\n");
  EXPECT_THAT(errorMessage<ParseError>([&] { readImageList(path); }),
              HasSubstr("ParseError: " + path + ": expected at least one image line"));
}

// ---------------------------------------------------------------------------------------------
// Trajectories

TEST_F(DatasetIoTest, ReadTrajectoryParsesTumLinesAndNormalisesQuaternions) {
  const std::string path = write("groundtruth.txt",
                                 "# ground truth trajectory\n"
                                 "# timestamp tx ty tz qx qy qz qw\n"
                                 "1305031098.6659 1.3563 0.6305 1.6380 0.6132 0.5962 -0.3311 "
                                 "-0.3986\n"
                                 "1305031098.6758 +1.0 -2.0 3e-1 0 0 0 1.005\n");
  const std::vector<StampedPose> poses = readTrajectory(path);
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_DOUBLE_EQ(poses[0].timestamp, 1305031098.6659);
  EXPECT_TRUE(
      poses[0].world_from_cam.translation().isApprox(Eigen::Vector3d(1.3563, 0.6305, 1.638)));
  const Eigen::Quaterniond q0(-0.3986, 0.6132, 0.5962, -0.3311);
  // The same rotation; Pose3 may store it as -q (it keeps qw >= 0).
  EXPECT_LT(poses[0].world_from_cam.rotation().angularDistance(q0.normalized()), 1e-12);
  EXPECT_TRUE(poses[1].world_from_cam.translation().isApprox(Eigen::Vector3d(1.0, -2.0, 0.3)));
  EXPECT_DOUBLE_EQ(poses[1].world_from_cam.rotation().w(), 1.0);
}

TEST_F(DatasetIoTest, WriteTrajectoryUsesOrbSlam2Format) {
  const Pose3 pose(Eigen::Quaterniond(0.5, -0.5, 0.5, 0.5), Eigen::Vector3d(1.0, -2.25, 1e-10));
  const std::string path = (folder_ / "trajectory.txt").string();
  writeTrajectory(path, {{1305031102.175304, pose}});
  EXPECT_EQ(read(path),
            "1305031102.175304 1.000000000 -2.250000000 0.000000000 -0.500000000 0.500000000 "
            "0.500000000 0.500000000\n");
}

TEST_F(DatasetIoTest, WriteTrajectoryRoundTripsAtStatedPrecision) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<StampedPose> written;
  for (int i = 0; i < 100; ++i) {
    const Eigen::Quaterniond q(unit(rng), unit(rng), unit(rng), unit(rng));
    const Eigen::Vector3d t(10.0 * unit(rng), 10.0 * unit(rng), 10.0 * unit(rng));
    written.push_back({1305031102.0 + 0.033 * i + 1e-7 * unit(rng), Pose3(q, t)});
  }
  const std::string path = (folder_ / "trajectory.txt").string();
  writeTrajectory(path, written);
  const std::vector<StampedPose> read_back = readTrajectory(path);
  ASSERT_EQ(read_back.size(), written.size());
  for (std::size_t i = 0; i < written.size(); ++i) {
    EXPECT_NEAR(read_back[i].timestamp, written[i].timestamp, 0.5e-6 + 1e-9);
    const Pose3& a = written[i].world_from_cam;
    const Pose3& b = read_back[i].world_from_cam;
    EXPECT_LE((a.translation() - b.translation()).cwiseAbs().maxCoeff(), 0.5e-9 + 1e-12);
    EXPECT_LE(a.rotation().angularDistance(b.rotation()), 1e-8);
  }
}

TEST_F(DatasetIoTest, ReadTrajectoryMissingFileIsIoError) {
  const std::string path = (folder_ / "groundtruth.txt").string();
  EXPECT_EQ(errorMessage<IoError>([&] { readTrajectory(path); }),
            "IoError: " + path + ": cannot open for reading");
  EXPECT_THAT(errorMessage<IoError>([&] { readTrajectory(folder_.string()); }),
              HasSubstr("cannot open for reading"));
}

TEST_F(DatasetIoTest, ReadTrajectoryWrongFieldCountNamesFileAndLine) {
  const std::string path = write("groundtruth.txt",
                                 "# timestamp tx ty tz qx qy qz qw\n"
                                 "1.0 0 0 0 0 0 0 1\n"
                                 "2.0 0 0 0 0 0 1\n");
  EXPECT_EQ(
      errorMessage<ParseError>([&] { readTrajectory(path); }),
      "ParseError: " + path + ":3: expected 8 fields \"timestamp tx ty tz qx qy qz qw\", found 7");
}

TEST_F(DatasetIoTest, ReadTrajectoryNonNumericFieldNamesFieldAndLine) {
  const std::string path = write("groundtruth.txt", "1.0 0 abc 0 0 0 0 1\n");
  EXPECT_EQ(errorMessage<ParseError>([&] { readTrajectory(path); }),
            "ParseError: " + path + ":1: expected a number in field 3 (ty), found \"abc\"");
}

TEST_F(DatasetIoTest, ReadTrajectoryRejectsTrailingGarbageAndNonFiniteNumbers) {
  for (const std::string token : {"1.5x", "inf", "-nan", "1e400", "1,5", "--1", "0x1p3"}) {
    const std::string path = write("groundtruth.txt", "\n1.0 0 0 0 0 0 0 " + token + "\n");
    EXPECT_EQ(
        errorMessage<ParseError>([&] { readTrajectory(path); }),
        "ParseError: " + path + ":2: expected a number in field 8 (qw), found \"" + token + "\"");
  }
}

TEST_F(DatasetIoTest, ReadTrajectoryNonUnitQuaternionIsParseError) {
  const std::string path = write("groundtruth.txt", "1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 0 0.9\n");
  EXPECT_THAT(errorMessage<ParseError>([&] { readTrajectory(path); }),
              HasSubstr("ParseError: " + path + ":2: expected a unit quaternion"));
  const std::string zero = write("zero.txt", "1.0 0 0 0 0 0 0 0\n");
  EXPECT_THAT(errorMessage<ParseError>([&] { readTrajectory(zero); }),
              HasSubstr(zero + ":1: expected a unit quaternion \"qx qy qz qw\" (|norm - 1| <= "
                               "0.01), found norm 0"));
}

TEST_F(DatasetIoTest, ReadTrajectoryEmptyFileIsParseError) {
  const std::string path = write("groundtruth.txt", "");
  EXPECT_EQ(errorMessage<ParseError>([&] { readTrajectory(path); }),
            "ParseError: " + path +
                ": expected at least one pose line \"timestamp tx ty tz qx qy qz qw\", found none");
}

TEST_F(DatasetIoTest, WriteTrajectoryToMissingFolderIsIoError) {
  const std::string path = (folder_ / "no_such_folder" / "trajectory.txt").string();
  EXPECT_EQ(errorMessage<IoError>([&] { writeTrajectory(path, {}); }),
            "IoError: " + path + ": cannot open for writing");
}

// ---------------------------------------------------------------------------------------------
// camera.yaml

TEST_F(DatasetIoTest, ReadCameraYamlParsesOrbSlam2File) {
  const Camera camera = readCameraYaml(write("camera.yaml", kOrbSlamCamera));
  const CameraIntrinsics& c = camera.intrinsics();
  EXPECT_DOUBLE_EQ(c.fx, 517.306408);
  EXPECT_DOUBLE_EQ(c.fy, 516.469215);
  EXPECT_DOUBLE_EQ(c.cx, 318.643040);
  EXPECT_DOUBLE_EQ(c.cy, 255.313989);
  EXPECT_DOUBLE_EQ(c.k1, 0.262383);
  EXPECT_DOUBLE_EQ(c.k2, -0.953104);
  EXPECT_DOUBLE_EQ(c.p1, -0.005358);
  EXPECT_DOUBLE_EQ(c.p2, 0.002628);
  EXPECT_DOUBLE_EQ(c.k3, 1.163314);
  EXPECT_EQ(c.width, 640);
  EXPECT_EQ(c.height, 480);
}

TEST_F(DatasetIoTest, ReadCameraYamlAcceptsEveryHeaderForm) {
  const std::string body = std::string(kOrbSlamCamera).substr(std::string("%YAML:1.0\n").size());
  for (const std::string header : {"%YAML 1.0\n", "%YAML:1.0\n---\n", "", "# comment\n",
                                   "# comment\n%YAML:1.0\n", "\xEF\xBB\xBF%YAML:1.0\n"}) {
    const Camera camera = readCameraYaml(write("camera.yaml", header + body));
    EXPECT_DOUBLE_EQ(camera.fx(), 517.306408) << "header " << header;
    EXPECT_EQ(camera.height(), 480) << "header " << header;
  }
}

TEST_F(DatasetIoTest, ReadCameraYamlDistortionDefaultsToZero) {
  const std::string path = write("camera.yaml",
                                 "Camera.fx: 500\nCamera.fy: 500\nCamera.cx: 320\nCamera.cy: 240\n"
                                 "Camera.width: 640.0\nCamera.height: 480\n");
  const Camera camera = readCameraYaml(path);
  EXPECT_FALSE(camera.hasDistortion());
  EXPECT_DOUBLE_EQ(camera.fx(), 500.0);
  EXPECT_EQ(camera.width(), 640);
}

TEST_F(DatasetIoTest, ReadCameraYamlMissingFileIsIoError) {
  const std::string path = (folder_ / "camera.yaml").string();
  EXPECT_EQ(errorMessage<IoError>([&] { readCameraYaml(path); }),
            "IoError: " + path + ": cannot open for reading");
}

TEST_F(DatasetIoTest, ReadCameraYamlWithoutFxIsParseError) {
  std::string text = kOrbSlamCamera;
  text.erase(text.find("Camera.fx: 517.306408\n"), std::string("Camera.fx: 517.306408\n").size());
  const std::string path = write("camera.yaml", text);
  EXPECT_EQ(errorMessage<ParseError>([&] { readCameraYaml(path); }),
            "ParseError: " + path +
                ": expected key Camera.fx (a number; or camera_matrix, image_width and "
                "image_height as OpenCV's calibration and ROS camera_info write them; or "
                "intrinsics and resolution as EuRoC's sensor.yaml), found no such key");
  const std::string empty = write("empty.yaml", "");
  EXPECT_THAT(errorMessage<ParseError>([&] { readCameraYaml(empty); }),
              HasSubstr(empty + ": expected key Camera.fx (a number; or camera_matrix"));
}

// What OpenCV's samples/cpp/calibration.cpp writes (abridged).
constexpr char kOpenCvCalibration[] = R"(%YAML:1.0
---
calibration_time: "Sun 06 Dec 2026 05:40:00 UTC"
image_width: 640
image_height: 480
flags: 0
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 5.2e+02, 0., 3.195e+02, 0., 5.21e+02, 2.395e+02, 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 5
   cols: 1
   dt: d
   data: [ 0.1, -0.2, 1.0e-03, -2.0e-03, 0.05 ]
avg_reprojection_error: 0.31
)";

// ROS camera_info as camera_calibration writes it (abridged; no YAML directive).
constexpr char kRosCameraInfo[] = R"(image_width: 752
image_height: 480
camera_name: narrow_stereo
camera_matrix:
  rows: 3
  cols: 3
  data: [458.654, 0, 367.215, 0, 457.296, 248.375, 0, 0, 1]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05, 0]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]
)";

TEST_F(DatasetIoTest, ReadCameraYamlParsesOpenCvCalibrationOutput) {
  const CameraIntrinsics c = readCameraYaml(write("camera.yaml", kOpenCvCalibration)).intrinsics();
  EXPECT_DOUBLE_EQ(c.fx, 520.0);
  EXPECT_DOUBLE_EQ(c.fy, 521.0);
  EXPECT_DOUBLE_EQ(c.cx, 319.5);
  EXPECT_DOUBLE_EQ(c.cy, 239.5);
  EXPECT_DOUBLE_EQ(c.k1, 0.1);
  EXPECT_DOUBLE_EQ(c.k2, -0.2);
  EXPECT_DOUBLE_EQ(c.p1, 1e-3);
  EXPECT_DOUBLE_EQ(c.p2, -2e-3);
  EXPECT_DOUBLE_EQ(c.k3, 0.05);
  EXPECT_EQ(c.width, 640);
  EXPECT_EQ(c.height, 480);
}

TEST_F(DatasetIoTest, ReadCameraYamlParsesRosCameraInfo) {
  const CameraIntrinsics c = readCameraYaml(write("camera.yaml", kRosCameraInfo)).intrinsics();
  EXPECT_DOUBLE_EQ(c.fx, 458.654);
  EXPECT_DOUBLE_EQ(c.cy, 248.375);
  EXPECT_DOUBLE_EQ(c.k1, -0.28340811);
  EXPECT_DOUBLE_EQ(c.p2, 1.76187114e-05);
  EXPECT_DOUBLE_EQ(c.k3, 0.0);
  EXPECT_EQ(c.width, 752);
}

TEST_F(DatasetIoTest, ReadCameraYamlCalibrationFormNamesWhatItCannotModel) {
  const auto message = [&](const std::string& from, const std::string& to) {
    std::string text = kOpenCvCalibration;
    text.replace(text.find(from), from.size(), to);
    const std::string path = write("camera.yaml", text);
    return errorMessage<ParseError>([&] { readCameraYaml(path); });
  };
  // OpenCV's rational model: 8 coefficients, k4 not zero.
  EXPECT_THAT(
      message("rows: 5\n   cols: 1\n   dt: d\n   data: [ 0.1, -0.2, 1.0e-03, -2.0e-03, 0.05 ]",
              "rows: 8\n   cols: 1\n   dt: d\n   data: [ 0.1, -0.2, 0, 0, 0.05, 0.3, 0, 0 ]"),
      HasSubstr(":12: expected key distortion_coefficients with k1 k2 p1 p2 k3 only "
                "(any further coefficient 0: the camera model is radial-tangential), "
                "found coefficient 6 = 0.3"));
  EXPECT_THAT(message("0., 0., 1. ]", "0., 1. ]"),
              HasSubstr(":7: expected key camera_matrix (a matrix of 9 numbers: data), found 8 "
                        "numbers"));
  EXPECT_THAT(message("5.2e+02, 0.,", "5.2e+02, 0.5,"),
              HasSubstr(":7: expected key camera_matrix = [fx 0 cx; 0 fy cy; 0 0 1] with fx, fy > "
                        "0 and zero skew, found [520 0.5 319.5; 0 521 239.5; 0 0 1]"));
  EXPECT_THAT(message("image_height: 480\n", ""),
              HasSubstr("expected key image_height (a number), found no such key"));
  EXPECT_THAT(message("flags: 0\n", "distortion_model: equidistant\n"),
              HasSubstr(":6: expected key distortion_model plumb_bob (radial-tangential, "
                        "OpenCV's model), found \"equidistant\""));
}

TEST_F(DatasetIoTest, ReadCameraYamlNonNumericValueNamesKeyAndLine) {
  std::string text = kOrbSlamCamera;
  text.replace(text.find("516.469215"), std::string("516.469215").size(), "fivehundred");
  const std::string path = write("camera.yaml", text);
  EXPECT_EQ(errorMessage<ParseError>([&] { readCameraYaml(path); }),
            "ParseError: " + path + ":5: expected key Camera.fy (a number), found \"fivehundred\"");
}

TEST_F(DatasetIoTest, ReadCameraYamlOutOfRangeValueNamesKeyAndLine) {
  std::string text = kOrbSlamCamera;
  text.replace(text.find("517.306408"), std::string("517.306408").size(), "-500");
  const std::string path = write("camera.yaml", text);
  EXPECT_EQ(errorMessage<ParseError>([&] { readCameraYaml(path); }),
            "ParseError: " + path + ":4: expected key Camera.fx > 0, found -500");

  text = kOrbSlamCamera;
  text.replace(text.find("height: 480"), std::string("height: 480").size(), "height: 479.5");
  const std::string fractional = write("fractional.yaml", text);
  EXPECT_EQ(errorMessage<ParseError>([&] { readCameraYaml(fractional); }),
            "ParseError: " + fractional +
                ":16: expected key Camera.height (a positive whole number of pixels), found 479.5");
}

TEST_F(DatasetIoTest, ReadCameraYamlMalformedYamlCarriesOpenCvLine) {
  // The bad line is the file's line 3 with and without a header: our own directive must not
  // shift OpenCV's line numbers.
  for (const std::string text : {"%YAML:1.0\nCamera.fx: 500\n\tCamera.fy: 2\nCamera.cx: 3\n",
                                 "# no header\nCamera.fx: 500\n\tCamera.fy: 2\nCamera.cx: 3\n"}) {
    const std::string path = write("camera.yaml", text);
    const std::string message = errorMessage<ParseError>([&] { readCameraYaml(path); });
    EXPECT_THAT(message, HasSubstr("ParseError: " + path + ":3: expected OpenCV FileStorage YAML"))
        << text;
    EXPECT_THAT(message, HasSubstr("OpenCV YAML parser")) << text;
  }
}

TEST_F(DatasetIoTest, ReadCameraYamlSequenceRootIsParseError) {
  const std::string path = write("camera.yaml", "%YAML:1.0\n- 1\n- 2\n");
  EXPECT_EQ(errorMessage<ParseError>([&] { readCameraYaml(path); }),
            "ParseError: " + path + ": expected a YAML mapping of Camera.* keys, found a sequence");
}

TEST_F(DatasetIoTest, WriteCameraYamlRoundTripsExactly) {
  // Values with no short decimal form, and an exponent, which OpenCV's parser must accept.
  CameraIntrinsics intrinsics;
  intrinsics.fx = 517.306408 + 1.0 / 3.0;
  intrinsics.k1 = 0.262383;
  intrinsics.k2 = -0.953104;
  intrinsics.p1 = -0.005358;
  intrinsics.p2 = 1e-7;
  intrinsics.k3 = 1.163314;
  intrinsics.width = 641;
  intrinsics.height = 479;
  const std::string path = (folder_ / "camera.yaml").string();
  writeCameraYaml(path, Camera(intrinsics));
  testing::expectSameIntrinsics(readCameraYaml(path).intrinsics(), intrinsics);
  EXPECT_THAT(read(path), HasSubstr("%YAML:1.0\n"));
}

TEST_F(DatasetIoTest, WriteCameraYamlToMissingFolderIsIoError) {
  const std::string path = (folder_ / "no_such_folder" / "camera.yaml").string();
  EXPECT_EQ(errorMessage<IoError>([&] { writeCameraYaml(path, Camera(CameraIntrinsics{})); }),
            "IoError: " + path + ": cannot open for writing");
}

// ---------------------------------------------------------------------------------------------
// Images

TEST_F(DatasetIoTest, WriteImageListRoundTripsWithRelativePaths) {
  const std::string path = (folder_ / "rgb.txt").string();
  writeImageList(path, {{0.0, "rgb/000000.png"}, {1.0 / 30.0, "rgb/000001.png"}});
  const std::vector<ImageEntry> entries = readImageList(path);
  ASSERT_EQ(entries.size(), 2u);
  EXPECT_EQ(entries[0].timestamp, 0.0);
  EXPECT_EQ(entries[1].timestamp, 0.033333);  // 6 decimals, as writeTrajectory
  EXPECT_EQ(entries[1].path, (folder_ / "rgb/000001.png").string());
  EXPECT_THROW(writeImageList(path, {{0.0, "a b.png"}}), CheckError);
}

TEST_F(DatasetIoTest, ImageWriteReadRoundTripsAndErrorsNameThePath) {
  cv::Mat image(4, 5, CV_8UC3, cv::Scalar(10, 20, 30));
  image.at<cv::Vec3b>(1, 2) = cv::Vec3b(200, 100, 0);
  const std::string path = (folder_ / "image.png").string();
  writeImage(path, image);
  EXPECT_EQ(cv::norm(readColorImage(path), image, cv::NORM_INF), 0.0);

  const std::string missing = (folder_ / "missing.png").string();
  EXPECT_EQ(errorMessage<IoError>([&] { readColorImage(missing); }),
            "IoError: " + missing + ": no such file");
  const std::string text = write("not_an_image.png", "hello");
  EXPECT_THAT(errorMessage<IoError>([&] { readColorImage(text); }),
              HasSubstr("IoError: " + text + ": cannot decode as an image"));
  const std::string unwritable = (folder_ / "no_such_folder" / "image.png").string();
  EXPECT_THAT(errorMessage<IoError>([&] { writeImage(unwritable, image); }),
              HasSubstr("IoError: " + unwritable + ": cannot write the image"));
}

}  // namespace
}  // namespace curvesfm
