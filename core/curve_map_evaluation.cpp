#include "core/curve_map_evaluation.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <utility>

#include "core/errors.h"

namespace curvesfm {

void CurveMapEvaluationOptions::validate() const {
  const OptionCheck require("CurveMapEvaluationOptions");
  require(!taus.empty(), "taus", static_cast<double>(taus.size()), "must hold at least one tau");
  for (std::size_t i = 0; i < taus.size(); ++i) {
    require.positive("taus", taus[i]);
    if (i > 0) require(taus[i] > taus[i - 1], "taus", taus[i], "must be strictly increasing");
  }
  require.nonNegative("sample_spacing", sample_spacing);
  require.nonNegative("crop_margin", crop_margin);
}

namespace {

// Pieces of `step` in `length`, at least 1 and at most a million: a runaway curve kilometres long
// (an old run, or --sanity-drop-curves false) is sampled coarser instead of exhausting memory.
int boundedCount(double length, double step) {
  constexpr double kMaxCount = 1e6;
  const double count = std::ceil(length / step);
  if (!(count >= 1.0)) return 1;
  return static_cast<int>(std::min(count, kMaxCount));
}

struct Segment {
  Eigen::Vector3d a, b;
};

double squaredDistanceToSegment(const Eigen::Vector3d& p, const Segment& s) {
  const Eigen::Vector3d ab = s.b - s.a;
  const double length2 = ab.squaredNorm();
  // A zero-length segment (a one-point polyline, a repeated vertex) is its point.
  const double t = length2 > 0.0 ? std::clamp((p - s.a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (s.a + t * ab - p).squaredNorm();
}

// Every segment of a polyline set, pieces no longer than one cell, each listed in every grid cell
// its bounding box touches (at most 2 x 2 x 2). The point of a piece nearest to a query within one
// cell size lies in a cell next to the query's, so the 27 cells around the query hold every piece
// within that distance: the search is exact up to the cell size.
class SegmentGrid {
 public:
  SegmentGrid(const Polylines3& polylines, double cell) : cell_(cell) {
    for (const std::vector<Eigen::Vector3d>& polyline : polylines) {
      if (polyline.size() == 1) addPiece({polyline[0], polyline[0]});
      for (std::size_t i = 1; i < polyline.size(); ++i) {
        const Eigen::Vector3d& a = polyline[i - 1];
        const Eigen::Vector3d& b = polyline[i];
        const int pieces = boundedCount((b - a).norm(), cell_);
        for (int k = 0; k < pieces; ++k) {
          addPiece({a + (b - a) * (static_cast<double>(k) / pieces),
                    a + (b - a) * (static_cast<double>(k + 1) / pieces)});
        }
      }
    }
  }

  /// The distance from `p` to the nearest segment if it is at most the cell size, else infinity.
  double distanceWithinCell(const Eigen::Vector3d& p) const {
    const Eigen::Array3i centre = cellOf(p);
    double best2 = cell_ * cell_;
    bool found = false;
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(key(centre + Eigen::Array3i(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (const int piece : it->second) {
            const double d2 = squaredDistanceToSegment(p, pieces_[piece]);
            if (d2 <= best2) {
              best2 = d2;
              found = true;
            }
          }
        }
      }
    }
    return found ? std::sqrt(best2) : std::numeric_limits<double>::infinity();
  }

 private:
  Eigen::Array3i cellOf(const Eigen::Vector3d& p) const {
    // Far-away coordinates wrap in key(): that only adds candidates, never loses one.
    const Eigen::Array3d c = (p.array() / cell_).floor().cwiseMax(-1e9).cwiseMin(1e9);
    return c.cast<int>();
  }
  static std::uint64_t key(const Eigen::Array3i& c) {
    constexpr std::uint64_t kMask = (std::uint64_t{1} << 21) - 1;
    return ((static_cast<std::uint64_t>(c.x()) & kMask) << 42) |
           ((static_cast<std::uint64_t>(c.y()) & kMask) << 21) |
           (static_cast<std::uint64_t>(c.z()) & kMask);
  }
  void addPiece(const Segment& piece) {
    const int index = static_cast<int>(pieces_.size());
    pieces_.push_back(piece);
    const Eigen::Array3i lo = cellOf(piece.a.cwiseMin(piece.b));
    const Eigen::Array3i hi = cellOf(piece.a.cwiseMax(piece.b));
    for (int x = lo.x(); x <= hi.x(); ++x) {
      for (int y = lo.y(); y <= hi.y(); ++y) {
        for (int z = lo.z(); z <= hi.z(); ++z)
          cells_[key(Eigen::Array3i(x, y, z))].push_back(index);
      }
    }
  }

  double cell_;
  std::vector<Segment> pieces_;
  std::unordered_map<std::uint64_t, std::vector<int>> cells_;
};

// Calls visit(sample, length it stands for) for every sample of `polylines`: the midpoints of the
// n equal parts of each segment, n the fewest that keep a part within `spacing`. A one-point
// polyline is one sample of no length.
template <class Visit>
void forEachSample(const Polylines3& polylines, double spacing, Visit&& visit) {
  for (const std::vector<Eigen::Vector3d>& polyline : polylines) {
    if (polyline.size() == 1) visit(polyline[0], 0.0);
    for (std::size_t i = 1; i < polyline.size(); ++i) {
      const Eigen::Vector3d& a = polyline[i - 1];
      const Eigen::Vector3d& b = polyline[i];
      const double length = (b - a).norm();
      const int parts = boundedCount(length, spacing);
      for (int k = 0; k < parts; ++k) {
        visit(a + (b - a) * ((k + 0.5) / parts), length / parts);
      }
    }
  }
}

double safeFraction(double part, double whole) { return whole > 0.0 ? part / whole : 0.0; }

}  // namespace

CurveMapEvaluation evaluateCurveMap(const Polylines3& estimate, const Polylines3& ground_truth,
                                    const CurveMapEvaluationOptions& options) {
  options.validate();
  CurveMapEvaluation result;
  result.options = options;
  const std::vector<double>& taus = options.taus;
  result.sample_spacing =
      options.sample_spacing > 0.0 ? options.sample_spacing : 0.1 * taus.front();
  result.estimate_polylines = static_cast<int>(estimate.size());
  result.ground_truth_polylines = static_cast<int>(ground_truth.size());

  const double inf = std::numeric_limits<double>::infinity();
  result.crop_min = Eigen::Vector3d::Constant(inf);
  result.crop_max = Eigen::Vector3d::Constant(-inf);
  for (const std::vector<Eigen::Vector3d>& polyline : ground_truth) {
    for (const Eigen::Vector3d& p : polyline) {
      result.crop_min = result.crop_min.cwiseMin(p);
      result.crop_max = result.crop_max.cwiseMax(p);
    }
  }
  if (ground_truth.empty()) result.crop_min = result.crop_max = Eigen::Vector3d::Zero();
  result.crop_min.array() -= options.crop_margin;
  result.crop_max.array() += options.crop_margin;

  const std::size_t n = taus.size();
  std::vector<double> estimate_length_within(n, 0.0), ground_truth_length_within(n, 0.0);
  result.scores.resize(n);
  for (std::size_t i = 0; i < n; ++i) result.scores[i].tau = taus[i];

  // Precision: estimated samples inside the crop against the ground truth.
  {
    const SegmentGrid grid(ground_truth, taus.back());
    forEachSample(estimate, result.sample_spacing, [&](const Eigen::Vector3d& p, double length) {
      ++result.estimate_samples;
      result.estimate_length += length;
      const bool inside = !options.crop || ((p.array() >= result.crop_min.array()).all() &&
                                            (p.array() <= result.crop_max.array()).all());
      if (!inside) return;
      ++result.estimate_samples_inside;
      result.estimate_length_inside += length;
      const double d = grid.distanceWithinCell(p);
      for (std::size_t i = 0; i < n; ++i) {
        if (d > taus[i]) continue;
        ++result.scores[i].estimate_samples_within;
        estimate_length_within[i] += length;
      }
    });
  }
  // Recall: ground-truth samples against the whole estimate.
  {
    const SegmentGrid grid(estimate, taus.back());
    forEachSample(ground_truth, result.sample_spacing,
                  [&](const Eigen::Vector3d& p, double length) {
                    ++result.ground_truth_samples;
                    result.ground_truth_length += length;
                    const double d = grid.distanceWithinCell(p);
                    for (std::size_t i = 0; i < n; ++i) {
                      if (d > taus[i]) continue;
                      ++result.scores[i].ground_truth_samples_within;
                      ground_truth_length_within[i] += length;
                    }
                  });
  }
  for (std::size_t i = 0; i < n; ++i) {
    CurveMapScore& s = result.scores[i];
    s.precision = safeFraction(estimate_length_within[i], result.estimate_length_inside);
    s.recall = safeFraction(ground_truth_length_within[i], result.ground_truth_length);
    s.f_score = safeFraction(2.0 * s.precision * s.recall, s.precision + s.recall);
  }
  return result;
}

}  // namespace curvesfm
