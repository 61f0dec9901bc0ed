#include "core/tum_dataset.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "core/errors.h"

namespace curvesfm {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// Three 8 x 6 frames at 1.0, 1.1 and 1.2 s, a camera, and initial poses at `pose_times`.
class TumDatasetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) / ("tum_dataset_test_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "rgb");
    CameraIntrinsics k;
    k.fx = k.fy = 8.0;
    k.cx = 3.5;
    k.cy = 2.5;
    k.width = 8;
    k.height = 6;
    writeCameraYaml(path("camera.yaml"), Camera(k));
    std::vector<ImageEntry> images;
    for (int i = 0; i < 3; ++i) {
      const std::string name = "rgb/" + std::to_string(i) + ".png";
      writeImage(path(name), cv::Mat(6, 8, CV_8UC3, cv::Scalar(90, 90, 90)));
      images.push_back({1.0 + 0.1 * i, name});
    }
    writeImageList(path("rgb.txt"), images);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void writePoses(const std::string& name, const std::vector<double>& times) const {
    std::vector<StampedPose> poses;
    for (double t : times) poses.push_back({t, Pose3()});
    writeTrajectory(path(name), poses);
  }

  fs::path dir_;
};

TEST_F(TumDatasetTest, KeepsTheImagesWithAnInitialPose) {
  writePoses("init_poses.txt", {1.0, 1.2});
  writePoses("groundtruth.txt", {1.0, 1.1, 1.2});
  const TumDataset d = loadTumDataset(dir_.string(), "", 0.02);
  EXPECT_EQ(d.images, 3);
  ASSERT_EQ(d.frames.size(), 2u);
  EXPECT_EQ(d.frames[1].timestamp, 1.2);
  EXPECT_EQ(d.frames[1].image_path, path("rgb/2.png"));
  EXPECT_EQ(d.init_poses_path, path("init_poses.txt"));
  EXPECT_EQ(d.ground_truth.size(), 3u);
  EXPECT_EQ(loadFrameImage(d.frames[0], *d.camera).cols, 8);
}

TEST_F(TumDatasetTest, NoInitialPosesNamesTheFileItLookedFor) {
  EXPECT_THAT([&] { loadTumDataset(dir_.string(), "", 0.02); },
              ::testing::ThrowsMessage<IoError>(HasSubstr(path("init_poses.txt"))));
}

TEST_F(TumDatasetTest, PosesThatMatchNoImageNameBothFiles) {
  writePoses("poses.txt", {5.0, 6.0});
  EXPECT_THAT([&] { loadTumDataset(dir_.string(), path("poses.txt"), 0.02); },
              ::testing::ThrowsMessage<ParseError>(
                  ::testing::AllOf(HasSubstr(path("poses.txt")), HasSubstr(dir_.string()))));
}

// run's initial poses: a file given, else DIR/init_poses.txt, else none (the initialiser's turn);
// a COLMAP model folder is read through colmapPosesForSequence (tested in colmap_model_test).
TEST_F(TumDatasetTest, InitialPosesComeFromTheFileGivenTheDatasetsOwnOrNowhere) {
  ImageSequenceOptions options;
  options.layout = DatasetLayout::kTum;
  const ImageSequence sequence = loadImageSequence(dir_.string(), options);
  std::string source = "stale";
  EXPECT_TRUE(readInitialPoses("", sequence, &source).empty());
  EXPECT_EQ(source, "");
  writePoses("init_poses.txt", {1.0, 1.2});
  EXPECT_EQ(readInitialPoses("", sequence, &source).size(), 2u);
  EXPECT_EQ(source, path("init_poses.txt"));
  writePoses("other.txt", {1.0, 1.1, 1.2});
  const std::vector<StampedPose> poses = readInitialPoses(path("other.txt"), sequence, &source);
  EXPECT_EQ(poses.size(), 3u);
  EXPECT_EQ(source, path("other.txt"));
  EXPECT_EQ(framesWithPoses(sequence, poses, 0.02, source).size(), 3u);
  EXPECT_THROW(readInitialPoses(path("missing.txt"), sequence, &source), IoError);
}

}  // namespace
}  // namespace curvesfm
