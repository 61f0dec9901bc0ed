#pragma once

// The fixture of the `curvesfm curve-ba` tests: the command wired as main wires it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "apps/cli/cli_options.h"
#include "apps/curve_ba_command.h"
#include "core/errors.h"

namespace curvesfm {
namespace testing {

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

}  // namespace testing
}  // namespace curvesfm
