#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "core/direction.h"
#include "core/eigen_types.h"

namespace curvesfm {

// Cubic Bézier curves and the smooth poly-Bézier of the paper (§2.1-2.2, eq. 2 and 3).
//
// All points are in one Euclidean frame chosen by the caller (usually the world frame) and in
// its length unit; the curve parameter t is dimensionless and lives in [0, 1] per segment
// (values outside extrapolate the cubic polynomial). Nothing here allocates on the heap except
// PolyBezier's construction and PolyBezier::sample(), so the evaluation functions can run in the
// inner loop of bundle adjustment.

/// Cubic Bernstein weights at t (paper eq. 2):
///   [(1-t)^3, 3(1-t)^2 t, 3(1-t) t^2, t^3].
/// They sum to 1 for every t; at t = 0 and t = 1 they are exactly e0 and e3.
Eigen::Vector4d bernsteinWeights(double t);

/// d/dt of bernsteinWeights(t): [-3(1-t)^2, 3(1-t)(1-3t), 3t(2-3t), 3t^2]. They sum to 0.
Eigen::Vector4d bernsteinDerivativeWeights(double t);

/// Bernstein weights at m uniformly spaced parameters t_k = k / (m-1), k = 0..m-1, as the
/// columns of a 4 x m matrix (the transpose of the fitting basis matrix of paper §2.3).
/// Requires m >= 2 (CheckError otherwise). Allocates: call it once per sample set, not per
/// evaluation.
Eigen::Matrix4Xd uniformBernsteinWeights(int m);

/// A cubic Bézier curve given by its four control points (paper eq. 2):
///   B(t) = sum_k w_k(t) P_k, with w = bernsteinWeights(t).
/// B(0) = P0, B(1) = P3, B'(0) = 3 (P1 - P0), B'(1) = 3 (P3 - P2).
struct CubicBezier {
  std::array<Eigen::Vector3d, 4> control;  ///< P0..P3, in the caller's frame and length unit.

  /// B(t). Exactly P0 at t = 0 and exactly P3 at t = 1.
  Eigen::Vector3d evaluate(double t) const { return weightedSum(bernsteinWeights(t)); }

  /// dB/dt at t (length unit per unit of t).
  Eigen::Vector3d derivative(double t) const { return weightedSum(bernsteinDerivativeWeights(t)); }

  /// sum_k weights[k] P_k: B(t) for weights = bernsteinWeights(t), B'(t) for the derivative
  /// weights. Lets a caller that evaluates the same t many times precompute the weights.
  Eigen::Vector3d weightedSum(const Eigen::Vector4d& weights) const {
    return weights[0] * control[0] + weights[1] * control[1] + weights[2] * control[2] +
           weights[3] * control[3];
  }
};

/// The latent variables of one segment of a smooth poly-Bézier (paper eq. 3, DESIGN.md
/// "The curve model"): start point q0 = Q_i, end point q1 = Q_{i+1}, unit tangents v0 = v_i and
/// v1 = v_{i+1}, and arm lengths d1 = d1_i, d2 = d2_i. Control points:
///   P0 = q0,  P1 = q0 + d1 v0,  P2 = q1 - d2 v1,  P3 = q1.
/// The lengths should be positive (PolyBezier enforces it); the formulas stay defined, and the
/// evaluation never throws, if an optimiser momentarily makes them zero or negative.
struct BezierSegmentParams {
  Eigen::Vector3d q0 = Eigen::Vector3d::Zero();  ///< Start point Q_i.
  Eigen::Vector3d q1 = Eigen::Vector3d::Zero();  ///< End point Q_{i+1}.
  Direction v0;                                  ///< Unit tangent at the start, v_i.
  Direction v1;                                  ///< Unit tangent at the end, v_{i+1}.
  double d1 = 1.0;  ///< Start arm length |P1 - P0|, in the length unit.
  double d2 = 1.0;  ///< End arm length |P3 - P2|, in the length unit.

  /// The four control points P0..P3 defined above.
  CubicBezier toCubic() const;
};

/// Jacobians of a segment point B = sum_k w_k P_k (with the weights w of evaluateSegment) w.r.t.
/// the segment variables. Expanding the control points,
///   B = (w0 + w1) q0 + (w2 + w3) q1 + w1 d1 v0 - w2 d2 v1,
/// so:
///   dB/dq0 = (w0 + w1) I          (3x3, stored as the scalar scale_q0)
///   dB/dq1 = (w2 + w3) I          (3x3, stored as the scalar scale_q1)
///   dB/dv0 = w1 d1 basis(v0)      (3x2, in the Direction tangent space, see Direction::retract)
///   dB/dv1 = -w2 d2 basis(v1)     (3x2, in the Direction tangent space)
///   dB/dd1 = w1 v0                (3x1)
///   dB/dd2 = -w2 v1               (3x1)
/// The point Jacobians are kept as scalars so that a factor can chain a 1x3 or 2x3 Jacobian
/// through them with a scalar multiply instead of a 3x3 product.
struct SegmentJacobians {
  double scale_q0 = 0.0;                           ///< dB/dq0 = scale_q0 * I.
  double scale_q1 = 0.0;                           ///< dB/dq1 = scale_q1 * I.
  Matrix32d H_v0 = Matrix32d::Zero();              ///< dB/dv0 in the tangent space of v0.
  Matrix32d H_v1 = Matrix32d::Zero();              ///< dB/dv1 in the tangent space of v1.
  Eigen::Vector3d H_d1 = Eigen::Vector3d::Zero();  ///< dB/dd1.
  Eigen::Vector3d H_d2 = Eigen::Vector3d::Zero();  ///< dB/dd2.

  /// dB/dq0 as a 3x3 matrix.
  Eigen::Matrix3d H_q0() const { return scale_q0 * Eigen::Matrix3d::Identity(); }
  /// dB/dq1 as a 3x3 matrix.
  Eigen::Matrix3d H_q1() const { return scale_q1 * Eigen::Matrix3d::Identity(); }
};

/// Evaluates sum_k weights[k] P_k for the segment `params` and, when H is non-null, fills all of
/// its Jacobians (see SegmentJacobians).
///
/// `weights` are Bernstein weights precomputed by the caller: bernsteinWeights(t) gives the point
/// B(t); bernsteinDerivativeWeights(t) gives the tangent B'(t) and its Jacobians, since both are
/// linear in the weights. Allocation-free and exception-free. Without H it costs one 4-term
/// weighted sum; with H it also computes the two tangent bases (use SegmentEvaluator to compute
/// them once for many samples of the same segment).
Eigen::Vector3d evaluateSegment(const BezierSegmentParams& params, const Eigen::Vector4d& weights,
                                SegmentJacobians* H = nullptr);

/// A segment prepared for evaluating many samples with Jacobians: the arms d1 v0, d2 v1 and the
/// scaled tangent bases d1 basis(v0), d2 basis(v1) are computed once at construction. evaluate()
/// returns exactly what evaluateSegment() returns for the same parameters, up to rounding.
/// A plain value (fixed-size members only), cheap to build on the stack per factor evaluation.
class SegmentEvaluator {
 public:
  explicit SegmentEvaluator(const BezierSegmentParams& params);

  /// Same contract as evaluateSegment(params, weights, H).
  Eigen::Vector3d evaluate(const Eigen::Vector4d& weights, SegmentJacobians* H = nullptr) const;

 private:
  Eigen::Vector3d q0_;
  Eigen::Vector3d q1_;
  Eigen::Vector3d v0_;
  Eigen::Vector3d v1_;
  Eigen::Vector3d arm0_;  // d1 v0 = P1 - P0.
  Eigen::Vector3d arm1_;  // d2 v1 = P3 - P2.
  Matrix32d arm0_basis_;  // d1 basis(v0).
  Matrix32d arm1_basis_;  // d2 basis(v1).
};

/// Arm lengths of one poly-Bézier segment: P1 - P0 = d1 v_i, P3 - P2 = d2 v_{i+1}.
struct SegmentLengths {
  double d1 = 1.0;  ///< Start arm length, > 0, in the length unit.
  double d2 = 1.0;  ///< End arm length, > 0, in the length unit.
};

/// A smooth poly-Bézier curve (paper §2.2): n >= 1 cubic segments over n+1 points Q_0..Q_n,
/// n+1 unit tangents v_0..v_n and n arm-length pairs (d1_i, d2_i). Segment i runs from Q_i to
/// Q_{i+1} with the control points of BezierSegmentParams, so neighbours share the end point
/// (C0) and the tangent direction (G1) by construction.
class PolyBezier {
 public:
  /// Throws CheckError unless points.size() >= 2, directions.size() == points.size(),
  /// lengths.size() == points.size() - 1, every point is finite and every length is finite and
  /// strictly positive.
  PolyBezier(std::vector<Eigen::Vector3d> points, std::vector<Direction> directions,
             std::vector<SegmentLengths> lengths);

  /// n, the number of cubic segments.
  int numSegments() const { return static_cast<int>(lengths_.size()); }
  /// n + 1, the number of shared points (and of tangents).
  int numPoints() const { return static_cast<int>(points_.size()); }

  const std::vector<Eigen::Vector3d>& points() const { return points_; }
  const std::vector<Direction>& directions() const { return directions_; }
  const std::vector<SegmentLengths>& lengths() const { return lengths_; }

  /// Replace Q_i (i in [0, n]); throws CheckError on a bad index or a non-finite point.
  void setPoint(int i, const Eigen::Vector3d& point);
  /// Replace v_i (i in [0, n]); throws CheckError on a bad index.
  void setDirection(int i, const Direction& direction);
  /// Replace (d1_i, d2_i) (i in [0, n-1]); throws CheckError on a bad index or a length that is
  /// not finite and strictly positive.
  void setLengths(int i, const SegmentLengths& lengths);

  /// The latent variables of segment i (i in [0, n-1]; CheckError otherwise).
  BezierSegmentParams segment(int i) const;
  /// The control points of segment i (i in [0, n-1]; CheckError otherwise).
  CubicBezier controlPoints(int i) const { return segment(i).toCubic(); }

  /// B_i(t), the point of segment i at t in [0, 1]. evaluate(i, 1) == evaluate(i + 1, 0) exactly.
  Eigen::Vector3d evaluate(int i, double t) const;
  /// dB_i/dt at t in [0, 1].
  Eigen::Vector3d derivative(int i, double t) const;

  /// Dense polyline along the curve: each segment at t = k / samples_per_segment for
  /// k = 0..samples_per_segment-1, then the final point Q_n, so shared end points appear once
  /// and the result has n * samples_per_segment + 1 points. samples_per_segment >= 1
  /// (1 gives exactly Q_0..Q_n). Allocates; meant for export and visualisation.
  std::vector<Eigen::Vector3d> sample(int samples_per_segment) const;

 private:
  void checkSegmentIndex(int i) const;
  void checkPointIndex(int i) const;

  std::vector<Eigen::Vector3d> points_;
  std::vector<Direction> directions_;
  std::vector<SegmentLengths> lengths_;
};

/// The number of segments of all `curves` together.
int totalSegments(const std::vector<PolyBezier>& curves);

/// One of the two ends of a poly-Bézier.
enum class CurveEnd {
  kFront,  ///< Q_0, where segment 0 starts.
  kBack,   ///< Q_n, where segment n-1 ends.
};

/// The point at `end`: Q_0 or Q_n.
const Eigen::Vector3d& endPoint(const PolyBezier& curve, CurveEnd end);
/// The unit tangent at `end` pointing away from the curve: -v_0 at the front, v_n at the back.
Eigen::Vector3d outwardTangent(const PolyBezier& curve, CurveEnd end);
/// The segment that touches `end`: 0 or n-1.
int endSegment(const PolyBezier& curve, CurveEnd end);

/// The same curve traversed the other way: Q_n..Q_0, tangents negated, and each segment's arm
/// lengths swapped. Point for point, segment n-1-i at 1 - t equals segment i at t.
PolyBezier reversed(const PolyBezier& curve);

/// The curve that runs along `head`, then along `tail`: head's segments, then tail's. The join
/// is head's last point and tangent; tail's first point and tangent are dropped, so tail's
/// first segment starts at head's end with its own arm lengths (exactly tail's segment when
/// they already coincide).
PolyBezier concatenate(const PolyBezier& head, const PolyBezier& tail);

}  // namespace curvesfm
