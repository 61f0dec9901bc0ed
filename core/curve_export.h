#pragma once

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
/// through its vertices (1-based indices, as OBJ counts them), preceded by `o curve_<k>`.
void writeCurvesObj(const std::string& path, const std::vector<PolyBezier>& curves,
                    int samples_per_segment);

}  // namespace curvesfm
