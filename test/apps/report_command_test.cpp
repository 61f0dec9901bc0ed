// `curvesfm report`: its messages and exit codes (the page itself: test/scripts).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "test/support/run_executable.h"

namespace curvesfm {
namespace {

using testing::CommandResult;
using ::testing::HasSubstr;
using testing::runCurvesfm;

TEST(ReportCommandTest, MissingReportJsonNamesItAndExitsWithOne) {
  const std::string dir = (std::filesystem::path(::testing::TempDir()) /
                           ("report_command_test_" + std::to_string(::getpid())))
                              .string();
  std::filesystem::create_directories(dir);
  const CommandResult result = runCurvesfm("report " + dir);
  std::filesystem::remove_all(dir);
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.output, HasSubstr(dir + "/report.json: cannot read"));
  EXPECT_THAT(result.output,
              HasSubstr("-m curvesfm_plots report " + dir + " failed (exit code 1)"));
}

TEST(ReportCommandTest, MissingRunDirIsAUsageError) {
  const CommandResult result = runCurvesfm("report");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("run_dir is required"));
}

}  // namespace
}  // namespace curvesfm
