// planar_bench's command line: a bad case selection or photo folder ends in one message naming
// the flag or folder and a non-zero exit, before any case runs.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "test/support/run_executable.h"

namespace curvesfm {
namespace {

using ::testing::HasSubstr;

testing::CommandResult runPlanarBench(const std::string& arguments) {
  return testing::runCommand(PLANAR_BENCH_EXECUTABLE, arguments);
}

TEST(PlanarBenchCommandLine, RejectsAPhotoOutsideTheBenchmark) {
  const testing::CommandResult r = runPlanarBench("--photos LinuxLogo.jpg,nope.jpg");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--photos: 'nope.jpg' is not a benchmark photo"));
}

TEST(PlanarBenchCommandLine, RejectsAnEmptyItem) {
  const testing::CommandResult r = runPlanarBench("--photos ,LinuxLogo.jpg");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--photos: empty item"));
}

TEST(PlanarBenchCommandLine, RejectsANoiseLevelThatIsNoPercentage) {
  for (const std::string level : {"abc", "101", "-5", "5x"}) {
    const testing::CommandResult r = runPlanarBench("--noise 0," + level);
    EXPECT_EQ(r.exit_code, 2) << level << ": " << r.output;
    EXPECT_THAT(r.output, HasSubstr("--noise: '" + level + "' is not a percentage in [0, 100]"));
  }
}

TEST(PlanarBenchCommandLine, NamesAPhotoFolderWithoutThePhotos) {
  const std::string out = ::testing::TempDir() + "planar_bench_no_photos";
  const testing::CommandResult r = runPlanarBench("--data-dir /nonexistent/photos --out " + out);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("/nonexistent/photos: none of the benchmark photos is readable"));
}

}  // namespace
}  // namespace curvesfm
