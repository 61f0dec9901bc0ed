// The curvesfm executable as a whole: --version.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "apps/cli/report_json.h"
#include "test/support/run_executable.h"

namespace curvesfm {
namespace {

using ::testing::MatchesRegex;

using testing::CommandResult;
using testing::runCurvesfm;

TEST(Curvesfm, VersionPrintsVersionAndCommitAndExits0) {
  const CommandResult result = runCurvesfm("--version");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  // A short hash of at least 4 hex digits (git's minimum), or "unknown" outside a git checkout.
  EXPECT_THAT(result.output,
              MatchesRegex("curvesfm [0-9]+\\.[0-9]+\\.[0-9]+ \\(([0-9a-f]{4,40}|unknown)\\)\n"));
  const nlohmann::json version = versionJson();
  EXPECT_EQ(result.output, "curvesfm " + version["version"].get<std::string>() + " (" +
                               version["commit"].get<std::string>() + ")\n");
}

TEST(Curvesfm, VersionJsonHoldsVersionAndCommit) {
  const nlohmann::json version = versionJson();
  ASSERT_TRUE(version["version"].is_string());
  ASSERT_TRUE(version["commit"].is_string());
  EXPECT_THAT(version["version"].get<std::string>(), MatchesRegex("[0-9]+\\.[0-9]+\\.[0-9]+"));
  EXPECT_FALSE(version["commit"].get<std::string>().empty());
}

}  // namespace
}  // namespace curvesfm
