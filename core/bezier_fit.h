#pragma once

#include <Eigen/Core>
#include <map>
#include <mutex>
#include <vector>

#include "core/bezier.h"

namespace curvesfm {

/// Linear least-squares fit of one cubic Bézier segment to m >= 4 ordered 3D points (paper §2.3).
///
/// Point k is assigned the curve parameter t_k = k / (m-1), and the control points solve
///   min_X || A X - p ||^2,   A (m x 4) with A(k, j) = bernsteinWeights(t_k)[j],
/// X (4 x 3) the control points as rows and p (m x 3) the points as rows. A depends only on m,
/// so the solution operator S = (A^T A)^{-1} A^T (4 x m) is computed once per m (through a
/// Householder QR of A, not the normal equations) and cached; a fit is then X = S p.
///
/// Complexity: building S for a new m costs O(m) time and stores 4 m doubles; every fit costs
/// O(m) (12 m multiply-adds). The cache is keyed by m and never shrinks; m is a segment's pixel
/// count, so in practice it holds a few hundred entries at most.
///
/// Thread-safe: fit() and solutionOperator() may be called concurrently; a mutex guards the cache
/// and the references it hands out stay valid for the fitter's lifetime (entries are never
/// erased or moved). Not copyable (it owns the mutex).
class BezierFitter {
 public:
  BezierFitter() = default;
  BezierFitter(const BezierFitter&) = delete;
  BezierFitter& operator=(const BezierFitter&) = delete;

  /// The 4 x m solution operator S for m points; column k weighs point k. Throws CheckError if
  /// m < 4 (a cubic has 4 control points, fewer points leave it undetermined).
  const Eigen::Matrix<double, 4, Eigen::Dynamic>& solutionOperator(int m) const;

  /// Control points fitted to `points` (m = points.size() >= 4, CheckError otherwise), in the
  /// points' frame and unit. Exact (to rounding) when the points lie on a cubic Bézier at the
  /// parameters t_k; m = 4 interpolates the points.
  CubicBezier fit(const std::vector<Eigen::Vector3d>& points) const;

  /// Same as fit() on the m consecutive points starting at `first`, e.g. one segment of a longer
  /// chain without copying it.
  CubicBezier fit(const Eigen::Vector3d* first, int m) const;

  /// Number of distinct m whose operator is cached.
  int cacheSize() const;

  /// A process-wide fitter, for callers with no reason to own one.
  static const BezierFitter& shared();

 private:
  mutable std::mutex mutex_;
  mutable std::map<int, Eigen::Matrix<double, 4, Eigen::Dynamic>> operators_;
};

/// Links independently fitted segments into a smooth poly-Bézier (paper §2.3, DESIGN.md):
///   Q_0 = fitted[0].P0, Q_i = fitted[i-1].P3 (i = 1..n; the paper replaces each segment's first
///   control point by the previous segment's last one), so Q_n = fitted[n-1].P3;
///   v_i = normalised mean of the unit end tangent of fitted[i-1] (P3 - P2) and the unit start
///   tangent of fitted[i] (P1 - P0) for interior i; v_0 and v_n from their single adjacent arm;
///   d1_i = |P1 - P0| and d2_i = |P3 - P2| of fitted[i].
///
/// Degenerate cases, so that the result is always a valid PolyBezier:
/// - An arm no longer than 1e-9 times the linked chord |Q_{i+1} - Q_i|, or than 1e-11 in absolute
///   terms (P1 == P0, say), has no usable direction; the linked chord of that segment replaces it.
/// - Two unit tangents at an interior point that (nearly) cancel (|sum| < 1e-6, a cusp) are
///   replaced by the direction of Q_{i+1} - Q_{i-1}.
/// - A zero chord as well (all points of a segment equal) falls back to the direction from Q_0
///   to Q_n, and finally to +x for a curve collapsed to one point.
/// - Lengths are floored at 1e-3 times the linked chord of their segment, and at 1e-9 in absolute
///   terms, so they stay strictly positive.
/// Throws CheckError if `fitted` is empty or holds a non-finite control point.
PolyBezier linkSegments(const std::vector<CubicBezier>& fitted);

}  // namespace curvesfm
