// The curvesfm executable as a whole: --version, and what holds for every sub-command's flags.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "apps/cli/report_json.h"
#include "apps/curve_ba_command.h"
#include "apps/eval_command.h"
#include "apps/point_ba_command.h"
#include "apps/report_command.h"
#include "apps/run_command.h"
#include "apps/synth_command.h"
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

// Every option of `command` and its sub-commands that takes more than one value, as "command
// --flag".
void collectMultiValueOptions(const CLI::App& command, std::vector<std::string>* found) {
  for (const CLI::Option* option : command.get_options()) {
    if (option->get_items_expected_max() > 1) {
      found->push_back(command.get_name() + " " + option->get_name());
    }
  }
  for (const CLI::App* sub : command.get_subcommands({})) collectMultiValueOptions(*sub, found);
}

// Config files refuse YAML lists (apps/cli/config_file.h) because no flag takes several values;
// a flag that did would need its list back.
TEST(Curvesfm, NoFlagTakesSeveralValues) {
  CLI::App app;
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  PointBaCommand point_ba(&app);
  CurveBaCommand curve_ba(&app);
  EvalCommand eval(&app);
  SynthCommand synth(&app);
  RunCommand run(&app);
  ReportCommand report(&app);
  std::vector<std::string> found;
  collectMultiValueOptions(app, &found);
  EXPECT_THAT(found, ::testing::IsEmpty());
  // The walk reaches nested sub-commands and counts options: run alone has more than 100.
  EXPECT_NE(app.get_subcommand("synth")->get_subcommand("planar"), nullptr);
  EXPECT_GT(app.get_subcommand("run")->get_options().size(), 100u);
}

}  // namespace
}  // namespace curvesfm
