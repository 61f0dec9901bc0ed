// real_bench's command line: a bad set or variant name and a missing data folder end in one
// message naming the flag or folder and a non-zero exit, before anything runs.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

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
