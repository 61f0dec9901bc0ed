// `curvesfm run` end to end: the real executable on small datasets written into a temp folder,
// its messages for bad input (one line naming the file, and the line where there is one), exit
// codes and the outputs of a short successful run.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/dataset_io.h"
#include "core/parallel.h"
#include "sim/planar_scene.h"
#include "test/apps/run_command_fixture.h"
#include "test/support/run_executable.h"

namespace curvesfm {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

using testing::CommandResult;
using testing::readReport;
using testing::ringsTexture;
using testing::RunCommandTest;
using testing::runCurvesfm;

TEST_F(RunCommandTest, AFolderInNoKnownLayoutSaysWhatWasLookedFor) {
  writeTinyDataset();
  std::filesystem::remove(path("rgb.txt"));
  const CommandResult result = run();
  expectOneLineError(result, "IoError: " + folder_.string() + ": no known dataset layout");
  EXPECT_THAT(result.output, HasSubstr("rgb.txt (tum)"));
}

TEST_F(RunCommandTest, ATumFolderWithoutItsImageListNamesIt) {
  writeTinyDataset();
  std::filesystem::remove(path("rgb.txt"));
  expectOneLineError(run("--layout tum"), "IoError: " + path("rgb.txt") + ": cannot open");
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
  EXPECT_THAT(result.output, HasSubstr("images of " + folder_.string()));
  EXPECT_THAT(result.output, HasSubstr("none of its 2 poses"));
}

TEST_F(RunCommandTest, FrontendPosesMissingAnImageNameTheFileAndTheImage) {
  writeTinyDataset();
  std::ofstream(path("frontend.txt")) << "1.0 0 0 0 0 0 0 1\n1.1 0 0 0 0 0 0 1\n";
  expectOneLineError(run("--diagnose-frontend-poses " + path("frontend.txt")),
                     "IoError: " + path("frontend.txt") +
                         ": has no pose within --max-dt of image " + path("rgb/2.png"));
}

TEST_F(RunCommandTest, FrontendPosesNeedGivenInitialPoses) {
  writeTinyDataset();
  std::filesystem::remove(path("init_poses.txt"));
  const CommandResult result = run("--diagnose-frontend-poses " + path("frontend.txt"));
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_THAT(result.output,
              HasSubstr("InvalidOptions: --diagnose-frontend-poses = " + path("frontend.txt") +
                        ": needs initial poses in the same frame"));
  EXPECT_FALSE(std::filesystem::exists(path("out")));
}

TEST_F(RunCommandTest, WithoutInitialPosesTheInitialiserRunsAndSaysWhyItFoundNone) {
  writeTinyDataset();  // Three flat 8x8 images: no texture, no tracks.
  std::filesystem::remove(path("init_poses.txt"));
  const CommandResult result = run();
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_THAT(result.output, HasSubstr("running the point initialiser on the 3 images first"));
  EXPECT_THAT(result.output, HasSubstr("init: 0 of 3 frames registered"));
  EXPECT_THAT(result.output, HasSubstr("run: the initialiser registered 0 frames: nothing to "
                                       "refine (no initial pair"));
  EXPECT_FALSE(std::filesystem::exists(path("out")));
}

TEST_F(RunCommandTest, BadOptionsAreUsageErrors) {
  writeTinyDataset();
  CommandResult result = run("--edges-sobel-aperture 4");
  EXPECT_EQ(result.exit_code, 2);
  // Range errors name the flag the user typed, then the field it sets.
  EXPECT_THAT(result.output, StartsWith("InvalidOptions: --edges-sobel-aperture = 4: must be 3 or "
                                        "5 (EdgeDetectorOptions.sobel_aperture)"));
  result = run("--reassociation-rounds -1");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("--reassociation-rounds = -1: >= 0 "
                                       "(PipelineOptions.reassociation_rounds)"));
  result = run("--extend-max-angle 0");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(
      result.output,
      HasSubstr("--extend-max-angle = 0: in (0, 180] (CurveExtensionOptions.max_angle_deg)"));
  result = run("--ba-motion-prior-translation -0.1");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output,
              HasSubstr("--ba-motion-prior-translation = -0.1: must be > 0 and finite "
                        "(CurveBundleAdjustmentOptions.motion_prior_translation_sigma_rel)"));
  result = run("--ba-start-prior-centre 0");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output,
              HasSubstr("--ba-start-prior-centre = 0: must be > 0 and finite "
                        "(CurveBundleAdjustmentOptions.start_prior_centre_sigma_rel)"));
  result = run("--start-model-max-variogram-growth -1");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output,
              HasSubstr("--start-model-max-variogram-growth = -1: must be > 0 and finite "
                        "(StartModelOptions.max_variogram_growth)"));
  // Unlike --reassociation-rounds, the start model's limit takes -1 (none) but nothing below.
  result = run("--start-model-reassociation-rounds -2");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("--start-model-reassociation-rounds = -2: -1 or in [0, 100] "
                                       "(StartModelOptions.reassociation_rounds)"));
  // The same struct in two places: the error names the place's flag.
  result = run("--global-ba-max-rounds 0");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("--global-ba-max-rounds = 0"));
  result = run("--track-max-iterations -1");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("--track-max-iterations = -1"));
  result = run("--progress-interval -1");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("progress-interval = -1: finite and >= 0"));
  result = run("--export-min-epipolar-angle 90");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("export-min-epipolar-angle = 90: in [0, 90)"));
  result = run("--relift-passes -1");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("relift-passes = -1: in [0, 100]"));
  result = run("--sanity-min-epipolar-angle -1");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("--sanity-min-epipolar-angle = -1: in [0, 90) "
                                       "(SanityOptions.min_epipolar_angle_deg)"));
  result = run("--sanity-extent-margin -1");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("--sanity-extent-margin = -1: must be >= 0 and finite "
                                       "(SanityOptions.extent_margin)"));
  result = run("--local-ba-strategy sideways");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("--local-ba-strategy"));
  result = run("--overlays --overlay-colour-by length");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("--overlay-colour-by"));
  EXPECT_THAT(result.output, HasSubstr("\"length\": expected one of none, residual, track, pull"));
  result = run("--images-ahead sometimes");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("--images-ahead"));
  EXPECT_EQ(runCurvesfm("run --out " + path("out")).exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(path("out")));
}

TEST_F(RunCommandTest, OverlaysColourTheCurvesAndDrawTheWorstOnesUnderTheirDocumentedNames) {
  const std::string out = path("planar_out");
  // As many solver threads as cores: --images-ahead auto keeps the image stage on the main thread.
  const std::string threads = std::to_string(availableCores());
  const CommandResult result = runCurvesfm(
      "run --dataset " + writeShortPlanarDataset() + " --out " + out +
      " --overlays --overlay-colour-by track --threads " + threads + shortPlanarFlags());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr(", overlays/, worst_curves/)"));
  EXPECT_THAT(result.output, Not(HasSubstr("images ahead:")));
  const nlohmann::json report = readReport(out);
  EXPECT_EQ(report["options"]["overlay"]["colour_by"], "track");
  EXPECT_EQ(report["options"]["images_ahead"], "auto");
  EXPECT_EQ(report["options"]["images_ahead_resolved"], false);
  EXPECT_TRUE(report["heap"].is_string());  // Which one depends on the allocator (sanitizers).
  EXPECT_TRUE(std::filesystem::exists(out + "/overlays/000005.png"));
  // Each worst curve drawn on its worst keyframe, under the name docs/run.md gives, and indexed.
  const nlohmann::json& statistics = report["curve_statistics"];
  ASSERT_FALSE(statistics["highest_residual"].empty());
  std::ifstream index_file(out + "/worst_curves/worst_curves.md");
  const std::string index((std::istreambuf_iterator<char>(index_file)),
                          std::istreambuf_iterator<char>());
  for (const char* ranking : {"residual", "pull"}) {
    const nlohmann::json& worst =
        statistics[std::string(ranking) == "residual" ? "highest_residual" : "most_pull"][0];
    char name[64];
    std::snprintf(name, sizeof(name), "%s_01_curve_%04d_kf_%04d.png", ranking,
                  worst["curve"].get<int>(), worst["worst_keyframe"].get<int>());
    EXPECT_TRUE(std::filesystem::exists(out + "/worst_curves/" + name)) << name;
    EXPECT_THAT(index, HasSubstr(std::string("[") + name + "](" + name + ")"));
  }
  EXPECT_EQ(report["counts"]["worst_curve_images"].get<std::size_t>(),
            statistics["highest_residual"].size() + statistics["most_pull"].size());
}

}  // namespace
}  // namespace curvesfm
