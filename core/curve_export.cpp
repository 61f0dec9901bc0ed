#include "core/curve_export.h"

#include <cstddef>
#include <fstream>
#include <functional>
#include <locale>

#include "core/check.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

using Polylines = std::vector<std::vector<Eigen::Vector3d>>;

Polylines samplePolylines(const std::vector<PolyBezier>& curves, int samples_per_segment) {
  CURVESFM_CHECK(samples_per_segment >= 1)
      << "samples_per_segment must be >= 1, got " << samples_per_segment;
  Polylines polylines;
  polylines.reserve(curves.size());
  for (const PolyBezier& curve : curves) polylines.push_back(curve.sample(samples_per_segment));
  return polylines;
}

std::size_t countVertices(const Polylines& polylines) {
  std::size_t count = 0;
  for (const auto& polyline : polylines) count += polyline.size();
  return count;
}

void writeVertex(std::ostream& out, const char* prefix, const Eigen::Vector3d& x) {
  out << prefix << x.x() << ' ' << x.y() << ' ' << x.z() << '\n';
}

// Fixed notation with 9 decimals keeps nanometre detail at any map scale a camera sees, and the
// classic locale keeps the decimal point a point whatever the user's locale.
void writeExport(const std::string& path, const std::function<void(std::ostream&)>& write) {
  std::ofstream out(path);
  if (!out) throw IoError(path, "cannot open for writing");
  out.imbue(std::locale::classic());
  out.setf(std::ios::fixed);
  out.precision(9);
  write(out);
  out.close();
  if (!out) throw IoError(path, "write failed");
}

void writePly(std::ostream& out, const Polylines& polylines) {
  const std::size_t vertices = countVertices(polylines);
  // Every polyline has at least 2 vertices, so it contributes one edge fewer than vertices.
  const std::size_t edges = vertices - polylines.size();
  out << "ply\nformat ascii 1.0\ncomment curvesfm: densely sampled poly-Bezier curves\n"
      << "element vertex " << vertices << "\nproperty double x\nproperty double y\n"
      << "property double z\nelement edge " << edges
      << "\nproperty int vertex1\nproperty int vertex2\nend_header\n";
  for (const auto& polyline : polylines) {
    for (const Eigen::Vector3d& x : polyline) writeVertex(out, "", x);
  }
  std::size_t first = 0;
  for (const auto& polyline : polylines) {
    for (std::size_t i = 1; i < polyline.size(); ++i) {
      out << first + i - 1 << ' ' << first + i << '\n';
    }
    first += polyline.size();
  }
}

void writeObj(std::ostream& out, const Polylines& polylines, const std::vector<std::size_t>& ids) {
  out << "# curvesfm: densely sampled poly-Bezier curves, one polyline per curve\n";
  std::size_t next = 1;
  for (std::size_t k = 0; k < polylines.size(); ++k) {
    out << "o curve_" << (ids.empty() ? k : ids[k]) << '\n';
    for (const Eigen::Vector3d& x : polylines[k]) writeVertex(out, "v ", x);
    out << 'l';
    for (std::size_t i = 0; i < polylines[k].size(); ++i) out << ' ' << next + i;
    out << '\n';
    next += polylines[k].size();
  }
}

}  // namespace

void writeCurvesPly(const std::string& path, const std::vector<PolyBezier>& curves,
                    int samples_per_segment) {
  const Polylines polylines = samplePolylines(curves, samples_per_segment);
  writeExport(path, [&](std::ostream& out) { writePly(out, polylines); });
}

void writeCurvesObj(const std::string& path, const std::vector<PolyBezier>& curves,
                    int samples_per_segment, const std::vector<std::size_t>& ids) {
  CURVESFM_CHECK(ids.empty() || ids.size() == curves.size())
      << ids.size() << " ids for " << curves.size() << " curves";
  const Polylines polylines = samplePolylines(curves, samples_per_segment);
  writeExport(path, [&](std::ostream& out) { writeObj(out, polylines, ids); });
}

}  // namespace curvesfm

namespace curvesfm {

void writePointsPly(const std::string& path, const std::vector<ExportedPoint>& points) {
  writeExport(path, [&](std::ostream& out) {
    out << "ply\nformat ascii 1.0\ncomment curvesfm: the point-based initialiser's map\n"
        << "element vertex " << points.size()
        << "\nproperty double x\nproperty double y\nproperty double z\n"
        << "property uchar red\nproperty uchar green\nproperty uchar blue\n"
        << "property int track_length\nend_header\n";
    for (const ExportedPoint& p : points) {
      out << p.position.x() << ' ' << p.position.y() << ' ' << p.position.z() << ' ' << int(p.red)
          << ' ' << int(p.green) << ' ' << int(p.blue) << ' ' << p.track_length << '\n';
    }
  });
}

}  // namespace curvesfm
