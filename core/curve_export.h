#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/bezier.h"

namespace curvesfm {

// Exporters of a curve map as polylines for viewers (MeshLab, CloudCompare, Blender): every curve
// is sampled densely with PolyBezier::sample(samples_per_segment), i.e. n * s + 1 vertices for a
// curve of n segments, and consecutive samples are joined by an edge (n * s edges per curve).
// Curves share no vertices. Coordinates are the curves' world frame, written with 9 decimals in
// the classic locale. Both throw CheckError for samples_per_segment < 1 and IoError naming the
// path if the file cannot be opened or written.

/// Writes an ASCII PLY file: `element vertex` with float64 x y z, then `element edge` with int
/// vertex1 vertex2 (0-based vertex indices), one line per vertex and per edge.
void writeCurvesPly(const std::string& path, const std::vector<PolyBezier>& curves,
                    int samples_per_segment);

/// Writes a Wavefront OBJ file: one `v x y z` line per vertex and, per curve, one `l i j ...` line
/// through its vertices (1-based indices, as OBJ counts them), preceded by `o curve_<k>`, k being
/// the curve's index in `curves`, or ids[index] when `ids` is given (one per curve: a subset of
/// a map keeps its curves' names).
void writeCurvesObj(const std::string& path, const std::vector<PolyBezier>& curves,
                    int samples_per_segment, const std::vector<std::size_t>& ids = {});

}  // namespace curvesfm

namespace curvesfm {

/// One point of a sparse map for writePointsPly.
struct ExportedPoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  std::uint8_t red = 0, green = 0, blue = 0;
  int track_length = 0;  ///< Images that observe it.
};

/// Writes an ASCII PLY point cloud, the point-based initialiser's map beside the curves: per
/// vertex x y z (double), red green blue (uchar) and track_length (int; MeshLab and CloudCompare
/// show it as a scalar field). IoError naming the file if it cannot be written.
void writePointsPly(const std::string& path, const std::vector<ExportedPoint>& points);

}  // namespace curvesfm
