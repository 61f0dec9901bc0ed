// real_bench's command line: a bad set or variant name, a missing data folder, photo or extra
// set, and two sets of one name end in one message naming the flag, file or folder and a
// non-zero exit, before anything runs.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "test/support/run_executable.h"

namespace curvesfm {
namespace {

using ::testing::HasSubstr;

testing::CommandResult runRealBench(const std::string& arguments) {
  return testing::runCommand(REAL_BENCH_EXECUTABLE, arguments);
}

TEST(RealBenchCommandLine, RejectsAnUnknownVariant) {
  const testing::CommandResult r = runRealBench("--variants init,points");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output,
              HasSubstr("--variants: 'points' is not one of init, curves, hybrid, colmap"));
}

TEST(RealBenchCommandLine, RejectsRepetitionsOutsideOneToTwenty) {
  for (const char* count : {"0", "21"}) {
    const testing::CommandResult r = runRealBench(std::string("--repetitions ") + count);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_THAT(r.output, HasSubstr("--repetitions")) << count;
  }
}

TEST(RealBenchCommandLine, RejectsAnUnknownSet) {
  const testing::CommandResult r = runRealBench("--sets kitti");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--sets: 'kitti' is not a benchmark set"));
}

TEST(RealBenchCommandLine, NamesAMissingDataFolder) {
  const std::string out = ::testing::TempDir() + "real_bench_no_data";
  const testing::CommandResult r = runRealBench("--data /nonexistent/data --out " + out);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("/nonexistent/data: no such folder"));
}

TEST(RealBenchCommandLine, NamesADataFolderWithoutTheSets) {
  const std::string out = ::testing::TempDir() + "real_bench_empty_data";
  const testing::CommandResult r = runRealBench("--data " + ::testing::TempDir() + " --out " + out);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("none of the benchmark's sets is there"));
}

TEST(RealBenchCommandLine, NamesAMissingExtraSet) {
  const std::string out = ::testing::TempDir() + "real_bench_no_extra";
  const testing::CommandResult r =
      runRealBench("--sets none --extra-sets /nonexistent/my_sequence --out " + out);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("/nonexistent/my_sequence: no such folder (--extra-sets)"));
}

TEST(RealBenchCommandLine, RefusesTwoSetsOfOneName) {
  const std::string root = ::testing::TempDir() + "real_bench_twins";
  std::filesystem::create_directories(root + "/a/walk");
  std::filesystem::create_directories(root + "/b/walk");
  const testing::CommandResult r = runRealBench("--sets none --extra-sets " + root + "/a/walk," +
                                                root + "/b/walk --out " + root + "/out");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("two sets named walk"));
}

TEST(RealBenchCommandLine, NamesAMissingPlanarPhoto) {
  const std::string out = ::testing::TempDir() + "real_bench_no_photo";
  const testing::CommandResult r = runRealBench(
      "--sets none --planar-dir /nonexistent/photos "
      "--planar-photos left01.jpg --out " +
      out);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("/nonexistent/photos/left01.jpg: no such photo"));
}

TEST(RealBenchCommandLine, RefusesTwoPlanarPhotosOfOneNameBeforeRenderingEither) {
  const std::string root = ::testing::TempDir() + "real_bench_photo_twins";
  std::filesystem::create_directories(root + "/photos");
  std::ofstream(root + "/photos/wall.png") << "not read before the check";
  std::ofstream(root + "/photos/wall.jpg") << "not read before the check";
  const testing::CommandResult r =
      runRealBench("--sets none --planar-dir " + root +
                   "/photos --planar-photos wall.png,wall.jpg" + " --out " + root + "/out");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--planar-photos = planar_wall: two sets named planar_wall"));
  EXPECT_FALSE(std::filesystem::exists(root + "/out/planar_sets"));
}

TEST(RealBenchCommandLine, NamesNoSetToRun) {
  const std::string out = ::testing::TempDir() + "real_bench_none";
  const testing::CommandResult r = runRealBench("--sets none --out " + out);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("no --planar-photos or --extra-sets given"));
}

TEST(RealBenchCommandLine, RejectsAStartOriginOtherThanNativeOrFirst) {
  const testing::CommandResult r = runRealBench("--start-origin centre");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--start-origin: centre not in {native,first}"));
}

TEST(RealBenchCommandLine, RejectsANegativeStartJitterSeed) {
  const testing::CommandResult r = runRealBench("--start-jitter-seed -1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--start-jitter-seed: Value -1 not in range 0 to 2147483647"));
}

TEST(RealBenchCommandLine, RejectsAMapAtLabelThatNamesNoStart) {
  for (const char* label : {"noise", "noise1x", "colmap", "noise12345678901234567890"}) {
    const testing::CommandResult r = runRealBench(std::string("--map-at ") + label);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_THAT(r.output,
                HasSubstr(std::string("--map-at: '") + label + "' is not truth or noise<seed>"));
  }
}

TEST(RealBenchCommandLine, RejectsAMapAtWithStartsOutsideTheTruthsFrame) {
  const std::string out = ::testing::TempDir() + "real_bench_map_at";
  const testing::CommandResult r = runRealBench("--map-at truth --starts noise,init --data " +
                                                ::testing::TempDir() + " --out " + out);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--map-at = truth: needs --starts of truth and noise only"));
}

}  // namespace
}  // namespace curvesfm
