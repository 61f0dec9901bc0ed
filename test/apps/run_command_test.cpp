// `curvesfm run` end to end: the real executable on small datasets written into a temp folder,
// its messages for bad input (one line naming the file, and the line where there is one), exit
// codes and the outputs of a short successful run.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/dataset_io.h"
#include "sim/planar_scene.h"
#include "test/support/run_executable.h"

namespace curvesfm {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

using testing::CommandResult;
using testing::runCurvesfm;

// Rings and bars of several colours on a grey ground: curved and straight edges in every
// direction for the planar views.
cv::Mat ringsTexture() {
  cv::Mat texture(240, 320, CV_8UC3, cv::Scalar(120, 120, 120));
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 3; ++j) {
      const cv::Point centre(40 + 80 * i, 40 + 80 * j);
      const cv::Scalar colour(60 * i, 255 - 80 * j, 40 + 50 * (i + j));
      if ((i + j) % 2 == 0) {
        cv::circle(texture, centre, 18 + 4 * j, colour, cv::FILLED, cv::LINE_AA);
      } else {
        cv::rectangle(texture, centre - cv::Point(20, 12), centre + cv::Point(20, 12), colour,
                      cv::FILLED);
      }
    }
  }
  return texture;
}

class RunCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = std::filesystem::path(::testing::TempDir()) /
              ("run_command_test_" + std::to_string(::getpid()));
    std::filesystem::remove_all(folder_);
    std::filesystem::create_directories(folder_ / "rgb");
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  std::string path(const std::string& name) const { return (folder_ / name).string(); }

  // Three 40 x 30 grey frames 0.1 s apart, their list, a camera and initial poses.
  void writeTinyDataset() const {
    CameraIntrinsics k;
    k.fx = k.fy = 40.0;
    k.cx = 19.5;
    k.cy = 14.5;
    k.width = 40;
    k.height = 30;
    writeCameraYaml(path("camera.yaml"), Camera(k));
    std::vector<ImageEntry> images;
    std::vector<StampedPose> poses;
    for (int i = 0; i < 3; ++i) {
      const std::string name = "rgb/" + std::to_string(i) + ".png";
      writeImage(path(name), cv::Mat(30, 40, CV_8UC3, cv::Scalar(100, 100, 100)));
      images.push_back({1.0 + 0.1 * i, name});
      poses.push_back({1.0 + 0.1 * i, Pose3()});
    }
    writeImageList(path("rgb.txt"), images);
    writeTrajectory(path("init_poses.txt"), poses);
  }

  CommandResult run(const std::string& extra = "") const {
    return runCurvesfm("run --dataset " + folder_.string() + " --out " + path("out") + " " + extra);
  }

  // A failed run: exit 1, one line that starts with `start`, and no output folder.
  void expectOneLineError(const CommandResult& result, const std::string& start) const {
    EXPECT_EQ(result.exit_code, 1) << result.output;
    EXPECT_THAT(result.output, StartsWith(start));
    EXPECT_EQ(std::count(result.output.begin(), result.output.end(), '\n'), 1) << result.output;
    EXPECT_FALSE(std::filesystem::exists(path("out")));
  }

  std::filesystem::path folder_;
};

TEST_F(RunCommandTest, MissingRgbListNamesTheFile) {
  writeTinyDataset();
  std::filesystem::remove(path("rgb.txt"));
  expectOneLineError(run(), "IoError: " + path("rgb.txt") + ": cannot open for reading");
}

TEST_F(RunCommandTest, ImageThatDoesNotLoadNamesTheFile) {
  writeTinyDataset();
  std::ofstream(path("rgb/0.png")) << "not an image";
  expectOneLineError(run(), "IoError: " + path("rgb/0.png") + ": cannot decode as an image");
}

TEST_F(RunCommandTest, MissingImageNamesTheFile) {
  writeTinyDataset();
  std::filesystem::remove(path("rgb/2.png"));
  expectOneLineError(run(), "IoError: " + path("rgb/2.png") + ": no such file");
}

TEST_F(RunCommandTest, CameraWithoutFxNamesTheFileAndTheKey) {
  writeTinyDataset();
  std::ofstream(path("camera.yaml")) << "%YAML:1.0\nCamera.fy: 40\nCamera.cx: 19.5\n"
                                     << "Camera.cy: 14.5\nCamera.width: 40\nCamera.height: 30\n";
  const CommandResult result = run();
  expectOneLineError(result, "ParseError: " + path("camera.yaml") + ":");
  EXPECT_THAT(result.output, HasSubstr("Camera.fx"));
}

TEST_F(RunCommandTest, MalformedInitialPoseLineNamesFileAndLine) {
  writeTinyDataset();
  std::ofstream(path("poses.txt")) << "1.0 0 0 0 0 0 0 1\n1.1 0 0 0 0 0 1\n";
  expectOneLineError(run("--init-poses " + path("poses.txt")),
                     "ParseError: " + path("poses.txt") + ":2: expected 8 fields");
}

TEST_F(RunCommandTest, InitialPosesThatMatchNoImageNameBothFiles) {
  writeTinyDataset();
  std::ofstream(path("poses.txt")) << "50.0 0 0 0 0 0 0 1\n50.1 0 0 0 0 0 0 1\n";
  const CommandResult result = run("--init-poses " + path("poses.txt"));
  expectOneLineError(result, "ParseError: " + path("poses.txt") + ": expected poses within 0.02 s");
  EXPECT_THAT(result.output, HasSubstr(path("rgb.txt")));
  EXPECT_THAT(result.output, HasSubstr("none of its 2 poses"));
}

TEST_F(RunCommandTest, NoInitialPosesSaysHowToPassThem) {
  writeTinyDataset();
  std::filesystem::remove(path("init_poses.txt"));
  const CommandResult result = run();
  expectOneLineError(result, "IoError: " + path("init_poses.txt") + ": no such file");
  EXPECT_THAT(result.output, HasSubstr("automatic initialiser is not available yet"));
  EXPECT_THAT(result.output, HasSubstr("--init-poses FILE"));
}

TEST_F(RunCommandTest, BadOptionsAreUsageErrors) {
  writeTinyDataset();
  CommandResult result = run("--edges-sobel-aperture 4");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("EdgeDetectorOptions.sobel_aperture = 4"));
  result = run("--reassociation-rounds -1");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("PipelineOptions.reassociation_rounds = -1"));
  result = run("--extend-max-angle 0");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("CurveExtensionOptions.max_angle_deg = 0"));
  result = run("--ba-motion-prior-translation -0.1");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output,
              HasSubstr("CurveBundleAdjustmentOptions.motion_prior_translation_sigma_rel"));
  result = run("--local-ba-strategy sideways");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("--local-ba-strategy"));
  EXPECT_EQ(runCurvesfm("run --out " + path("out")).exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(path("out")));
}

// A short orbit over a planar photo, every frame a keyframe: all outputs are written and read
// back, and the configuration written beside them runs again.
TEST_F(RunCommandTest, ShortPlanarRunWritesEveryOutput) {
  PlanarSceneOptions options;
  options.num_frames = 6;
  options.arc_degrees = 15.0;
  options.width = 240;
  options.height = 180;
  options.fx = options.fy = 200.0;
  options.cx = 119.5;
  options.cy = 89.5;
  options.intensity_noise = 0.01;
  options.init_noise_model = InitNoiseModel::kIndependent;
  options.init_noise_translation = 0.005;
  options.init_noise_rotation_deg = 0.2;
  const std::string dataset = path("planar");
  writePlanarDataset(dataset, makePlanarScene(ringsTexture(), options));
  const std::string out = path("planar_out");
  const std::string flags =
      " --map-keyframe-translation 0 --map-keyframe-rotation 0 --global-ba-max-iterations 10";
  const CommandResult result =
      runCurvesfm("run --dataset " + dataset + " --out " + out + " --overlays" + flags);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("frame 1/6 keyframe 0: curves "));
  EXPECT_THAT(result.output, HasSubstr("frame 6/6 keyframe 5: curves "));
  EXPECT_THAT(result.output, HasSubstr("run: 6 frames (0 of 6 images without an initial pose"));
  EXPECT_THAT(result.output, HasSubstr("ATE (sim3) vs " + dataset + "/groundtruth.txt"));
  EXPECT_THAT(result.output, HasSubstr("frontend per keyframe (mean ms): undistort "));

  EXPECT_EQ(readTrajectory(out + "/trajectory.txt").size(), 6u);
  for (const char* name : {"curves.ply", "curves.obj", "config.yaml", "overlays/000005.png"}) {
    EXPECT_TRUE(std::filesystem::exists(out + "/" + name)) << name;
  }
  std::ifstream report_file(out + "/report.json");
  const nlohmann::json report = nlohmann::json::parse(report_file);
  EXPECT_EQ(report["counts"]["keyframes"], 6);
  EXPECT_GT(report["counts"]["curves"].get<int>(), 0);
  // Every final curve was started once; extensions add none.
  EXPECT_GE(report["counts"]["curves_started"].get<int>(), report["counts"]["curves"].get<int>());
  EXPECT_GE(report["counts"]["curves_extended"].get<int>(), 0);
  EXPECT_EQ(report["frames"].size(), 6u);
  EXPECT_EQ(report["options"]["pipeline"]["local_ba"]["strategy"], "alternating");
  EXPECT_EQ(report["options"]["pipeline"]["global_ba"]["optimizer"]["max_iterations"], 10);
  EXPECT_EQ(report["options"]["pipeline"]["map"]["min_keyframe_translation"], 0.0);
  EXPECT_TRUE(report["global_ba"].contains("rounds"));
  EXPECT_EQ(report["options"]["pipeline"]["pipeline"]["reassociation_rounds"], 3);
  ASSERT_TRUE(report["reassociation"].is_array());
  for (const auto& round : report["reassociation"]) {
    EXPECT_GT(round["added_observations"].get<int>(), 0);
    EXPECT_TRUE(round["global_ba"].contains("rounds"));
  }
  EXPECT_TRUE(report["frames"][5]["rejected_segments"].contains("edge_distance"));
  EXPECT_TRUE(report["ate"]["refined_m"].contains("rmse"));
  // What `curvesfm report` draws: the initial keyframe poses, the undistorted camera, and the
  // aligned positions of both trajectories beside the ground truth's.
  EXPECT_EQ(readTrajectory(out + "/trajectory_initial.txt").size(), 6u);
  EXPECT_EQ(report["camera"]["width"], 240);
  EXPECT_EQ(report["camera"]["height"], 180);
  EXPECT_NEAR(report["camera"]["fx"].get<double>(), 200.0, 1e-9);
  for (const char* which : {"initial", "refined"}) {
    const nlohmann::json& poses = report["ate"]["per_pose"][which];
    EXPECT_EQ(poses["timestamp"].size(), 6u) << which;
    EXPECT_EQ(poses["error_m"].size(), 6u) << which;
    ASSERT_EQ(poses["aligned_position"].size(), 6u) << which;
    EXPECT_EQ(poses["aligned_position"][0].size(), 3u) << which;
    EXPECT_EQ(poses["ground_truth_position"].size(), 6u) << which;
  }

  // config.yaml holds every flag in force: a rerun from it alone writes the same keyframes.
  const CommandResult again =
      runCurvesfm("run --config " + out + "/config.yaml --out " + path("again"));
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(readTrajectory(path("again") + "/trajectory.txt").size(), 6u);
  EXPECT_TRUE(std::filesystem::exists(path("again") + "/overlays/000005.png"));
}

}  // namespace
}  // namespace curvesfm
