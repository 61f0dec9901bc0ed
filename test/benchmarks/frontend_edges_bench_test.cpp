// frontend_edges_bench's --images: a missing file is a usage error naming it, a file OpenCV cannot
// read as an image ends the bench with one message naming it, before anything is timed.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "test/support/run_executable.h"

namespace curvesfm {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

testing::CommandResult runFrontendEdgesBench(const std::string& arguments) {
  return testing::runCommand(FRONTEND_EDGES_BENCH_EXECUTABLE, arguments);
}

TEST(FrontendEdgesBenchCommandLine, NamesAMissingImage) {
  const testing::CommandResult r = runFrontendEdgesBench("--images /nonexistent/frame.png");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("/nonexistent/frame.png"));
}

TEST(FrontendEdgesBenchCommandLine, NamesAFileThatIsNoImage) {
  const std::string path = ::testing::TempDir() + "frontend_edges_bench_not_an_image.png";
  std::ofstream(path) << "not an image\n";
  const testing::CommandResult r = runFrontendEdgesBench("--repeats 1 --images " + path);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr(path + ": not an image OpenCV can read"));
  EXPECT_THAT(r.output, Not(HasSubstr("edges_ms_")));
}

}  // namespace
}  // namespace curvesfm
