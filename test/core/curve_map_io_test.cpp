#include "core/curve_map_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "core/curve_export.h"
#include "core/errors.h"
#include "test/support/temp_folder.h"

namespace curvesfm {
namespace {

using ::testing::HasSubstr;

class CurveMapIoTest : public testing::TempFolderTest {
 protected:
  // The message of the ParseError `read` throws, or a failure.
  template <class Read>
  std::string parseError(Read&& read) {
    try {
      read();
    } catch (const ParseError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no ParseError";
    return "";
  }
  // A Pavilion-like curve graph of four points: edges 1-2 and 2-4, indices written as floats.
  void writeGraph(const std::string& edges) {
    write("graph/gt-points.txt",
          "   0.0E+00   0.0E+00   0.0E+00\n   1.0E+00   0.0E+00   0.0E+00\n"
          "   1.0E+00   1.0E+00   0.0E+00\n   1.0E+00   1.0E+00   1.0E+00\n");
    write("graph/gt-edges.txt", edges);
  }
};

TEST_F(CurveMapIoTest, ReadsObjPolylinesAsWriteCurvesObjWritesThem) {
  const Direction x(Eigen::Vector3d::UnitX());
  const PolyBezier curve({Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX()}, {x, x},
                         {SegmentLengths{0.3, 0.3}});
  writeCurvesObj(path("curves.obj"), {curve, curve}, 4);
  const Polylines3 polylines = readObjPolylines(path("curves.obj"));
  ASSERT_EQ(polylines.size(), 2u);
  ASSERT_EQ(polylines[1].size(), 5u);
  EXPECT_NEAR((polylines[1][4] - Eigen::Vector3d(1, 0, 0)).norm(), 0.0, 1e-9);
  EXPECT_EQ(detectCurveMapFormat(path("curves.obj")), CurveMapFormat::kObj);
}

TEST_F(CurveMapIoTest, ObjNegativeIndicesCountBack) {
  write("a.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nl -3 -2 -1\n");
  const Polylines3 polylines = readObjPolylines(path("a.obj"));
  ASSERT_EQ(polylines.size(), 1u);
  EXPECT_EQ(polylines[0][2], Eigen::Vector3d(2, 0, 0));
}

TEST_F(CurveMapIoTest, ObjErrorsNameFileAndLine) {
  write("face.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n");
  EXPECT_THAT(parseError([&] { readObjPolylines(path("face.obj")); }),
              HasSubstr("face.obj:4: expected a \"v\", \"l\", \"o\", \"g\" or \"s\" record, found "
                        "\"f\""));
  write("index.obj", "v 0 0 0\nl 1 2\nv 1 0 0\n");
  EXPECT_THAT(parseError([&] { readObjPolylines(path("index.obj")); }),
              HasSubstr("index.obj:2: expected a vertex index in 1..1"));
  write("number.obj", "# curves\nv 0 zero 0\n");
  EXPECT_THAT(parseError([&] { readObjPolylines(path("number.obj")); }),
              HasSubstr("number.obj:2: expected a number in field 3 (y)"));
  write("short.obj", "v 0 0\n");
  EXPECT_THAT(parseError([&] { readObjPolylines(path("short.obj")); }),
              HasSubstr("short.obj:1: expected a vertex \"v x y z\", found 2 numbers"));
  write("empty.obj", "v 0 0 0\n");
  EXPECT_THAT(parseError([&] { readObjPolylines(path("empty.obj")); }),
              HasSubstr("empty.obj: expected at least one \"l\" record, found none"));
}

TEST_F(CurveMapIoTest, ReadsCurveGraphEdgesAsTwoPointPolylines) {
  writeGraph("1.0E+00\n2.0E+00\n   4.0000000E+00\n   2.0000000E+00\n");
  const Polylines3 edges = readCurveGraph(path("graph"));
  ASSERT_EQ(edges.size(), 2u);
  EXPECT_EQ(edges[0][1], Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(edges[1][0], Eigen::Vector3d(1, 1, 1));
  EXPECT_EQ(detectCurveMapFormat(path("graph")), CurveMapFormat::kCurveGraph);
  EXPECT_EQ(readCurveMap(path("graph")).size(), 2u);
}

TEST_F(CurveMapIoTest, CurveGraphErrorsNameFileAndLine) {
  writeGraph("1\n2\n3\n");
  EXPECT_THAT(parseError([&] { readCurveGraph(path("graph")); }),
              HasSubstr("gt-edges.txt:3: expected an even number of point indices (pairs), found "
                        "an odd number"));
  writeGraph("1\n5\n");
  EXPECT_THAT(parseError([&] { readCurveGraph(path("graph")); }),
              HasSubstr("gt-edges.txt:2: expected a point index in 1..4"));
  writeGraph("1\n2.5\n");
  EXPECT_THAT(parseError([&] { readCurveGraph(path("graph")); }),
              HasSubstr("gt-edges.txt:2: expected a whole number (point index), found \"2.5\""));
  writeGraph("1 2\n");
  EXPECT_THAT(parseError([&] { readCurveGraph(path("graph")); }),
              HasSubstr("gt-edges.txt:1: expected 1 fields"));
  writeGraph("");
  EXPECT_THAT(parseError([&] { readCurveGraph(path("graph")); }),
              HasSubstr("gt-edges.txt: expected at least one pair of point indices, found none"));
  write("graph/gt-points.txt", "0 0 0\n1 0\n");
  EXPECT_THAT(parseError([&] { readCurveGraph(path("graph")); }),
              HasSubstr("gt-points.txt:2: expected 3 fields \"x y z\", found 2"));
}

TEST_F(CurveMapIoTest, ReadsSynthCurvesSplittingAtIdChanges) {
  write("synth/crv-3D-pts.txt", "0 0 0\n0 1 0\n0 2 0\n5 5 5\n6 5 5\n");
  write("synth/crv-ids.txt", "0\n0\n0\n1\n1\n");
  const Polylines3 curves = readSynthCurves(path("synth"));
  ASSERT_EQ(curves.size(), 2u);
  EXPECT_EQ(curves[0].size(), 3u);
  EXPECT_EQ(curves[1][1], Eigen::Vector3d(6, 5, 5));
  EXPECT_EQ(detectCurveMapFormat(path("synth")), CurveMapFormat::kSynthCurves);
}

TEST_F(CurveMapIoTest, SynthCurvesErrorsNameFileAndLine) {
  write("synth/crv-3D-pts.txt", "0 0 0\n0 1 0\n");
  write("synth/crv-ids.txt", "0\n");
  EXPECT_THAT(parseError([&] { readSynthCurves(path("synth")); }),
              HasSubstr("crv-ids.txt:1: expected as many ids as points in"));
  write("synth/crv-ids.txt", "0\n0\n1\n");
  EXPECT_THAT(parseError([&] { readSynthCurves(path("synth")); }),
              HasSubstr("crv-ids.txt:3: expected as many ids as points in"));
  write("synth/crv-ids.txt", "0\nx\n");
  EXPECT_THAT(parseError([&] { readSynthCurves(path("synth")); }),
              HasSubstr("crv-ids.txt:2: expected a whole number (curve id), found \"x\""));
}

TEST_F(CurveMapIoTest, DetectionNamesWhatItLookedFor) {
  write("nothing/readme.txt", "no curves\n");
  try {
    detectCurveMapFormat(path("nothing"));
    ADD_FAILURE() << "no IoError";
  } catch (const IoError& e) {
    EXPECT_THAT(e.what(), HasSubstr("nothing: not a curve map: expected a .obj file"));
    EXPECT_THAT(e.what(), HasSubstr("gt-points.txt and gt-edges.txt"));
  }
  writeGraph("1\n2\n");
  write("graph/crv-3D-pts.txt", "0 0 0\n");
  write("graph/crv-ids.txt", "0\n");
  EXPECT_THROW(detectCurveMapFormat(path("graph")), IoError);
  EXPECT_THROW(readCurveMap(path("missing")), IoError);
}

TEST_F(CurveMapIoTest, MissingFileIsIoError) {
  write("half/gt-points.txt", "0 0 0\n");
  EXPECT_THROW(readCurveGraph(path("half")), IoError);
}

}  // namespace
}  // namespace curvesfm
