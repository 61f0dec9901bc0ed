#include "core/bezier_fit.h"

#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <initializer_list>
#include <utility>

#include "core/check.h"

namespace curvesfm {
namespace {

// Below this norm relative to the segment's chord an arm carries no usable direction.
constexpr double kMinRelativeArm = 1e-9;
// Direction() rejects norms at or below 1e-12; stay clear of that bound.
constexpr double kMinAbsoluteNorm = 1e-11;
// Two unit tangents whose sum is shorter than this are (numerically) opposite: a cusp.
constexpr double kMinTangentSum = 1e-6;
// Length floors: relative to the linked chord, and absolute for a collapsed segment.
constexpr double kMinRelativeLength = 1e-3;
constexpr double kMinAbsoluteLength = 1e-9;

Eigen::Matrix<double, 4, Eigen::Dynamic> buildSolutionOperator(int m) {
  const Eigen::MatrixXd basis = uniformBernsteinWeights(m).transpose();  // A, m x 4.
  // QR keeps the conditioning of A instead of squaring it as the normal equations would:
  // S = R^{-1} Q1^T with Q1 the thin (m x 4) orthonormal factor.
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(basis);
  const Eigen::MatrixXd thin_q = qr.householderQ() * Eigen::MatrixXd::Identity(m, 4);
  return qr.matrixQR().topLeftCorner<4, 4>().triangularView<Eigen::Upper>().solve(
      thin_q.transpose());
}

// The first candidate long enough to normalise safely; +x if all of them are degenerate, which
// only happens for a curve collapsed to a single point.
Direction firstUsableDirection(std::initializer_list<Eigen::Vector3d> candidates) {
  for (const Eigen::Vector3d& candidate : candidates) {
    if (candidate.norm() > kMinAbsoluteNorm) return Direction(candidate);
  }
  return Direction(Eigen::Vector3d::UnitX());
}

// An arm that is tiny next to its chord has a direction dominated by fitting noise, so the
// chord (and then the whole curve's chord) is the more faithful tangent.
Direction armDirection(const Eigen::Vector3d& arm, const Eigen::Vector3d& chord,
                       const Eigen::Vector3d& curve_chord) {
  if (arm.norm() > kMinRelativeArm * chord.norm()) {
    return firstUsableDirection({arm, chord, curve_chord});
  }
  return firstUsableDirection({chord, curve_chord});
}

double flooredLength(double length, const Eigen::Vector3d& chord) {
  return std::max({length, kMinRelativeLength * chord.norm(), kMinAbsoluteLength});
}

}  // namespace

const Eigen::Matrix<double, 4, Eigen::Dynamic>& BezierFitter::solutionOperator(int m) const {
  CURVESFM_CHECK(m >= 4) << "a cubic Bezier fit needs at least 4 points, got " << m;
  const std::lock_guard<std::mutex> lock(mutex_);
  auto it = operators_.find(m);
  if (it == operators_.end()) it = operators_.emplace(m, buildSolutionOperator(m)).first;
  return it->second;
}

CubicBezier BezierFitter::fit(const std::vector<Eigen::Vector3d>& points) const {
  CURVESFM_CHECK(points.size() >= 4)
      << "a cubic Bezier fit needs at least 4 points, got " << points.size();
  return fit(points.data(), static_cast<int>(points.size()));
}

CubicBezier BezierFitter::fit(const Eigen::Vector3d* first, int m) const {
  const Eigen::Matrix<double, 4, Eigen::Dynamic>& solution = solutionOperator(m);
  CubicBezier cubic;
  cubic.control.fill(Eigen::Vector3d::Zero());
  for (int k = 0; k < m; ++k) {
    for (int j = 0; j < 4; ++j) cubic.control[j] += solution(j, k) * first[k];
  }
  return cubic;
}

int BezierFitter::cacheSize() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(operators_.size());
}

const BezierFitter& BezierFitter::shared() {
  static const BezierFitter fitter;
  return fitter;
}

PolyBezier linkSegments(const std::vector<CubicBezier>& fitted) {
  CURVESFM_CHECK(!fitted.empty()) << "linking needs at least one fitted segment";
  const int n = static_cast<int>(fitted.size());
  for (int i = 0; i < n; ++i) {
    for (const Eigen::Vector3d& p : fitted[i].control) {
      CURVESFM_CHECK(p.allFinite()) << "fitted segment " << i << " has a non-finite control point";
    }
  }

  std::vector<Eigen::Vector3d> points(n + 1);
  points[0] = fitted[0].control[0];
  for (int i = 1; i <= n; ++i) points[i] = fitted[i - 1].control[3];
  const Eigen::Vector3d curve_chord = points[n] - points[0];

  // Unit start and end tangents of every segment, measured on the fitted arms but judged
  // against the linked chord, which is the geometry the curve will actually have.
  std::vector<Direction> starts;
  std::vector<Direction> ends;
  std::vector<SegmentLengths> lengths(n);
  starts.reserve(n);
  ends.reserve(n);
  for (int i = 0; i < n; ++i) {
    const std::array<Eigen::Vector3d, 4>& p = fitted[i].control;
    const Eigen::Vector3d chord = points[i + 1] - points[i];
    starts.push_back(armDirection(p[1] - p[0], chord, curve_chord));
    ends.push_back(armDirection(p[3] - p[2], chord, curve_chord));
    lengths[i] = {flooredLength((p[1] - p[0]).norm(), chord),
                  flooredLength((p[3] - p[2]).norm(), chord)};
  }

  std::vector<Direction> directions;
  directions.reserve(n + 1);
  directions.push_back(starts[0]);
  for (int i = 1; i < n; ++i) {
    const Eigen::Vector3d sum = ends[i - 1].vector() + starts[i].vector();
    if (sum.norm() > kMinTangentSum) {
      directions.emplace_back(sum);
    } else {
      // At a cusp the mean is undefined; the central chord through the link point is the
      // tangent a smooth curve through the three points would have.
      directions.push_back(
          firstUsableDirection({points[i + 1] - points[i - 1], curve_chord, starts[i].vector()}));
    }
  }
  directions.push_back(ends[n - 1]);
  return PolyBezier(std::move(points), std::move(directions), std::move(lengths));
}

}  // namespace curvesfm
