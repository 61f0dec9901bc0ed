#pragma once

// The fixture of the `curvesfm run` tests: a temp folder per process, tiny and planar datasets
// written into it, and the executable run on them (test/support/run_executable.h).
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
namespace testing {

// The report.json a command wrote into `out_dir`.
inline nlohmann::json readReport(const std::string& out_dir) {
  std::ifstream file(out_dir + "/report.json");
  return nlohmann::json::parse(file);
}

// Rings and bars of several colours on a grey ground: curved and straight edges in every
// direction for the planar views.
inline cv::Mat ringsTexture() {
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

  // Six 240 x 180 views of ringsTexture() over a 15 degree arc with perturbed initial poses:
  // a run on it takes well under a second with shortPlanarFlags(). Returns the folder.
  std::string writeShortPlanarDataset() const {
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
    return dataset;
  }
  // Every frame a keyframe, and a short global BA.
  static std::string shortPlanarFlags() {
    return " --map-keyframe-translation 0 --map-keyframe-rotation 0 --global-ba-max-iterations 10";
  }

  CommandResult run(const std::string& extra = "") const {
    return runCurvesfm("run --dataset " + folder_.string() + " --out " + path("out") + " " + extra);
  }

  // A failed run: exit 1, one line that starts with `start`, and no output folder.
  void expectOneLineError(const CommandResult& result, const std::string& start) const {
    EXPECT_EQ(result.exit_code, 1) << result.output;
    EXPECT_THAT(result.output, ::testing::StartsWith(start));
    EXPECT_EQ(std::count(result.output.begin(), result.output.end(), '\n'), 1) << result.output;
    EXPECT_FALSE(std::filesystem::exists(path("out")));
  }

  std::filesystem::path folder_;
};

}  // namespace testing
}  // namespace curvesfm
