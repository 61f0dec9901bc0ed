#include "core/curve_map_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <optional>

#include "core/errors.h"
#include "core/text_records.h"

namespace curvesfm {
namespace {

constexpr char kPointFormat[] = "x y z";

std::string joinPath(const std::string& dir, const char* name) {
  return (std::filesystem::path(dir) / name).string();
}

Eigen::Vector3d pointRecord(const std::string& path, int line, const TextFields& fields) {
  requireFieldCount(path, line, fields, 3, kPointFormat);
  return {numberField(path, line, fields, 0, "x"), numberField(path, line, fields, 1, "y"),
          numberField(path, line, fields, 2, "z")};
}

std::vector<Eigen::Vector3d> readPoints(const std::string& path) {
  std::vector<Eigen::Vector3d> points;
  forEachRecord(path, [&](int line, const TextFields& fields) {
    points.push_back(pointRecord(path, line, fields));
  });
  if (points.empty()) {
    throw ParseError(path, 0, std::string("at least one point line \"") + kPointFormat + "\"",
                     "none");
  }
  return points;
}

// The whole number a one-field line holds (the datasets write integers as "4.45E+02").
long long wholeNumberRecord(const std::string& path, int line, const TextFields& fields,
                            const char* name) {
  requireFieldCount(path, line, fields, 1, name);
  const std::optional<double> value = parseFiniteNumber(fields[0]);
  if (!value || *value != std::round(*value) || std::abs(*value) > 1e15) {
    throw ParseError(path, line, std::string("a whole number (") + name + ")",
                     quoteToken(fields[0]));
  }
  return static_cast<long long>(*value);
}

// The 0-based vertex an OBJ index names among the `vertex_count` defined so far, if any.
std::optional<std::size_t> objVertex(std::string_view token, std::size_t vertex_count) {
  // OBJ allows "i/t" and "i/t/n" forms; polylines carry at most a texture index.
  token = token.substr(0, token.find('/'));
  const std::optional<double> value = parseFiniteNumber(token);
  if (!value || *value != std::round(*value)) return std::nullopt;
  const double count = static_cast<double>(vertex_count);
  if (*value >= 1 && *value <= count) return static_cast<std::size_t>(*value) - 1;
  if (*value <= -1 && *value >= -count) return static_cast<std::size_t>(count + *value);
  return std::nullopt;
}

bool isFile(const std::string& dir, const char* name) {
  std::error_code ignored;
  return std::filesystem::is_regular_file(std::filesystem::path(dir) / name, ignored);
}

}  // namespace

Polylines3 readObjPolylines(const std::string& path) {
  std::vector<Eigen::Vector3d> vertices;
  Polylines3 polylines;
  forEachRecord(path, [&](int line, const TextFields& fields) {
    const std::string_view kind = fields[0];
    if (kind == "v") {
      if (fields.size() != 4 && fields.size() != 5) {
        throw ParseError(path, line, "a vertex \"v x y z\"",
                         std::to_string(fields.size() - 1) + " numbers");
      }
      vertices.emplace_back(numberField(path, line, fields, 1, "x"),
                            numberField(path, line, fields, 2, "y"),
                            numberField(path, line, fields, 3, "z"));
    } else if (kind == "l") {
      if (fields.size() < 3) {
        throw ParseError(path, line, "a polyline \"l i j ...\" of at least two vertices",
                         std::to_string(fields.size() - 1) + " indices");
      }
      std::vector<Eigen::Vector3d>& polyline = polylines.emplace_back();
      for (std::size_t i = 1; i < fields.size(); ++i) {
        const std::optional<std::size_t> vertex = objVertex(fields[i], vertices.size());
        if (!vertex) {
          throw ParseError(path, line,
                           "a vertex index in 1.." + std::to_string(vertices.size()) +
                               " (the vertices defined above)",
                           quoteToken(fields[i]));
        }
        polyline.push_back(vertices[*vertex]);
      }
    } else if (kind != "o" && kind != "g" && kind != "s") {
      throw ParseError(path, line, "a \"v\", \"l\", \"o\", \"g\" or \"s\" record",
                       quoteToken(kind));
    }
  });
  if (polylines.empty()) throw ParseError(path, 0, "at least one \"l\" record", "none");
  return polylines;
}

Polylines3 readCurveGraph(const std::string& dir) {
  const std::string points_path = joinPath(dir, "gt-points.txt");
  const std::string edges_path = joinPath(dir, "gt-edges.txt");
  const std::vector<Eigen::Vector3d> points = readPoints(points_path);
  Polylines3 edges;
  // The first point of the pair being read (a plain flag: GCC 12 warns on an optional here).
  std::size_t first = 0;
  bool have_first = false;
  int last_line = 0;
  forEachRecord(edges_path, [&](int line, const TextFields& fields) {
    const long long index = wholeNumberRecord(edges_path, line, fields, "point index");
    if (index < 1 || index > static_cast<long long>(points.size())) {
      throw ParseError(
          edges_path, line,
          "a point index in 1.." + std::to_string(points.size()) + " (" + points_path + ")",
          std::to_string(index));
    }
    const std::size_t vertex = static_cast<std::size_t>(index - 1);
    if (have_first) {
      edges.push_back({points[first], points[vertex]});
    } else {
      first = vertex;
    }
    have_first = !have_first;
    last_line = line;
  });
  if (have_first) {
    throw ParseError(edges_path, last_line, "an even number of point indices (pairs)",
                     "an odd number");
  }
  if (edges.empty()) throw ParseError(edges_path, 0, "at least one pair of point indices", "none");
  return edges;
}

Polylines3 readSynthCurves(const std::string& dir) {
  const std::string points_path = joinPath(dir, "crv-3D-pts.txt");
  const std::string ids_path = joinPath(dir, "crv-ids.txt");
  const std::vector<Eigen::Vector3d> points = readPoints(points_path);
  Polylines3 polylines;
  std::size_t sample = 0;
  long long previous_id = 0;
  int last_line = 0;
  forEachRecord(ids_path, [&](int line, const TextFields& fields) {
    const long long id = wholeNumberRecord(ids_path, line, fields, "curve id");
    if (sample == points.size()) {
      throw ParseError(
          ids_path, line,
          "as many ids as points in " + points_path + " (" + std::to_string(points.size()) + ")",
          "more");
    }
    if (sample == 0 || id != previous_id) polylines.emplace_back();
    polylines.back().push_back(points[sample]);
    previous_id = id;
    ++sample;
    last_line = line;
  });
  if (sample < points.size()) {
    throw ParseError(
        ids_path, last_line,
        "as many ids as points in " + points_path + " (" + std::to_string(points.size()) + ")",
        std::to_string(sample));
  }
  return polylines;
}

CurveMapFormat detectCurveMapFormat(const std::string& path) {
  std::error_code ignored;
  if (!std::filesystem::exists(path, ignored)) throw IoError(path, "does not exist");
  if (std::filesystem::is_regular_file(path, ignored)) {
    std::string extension = std::filesystem::path(path).extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    if (extension == ".obj") return CurveMapFormat::kObj;
  }
  const bool graph = isFile(path, "gt-points.txt") && isFile(path, "gt-edges.txt");
  const bool synth = isFile(path, "crv-3D-pts.txt") && isFile(path, "crv-ids.txt");
  if (graph && synth) {
    throw IoError(path,
                  "holds two curve maps (gt-points.txt + gt-edges.txt and crv-3D-pts.txt + "
                  "crv-ids.txt); name a folder with one");
  }
  if (graph) return CurveMapFormat::kCurveGraph;
  if (synth) return CurveMapFormat::kSynthCurves;
  throw IoError(path,
                "not a curve map: expected a .obj file, or a folder with gt-points.txt and "
                "gt-edges.txt (curve graph), or with crv-3D-pts.txt and crv-ids.txt (synthcurves)");
}

Polylines3 readCurveMap(const std::string& path) {
  switch (detectCurveMapFormat(path)) {
    case CurveMapFormat::kObj:
      return readObjPolylines(path);
    case CurveMapFormat::kCurveGraph:
      return readCurveGraph(path);
    case CurveMapFormat::kSynthCurves:
      return readSynthCurves(path);
  }
  return {};
}

}  // namespace curvesfm
