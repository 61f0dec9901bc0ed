// `curvesfm synth planar` and `synth curves` end to end: the real executable, the dataset it writes
// read back with the dataset readers, its messages and exit codes.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <string>

#include "core/curve_map_io.h"
#include "core/dataset_io.h"
#include "test/support/run_executable.h"

namespace curvesfm {
namespace {

using ::testing::HasSubstr;

using testing::CommandResult;
using testing::runCurvesfm;

// What a synth command wrote, read back with the dataset readers.
struct WrittenDataset {
  std::vector<ImageEntry> images;
  std::vector<StampedPose> truth;
  std::vector<StampedPose> initial;
  Camera camera;

  bool hasFrames(std::size_t n) const {
    return images.size() == n && truth.size() == n && initial.size() == n;
  }
};

WrittenDataset readWrittenDataset(const std::string& out) {
  return {readImageList(out + "/rgb.txt"), readTrajectory(out + "/groundtruth.txt"),
          readTrajectory(out + "/init_poses.txt"), readCameraYaml(out + "/camera.yaml")};
}

class SynthCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = std::filesystem::path(::testing::TempDir()) /
              ("synth_command_test_" + std::to_string(::getpid()));
    std::filesystem::remove_all(folder_);
    std::filesystem::create_directories(folder_);
    // A small photo with structure: a colour gradient and a dark disc.
    cv::Mat photo(60, 80, CV_8UC3);
    for (int r = 0; r < photo.rows; ++r) {
      for (int c = 0; c < photo.cols; ++c) {
        const bool disc = (r - 30) * (r - 30) + (c - 40) * (c - 40) < 15 * 15;
        photo.at<cv::Vec3b>(r, c) = disc ? cv::Vec3b(20, 20, 20) : cv::Vec3b(3 * c, 4 * r, 200);
      }
    }
    writeImage(path("photo.png"), photo);
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  std::string path(const std::string& name) const { return (folder_ / name).string(); }

  std::filesystem::path folder_;
};

TEST_F(SynthCommandTest, WritesAThreeFrameDatasetThatTheReadersReadBack) {
  const std::string out = path("dataset");
  const CommandResult result =
      runCurvesfm("synth planar --image " + path("photo.png") + " --out " + out +
                  " --frames 3 --width 160 --height 120 --noise 0.05 --seed 4");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("synth planar: 3 frames of 160x120 px"));
  EXPECT_THAT(result.output, HasSubstr("baseline: "));
  EXPECT_THAT(result.output, HasSubstr("noise: intensity std dev 12.75 levels"));
  EXPECT_THAT(result.output, HasSubstr("written: " + out));

  const WrittenDataset written = readWrittenDataset(out);
  ASSERT_TRUE(written.hasFrames(3u));
  EXPECT_EQ(written.camera.width(), 160);
  EXPECT_EQ(written.camera.height(), 120);
  EXPECT_EQ(written.camera.cx(), 79.5);
  EXPECT_EQ(written.camera.fx(), 525.0);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(written.images[i].timestamp, written.truth[i].timestamp);
    EXPECT_EQ(written.images[i].timestamp, written.initial[i].timestamp);
    const cv::Mat image = readColorImage(written.images[i].path);
    EXPECT_EQ(image.cols, 160);
    EXPECT_EQ(image.rows, 120);
    // Camera-to-world: the translation is the camera centre, 0.6 m above the plane.
    EXPECT_NEAR(written.truth[i].world_from_cam.translation().z(), 0.6, 1e-9);
    EXPECT_GT((written.initial[i].world_from_cam.translation() -
               written.truth[i].world_from_cam.translation())
                  .norm(),
              0.0);
  }
}

TEST_F(SynthCommandTest, PhotoThatDoesNotLoadIsOneLineNamingTheFileAndExit1) {
  const std::string missing = path("missing.png");
  CommandResult result = runCurvesfm("synth planar --image " + missing + " --out " + path("d"));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_EQ(result.output, "IoError: " + missing + ": no such file\n");

  const std::string text = path("text.png");
  std::ofstream(text) << "not an image";
  result = runCurvesfm("synth planar --image " + text + " --out " + path("d"));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.output, HasSubstr("IoError: " + text + ": cannot decode as an image"));
  EXPECT_FALSE(std::filesystem::exists(path("d")));
}

TEST_F(SynthCommandTest, BadValuesAreUsageErrorsNamingTheOption) {
  const std::string flags = "synth planar --image " + path("photo.png") + " --out " + path("d");
  CommandResult result = runCurvesfm(flags + " --noise 5");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("--noise = 5: must be in [0, 1] (a fraction of 255) "
                                       "(PlanarSceneOptions.intensity_noise)"));
  result = runCurvesfm(flags + " --frames 1");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output,
              HasSubstr("--frames = 1: must be >= 2 (PlanarSceneOptions.num_frames)"));
  result = runCurvesfm(flags + " --frames 100000");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("--frames = 100000: must be <= 4660 "));
  result = runCurvesfm(flags + " --init-noise-model gaussian");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("expected one of independent, drift"));
  result = runCurvesfm(flags + " --frames many");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("--frames"));
  result = runCurvesfm("synth planar --image " + path("photo.png"));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("--out is required"));
  EXPECT_EQ(runCurvesfm("synth").exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(path("d")));
}

TEST_F(SynthCommandTest, ConfigFileSuppliesEveryFlagAndTheCommandLineWins) {
  const std::string config = path("planar.yaml");
  std::ofstream(config) << "image: " << path("photo.png") << "\nout: " << path("from_config")
                        << "\nframes: 2\nwidth: 80\nheight: 60\n";
  const CommandResult result = runCurvesfm("synth planar --config " + config + " --frames 3");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(readImageList(path("from_config") + "/rgb.txt").size(), 3u);
  EXPECT_EQ(readCameraYaml(path("from_config") + "/camera.yaml").width(), 80);

  std::ofstream(config) << "frames: 2\nframe: 3\n";
  const CommandResult bad = runCurvesfm("synth planar --config " + config);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_THAT(bad.output, HasSubstr(config + ":2: expected a flag of 'curvesfm synth planar'"));
}

TEST_F(SynthCommandTest, CurvesWritesTheSequenceAndItsTrueCurves) {
  const std::string out = path("room");
  const CommandResult result =
      runCurvesfm("synth curves --out " + out + " --keyframes 4 --curves 5 --seed 3");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("synth curves: 4 frames of 640x480 px"));
  EXPECT_THAT(result.output, HasSubstr("path: orbit of radius 3.000 m"));
  EXPECT_THAT(result.output, HasSubstr("curves: 5 (15 segments, mixed)"));

  const WrittenDataset written = readWrittenDataset(out);
  ASSERT_TRUE(written.hasFrames(4u));
  EXPECT_EQ(written.camera.intrinsics().k1, -0.05);  // The scene's distortion reaches the reader.
  EXPECT_EQ(readColorImage(written.images[3].path).cols, 640);
  // Orbit cameras 3 m from the room centre; the first start pose is the truth (the gauge).
  EXPECT_NEAR(written.truth[2].world_from_cam.translation().norm(), 3.0, 0.35);
  EXPECT_EQ(written.initial[0].world_from_cam.translation(),
            written.truth[0].world_from_cam.translation());
  EXPECT_GT((written.initial[2].world_from_cam.translation() -
             written.truth[2].world_from_cam.translation())
                .norm(),
            0.0);
  EXPECT_EQ(readCurveMap(out + "/gt_curves.obj").size(), 5u);

  const CommandResult bad = runCurvesfm("synth curves --out " + out + " --keyframes 1");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_THAT(bad.output, HasSubstr("--keyframes = 1: must be >= 2"));
  const CommandResult none = runCurvesfm("synth curves --out " + path("bare") +
                                         " --keyframes 2 --curves 2 --init-poses false");
  ASSERT_EQ(none.exit_code, 0) << none.output;
  EXPECT_FALSE(std::filesystem::exists(path("bare") + "/init_poses.txt"));
}

}  // namespace
}  // namespace curvesfm
