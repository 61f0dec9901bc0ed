#include "factors/curve_statistics.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "core/angles.h"
#include "core/median.h"
#include "graph/key.h"

namespace curvesfm {
namespace {

constexpr int kLengthSamplesPerSegment = 16;

double arcLength(const PolyBezier& curve) {
  double length = 0.0;
  Eigen::Vector3d previous = curve.evaluate(0, 0.0);
  for (int i = 0; i < curve.numSegments(); ++i) {
    for (int k = 1; k <= kLengthSamplesPerSegment; ++k) {
      const Eigen::Vector3d p =
          curve.evaluate(i, static_cast<double>(k) / kLengthSamplesPerSegment);
      length += (p - previous).norm();
      previous = p;
    }
  }
  return length;
}

Eigen::Vector3d middleOf(const PolyBezier& curve) {
  const double t = 0.5 * curve.numSegments();
  const int i = std::min(static_cast<int>(t), curve.numSegments() - 1);
  return curve.evaluate(i, t - i);
}

// Camera distances and the widest ray angle at `point` over the centres given.
void viewingGeometry(const std::vector<Eigen::Vector3d>& centres, const Eigen::Vector3d& point,
                     CurveStatistics* s) {
  std::vector<double> distances;
  for (const Eigen::Vector3d& c : centres) distances.push_back((c - point).norm());
  s->median_camera_distance = upperMedian(distances);
  double widest = 0.0;
  for (std::size_t a = 0; a < centres.size(); ++a) {
    for (std::size_t b = a + 1; b < centres.size(); ++b) {
      const Eigen::Vector3d ra = centres[a] - point;
      const Eigen::Vector3d rb = centres[b] - point;
      widest = std::max(widest, std::atan2(ra.cross(rb).norm(), ra.dot(rb)));
    }
  }
  s->triangulation_angle_deg = widest * kRadToDeg;
}

// At most this many observing centres, spread evenly over the track, enter the epipolar angle
// (their pairs are tried per sample).
constexpr int kEpipolarCentres = 6;

// The widest angle (rad) over pairs of `centres` between `tangent` (unit) and the plane through
// `point` and the pair; 0 when no pair spans a plane with the point.
double widestEpipolarAngle(const std::vector<Eigen::Vector3d>& centres,
                           const Eigen::Vector3d& point, const Eigen::Vector3d& tangent) {
  double widest = 0.0;
  for (std::size_t a = 0; a < centres.size(); ++a) {
    for (std::size_t b = a + 1; b < centres.size(); ++b) {
      const Eigen::Vector3d normal = (centres[b] - centres[a]).cross(point - centres[a]);
      const double norm = normal.norm();
      if (norm <= 0.0) continue;
      widest = std::max(widest, std::asin(std::min(1.0, std::abs(normal.dot(tangent)) / norm)));
    }
  }
  return widest;
}

// CurveStatistics::epipolar_angle_deg of `curve` seen from `centres` (in track order).
double epipolarAngleDeg(const PolyBezier& curve, const std::vector<Eigen::Vector3d>& centres) {
  if (centres.size() < 2) return 90.0;
  std::vector<Eigen::Vector3d> spread;
  const std::size_t n = std::min<std::size_t>(centres.size(), kEpipolarCentres);
  for (std::size_t k = 0; k < n; ++k) spread.push_back(centres[k * (centres.size() - 1) / (n - 1)]);
  std::vector<double> angles;
  for (int i = 0; i < curve.numSegments(); ++i) {
    for (int k = 0; k < kLengthSamplesPerSegment; ++k) {
      const double t = (k + 0.5) / kLengthSamplesPerSegment;
      const Eigen::Vector3d tangent = curve.derivative(i, t);
      if (tangent.norm() <= 0.0) continue;
      angles.push_back(widestEpipolarAngle(spread, curve.evaluate(i, t), tangent.normalized()));
    }
  }
  return angles.empty() ? 90.0 : upperMedian(angles) * kRadToDeg;
}

// Sum of squared residuals over some samples.
struct SquaredResiduals {
  double squared = 0.0;
  int rows = 0;

  void add(const Eigen::VectorXd& error) {
    squared += error.squaredNorm();
    rows += static_cast<int>(error.size());
  }
  double rms() const { return rows > 0 ? std::sqrt(squared / rows) : 0.0; }
};

// The residual RMS over every keyframe, and the keyframe where it is largest.
void residualsOverKeyframes(const std::map<int, SquaredResiduals>& per_keyframe,
                            CurveStatistics* s) {
  SquaredResiduals total;
  double worst_rms = -1.0;
  for (const auto& [keyframe, residuals] : per_keyframe) {
    total.squared += residuals.squared;
    total.rows += residuals.rows;
    if (residuals.rms() > worst_rms) {
      worst_rms = residuals.rms();
      s->worst_keyframe = keyframe;
    }
  }
  s->residual_rms_px = total.rms();
}

// Sum of curve c's chords over the sum of its reference lengths (1 without references).
double chordRatio(const CurveBundleAdjustmentInput& input, std::size_t c) {
  if (input.segment_reference_lengths.empty()) return 1.0;
  const std::vector<Eigen::Vector3d>& q = input.curves[c].points();
  double chords = 0.0;
  for (std::size_t i = 0; i + 1 < q.size(); ++i) chords += (q[i + 1] - q[i]).norm();
  double reference = 0.0;
  for (const double length : input.segment_reference_lengths[c]) reference += length;
  return reference > 0.0 ? chords / reference : 1.0;
}

}  // namespace

std::vector<CurveStatistics> curveStatistics(const CurveBundleAdjustmentInput& input,
                                             const CurveBundleAdjustmentOptions& options) {
  const std::size_t n = input.curves.size();
  std::vector<CurveStatistics> stats(n);
  std::vector<std::set<int>> keyframes_of(n);
  for (const SegmentObservation& o : input.observations) {
    ++stats[o.curve].observations;
    keyframes_of[o.curve].insert(o.keyframe);
  }
  for (std::size_t c = 0; c < n; ++c) {
    CurveStatistics& s = stats[c];
    s.keyframes = static_cast<int>(keyframes_of[c].size());
    s.first_keyframe = keyframes_of[c].empty() ? -1 : *keyframes_of[c].begin();
    s.last_keyframe = keyframes_of[c].empty() ? -1 : *keyframes_of[c].rbegin();
    s.length = arcLength(input.curves[c]);
    s.chord_ratio = chordRatio(input, c);
    std::vector<Eigen::Vector3d> centres;
    for (int j : keyframes_of[c]) centres.push_back(input.cam_from_world[j].inverseTranslation());
    viewingGeometry(centres, middleOf(input.curves[c]), &s);
    s.epipolar_angle_deg = epipolarAngleDeg(input.curves[c], centres);
  }
  if (input.observations.empty()) return stats;

  const CurveBundleAdjustmentProblem problem = buildCurveBundleAdjustment(input, options);
  std::vector<std::map<int, SquaredResiduals>> residuals(n);  // Per curve, per keyframe.
  std::vector<std::map<int, Vector6d>> gradient(n);           // Per curve, per pose.
  for (const auto& factor : problem.graph) {
    const auto* edge = dynamic_cast<const CurveReprojectionFactor*>(factor.get());
    if (edge == nullptr) continue;
    const int pose = static_cast<int>(edge->keys()[0].index());
    const std::size_t c = edge->keys()[1].index();
    const Linearization l = edge->linearize(problem.values);
    const NoiseModel& noise = edge->noiseModel();
    double rho[3];
    noise.kernel.evaluate(l.error.squaredNorm() / (noise.sigma * noise.sigma), rho);
    const Vector6d g = rho[1] * l.jacobians[0].transpose() * l.error / (noise.sigma * noise.sigma);
    // The gauge's first pose is held by the solver: nothing can pull it anywhere.
    const bool held =
        problem.config.isConstant(edge->keys()[0]) || (options.fix_first_pose && pose == 0);
    if (!held) {
      auto [entry, inserted] = gradient[c].emplace(pose, g);
      if (!inserted) entry->second += g;
    }
    residuals[c][pose].add(l.error);
  }
  double total_pull = 0.0;
  for (std::size_t c = 0; c < n; ++c) {
    residualsOverKeyframes(residuals[c], &stats[c]);
    for (const auto& [pose, g] : gradient[c]) stats[c].pose_pull += g.norm();
    total_pull += stats[c].pose_pull;
  }
  for (CurveStatistics& s : stats) {
    s.pose_pull_share = total_pull > 0.0 ? s.pose_pull / total_pull : 0.0;
  }
  return stats;
}

}  // namespace curvesfm
