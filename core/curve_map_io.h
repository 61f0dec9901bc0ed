#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "core/enum_names.h"

namespace curvesfm {

// Readers of 3D curve maps as polylines, for curve-map evaluation (core/curve_map_evaluation.h):
// the estimate a run writes (curves.obj) and the ground truths of the curve datasets in
// ../shared/data, each read in the form it is published in. A polyline is a chain of straight
// segments between consecutive points; a curve graph (Pavilion) becomes one two-point polyline
// per edge, which describes the same set of points.
//
// Errors, as every reader of core/: IoError "<path>: <problem>" for a file that cannot be read or
// a folder in no (or more than one) known format; ParseError "<path>:<line>: expected ..., found
// ..." for malformed content (line 0: the file as a whole, e.g. no records at all).

/// 3D polylines in one frame and unit; a polyline of one point marks a point with no length.
using Polylines3 = std::vector<std::vector<Eigen::Vector3d>>;

/// The formats of a curve map on disk.
enum class CurveMapFormat {
  kObj,          ///< A Wavefront OBJ file of `v` and `l` records (curves.obj of `curvesfm run`).
  kCurveGraph,   ///< Pavilion: a folder with gt-points.txt and gt-edges.txt.
  kSynthCurves,  ///< synthcurves: a folder with crv-3D-pts.txt and crv-ids.txt.
};

template <>
struct EnumNames<CurveMapFormat> {
  static constexpr std::array<std::pair<CurveMapFormat, const char*>, 3> kNames = {{
      {CurveMapFormat::kObj, "obj"},
      {CurveMapFormat::kCurveGraph, "curve_graph"},
      {CurveMapFormat::kSynthCurves, "synthcurves"},
  }};
};

/// Reads a Wavefront OBJ file's polylines: `v x y z` records (a fourth weight field is allowed
/// and ignored) and `l i j ...` records of 1-based indices of vertices defined above (negative
/// indices count back from the last vertex, as OBJ allows); one polyline per `l` record. `o`, `g`,
/// `s` and comment lines are skipped. ParseError for any other record (e.g. faces), a malformed
/// number, an index that names no vertex defined so far, or a file without `l` records.
Polylines3 readObjPolylines(const std::string& path);

/// Reads a curve graph (Pavilion's 3d/cropped/): `dir`/gt-points.txt, one point `x y z` per line,
/// and `dir`/gt-edges.txt, one number per line (integers, written as floats in the dataset), read
/// as pairs of lines 2k+1, 2k+2 holding the 1-based indices of two points joined by an edge.
/// Returns one two-point polyline per edge, in file order. ParseError for a malformed line, an
/// index that is not a whole number in 1..points, an odd number of indices (naming the last
/// line), or files without points or edges.
Polylines3 readCurveGraph(const std::string& dir);

/// Reads synthcurves' exact curves: `dir`/crv-3D-pts.txt, one sample `x y z` per line, and
/// `dir`/crv-ids.txt, the curve id (a whole number) of each sample on the same line number;
/// consecutive samples with one id form a polyline. ParseError for a malformed line, an id that is
/// not a whole number, or files whose numbers of records differ (naming the shorter file's end).
Polylines3 readSynthCurves(const std::string& dir);

/// The format `path` holds: a file ending in .obj (any case) -> kObj; a folder with gt-points.txt
/// and gt-edges.txt -> kCurveGraph; a folder with crv-3D-pts.txt and crv-ids.txt -> kSynthCurves.
/// IoError naming the path when it does not exist, and naming the formats looked for when it holds
/// none or both folder formats.
CurveMapFormat detectCurveMapFormat(const std::string& path);

/// Reads `path` in the format detectCurveMapFormat finds.
Polylines3 readCurveMap(const std::string& path);

}  // namespace curvesfm
