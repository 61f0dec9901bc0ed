#include "apps/cli/options_table.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "apps/cli/cli_options.h"
#include "apps/cli/config_file.h"
#include "apps/cli/option_tables.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

using ::testing::HasSubstr;

// Every options struct of the libraries, with the tables of every command, in one place.
struct AllOptions {
  PipelineOptions pipeline;
  CurveOverlayOptions overlay;
  OverlayColouringOptions overlay_colouring;
  PointInitialiserOptions points;
  StartModelOptions start_model;
  ImageSequenceOptions sequence;
  CurveSceneOptions curve_scene;
  CurveBundleAdjustmentOptions curve_ba;
  SchedulerOptions scheduler;
  PointSceneOptions point_scene;
  PointBundleAdjustmentOptions point_ba;
  OptimizerOptions optimizer;
  PlanarSceneOptions planar;
  TrajectoryEvaluationOptions evaluation;
  CurveMapEvaluationOptions curve_map;
  EdgeCoverageOptions edge_coverage;
};

// The tables as the commands build them (run, curve-ba, point-ba, synth planar, eval, eval-map);
// init's table is run's point initialiser part.
std::vector<OptionsTable> commandTables(AllOptions* o) {
  std::vector<OptionsTable> tables(6);
  addPipelineOptions(&tables[0], &o->pipeline, "/pipeline");
  addCurveOverlayOptions(&tables[0], &o->overlay, {"/overlay", "overlay-", "Overlays", ""});
  addOverlayColouringOptions(&tables[0], &o->overlay_colouring,
                             {"/overlay", "overlay-", "Overlays", ""});
  addPointInitialiserOptions(&tables[0], &o->points, "/points");
  addStartModelOptions(&tables[0], &o->start_model, "/start_model");
  addImageSequenceOptions(&tables[0], &o->sequence);
  addCurveSceneOptions(&tables[1], &o->curve_scene, {"/scene", "", "Scene", ""});
  addCurveBundleAdjustmentOptions(&tables[1], &o->curve_ba, {"/ba", "", "Objective", ""});
  addSchedulerOptions(&tables[1], &o->scheduler, {"/scheduler", "", "Schedule", ""},
                      &o->curve_ba.fix_first_pose);
  addPointSceneOptions(&tables[2], &o->point_scene, {"/scene", "", "Scene", ""});
  addPointBundleAdjustmentOptions(&tables[2], &o->point_ba, {"/ba", "", "Objective", ""});
  addOptimizerOptions(&tables[2], &o->optimizer, {"/optimizer", "", "Solver", ""});
  addPlanarSceneOptions(&tables[3], &o->planar, {"", "", "Scene", ""});
  addTrajectoryEvaluationOptions(&tables[4], &o->evaluation, {"", "", "Evaluation", ""});
  addImageSequenceOptions(&tables[5], &o->sequence);
  addTrajectoryEvaluationOptions(&tables[5], &o->evaluation,
                                 {"/alignment", "", "Trajectory alignment", ""});
  addCurveMapEvaluationOptions(&tables[5], &o->curve_map, {"/curve_map", "", "Curve map", ""});
  addEdgeCoverageOptions(&tables[5], &o->edge_coverage,
                         {"/edge_coverage", "edge-coverage-", "Edge coverage", ""});
  return tables;
}

// `struct XxxOptions {` of every header below the libraries' folders.
std::set<std::string> declaredOptionsStructs() {
  const std::regex declaration(R"(^struct (\w+Options) \{)");
  std::set<std::string> names;
  for (const char* folder : {"core", "graph", "factors", "frontend", "sim"}) {
    const auto root = std::filesystem::path(CURVESFM_SOURCE_DIR) / folder;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
      if (entry.path().extension() != ".h") continue;
      std::ifstream in(entry.path());
      std::smatch match;
      for (std::string line; std::getline(in, line);) {
        if (std::regex_search(line, match, declaration)) names.insert(match[1]);
      }
    }
  }
  return names;
}

struct ThreeFields {
  int a = 0;
  double b = 0.0;
  CameraIntrinsics nested;
};

TEST(AggregateFieldCount, CountsEveryFieldNestedStructsAsOne) {
  static_assert(aggregateFieldCount<ThreeFields>() == 3);
  static_assert(aggregateFieldCount<CameraIntrinsics>() == 11);
  static_assert(aggregateFieldCount<SchedulerOptions>() == 7);
}

TEST(OptionsTable, EveryFieldOfEveryOptionsStructHasARow) {
  AllOptions options;
  std::set<std::string> tabled;
  for (const OptionsTable& table : commandTables(&options)) {
    for (const OptionGroup& group : table.groups()) {
      tabled.insert(group.struct_name);
      EXPECT_EQ(group.fields.size(), group.struct_fields)
          << group.struct_name << " at " << group.path << ": " << group.struct_fields
          << " fields declared, " << group.fields.size() << " in the table";
      for (const OptionField& row : group.fields) {
        EXPECT_TRUE(!row.flag.empty() || !row.note.empty() || !row.value)
            << group.struct_name << "." << row.field << ": neither a flag nor a reason for none";
      }
    }
  }
  const std::set<std::string> declared = declaredOptionsStructs();
  EXPECT_GE(declared.size(), 15u);  // The scan found the headers.
  for (const std::string& name : declared) EXPECT_EQ(tabled.count(name), 1u) << name;
}

TEST(OptionsTable, FlagsAreUniqueWithinACommand) {
  AllOptions options;
  for (const OptionsTable& table : commandTables(&options)) {
    std::set<std::string> flags;
    for (const OptionGroup& group : table.groups()) {
      for (const OptionField& row : group.fields) {
        if (!row.flag.empty()) {
          EXPECT_TRUE(flags.insert(row.flag).second) << row.flag;
        }
      }
    }
  }
}

class PipelineTableTest : public ::testing::Test {
 protected:
  void SetUp() override {
    app_.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    addPipelineOptions(&table_, &options_, "/pipeline");
    table_.addFlags(&app_);
  }
  void parse(const std::vector<std::string>& args) { parseCommandLine(&app_, args); }

  CLI::App app_;
  PipelineOptions options_;
  OptionsTable table_;
};

TEST_F(PipelineTableTest, ThreadsSetsEveryStageWhoseOwnFlagIsNotGiven) {
  parse({"--threads", "3", "--global-ba-threads", "1"});
  EXPECT_EQ(options_.local_ba.optimizer.num_threads, 3);
  EXPECT_EQ(options_.tracking.num_threads, 3);
  EXPECT_EQ(options_.global_ba.optimizer.num_threads, 1);
}

// config.yaml gives every flag; were a stage's count echoed as its default, a run from that file
// would take it as given and keep one thread where the first run had --threads.
TEST_F(PipelineTableTest, TheEchoedConfigCarriesTheThreadCountsThreadsSet) {
  parse({"--threads", "3", "--global-ba-threads", "1"});
  std::map<std::string, std::string> echoed;
  for (const auto& [name, value] : effectiveOptions(app_)) echoed[name] = value;
  EXPECT_EQ(echoed["local-ba-threads"], "3");
  EXPECT_EQ(echoed["global-ba-threads"], "1");
  EXPECT_EQ(echoed["threads"], "3");
}

TEST_F(PipelineTableTest, RangeErrorsNameTheFlagOfTheirPlace) {
  parse({"--global-ba-local-window", "0"});
  EXPECT_THAT([&] { table_.validate(); },
              ::testing::ThrowsMessage<InvalidOptions>(::testing::StartsWith(
                  "InvalidOptions: --global-ba-local-window = 0: must be >= 1 "
                  "(SchedulerOptions.local_window)")));
}

TEST_F(PipelineTableTest, JsonMirrorsTheStructsAndHelpHasAHeadingPerStage) {
  parse({"--local-ba-max-iterations", "7", "--ba-kernel", "cauchy"});
  const nlohmann::json json = table_.toJson();
  EXPECT_EQ(json["pipeline"]["local_ba"]["optimizer"]["max_iterations"], 7);
  EXPECT_EQ(json["pipeline"]["ba"]["kernel"], "cauchy");
  // The gauge has one switch: the schedulers echo the BA objective's.
  EXPECT_EQ(json["pipeline"]["global_ba"]["fix_first_pose"], true);
  const std::string help = app_.help();
  for (const char* heading : {"Edges:", "Depth:", "Local BA:", "Global BA:", "Pose tracking:"}) {
    EXPECT_THAT(help, HasSubstr(heading));
  }
}

TEST(OptionsTable, VectorFlagsTakeThreeNumbersAndNameTheFlagOtherwise) {
  CLI::App app;
  CurveSceneOptions scene;
  CurveOverlayOptions overlay;
  OptionsTable table;
  addCurveSceneOptions(&table, &scene, {"/scene", "", "Scene", ""});
  addCurveOverlayOptions(&table, &overlay, {"/overlay", "overlay-", "Overlays", ""});
  table.addFlags(&app);
  parseCommandLine(&app, {"--volume-half-extents", "1,2.5,3", "--overlay-colour", "0,0,255"});
  EXPECT_EQ(scene.volume_half_extents, Eigen::Vector3d(1.0, 2.5, 3.0));
  EXPECT_EQ(overlay.colour, cv::Scalar(0, 0, 255));
  EXPECT_EQ(table.toJson()["scene"]["volume_half_extents"], "1,2.5,3");
  for (const char* bad : {"1,2", "1,2,3,4", "1;2;3", "1,2,x", "1,2,inf"}) {
    app.clear();
    try {
      parseCommandLine(&app, {"--volume-half-extents", bad});
      ADD_FAILURE() << bad << " accepted";
    } catch (const CLI::ParseError& e) {
      EXPECT_THAT(e.what(), HasSubstr("--volume-half-extents")) << bad;
      EXPECT_THAT(e.what(), HasSubstr("expected three numbers")) << bad;
    }
  }
}

}  // namespace
}  // namespace curvesfm
