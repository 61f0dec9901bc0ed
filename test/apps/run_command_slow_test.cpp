// `curvesfm run` end to end on a short planar sequence: every output (ctest label "slow").
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "apps/cli/report_json.h"
#include "core/dataset_io.h"
#include "frontend/mapping/start_model.h"
#include "test/apps/run_command_fixture.h"
#include "test/support/run_executable.h"

namespace curvesfm {
namespace {

using ::testing::ContainsRegex;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

using testing::CommandResult;
using testing::readReport;
using testing::RunCommandTest;
using testing::runCurvesfm;

struct RunWithReport {
  CommandResult result;
  nlohmann::json report;
};

// Runs `command --out out_dir`, expects it to succeed and reads its report.json.
RunWithReport runWithReport(const std::string& command, const std::string& out_dir) {
  CommandResult result = runCurvesfm(command + " --out " + out_dir);
  EXPECT_EQ(result.exit_code, 0) << result.output;
  return {result, readReport(out_dir)};
}

TEST_F(RunCommandTest, ShortPlanarRunWritesEveryOutput) {
  const std::string dataset = writeShortPlanarDataset();
  const std::string out = path("planar_out");
  const CommandResult result =
      runCurvesfm("run --dataset " + dataset + " --out " + out + " --overlays" +
                  " --progress-interval 0" + shortPlanarFlags());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  // With no interval, global BA prints a progress line per iteration.
  EXPECT_THAT(result.output, HasSubstr("global BA: iteration 1, cost "));
  EXPECT_THAT(result.output, HasSubstr("frame 1/6 keyframe 0: curves "));
  EXPECT_THAT(result.output, HasSubstr("frame 6/6 keyframe 5: curves "));
  EXPECT_THAT(result.output, HasSubstr("run: 6 frames (0 of 6 images without an initial pose"));
  EXPECT_THAT(result.output, HasSubstr("ATE (sim3) vs " + dataset + "/groundtruth.txt"));
  EXPECT_THAT(result.output, HasSubstr("frontend per keyframe (mean ms): undistort "));
  EXPECT_THAT(result.output, ContainsRegex("\\(image stage [0-9.]+, the rest [0-9.]+\\)"));

  EXPECT_EQ(readTrajectory(out + "/trajectory.txt").size(), 6u);
  for (const char* name :
       {"curves.ply", "curves.obj", "curves.csv", "config.yaml", "overlays/000005.png"}) {
    EXPECT_TRUE(std::filesystem::exists(out + "/" + name)) << name;
  }
  const nlohmann::json report = readReport(out);
  EXPECT_EQ(report["curvesfm"], versionJson());
  EXPECT_EQ(report["options"]["progress_interval_s"], 0.0);
  EXPECT_EQ(report["counts"]["keyframes"], 6);
  EXPECT_GT(report["counts"]["curves"].get<int>(), 0);
  // Every final curve was started once; extensions add none.
  EXPECT_GE(report["counts"]["curves_started"].get<int>(), report["counts"]["curves"].get<int>());
  EXPECT_GE(report["counts"]["curves_extended"].get<int>(), 0);
  // Registrations of map segments in later keyframes, and the rejections, summed over frames.
  int registered = 0, rejected_edge_distance = 0;
  for (const auto& frame : report["frames"]) {
    registered += frame["registered_segments"].get<int>();
    rejected_edge_distance += frame["rejected_segments"]["edge_distance"].get<int>();
  }
  EXPECT_GT(registered, 0);
  EXPECT_EQ(report["counts"]["segments_registered"].get<int>(), registered);
  EXPECT_EQ(report["counts"]["registrations_rejected_edge_distance"].get<int>(),
            rejected_edge_distance);
  EXPECT_GE(report["counts"]["registrations_rejected"].get<int>(), rejected_edge_distance);
  EXPECT_THAT(result.output, HasSubstr(" segment registrations in later keyframes, "));
  EXPECT_EQ(report["frames"].size(), 6u);
  EXPECT_EQ(report["options"]["pipeline"]["local_ba"]["strategy"], "alternating");
  EXPECT_EQ(report["options"]["pipeline"]["global_ba"]["optimizer"]["max_iterations"], 10);
  EXPECT_EQ(report["options"]["pipeline"]["map"]["min_keyframe_translation"], 0.0);
  EXPECT_TRUE(report["global_ba"].contains("rounds"));
  EXPECT_EQ(report["options"]["pipeline"]["reassociation_rounds"], 3);
  ASSERT_TRUE(report["reassociation"].is_array());
  for (const auto& round : report["reassociation"]) {
    // Only the last round may add nothing: it ends the rounds, and after a budgeted global BA
    // (--reassociation-interim-iterations) its own BA still runs to convergence.
    if (&round != &report["reassociation"].back()) {
      EXPECT_GT(round["added_observations"].get<int>(), 0);
    }
    EXPECT_EQ(round["left_to_other_curves"].get<int>(), 0);  // Both checks are off by default.
    EXPECT_TRUE(round["global_ba"].contains("rounds"));
  }
  // The fit the run ends at: the last global BA's costs per factor type.
  const nlohmann::json& last_ba = report["reassociation"].empty()
                                      ? report["global_ba"]
                                      : report["reassociation"].back()["global_ba"];
  nlohmann::json last_costs;
  for (const auto& round : last_ba["rounds"]) {
    if (!round["skipped"].get<bool>()) last_costs = round["summary"]["final_cost_by_type"];
  }
  EXPECT_EQ(report["final_fit"], last_costs);
  EXPECT_GT(report["final_fit"]["curve_reprojection"]["count"].get<int>(), 0);
  EXPECT_THAT(result.output, HasSubstr("fit: curve cost "));
  // How precisely that map's curves fix the centres, from the residuals of the same state.
  const nlohmann::json& precision = report["curve_precision"];
  ASSERT_TRUE(precision.is_object());
  EXPECT_GT(precision["samples"].get<int>(), precision["observations"].get<int>());
  EXPECT_GT(precision["pixel_sigma"].get<double>(), 0.0);
  ASSERT_TRUE(precision["predicted_centre_ate"].is_number());
  EXPECT_GT(precision["predicted_centre_ate"].get<double>(), 0.0);
  if (precision["sample_correlation"].get<double>() > 0.0) {
    EXPECT_GT(precision["predicted_centre_ate_correlated"].get<double>(),
              precision["predicted_centre_ate"].get<double>());
  }
  EXPECT_GE(precision["seconds"].get<double>(), 0.0);
  EXPECT_THAT(result.output, HasSubstr("curves' precision: their edge noise"));
  EXPECT_TRUE(report["frames"][5]["rejected_segments"].contains("edge_distance"));
  // Keyframe 5's local BA refined the curves its window observes.
  EXPECT_GT(report["frames"][5]["local_ba_iterations"].get<int>(), 0);
  EXPECT_TRUE(report["ate"]["refined_m"].contains("rmse"));
  // How far each stage moved the poses, and the curves that pull them most.
  ASSERT_TRUE(report["pose_stages"].is_array());
  EXPECT_EQ(report["pose_stages"].size(), 2 + report["reassociation"].size());
  EXPECT_EQ(report["pose_stages"][0]["stage"], "incremental");
  EXPECT_LT(report["pose_stages"][0]["moved_rmse"].get<double>(), 1e-12);  // Local BA held them.
  EXPECT_THAT(result.output, HasSubstr("poses moved from the start (Sim(3) rmse, pose units): "));
  EXPECT_THAT(result.output, HasSubstr("curves: track median "));
  EXPECT_GE(report["curve_statistics"]["median_track_keyframes"].get<int>(), 2);
  EXPECT_GT(report["curve_statistics"]["median_chord_ratio"].get<double>(), 0.0);
  const double collapsed = report["curve_statistics"]["collapsed_fraction"].get<double>();
  EXPECT_GE(collapsed, 0.0);
  EXPECT_LE(collapsed, 1.0);
  EXPECT_THAT(result.output, HasSubstr(" % collapsed (chords below 0.1 of their lengths"));
  EXPECT_EQ(report["curve_statistics"]["most_pull"].size(),
            std::min<std::size_t>(10, report["counts"]["curves"].get<std::size_t>()));
  // curves.csv lists every curve of the map, its last column saying whether curves.obj holds it.
  std::ifstream csv(out + "/curves.csv");
  int csv_lines = 0;
  int exported = 0;
  for (std::string line; std::getline(csv, line);) {
    if (csv_lines++ == 0) continue;
    exported += line.back() == '1' ? 1 : 0;
  }
  EXPECT_EQ(csv_lines, 1 + report["counts"]["curves"].get<int>());
  EXPECT_EQ(exported, report["counts"]["curves_exported"].get<int>());
  EXPECT_GT(exported, 0);
  std::ifstream obj(out + "/curves.obj");
  int objects = 0;
  for (std::string line; std::getline(obj, line);) objects += line.rfind("o curve_", 0) == 0;
  EXPECT_EQ(objects, exported);
  EXPECT_THAT(result.output, HasSubstr(" curves in curves.obj and curves.ply; "));
  // The sanity checks: the extent, the counts, and each verdict printed as a warning line.
  EXPECT_THAT(result.output, HasSubstr("sanity: scene extent "));
  const nlohmann::json& sanity = report["sanity"];
  EXPECT_GT(sanity["extent"]["diagonal"].get<double>(), 0.0);
  EXPECT_EQ(sanity["counts"]["checked"].get<int>(),
            report["counts"]["curves"].get<int>() + sanity["counts"]["dropped"].get<int>());
  EXPECT_EQ(sanity["implausible_curves"].size(), sanity["counts"]["implausible"].get<size_t>());
  EXPECT_TRUE(sanity["largest_pose_move"].contains("spacings"));
  ASSERT_TRUE(sanity["verdicts"].is_array());
  for (const auto& verdict : sanity["verdicts"]) {
    EXPECT_THAT(result.output, HasSubstr("warning: " + verdict["message"].get<std::string>()));
  }
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

TEST_F(RunCommandTest, AReliftPassLiftsTheMapAtTheRefinedPosesAndStartsBaFromTheInitialOnes) {
  // Every frame is a keyframe. The relift pass's incremental stage works at the first run's
  // refined poses, so its move from the start is the first run's final move; its BA then starts
  // from the initial poses, which trajectory_initial.txt keeps.
  const std::string dataset = writeShortPlanarDataset();
  const std::string flags = shortPlanarFlags() + " --threads 1 --ba-motion-prior false";
  const auto runInto = [&](const std::string& out, const std::string& extra) {
    return runWithReport("run --dataset " + dataset + flags + extra, path(out));
  };
  const auto [first_output, first] = runInto("first", "");
  const auto [relift_output, relift] = runInto("relift", " --relift-passes 1");
  EXPECT_THAT(relift_output.output,
              HasSubstr("relift 1 of 1: lifting the curves again at the refined poses (ATE "));
  EXPECT_EQ(relift["options"]["relift_passes"], 1);

  const nlohmann::json& first_final = first["pose_stages"].back();
  const nlohmann::json& relift_start = relift["pose_stages"].front();
  ASSERT_EQ(relift_start["stage"], "incremental");
  const double moved = first_final["moved_rmse"].get<double>();
  ASSERT_GT(moved, 0.0);
  EXPECT_NEAR(relift_start["moved_rmse"].get<double>(), moved, 1e-6 * moved);
  EXPECT_LT(first["pose_stages"].front()["moved_rmse"].get<double>(), 1e-9 * moved);

  const std::vector<StampedPose> initial = readTrajectory(path("first/trajectory_initial.txt"));
  const std::vector<StampedPose> relift_initial =
      readTrajectory(path("relift/trajectory_initial.txt"));
  ASSERT_EQ(relift_initial.size(), initial.size());
  for (std::size_t i = 0; i < initial.size(); ++i) {
    EXPECT_LT(
        (relift_initial[i].world_from_cam.translation() - initial[i].world_from_cam.translation())
            .norm(),
        1e-9);
  }
}

// Start-model thresholds under which any measured start of the short sequence moves: with
// `max_growth` 1e12 it is read as per pose, with 1e-12 as drifting.
std::string verdictOnAnyStart(const std::string& max_growth) {
  return " --threads 1 --start-model-min-frames 3 --start-model-min-points 6"
         " --start-model-min-rotation 1e-12 --start-model-min-rotation-to-measurement 1e-12"
         " --start-model-max-variogram-growth " +
         max_growth;
}

// A start the images read as off per pose is lifted again once by default. The short sequence is
// too short for a verdict under the defaults, so the test lowers every threshold until any
// measured start is per pose: what it checks is the run's response to that verdict.
TEST_F(RunCommandTest, AStartOffPerPoseIsLiftedAgainOnce) {
  const std::string dataset = writeShortPlanarDataset();
  const std::string flags = shortPlanarFlags() + verdictOnAnyStart("1e12");
  const auto runInto = [&](const std::string& out, const std::string& extra) {
    return runWithReport("run --dataset " + dataset + flags + extra, path(out));
  };
  const auto [output, report] = runInto("per_pose", " --start-model-rotation-prior-sigma-scale 3");
  const nlohmann::json& model = report["start_model"];
  ASSERT_EQ(model["model"], "per_pose") << output.output;
  EXPECT_TRUE(model["switched_to_start_prior"].get<bool>());
  // Each sigma is its own scale times what was measured.
  EXPECT_DOUBLE_EQ(model["start_prior_rotation_sigma_deg"].get<double>(),
                   3.0 * model["rotation_rms_deg"].get<double>());
  EXPECT_DOUBLE_EQ(
      model["start_prior_centre_sigma_spacings"].get<double>(),
      StartModelOptions{}.prior_sigma_scale * model["centre_rms_spacings"].get<double>());
  EXPECT_EQ(report["relift_passes_run"], 1);
  EXPECT_THAT(output.output, HasSubstr("relift 1 of 1: lifting the curves again"));

  const auto [none_output, none] = runInto("no_relift", " --start-model-relift-passes 0");
  EXPECT_EQ(none["relift_passes_run"], 0);
  EXPECT_THAT(none_output.output, Not(HasSubstr("relift 1 of")));
}

// A start read as drifting is tied per pose too unless --start-model-tie-drifting-per-pose false
// leaves it to the motion prior; only a tied start's re-association rounds are limited. As above,
// the thresholds are set so that any measured start of the short sequence is read as drifting.
TEST_F(RunCommandTest, ADriftingStartIsTiedPerPoseUnlessLeftToTheMotionPrior) {
  const std::string dataset = writeShortPlanarDataset();
  const std::string flags = shortPlanarFlags() + verdictOnAnyStart("1e-12") +
                            " --start-model-relift-passes 0 --reassociation-rounds 2" +
                            " --start-model-reassociation-rounds 0";
  const auto runInto = [&](const std::string& out, const std::string& extra) {
    return runWithReport("run --dataset " + dataset + flags + extra, path(out));
  };
  const auto [tied_output, tied] = runInto("tied", "");
  ASSERT_EQ(tied["start_model"]["model"], "drifting") << tied_output.output;
  EXPECT_TRUE(tied["start_model"]["switched_to_start_prior"].get<bool>());
  EXPECT_GT(tied["start_model"]["start_prior_rotation_sigma_deg"].get<double>(), 0.0);
  EXPECT_THAT(tied_output.output, HasSubstr("the BA ties each keyframe to its start"));
  EXPECT_EQ(tied["reassociation_rounds_allowed"], 0);
  EXPECT_TRUE(tied["reassociation"].empty());

  const auto [kept_output, kept] = runInto("kept", " --start-model-tie-drifting-per-pose false");
  ASSERT_EQ(kept["start_model"]["model"], "drifting") << kept_output.output;
  EXPECT_FALSE(kept["start_model"]["switched_to_start_prior"].get<bool>());
  EXPECT_TRUE(kept["start_model"]["start_prior_rotation_sigma_deg"].is_null());
  EXPECT_THAT(kept_output.output, Not(HasSubstr("the BA ties each keyframe to its start")));
  EXPECT_EQ(kept["reassociation_rounds_allowed"], 2);
  EXPECT_FALSE(kept["reassociation"].empty());
}

// The fit checks after global BA: with a residual bound no curve meets, every curve of the global
// map is found implausible for its residual, dropped and counted under its reason, and a run
// left with nothing plausible says so and fails.
TEST_F(RunCommandTest, FitChecksDropCurvesThatDoNotFitTheirViews) {
  const std::string dataset = writeShortPlanarDataset();
  const std::string out = path("fit_out");
  const CommandResult result =
      runCurvesfm("run --dataset " + dataset + " --out " + out + shortPlanarFlags() +
                  " --sanity-max-curve-residual 0.001 --sanity-min-chord-ratio 0.5");
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_THAT(result.output, HasSubstr("was implausible and dropped: nothing plausible"));
  const nlohmann::json report = readReport(out);
  const nlohmann::json& counts = report["sanity"]["counts"];
  EXPECT_GT(counts["checked"].get<int>(), 0);
  EXPECT_EQ(counts["high_residual"].get<int>() + counts["collapsed"].get<int>(),
            counts["checked"].get<int>());
  EXPECT_GT(counts["high_residual"].get<int>(), 0);
  EXPECT_EQ(counts["dropped"], counts["checked"]);
  EXPECT_EQ(report["counts"]["curves"], 0);
  EXPECT_EQ(report["options"]["pipeline"]["sanity"]["max_curve_residual_px"], 0.001);
  EXPECT_THAT(result.output, HasSubstr(" above the residual bound, 0 below the chord-ratio bound, "
                                       "0 along their epipolar planes)"));
  EXPECT_THAT(result.output, HasSubstr(", residual above the bound, dropped after 1 global BA"));
  EXPECT_THAT(result.output, HasSubstr("were implausible (outside the scene's extent"));
}

// What a user of COLMAP has: a bare folder of images and the model COLMAP made of them.
TEST_F(RunCommandTest, APlainImageFolderTakesPosesAndCameraFromACOLMAPModel) {
  const std::string dataset = writeShortPlanarDataset();
  const std::string images = path("plain"), model = path("model");
  std::filesystem::create_directories(images);
  std::filesystem::create_directories(model);
  // COLMAP's pixel centres are at +0.5: the planar camera's 119.5, 89.5 is its 120, 90.
  std::ofstream(model + "/cameras.txt") << "1 PINHOLE 240 180 200 200 120 90\n";
  std::ofstream images_txt(model + "/images.txt");
  const std::vector<ImageEntry> entries = readImageList(dataset + "/rgb.txt");
  const std::vector<StampedPose> poses = readTrajectory(dataset + "/init_poses.txt");
  ASSERT_EQ(entries.size(), poses.size());
  images_txt << std::setprecision(17);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const std::string name = "view" + std::to_string(i) + ".png";
    std::filesystem::copy_file(entries[i].path, images + "/" + name);
    const Pose3 cam_from_world = poses[i].world_from_cam.inverse();
    const Eigen::Quaterniond& q = cam_from_world.rotation();
    const Eigen::Vector3d& t = cam_from_world.translation();
    images_txt << i + 1 << " " << q.w() << " " << q.x() << " " << q.y() << " " << q.z() << " "
               << t.x() << " " << t.y() << " " << t.z() << " 1 " << name << "\n\n";
  }
  images_txt.close();
  const RunWithReport run = runWithReport(
      "run --dataset " + images + " --init-poses " + model + shortPlanarFlags(), path("out"));
  EXPECT_THAT(run.result.output, HasSubstr(images +
                                           " (images layout), 6 of 6 images with an "
                                           "initial pose (" +
                                           model + ")"));
  EXPECT_EQ(run.report["dataset"]["layout"], "images");
  EXPECT_EQ(run.report["dataset"]["camera"], "the COLMAP model " + model);
  EXPECT_EQ(run.report["camera"]["cx"], 119.5);
  EXPECT_EQ(run.report["counts"]["keyframes"], 6);
}

}  // namespace
}  // namespace curvesfm
