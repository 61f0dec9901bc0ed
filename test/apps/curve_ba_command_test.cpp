#include "apps/curve_ba_command.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "apps/cli_options.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

// The command as main wires it: last value wins, --config expanded before the user's flags.
class CurveBaCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    app_.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    command_ = std::make_unique<CurveBaCommand>(&app_);
    folder_ = std::filesystem::path(::testing::TempDir()) /
              ("curve_ba_command_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(folder_);
  }

  void parse(std::vector<std::string> args) {
    args.insert(args.begin(), "curve-ba");
    parseCommandLine(&app_, args);
  }
  // The one-line message a bad command line ends in.
  std::string messageOf(const std::vector<std::string>& args) {
    try {
      parse(args);
      command_->validate();
    } catch (const CLI::ParseError& e) {
      return e.what();
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  }
  std::string write(const std::string& name, const std::string& text) {
    const std::string path = (folder_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  // Runs the parsed command with --report and returns the report.
  nlohmann::json runWithReport(std::vector<std::string> args) {
    const std::string report = (folder_ / "report.json").string();
    args.insert(args.end(), {"--report", report});
    parse(args);
    EXPECT_EQ(command_->run(), 0);
    std::ifstream in(report);
    return nlohmann::json::parse(in);
  }

  CLI::App app_;
  std::unique_ptr<CurveBaCommand> command_;
  std::filesystem::path folder_;
};

TEST_F(CurveBaCommandTest, ConfigFileSetsEnumsAndBoolsAndFlagsWin) {
  const std::string config = write("curve-ba.yaml",
                                   "strategy: alternating\n"
                                   "camera-path: forward_walk\n"
                                   "subpixel-edges: false\n"
                                   "kernel: cauchy\n"
                                   "lambda1: 7\n"
                                   "keyframes: 3\n"
                                   "curves: 2\n"
                                   "max-iterations: 2\n"
                                   "max-rounds: 1\n");
  const nlohmann::json report = runWithReport({"--config", config, "--lambda1", "9"});
  const nlohmann::json& options = report["options"];
  EXPECT_EQ(options["scheduler"]["strategy"], "alternating");
  EXPECT_EQ(options["scene"]["camera_path"], "forward_walk");
  EXPECT_EQ(options["bundle_adjustment"]["use_subpixel_edges"], false);
  EXPECT_EQ(options["bundle_adjustment"]["kernel"], "cauchy");
  EXPECT_EQ(options["bundle_adjustment"]["lambda1"], 9.0);  // the flag beats the file
  EXPECT_EQ(options["scene"]["num_keyframes"], 3);
  EXPECT_EQ(report["config"]["lambda1"], "9");
  EXPECT_EQ(report["config"]["subpixel-edges"], "false");
}

TEST_F(CurveBaCommandTest, UnknownEnumValueNamesTheFlagAndTheAcceptedNames) {
  const std::string flag = messageOf({"--strategy", "joinnt"});
  EXPECT_NE(flag.find("--strategy"), std::string::npos) << flag;
  EXPECT_NE(flag.find("\"joinnt\""), std::string::npos) << flag;
  EXPECT_NE(flag.find("joint, alternating, inner_iterations"), std::string::npos) << flag;

  const std::string file = messageOf({"--config", write("bad.yaml", "curve-kind: spiral\n")});
  EXPECT_NE(file.find("--curve-kind"), std::string::npos) << file;
  EXPECT_NE(file.find("line, arc, helix, mixed"), std::string::npos) << file;
}

TEST_F(CurveBaCommandTest, BadBoolAndOutOfRangeValuesAreRejected) {
  const std::string boolean = messageOf({"--fix-scale", "maybe"});
  EXPECT_NE(boolean.find("--fix-scale"), std::string::npos) << boolean;
  EXPECT_NE(boolean.find("'maybe'"), std::string::npos) << boolean;
  const std::string range = messageOf({"--lambda2", "-1"});
  EXPECT_EQ(range.rfind("InvalidOptions: ", 0), 0u) << range;
  EXPECT_NE(range.find("lambda2"), std::string::npos) << range;
}

TEST_F(CurveBaCommandTest, TinyRunLowersTheAteAndEchoesTheConfiguration) {
  const nlohmann::json report =
      runWithReport({"--keyframes", "8", "--curves", "8", "--max-iterations", "30", "--lambda1",
                     "150", "--lambda2", "2", "--kernel", "cauchy", "--strategy", "joint"});
  const nlohmann::json& config = report["config"];
  EXPECT_EQ(config["lambda1"], "150");
  EXPECT_EQ(config["lambda2"], "2");
  EXPECT_EQ(config["kernel"], "cauchy");
  EXPECT_EQ(config["strategy"], "joint");
  EXPECT_EQ(report["options"]["bundle_adjustment"]["lambda2"], 2.0);
  EXPECT_EQ(report["scene"]["keyframes"], 8);

  // Measured (seed 42): ATE 30 -> 1.9 mm.
  const double before = report["before"]["errors"]["camera_ate_sim3_m"];
  const double after = report["after"]["errors"]["camera_ate_sim3_m"];
  EXPECT_LT(after, 0.5 * before);
  EXPECT_GT(report["after"]["samples"]["on_field"], 0);
  EXPECT_TRUE(report["after"]["cost_by_type"].contains("curve_reprojection"));
  EXPECT_FALSE(report["schedule"]["stop_reason"].get<std::string>().empty());
  EXPECT_EQ(report["schedule"]["rounds"].size(), 1u);
}

}  // namespace
}  // namespace curvesfm
