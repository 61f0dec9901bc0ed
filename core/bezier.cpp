#include "core/bezier.h"

#include <cmath>
#include <utility>

#include "core/check.h"

namespace curvesfm {
namespace {

bool isPositiveLength(double d) { return std::isfinite(d) && d > 0.0; }

}  // namespace

Eigen::Vector4d bernsteinWeights(double t) {
  const double s = 1.0 - t;
  // Computing s once keeps the end cases exact: at t = 1, s is exactly 0 and w = e3.
  return Eigen::Vector4d(s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t);
}

Eigen::Vector4d bernsteinDerivativeWeights(double t) {
  const double s = 1.0 - t;
  return Eigen::Vector4d(-3.0 * s * s, 3.0 * s * (1.0 - 3.0 * t), 3.0 * t * (2.0 - 3.0 * t),
                         3.0 * t * t);
}

Eigen::Matrix4Xd uniformBernsteinWeights(int m) {
  CURVESFM_CHECK(m >= 2) << "uniform Bernstein weights need at least 2 samples, got " << m;
  Eigen::Matrix4Xd weights(4, m);
  const double step = 1.0 / static_cast<double>(m - 1);
  for (int k = 0; k < m; ++k) {
    // The last column uses t = 1 exactly rather than (m-1) * step, which may round below 1.
    const double t = k == m - 1 ? 1.0 : static_cast<double>(k) * step;
    weights.col(k) = bernsteinWeights(t);
  }
  return weights;
}

CubicBezier BezierSegmentParams::toCubic() const {
  return CubicBezier{{q0, q0 + d1 * v0.vector(), q1 - d2 * v1.vector(), q1}};
}

Eigen::Vector3d evaluateSegment(const BezierSegmentParams& params, const Eigen::Vector4d& weights,
                                SegmentJacobians* H) {
  if (H != nullptr) return SegmentEvaluator(params).evaluate(weights, H);
  return params.toCubic().weightedSum(weights);
}

SegmentEvaluator::SegmentEvaluator(const BezierSegmentParams& params)
    : q0_(params.q0),
      q1_(params.q1),
      v0_(params.v0.vector()),
      v1_(params.v1.vector()),
      arm0_(params.d1 * params.v0.vector()),
      arm1_(params.d2 * params.v1.vector()),
      arm0_basis_(params.d1 * params.v0.basis()),
      arm1_basis_(params.d2 * params.v1.basis()) {}

Eigen::Vector3d SegmentEvaluator::evaluate(const Eigen::Vector4d& weights,
                                           SegmentJacobians* H) const {
  // Grouping by variable (rather than summing the four control points) gives the point and the
  // Jacobian coefficients from the same scalars.
  const double scale_q0 = weights[0] + weights[1];
  const double scale_q1 = weights[2] + weights[3];
  if (H != nullptr) {
    H->scale_q0 = scale_q0;
    H->scale_q1 = scale_q1;
    H->H_v0 = weights[1] * arm0_basis_;
    H->H_v1 = -weights[2] * arm1_basis_;
    H->H_d1 = weights[1] * v0_;
    H->H_d2 = -weights[2] * v1_;
  }
  return scale_q0 * q0_ + scale_q1 * q1_ + weights[1] * arm0_ - weights[2] * arm1_;
}

PolyBezier::PolyBezier(std::vector<Eigen::Vector3d> points, std::vector<Direction> directions,
                       std::vector<SegmentLengths> lengths)
    : points_(std::move(points)), directions_(std::move(directions)), lengths_(std::move(lengths)) {
  CURVESFM_CHECK(points_.size() >= 2)
      << "a poly-Bezier needs at least 2 points (1 segment), got " << points_.size();
  CURVESFM_CHECK(directions_.size() == points_.size())
      << "expected one direction per point (" << points_.size() << "), got " << directions_.size();
  CURVESFM_CHECK(lengths_.size() + 1 == points_.size())
      << "expected one length pair per segment (" << points_.size() - 1 << "), got "
      << lengths_.size();
  for (int i = 0; i < numPoints(); ++i) {
    CURVESFM_CHECK(points_[i].allFinite()) << "point " << i << " is not finite";
  }
  for (int i = 0; i < numSegments(); ++i) {
    CURVESFM_CHECK(isPositiveLength(lengths_[i].d1) && isPositiveLength(lengths_[i].d2))
        << "segment " << i << " lengths must be finite and > 0, got d1 = " << lengths_[i].d1
        << ", d2 = " << lengths_[i].d2;
  }
}

void PolyBezier::checkSegmentIndex(int i) const {
  CURVESFM_CHECK(i >= 0 && i < numSegments())
      << "segment index " << i << " outside [0, " << numSegments() << ")";
}

void PolyBezier::checkPointIndex(int i) const {
  CURVESFM_CHECK(i >= 0 && i < numPoints())
      << "point index " << i << " outside [0, " << numPoints() << ")";
}

void PolyBezier::setPoint(int i, const Eigen::Vector3d& point) {
  checkPointIndex(i);
  CURVESFM_CHECK(point.allFinite()) << "point " << i << " is not finite";
  points_[i] = point;
}

void PolyBezier::setDirection(int i, const Direction& direction) {
  checkPointIndex(i);
  directions_[i] = direction;
}

void PolyBezier::setLengths(int i, const SegmentLengths& lengths) {
  checkSegmentIndex(i);
  CURVESFM_CHECK(isPositiveLength(lengths.d1) && isPositiveLength(lengths.d2))
      << "segment " << i << " lengths must be finite and > 0, got d1 = " << lengths.d1
      << ", d2 = " << lengths.d2;
  lengths_[i] = lengths;
}

BezierSegmentParams PolyBezier::segment(int i) const {
  checkSegmentIndex(i);
  return BezierSegmentParams{points_[i],         points_[i + 1], directions_[i],
                             directions_[i + 1], lengths_[i].d1, lengths_[i].d2};
}

Eigen::Vector3d PolyBezier::evaluate(int i, double t) const { return controlPoints(i).evaluate(t); }

Eigen::Vector3d PolyBezier::derivative(int i, double t) const {
  return controlPoints(i).derivative(t);
}

std::vector<Eigen::Vector3d> PolyBezier::sample(int samples_per_segment) const {
  CURVESFM_CHECK(samples_per_segment >= 1)
      << "samples_per_segment must be >= 1, got " << samples_per_segment;
  std::vector<Eigen::Vector3d> samples;
  samples.reserve(static_cast<size_t>(numSegments()) * samples_per_segment + 1);
  const double step = 1.0 / static_cast<double>(samples_per_segment);
  for (int i = 0; i < numSegments(); ++i) {
    const CubicBezier cubic = controlPoints(i);
    for (int k = 0; k < samples_per_segment; ++k) {
      samples.push_back(cubic.evaluate(static_cast<double>(k) * step));
    }
  }
  // Each segment's t = 1 is the next segment's t = 0; only the last one is not yet in the list.
  samples.push_back(points_.back());
  return samples;
}

int totalSegments(const std::vector<PolyBezier>& curves) {
  int segments = 0;
  for (const PolyBezier& curve : curves) segments += curve.numSegments();
  return segments;
}

const Eigen::Vector3d& endPoint(const PolyBezier& curve, CurveEnd end) {
  return end == CurveEnd::kFront ? curve.points().front() : curve.points().back();
}

Eigen::Vector3d outwardTangent(const PolyBezier& curve, CurveEnd end) {
  return end == CurveEnd::kFront ? Eigen::Vector3d(-curve.directions().front().vector())
                                 : curve.directions().back().vector();
}

int endSegment(const PolyBezier& curve, CurveEnd end) {
  return end == CurveEnd::kFront ? 0 : curve.numSegments() - 1;
}

PolyBezier reversed(const PolyBezier& curve) {
  std::vector<Eigen::Vector3d> points(curve.points().rbegin(), curve.points().rend());
  std::vector<Direction> directions;
  for (auto it = curve.directions().rbegin(); it != curve.directions().rend(); ++it) {
    directions.emplace_back(-it->vector());
  }
  std::vector<SegmentLengths> lengths;
  for (auto it = curve.lengths().rbegin(); it != curve.lengths().rend(); ++it) {
    lengths.push_back({it->d2, it->d1});
  }
  return PolyBezier(std::move(points), std::move(directions), std::move(lengths));
}

PolyBezier concatenate(const PolyBezier& head, const PolyBezier& tail) {
  std::vector<Eigen::Vector3d> points = head.points();
  points.insert(points.end(), tail.points().begin() + 1, tail.points().end());
  std::vector<Direction> directions = head.directions();
  directions.insert(directions.end(), tail.directions().begin() + 1, tail.directions().end());
  std::vector<SegmentLengths> lengths = head.lengths();
  lengths.insert(lengths.end(), tail.lengths().begin(), tail.lengths().end());
  return PolyBezier(std::move(points), std::move(directions), std::move(lengths));
}

}  // namespace curvesfm
