#include "core/image_sequence.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <opencv2/core.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.h"
#include "test/support/cameras.h"
#include "test/support/temp_folder.h"

namespace curvesfm {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// Each test writes a tiny dataset (8 x 6 px images) into its own temporary folder.
class ImageSequenceTest : public testing::TempFolderTest {
 protected:
  void image(const std::string& name, int width = 8, int height = 6) const {
    fs::create_directories(fs::path(path(name)).parent_path());
    writeImage(path(name), cv::Mat(height, width, CV_8UC3, cv::Scalar(90, 90, 90)));
  }
  ImageSequence load(DatasetLayout layout = DatasetLayout::kAuto,
                     const std::string& camera = "") const {
    ImageSequenceOptions options;
    options.layout = layout;
    options.camera = camera;
    return loadImageSequence(dir_.string(), options);
  }
};

// A camera at centre c looking along +z after rotating by `angle` about y.
Pose3 worldFromCam(double angle, const Eigen::Vector3d& c) {
  return Pose3(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix(), c);
}

std::string numbers(const Eigen::MatrixXd& m) {
  std::ostringstream out;
  out << std::setprecision(17);
  for (int r = 0; r < m.rows(); ++r) {
    for (int c = 0; c < m.cols(); ++c) out << (c ? " " : "") << m(r, c);
    out << "\n";
  }
  return out.str();
}

Eigen::Matrix3d testK() {
  Eigen::Matrix3d K;
  K << 10.0, 0.0, 3.5, 0.0, 11.0, 2.5, 0.0, 0.0, 1.0;
  return K;
}

void expectPoseNear(const Pose3& a, const Pose3& b) {
  EXPECT_LT((a.translation() - b.translation()).norm(), 1e-9);
  EXPECT_LT(a.rotation().angularDistance(b.rotation()), 1e-9);
}

// --- TUM ---------------------------------------------------------------------------------------

TEST_F(ImageSequenceTest, TumReadsImagesCameraAndGroundTruth) {
  image("rgb/a.png");
  image("rgb/b.png");
  write("rgb.txt", "# color\n1.5 rgb/a.png\n1.6 rgb/b.png\n");
  write("groundtruth.txt", "1.5 0 0 0 0 0 0 1\n1.55 1 0 0 0 0 0 1\n1.6 2 0 0 0 0 0 1\n");
  CameraIntrinsics k;
  k.width = 8;
  k.height = 6;
  k.fx = 9.0;
  writeCameraYaml(path("camera.yaml"), Camera(k));
  const ImageSequence s = load();
  EXPECT_EQ(s.layout, "tum");
  ASSERT_EQ(s.images.size(), 2u);
  EXPECT_EQ(s.images[1].timestamp, 1.6);
  EXPECT_EQ(s.images[1].image_path, path("rgb/b.png"));
  EXPECT_EQ(s.images[1].name, "b.png");
  EXPECT_EQ(s.camera.fx(), 9.0);
  EXPECT_EQ(s.camera_source, path("camera.yaml"));
  EXPECT_EQ(s.ground_truth.size(), 3u);
  EXPECT_EQ(s.ground_truth_source, path("groundtruth.txt"));
}

TEST_F(ImageSequenceTest, CameraStringOverridesAndTakesTheImageSize) {
  image("a.png", 12, 10);
  write("rgb.txt", "0 a.png\n");
  const ImageSequence s = load(DatasetLayout::kTum, "100, 101, 5.5, 4.5, 0.1, 0, 0, 0");
  EXPECT_EQ(s.camera.fy(), 101.0);
  EXPECT_EQ(s.camera.intrinsics().k1, 0.1);
  EXPECT_EQ(s.camera.width(), 12);
  EXPECT_EQ(s.camera.height(), 10);
  EXPECT_EQ(s.camera_source, "--camera");
  EXPECT_TRUE(s.ground_truth.empty());
}

TEST_F(ImageSequenceTest, TumOrPlainFolderWithoutIntrinsicsSaysToPassCamera) {
  image("a.png");
  write("rgb.txt", "0 a.png\n");
  for (const DatasetLayout layout : {DatasetLayout::kTum, DatasetLayout::kImages}) {
    EXPECT_THAT([&] { load(layout); }, ThrowsMessage<IoError>(AllOf(HasSubstr(path("camera.yaml")),
                                                                    HasSubstr("--camera"))));
  }
}

TEST(CameraString, FormattedCameraReadsBackTheSameIntrinsics) {
  const Camera distorted(
      CameraIntrinsics{546.6773, 546.6773, 319.5, 239.5, 0.1 / 3, -0.2, 1e-3, 0.0, 0.0, 640, 480});
  const std::string text = formatCameraString(distorted);
  testing::expectSameIntrinsics(parseCameraString(text, 640, 480).intrinsics(),
                                distorted.intrinsics(), text);
  // A pinhole camera gives its four numbers only.
  EXPECT_EQ(
      formatCameraString(Camera(CameraIntrinsics{525, 525, 320, 240, 0, 0, 0, 0, 0, 640, 480})),
      "525,525,320,240");
}

TEST_F(ImageSequenceTest, MalformedCameraStringNamesTheField) {
  image("a.png");
  write("rgb.txt", "0 a.png\n");
  EXPECT_THAT([&] { load(DatasetLayout::kTum, "100,100,3"); },
              ThrowsMessage<InvalidOptions>(
                  AllOf(HasSubstr("ImageSequenceOptions.camera"), HasSubstr("3 values"))));
  EXPECT_THAT([&] { load(DatasetLayout::kTum, "100,x,3,2"); },
              ThrowsMessage<InvalidOptions>(HasSubstr("value 2 is not a finite number")));
}

TEST_F(ImageSequenceTest, MissingImageIsNamed) {
  image("a.png");
  write("rgb.txt", "0 a.png\n1 gone.png\n");
  EXPECT_THAT([&] { load(DatasetLayout::kTum, "10,10,3,2"); },
              ThrowsMessage<IoError>(HasSubstr(path("gone.png") + ": no such file")));
}

TEST_F(ImageSequenceTest, StrideAndMaxFramesKeepTheDatasetTimes) {
  for (int i = 0; i < 7; ++i) image("f" + std::to_string(i) + ".png");
  std::string list;
  for (int i = 0; i < 7; ++i) list += std::to_string(i) + " f" + std::to_string(i) + ".png\n";
  write("rgb.txt", list);
  ImageSequenceOptions options;
  options.camera = "10,10,3,2";
  options.stride = 2;
  options.max_frames = 3;
  const ImageSequence s = loadImageSequence(dir_.string(), options);
  ASSERT_EQ(s.images.size(), 3u);
  EXPECT_EQ(s.images[2].timestamp, 4.0);
  options.stride = 0;
  EXPECT_THROW(loadImageSequence(dir_.string(), options), InvalidOptions);
}

// --- Detection ---------------------------------------------------------------------------------

TEST_F(ImageSequenceTest, NoLayoutListsWhatWasLookedForAndSubfoldersThatMatch) {
  write("seq/calib.txt", "");
  EXPECT_THAT([&] { load(); }, ThrowsMessage<IoError>(AllOf(
                                   HasSubstr("no known dataset layout"), HasSubstr("rgb.txt (tum)"),
                                   HasSubstr("*_par.txt (middlebury)"),
                                   HasSubstr(path("seq") + " looks like kitti"))));
}

TEST_F(ImageSequenceTest, SeveralLayoutsAskForOne) {
  write("rgb.txt", "0 a.png\n");
  write("calib.txt", "");
  EXPECT_THAT([&] { load(); },
              ThrowsMessage<IoError>(HasSubstr("several dataset layouts (tum, kitti)")));
}

// --- KITTI -------------------------------------------------------------------------------------

std::string kittiP(double tx) {
  return "7.0e+00 0 3.5 " + std::to_string(tx) + " 0 7.0e+00 2.5 0 0 0 1 0\n";
}

std::string kittiPose(const Pose3& world_from_cam) {
  Eigen::Matrix<double, 3, 4> T;
  T << world_from_cam.rotationMatrix(), world_from_cam.translation();
  std::string line = numbers(
      Eigen::Map<Eigen::Matrix<double, 1, 12>>(Eigen::Matrix<double, 4, 3>(T.transpose()).data()));
  return line;
}

TEST_F(ImageSequenceTest, KittiAsCopiedWithImageLAndBareCalibLines) {
  for (int i = 0; i < 3; ++i) image("image_l/00000" + std::to_string(i) + ".png");
  write("calib.txt", kittiP(0) + kittiP(-3.7));
  const Pose3 second = worldFromCam(0.1, {0.0, 0.0, 1.0});
  write("poses.txt", kittiPose(Pose3()) + kittiPose(second) + kittiPose(Pose3()));
  const ImageSequence s = load();
  EXPECT_EQ(s.layout, "kitti");
  ASSERT_EQ(s.images.size(), 3u);
  EXPECT_EQ(s.images[2].timestamp, 2.0);
  EXPECT_EQ(s.camera.fx(), 7.0);
  EXPECT_EQ(s.camera.cy(), 2.5);
  EXPECT_EQ(s.camera.width(), 8);
  ASSERT_EQ(s.ground_truth.size(), 3u);
  expectPoseNear(s.ground_truth[1].world_from_cam, second);
}

TEST_F(ImageSequenceTest, KittiOfficialTreeWithTimesAndTheColourCameraOffset) {
  const std::string seq = "sequences/06/";
  for (int i = 0; i < 2; ++i) image(seq + "image_2/00000" + std::to_string(i) + ".png");
  write(seq + "calib.txt", "P0: " + kittiP(0) + "P1: " + kittiP(-3.7) + "P2: " + kittiP(0.7) +
                               "P3: " + kittiP(-3.0) + "Tr: 1 0 0 0 0 1 0 0 0 0 1 0\n");
  write(seq + "times.txt", "0.0\n0.103\n");
  write("poses/06.txt", kittiPose(Pose3()) + kittiPose(Pose3()));
  const ImageSequence s = loadImageSequence(path(seq), {});
  ASSERT_EQ(s.images.size(), 2u);
  EXPECT_EQ(s.images[1].timestamp, 0.103);
  ASSERT_EQ(s.ground_truth.size(), 2u);
  // P2 = K [I | (0.1, 0, 0)]: camera 2 sits 0.1 to the left of camera 0 (x_cam2 = x_cam0 + 0.1).
  EXPECT_NEAR(s.ground_truth[0].world_from_cam.translation().x(), -0.1, 1e-12);
}

TEST_F(ImageSequenceTest, KittiPoseNonNumberNamesFileAndLine) {
  image("image_0/000000.png");
  write("calib.txt", kittiP(0));
  write("poses.txt", "1 0 0 0 0 1 0 0 0 0 1 zero\n");
  EXPECT_THAT([&] { load(); }, ThrowsMessage<ParseError>(AllOf(HasSubstr(path("poses.txt") + ":1:"),
                                                               HasSubstr("\"zero\""))));
}

TEST_F(ImageSequenceTest, KittiPoseThatIsNoRotationNamesFileAndLine) {
  image("image_0/000000.png");
  write("calib.txt", kittiP(0));
  write("poses.txt", "# c2w\n2 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_THAT([&] { load(); }, ThrowsMessage<ParseError>(AllOf(HasSubstr(path("poses.txt") + ":2:"),
                                                               HasSubstr("rotation"))));
}

TEST_F(ImageSequenceTest, KittiCalibWithoutTheImageFoldersLine) {
  image("image_2/000000.png");
  write("calib.txt", "P0: " + kittiP(0));
  EXPECT_THAT([&] { load(); }, ThrowsMessage<ParseError>(
                                   AllOf(HasSubstr(path("calib.txt")), HasSubstr("a line P2"))));
}

TEST_F(ImageSequenceTest, KittiPoseCountMustMatchTheImages) {
  image("image_0/000000.png");
  image("image_0/000001.png");
  write("calib.txt", kittiP(0));
  write("poses.txt", kittiPose(Pose3()));
  EXPECT_THAT([&] { load(); }, ThrowsMessage<ParseError>(AllOf(HasSubstr(path("poses.txt")),
                                                               HasSubstr("2 poses, one per image"),
                                                               HasSubstr("found 1"))));
}

// --- Middlebury --------------------------------------------------------------------------------

std::string parLine(const std::string& name, const Eigen::Matrix3d& K,
                    const Pose3& cam_from_world) {
  Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R = cam_from_world.rotationMatrix();
  Eigen::Matrix<double, 3, 3, Eigen::RowMajor> Kr = K;
  return name + " " + numbers(Eigen::Map<Eigen::Matrix<double, 1, 9>>(Kr.data())).substr(0) +
         numbers(Eigen::Map<Eigen::Matrix<double, 1, 9>>(R.data())) +
         numbers(cam_from_world.translation().transpose());
}

// The par format is one line per view; numbers() ends each block with a newline.
std::string oneLine(std::string text) {
  for (std::size_t i = 0; i + 1 < text.size(); ++i) {
    if (text[i] == '\n') text[i] = ' ';
  }
  return text;
}

TEST_F(ImageSequenceTest, MiddleburySkipsViewsWithoutImagesAndKeepsTheirIndex) {
  const Pose3 c1 = worldFromCam(0.3, {1.0, 0.0, -2.0}).inverse();
  image("t0001.png");
  image("t0003.png");
  write("t_par.txt", "3\n" + oneLine(parLine("t0001.png", testK(), Pose3())) +
                         oneLine(parLine("t0002.png", testK(), Pose3())) +
                         oneLine(parLine("t0003.png", testK(), c1)));
  const ImageSequence s = load();
  EXPECT_EQ(s.layout, "middlebury");
  ASSERT_EQ(s.images.size(), 2u);
  EXPECT_EQ(s.images[1].timestamp, 2.0);
  EXPECT_EQ(s.camera.fy(), 11.0);
  ASSERT_EQ(s.ground_truth.size(), 2u);
  expectPoseNear(s.ground_truth[1].world_from_cam, c1.inverse());
}

TEST_F(ImageSequenceTest, MiddleburyWrongFieldCountNamesTheLine) {
  image("t0001.png");
  write("t_par.txt", "1\nt0001.png 1 2 3\n");
  EXPECT_THAT([&] { load(); }, ThrowsMessage<ParseError>(AllOf(HasSubstr(path("t_par.txt") + ":2:"),
                                                               HasSubstr("expected 22 fields"),
                                                               HasSubstr("found 4"))));
}

TEST_F(ImageSequenceTest, MiddleburyInconsistentKNamesTheLine) {
  image("t0001.png");
  Eigen::Matrix3d other = testK();
  other(0, 0) = 12.0;
  write("t_par.txt", "2\n" + oneLine(parLine("t0001.png", testK(), Pose3())) +
                         oneLine(parLine("t0002.png", other, Pose3())));
  EXPECT_THAT([&] { load(); },
              ThrowsMessage<ParseError>(AllOf(
                  HasSubstr(path("t_par.txt") + ":3:"),
                  HasSubstr("the same K as " + path("t_par.txt") + ":2"), HasSubstr("fx 12"))));
}

TEST_F(ImageSequenceTest, MiddleburyCountDisagreesWithTheLines) {
  image("t0001.png");
  write("t_par.txt", "2\n" + oneLine(parLine("t0001.png", testK(), Pose3())));
  EXPECT_THAT([&] { load(); }, ThrowsMessage<ParseError>(HasSubstr("expected 2 camera lines")));
}

// --- Projection matrices -----------------------------------------------------------------------

std::string projection(const Eigen::Matrix3d& K, const Pose3& cam_from_world, double scale) {
  Eigen::Matrix<double, 3, 4> Rt;
  Rt << cam_from_world.rotationMatrix(), cam_from_world.translation();
  return numbers(scale * K * Rt);
}

TEST_F(ImageSequenceTest, ProjectionMatricesDecomposeToKAndPose) {
  const Pose3 c0 = worldFromCam(0.2, {0.5, -1.0, -4.0}).inverse();
  const Pose3 c1 = Pose3(Eigen::Quaterniond(0.9, 0.1, -0.3, 0.2).normalized(), {1, 2, 3});
  image("images/midday/m-640x-0001.png");
  image("images/midday/m-640x-0002.png");
  write("cameras/001.projmatrix", projection(testK(), c0, 3.0));
  // P is defined up to scale, a negative one included.
  write("cameras/002.projmatrix", projection(testK(), c1, -0.02));
  const ImageSequence s = load();
  EXPECT_EQ(s.layout, "projection");
  ASSERT_EQ(s.images.size(), 2u);
  EXPECT_EQ(s.images[0].name, "m-640x-0001.png");
  EXPECT_NEAR(s.camera.fx(), 10.0, 1e-9);
  EXPECT_NEAR(s.camera.fy(), 11.0, 1e-9);
  EXPECT_NEAR(s.camera.cx(), 3.5, 1e-9);
  ASSERT_EQ(s.ground_truth.size(), 2u);
  expectPoseNear(s.ground_truth[0].world_from_cam, c0.inverse());
  expectPoseNear(s.ground_truth[1].world_from_cam, c1.inverse());
}

TEST_F(ImageSequenceTest, ProjectionPmvsTxtWithContourHeader) {
  image("visualize/00000000.jpg");
  write("txt/00000000.txt", "CONTOUR\n" + projection(testK(), Pose3(), 1.0));
  const ImageSequence s = load();
  EXPECT_EQ(s.layout, "projection");
  EXPECT_NEAR(s.camera.cy(), 2.5, 1e-9);
}

TEST_F(ImageSequenceTest, ProjectionInconsistentKNamesTheFile) {
  image("images/a.png");
  image("images/b.png");
  Eigen::Matrix3d other = testK();
  other(1, 2) = 4.0;
  write("cameras/001.projmatrix", projection(testK(), Pose3(), 1.0));
  write("cameras/002.projmatrix", projection(other, Pose3(), 1.0));
  EXPECT_THAT([&] { load(); },
              ThrowsMessage<ParseError>(AllOf(HasSubstr(path("cameras/002.projmatrix")),
                                              HasSubstr("the same K"), HasSubstr("cy 4"))));
}

TEST_F(ImageSequenceTest, ProjectionCountsMustAgree) {
  image("images/a.png");
  write("cameras/001.projmatrix", projection(testK(), Pose3(), 1.0));
  write("cameras/002.projmatrix", projection(testK(), Pose3(), 1.0));
  EXPECT_THAT([&] { load(); }, ThrowsMessage<IoError>(HasSubstr("1 images in")));
}

TEST_F(ImageSequenceTest, ProjectionShortFileNamesIt) {
  image("images/a.png");
  write("cameras/001.projmatrix", "1 2 3 4\n5 6 7 8\n");
  EXPECT_THAT([&] { load(); },
              ThrowsMessage<ParseError>(AllOf(HasSubstr(path("cameras/001.projmatrix")),
                                              HasSubstr("3 lines of a 3x4 projection matrix"))));
}

// --- Strecha -----------------------------------------------------------------------------------

std::string strechaCamera(const Pose3& world_from_cam, const std::string& distortion = "0 0 0") {
  return numbers(testK()) + distortion + "\n" + numbers(world_from_cam.rotationMatrix()) +
         numbers(world_from_cam.translation().transpose()) + "8 6\n";
}

TEST_F(ImageSequenceTest, StrechaReadsKAndCameraToWorldWithCentre) {
  const Pose3 second = worldFromCam(-0.4, {-7.0, -7.5, 0.2});
  image("images/0000.jpg");
  image("images/0001.jpg");
  write("images/K.txt", numbers(testK()));
  write("gt_dense_cameras/0000.jpg.camera", strechaCamera(Pose3()));
  write("gt_dense_cameras/0001.jpg.camera", strechaCamera(second));
  const ImageSequence s = load();
  EXPECT_EQ(s.layout, "strecha");
  ASSERT_EQ(s.images.size(), 2u);
  EXPECT_EQ(s.camera.width(), 8);
  EXPECT_EQ(s.camera.fx(), 10.0);
  ASSERT_EQ(s.ground_truth.size(), 2u);
  expectPoseNear(s.ground_truth[1].world_from_cam, second);
}

TEST_F(ImageSequenceTest, StrechaMissingCameraFileIsNamed) {
  image("images/0000.jpg");
  image("images/0001.jpg");
  write("gt_dense_cameras/0000.jpg.camera", strechaCamera(Pose3()));
  EXPECT_THAT(
      [&] { load(); },
      ThrowsMessage<IoError>(HasSubstr(path("gt_dense_cameras/0001.jpg.camera") + ": no such")));
}

TEST_F(ImageSequenceTest, StrechaDistortionIsRejectedAtItsLine) {
  image("images/0000.jpg");
  write("gt_dense_cameras/0000.jpg.camera", strechaCamera(Pose3(), "0.1 0 0"));
  EXPECT_THAT([&] { load(); }, ThrowsMessage<ParseError>(
                                   HasSubstr(path("gt_dense_cameras/0000.jpg.camera") + ":4:")));
}

// --- 7-Scenes ----------------------------------------------------------------------------------

TEST_F(ImageSequenceTest, SevenScenesReadsFramePoses) {
  const Pose3 pose = worldFromCam(0.5, {0.1, 0.2, 0.3});
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = pose.rotationMatrix();
  T.topRightCorner<3, 1>() = pose.translation();
  for (int i = 0; i < 2; ++i) {
    image("frame-00000" + std::to_string(i) + ".color.jpg");
    write("frame-00000" + std::to_string(i) + ".pose.txt", numbers(T));
  }
  write("camera-intrinsics.txt", numbers(testK()));
  const ImageSequence s = load();
  EXPECT_EQ(s.layout, "7scenes");
  ASSERT_EQ(s.ground_truth.size(), 2u);
  expectPoseNear(s.ground_truth[1].world_from_cam, pose);
  EXPECT_EQ(s.camera.cx(), 3.5);
}

// --- A plain folder of images ------------------------------------------------------------------

TEST_F(ImageSequenceTest, PlainFolderReadsImagesInNameOrderWithCameraYamlAndGroundTruth) {
  for (const char* name : {"img10.png", "img2.jpg", "img1.png"}) image(name);
  write("notes.txt", "not an image\n");
  CameraIntrinsics k;
  k.width = 8;
  k.height = 6;
  k.fx = 9.0;
  writeCameraYaml(path("camera.yaml"), Camera(k));
  write("groundtruth.txt", "0 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n2 2 0 0 0 0 0 1\n");
  const ImageSequence s = load();
  EXPECT_EQ(s.layout, "images");
  ASSERT_EQ(s.images.size(), 3u);
  EXPECT_EQ(s.images[0].name, "img1.png");
  EXPECT_EQ(s.images[1].name, "img2.jpg");
  EXPECT_EQ(s.images[2].name, "img10.png");
  EXPECT_EQ(s.images[2].timestamp, 2.0);
  EXPECT_EQ(s.camera.fx(), 9.0);
  EXPECT_EQ(s.camera_source, path("camera.yaml"));
  ASSERT_EQ(s.ground_truth.size(), 3u);
  EXPECT_EQ(s.ground_truth[2].world_from_cam.translation().x(), 2.0);
  EXPECT_EQ(s.ground_truth_source, path("groundtruth.txt"));
}

TEST_F(ImageSequenceTest, PlainImagesMayLieInImagesOrItsOneSubfolder) {
  image("images/b.png");
  image("images/a.png");
  ImageSequence s = load(DatasetLayout::kAuto, "10,10,3,2");
  EXPECT_EQ(s.layout, "images");
  ASSERT_EQ(s.images.size(), 2u);
  EXPECT_EQ(s.images[0].image_path, path("images/a.png"));
  EXPECT_TRUE(s.ground_truth.empty());
  fs::rename(path("images"), path("camera_1"));
  image("images/camera_1/a.png");
  s = load(DatasetLayout::kAuto, "10,10,3,2");
  EXPECT_EQ(s.images[0].image_path, path("images/camera_1/a.png"));
  image("images/camera_2/a.png");
  EXPECT_THAT([&] { load(DatasetLayout::kAuto, "10,10,3,2"); },
              ThrowsMessage<IoError>(
                  AllOf(HasSubstr(path("images")), HasSubstr("several folders of them (camera_1 "
                                                             "camera_2)"))));
}

TEST_F(ImageSequenceTest, PlainFolderNamesAFileThatIsNoImage) {
  image("a.png");
  write("b.png", "not a png\n");
  EXPECT_THAT([&] { load(DatasetLayout::kAuto, "10,10,3,2"); },
              ThrowsMessage<IoError>(HasSubstr(path("b.png") + ": cannot decode")));
}

TEST_F(ImageSequenceTest, OtherLayoutsComeBeforeAPlainFolder) {
  image("a.png");
  write("rgb.txt", "0 a.png\n");
  EXPECT_EQ(load(DatasetLayout::kAuto, "10,10,3,2").layout, "tum");
}

TEST_F(ImageSequenceTest, AFolderWithoutImagesSaysWhereItLooked) {
  write("notes.txt", "not an image\n");
  image("sequence_1/a.png");
  EXPECT_THAT([&] { load(); },
              ThrowsMessage<IoError>(AllOf(HasSubstr("no known dataset layout"),
                                           HasSubstr("image files in it or in images/ (images)"),
                                           HasSubstr(path("sequence_1") + " holds images"))));
  EXPECT_THAT([&] { load(DatasetLayout::kImages, "10,10,3,2"); },
              ThrowsMessage<IoError>(
                  AllOf(HasSubstr(dir_.string() + ": holds no images"), HasSubstr(".png, .jpg"))));
}

TEST_F(ImageSequenceTest, AFallbackCameraServesOnlyADatasetWithoutIntrinsics) {
  image("a.png", 8, 6);
  CameraIntrinsics k;
  k.fx = k.fy = 7.0;
  k.width = 8;
  k.height = 6;
  const FallbackCamera fallback{Camera(k), "the COLMAP model M"};
  const ImageSequence s = loadImageSequence(dir_.string(), {}, fallback);
  EXPECT_EQ(s.camera.fx(), 7.0);
  EXPECT_EQ(s.camera_source, "the COLMAP model M");
  ImageSequenceOptions options;
  options.camera = "10,10,3,2";
  EXPECT_EQ(loadImageSequence(dir_.string(), options, fallback).camera.fx(), 10.0);
  k.fx = 9.0;
  writeCameraYaml(path("camera.yaml"), Camera(k));
  EXPECT_EQ(loadImageSequence(dir_.string(), {}, fallback).camera.fx(), 9.0);
  fs::remove(path("camera.yaml"));
  k.width = 16;
  EXPECT_THAT(
      [&] {
        loadImageSequence(dir_.string(), {}, FallbackCamera{Camera(k), "M"});
      },
      ThrowsMessage<IoError>(HasSubstr(path("a.png") + ": is 8x6 px, the camera of M 16x6")));
}

// --- EuRoC MAV ---------------------------------------------------------------------------------

// cam0's sensor.yaml as EuRoC publishes it (abridged), T_BS a turn of 90 degrees about z and a
// shift.
constexpr char kEurocSensor[] = R"(%YAML:1.0
sensor_type: camera
comment: VI-Sensor cam0 (MT9M034)

# Sensor extrinsics wrt. the body-frame.
T_BS:
  cols: 4
  rows: 4
  data: [0.0, -1.0, 0.0, 0.1,
         1.0, 0.0, 0.0, 0.2,
         0.0, 0.0, 1.0, 0.3,
         0.0, 0.0, 0.0, 1.0]

# Camera specific definitions.
rate_hz: 20
resolution: [8, 6]
camera_model: pinhole
intrinsics: [458.654, 457.296, 367.215, 248.375] #fu, fv, cu, cv
distortion_model: radial-tangential
distortion_coefficients: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]
)";

class EurocSequenceTest : public ImageSequenceTest {
 protected:
  void writeEuroc() const {
    image("mav0/cam0/data/1403636579763555584.png");
    image("mav0/cam0/data/1403636579813555456.png");
    write("mav0/cam0/data.csv",
          "#timestamp [ns],filename\r\n1403636579763555584,1403636579763555584.png\r\n"
          "1403636579813555456,1403636579813555456.png\r\n");
    write("mav0/cam0/sensor.yaml", kEurocSensor);
    write("mav0/state_groundtruth_estimate0/data.csv",
          "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
          "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y, v_RS_R_z, b_w_x, b_w_y, b_w_z, b_a_x, b_a_y, "
          "b_a_z\n"
          "1403636579758555392,4.688319,-1.786938,0.783338,1,0,0,0,0,0,0,0,0,0,0,0,0\n"
          "1403636579763555584,4.688177,-1.786770,0.787350,0,0,0,1,0,0,0,0,0,0,0,0,0\n");
  }
};

TEST_F(EurocSequenceTest, ReadsCameraTimesAndTheCamerasGroundTruthFromAnyLevel) {
  writeEuroc();
  for (const std::string level : {"", "/mav0", "/mav0/cam0", "/mav0/cam0/"}) {
    const ImageSequence s = loadImageSequence(dir_.string() + level, {});
    EXPECT_EQ(s.layout, "euroc") << level;
    ASSERT_EQ(s.images.size(), 2u) << level;
    EXPECT_NEAR(s.images[1].timestamp, 1403636579.813555456, 1e-6) << level;
    EXPECT_EQ(s.images[1].name, "1403636579813555456.png") << level;
    EXPECT_EQ(s.camera.fx(), 458.654) << level;
    EXPECT_EQ(s.camera.intrinsics().p2, 1.76187114e-05) << level;
    EXPECT_EQ(s.camera.width(), 8) << level;
    ASSERT_EQ(s.ground_truth.size(), 2u) << level;
  }
  const ImageSequence s = loadImageSequence(dir_.string(), {});
  // The body turned 180 deg about z at (4.688177, -1.786770, 0.787350); the camera sits at
  // T_BS's (0.1, 0.2, 0.3) in the body, so at that point minus (0.1, 0.2) in x and y, plus 0.3.
  const Pose3& camera = s.ground_truth[1].world_from_cam;
  expectPoseNear(camera,
                 Pose3(Eigen::Matrix3d(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitZ())),
                       Eigen::Vector3d(4.588177, -1.98677, 1.08735)));
  EXPECT_NEAR(s.ground_truth[1].timestamp, 1403636579.763555584, 1e-6);
}

TEST_F(EurocSequenceTest, ABadGroundTruthLineOrExtrinsicsIsNamed) {
  writeEuroc();
  write("mav0/state_groundtruth_estimate0/data.csv", "#t\n1,0,0,0,2,0,0,0\n");
  EXPECT_THAT([&] { load(); }, ThrowsMessage<ParseError>(
                                   HasSubstr(path("mav0/state_groundtruth_estimate0/data.csv") +
                                             ":2: expected a unit "
                                             "quaternion q_RS (w x y z), found norm 2")));
  write("mav0/state_groundtruth_estimate0/data.csv", "#t\n1,0,0,0,1,0,0\n");
  EXPECT_THAT([&] { load(); }, ThrowsMessage<ParseError>(HasSubstr(":2: expected 8 fields")));
  write("mav0/cam0/data.csv", "#timestamp [ns],filename\n1403636579763555584\n");
  EXPECT_THAT([&] { load(); }, ThrowsMessage<ParseError>(HasSubstr(path("mav0/cam0/data.csv") +
                                                                   ":2: expected 2 fields")));
  writeEuroc();
  write("mav0/state_groundtruth_estimate0/data.csv", "#t\n1,0,0,0,1,0,0,0\n");
  std::string sensor = kEurocSensor;
  sensor.replace(sensor.find("0.0, -1.0, 0.0, 0.1"), 19, "0.0, -2.0, 0.0, 0.1");
  write("mav0/cam0/sensor.yaml", sensor);
  EXPECT_THAT([&] { load(); },
              ThrowsMessage<ParseError>(AllOf(HasSubstr(path("mav0/cam0/sensor.yaml")),
                                              HasSubstr("T_BS's 3x3 block to be a rotation"))));
  sensor = kEurocSensor;
  sensor.replace(sensor.find("radial-tangential"), 17, "equidistant");
  write("mav0/cam0/sensor.yaml", sensor);
  EXPECT_THAT([&] { load(); },
              ThrowsMessage<ParseError>(HasSubstr(
                  path("mav0/cam0/sensor.yaml") +
                  ":19: expected key distortion_model "
                  "radial-tangential (the camera model is a pinhole with radial-tangential "
                  "distortion), found \"equidistant\"")));
}

}  // namespace
}  // namespace curvesfm
