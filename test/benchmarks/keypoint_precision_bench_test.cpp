// keypoint_precision_bench end to end on a rendered plane (`curvesfm synth planar`): under the
// true poses its keypoints lie a fraction of a pixel from their epipolar lines; under poses in the
// wrong order they do not; a dataset without ground truth is named in one message.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "core/dataset_io.h"
#include "test/support/run_executable.h"
#include "test/support/textures.h"

namespace curvesfm {
namespace {

using ::testing::HasSubstr;

testing::CommandResult runBench(const std::string& arguments) {
  return testing::runCommand(KEYPOINT_PRECISION_BENCH_EXECUTABLE, arguments);
}

// The value of a `key: value` line of the bench's output; NaN when absent.
double valueOf(const std::string& output, const std::string& key) {
  std::smatch m;
  if (!std::regex_search(output, m, std::regex(key + ": ([-0-9.eE+]+)"))) return std::nan("");
  return std::stod(m[1]);
}

class KeypointPrecisionBenchTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = std::filesystem::path(::testing::TempDir()) /
              ("keypoint_precision_bench_test_" + std::to_string(::getpid()));
    std::filesystem::remove_all(folder_);
    std::filesystem::create_directories(folder_);
    writeImage((folder_ / "photo.png").string(), testing::denseTexture());
    dataset_ = (folder_ / "plane").string();
    const testing::CommandResult synth = testing::runCommand(
        CURVESFM_EXECUTABLE, "synth planar --image " + (folder_ / "photo.png").string() +
                                 " --out " + dataset_ + " --frames 4 --width 320 --height 240");
    ASSERT_EQ(synth.exit_code, 0) << synth.output;
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  std::filesystem::path folder_;
  std::string dataset_;
};

TEST_F(KeypointPrecisionBenchTest, KeypointsLieOnTheTrueEpipolarLinesAndOffWrongOnes) {
  const testing::CommandResult truth = runBench("--dataset " + dataset_ + " --pair-gap 1");
  ASSERT_EQ(truth.exit_code, 0) << truth.output;
  EXPECT_GT(valueOf(truth.output, "matches"), 100.0) << truth.output;
  EXPECT_LT(valueOf(truth.output, "median_epipolar_distance_px"), 0.3) << truth.output;
  EXPECT_THAT(truth.output, HasSubstr("size 2.3-3.2 |"));

  // The same views with their poses in reverse order: their matches no longer fit.
  const std::string path = dataset_ + "/groundtruth.txt";
  std::vector<StampedPose> poses = readTrajectory(path);
  std::vector<StampedPose> reversed = poses;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    reversed[i].world_from_cam = poses[poses.size() - 1 - i].world_from_cam;
  }
  writeTrajectory(path, reversed);
  const testing::CommandResult wrong =
      runBench("--dataset " + dataset_ + " --pair-gap 1 --max-distance 1000");
  ASSERT_EQ(wrong.exit_code, 0) << wrong.output;
  EXPECT_GT(valueOf(wrong.output, "median_epipolar_distance_px"), 2.0) << wrong.output;
}

TEST_F(KeypointPrecisionBenchTest, NamesADatasetWithoutGroundTruth) {
  std::filesystem::remove(dataset_ + "/groundtruth.txt");
  const testing::CommandResult r = runBench("--dataset " + dataset_);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr(dataset_));
  EXPECT_THAT(r.output, HasSubstr("no ground truth"));
}

}  // namespace
}  // namespace curvesfm
