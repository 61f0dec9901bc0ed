#include "core/curve_export.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/errors.h"

namespace curvesfm {
namespace {

using ::testing::HasSubstr;

// The segment from (0,0,0) to (1,0,0) with arms of a third: B(t) = (t, 0, 0).
PolyBezier unitLine() {
  const Direction x(Eigen::Vector3d::UnitX());
  return PolyBezier({Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX()}, {x, x},
                    {SegmentLengths{1.0 / 3.0, 1.0 / 3.0}});
}

// Two segments along y at height 2.
PolyBezier twoSegmentLine() {
  const Direction y(Eigen::Vector3d::UnitY());
  return PolyBezier({Eigen::Vector3d(0, 0, 2), Eigen::Vector3d(0, 1, 2), Eigen::Vector3d(0, 3, 2)},
                    {y, y, y}, {SegmentLengths{0.3, 0.3}, SegmentLengths{0.5, 0.5}});
}

std::vector<std::string> readLines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::vector<std::string> linesStartingWith(const std::vector<std::string>& lines,
                                           const std::string& prefix) {
  std::vector<std::string> found;
  for (const std::string& line : lines) {
    if (line.rfind(prefix, 0) == 0) found.push_back(line);
  }
  return found;
}

class CurveExportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = std::filesystem::path(::testing::TempDir()) /
              ("curve_export_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(folder_);
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }
  std::string path(const std::string& name) const { return (folder_ / name).string(); }

  std::filesystem::path folder_;
};

TEST_F(CurveExportTest, PlyHasOneVertexPerSampleAndEdgesWithinEachCurve) {
  writeCurvesPly(path("c.ply"), {unitLine(), twoSegmentLine()}, 4);
  const std::vector<std::string> lines = readLines(path("c.ply"));
  // unitLine: 1 * 4 + 1 = 5 vertices, 4 edges; twoSegmentLine: 2 * 4 + 1 = 9 vertices, 8 edges.
  ASSERT_GE(lines.size(), 3u);
  EXPECT_EQ(lines[0], "ply");
  EXPECT_EQ(lines[1], "format ascii 1.0");
  EXPECT_THAT(linesStartingWith(lines, "element vertex "),
              ::testing::ElementsAre("element vertex 14"));
  EXPECT_THAT(linesStartingWith(lines, "element edge "), ::testing::ElementsAre("element edge 12"));
  const auto header_end = std::find(lines.begin(), lines.end(), "end_header");
  ASSERT_NE(header_end, lines.end());
  const std::vector<std::string> body(header_end + 1, lines.end());
  ASSERT_EQ(body.size(), 14u + 12u);
  EXPECT_EQ(body[0], "0.000000000 0.000000000 0.000000000");
  EXPECT_EQ(body[1], "0.250000000 0.000000000 0.000000000");
  EXPECT_EQ(body[4], "1.000000000 0.000000000 0.000000000");
  EXPECT_EQ(body[5], "0.000000000 0.000000000 2.000000000");
  EXPECT_EQ(body[13], "0.000000000 3.000000000 2.000000000");
  // Edges: 0-1 .. 3-4 for the first curve, then 5-6 .. 12-13; none joins the two curves.
  EXPECT_EQ(body[14], "0 1");
  EXPECT_EQ(body[17], "3 4");
  EXPECT_EQ(body[18], "5 6");
  EXPECT_EQ(body[25], "12 13");
}

TEST_F(CurveExportTest, ObjHasVertexLinesAndOnePolylinePerCurveWithOneBasedIndices) {
  writeCurvesObj(path("c.obj"), {unitLine(), twoSegmentLine()}, 2);
  const std::vector<std::string> lines = readLines(path("c.obj"));
  const std::vector<std::string> vertices = linesStartingWith(lines, "v ");
  ASSERT_EQ(vertices.size(), 3u + 5u);
  EXPECT_EQ(vertices[1], "v 0.500000000 0.000000000 0.000000000");
  EXPECT_THAT(linesStartingWith(lines, "l "), ::testing::ElementsAre("l 1 2 3", "l 4 5 6 7 8"));
  EXPECT_THAT(linesStartingWith(lines, "o "), ::testing::ElementsAre("o curve_0", "o curve_1"));
}

TEST_F(CurveExportTest, ObjNamesTheCurvesOfASubsetByTheirIds) {
  writeCurvesObj(path("c.obj"), {unitLine(), twoSegmentLine()}, 2, {3, 7});
  EXPECT_THAT(linesStartingWith(readLines(path("c.obj")), "o "),
              ::testing::ElementsAre("o curve_3", "o curve_7"));
  EXPECT_THROW(writeCurvesObj(path("c.obj"), {unitLine()}, 2, {1, 2}), CheckError);
}

TEST_F(CurveExportTest, NoCurvesGiveValidEmptyFiles) {
  writeCurvesPly(path("e.ply"), {}, 10);
  writeCurvesObj(path("e.obj"), {}, 10);
  const std::vector<std::string> ply = readLines(path("e.ply"));
  EXPECT_THAT(linesStartingWith(ply, "element "),
              ::testing::ElementsAre("element vertex 0", "element edge 0"));
  EXPECT_EQ(ply.back(), "end_header");
  EXPECT_TRUE(linesStartingWith(readLines(path("e.obj")), "v ").empty());
}

TEST_F(CurveExportTest, UnwritablePathIsAnIoErrorNamingIt) {
  const std::string bad = path("no_such_folder/c.ply");
  try {
    writeCurvesPly(bad, {unitLine()}, 4);
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_THAT(e.what(), HasSubstr(bad));
  }
  EXPECT_THROW(writeCurvesObj(path("no_such_folder/c.obj"), {unitLine()}, 4), IoError);
}

TEST_F(CurveExportTest, SamplesPerSegmentBelowOneIsACheckError) {
  EXPECT_THROW(writeCurvesPly(path("c.ply"), {unitLine()}, 0), CheckError);
  EXPECT_THROW(writeCurvesObj(path("c.obj"), {unitLine()}, 0), CheckError);
}

}  // namespace
}  // namespace curvesfm
