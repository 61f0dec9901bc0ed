#include "core/bezier.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "core/errors.h"

namespace curvesfm {
namespace {

constexpr double kStep = 1e-6;  // Central-difference step.

Eigen::Vector3d randomVector(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> uniform(-scale, scale);
  return Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng));
}

Direction randomDirection(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  return Direction(Eigen::Vector3d(normal(rng), normal(rng), normal(rng)));
}

BezierSegmentParams randomSegment(std::mt19937& rng) {
  std::uniform_real_distribution<double> length(0.1, 3.0);
  BezierSegmentParams params;
  params.q0 = randomVector(rng, 5.0);
  params.q1 = randomVector(rng, 5.0);
  params.v0 = randomDirection(rng);
  params.v1 = randomDirection(rng);
  params.d1 = length(rng);
  params.d2 = length(rng);
  return params;
}

CubicBezier randomCubic(std::mt19937& rng) {
  return CubicBezier{{randomVector(rng, 5.0), randomVector(rng, 5.0), randomVector(rng, 5.0),
                      randomVector(rng, 5.0)}};
}

// Central differences of a 3-vector function of an N-vector perturbation around 0.
template <int N, class Function>
Eigen::Matrix<double, 3, N> numericalJacobian(const Function& f) {
  Eigen::Matrix<double, 3, N> jacobian;
  for (int k = 0; k < N; ++k) {
    Eigen::Matrix<double, N, 1> delta = Eigen::Matrix<double, N, 1>::Zero();
    delta[k] = kStep;
    jacobian.col(k) = (f(delta) - f(-delta)) / (2.0 * kStep);
  }
  return jacobian;
}

// Approximate equality with a tolerance relative to the magnitude of the expected value.
template <class A, class B>
::testing::AssertionResult nearlyEqual(const A& actual, const B& expected, double tolerance) {
  const double error = (actual - expected).cwiseAbs().maxCoeff();
  const double scale = 1.0 + expected.cwiseAbs().maxCoeff();
  if (error <= tolerance * scale) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "max error " << error << " > " << tolerance * scale << "\nactual:\n"
         << actual << "\nexpected:\n"
         << expected;
}

TEST(Bernstein, WeightsArePositiveAndSumToOne) {
  for (int k = 0; k <= 100; ++k) {
    const double t = k / 100.0;
    const Eigen::Vector4d w = bernsteinWeights(t);
    EXPECT_NEAR(w.sum(), 1.0, 1e-15) << "t = " << t;
    EXPECT_GE(w.minCoeff(), 0.0) << "t = " << t;
  }
}

TEST(Bernstein, WeightsAreExactAtTheEnds) {
  EXPECT_EQ(bernsteinWeights(0.0), Eigen::Vector4d(1.0, 0.0, 0.0, 0.0));
  EXPECT_EQ(bernsteinWeights(1.0), Eigen::Vector4d(0.0, 0.0, 0.0, 1.0));
}

TEST(Bernstein, HandComputedValueAtOneHalf) {
  EXPECT_TRUE(bernsteinWeights(0.5).isApprox(Eigen::Vector4d(0.125, 0.375, 0.375, 0.125)));
  EXPECT_TRUE(bernsteinDerivativeWeights(0.5).isApprox(Eigen::Vector4d(-0.75, -0.75, 0.75, 0.75)));
}

TEST(Bernstein, DerivativeWeightsMatchCentralDifferences) {
  for (int k = 0; k <= 50; ++k) {
    const double t = -0.2 + 1.4 * k / 50.0;  // Beyond [0, 1] too: they are polynomials.
    const Eigen::Vector4d numerical =
        (bernsteinWeights(t + kStep) - bernsteinWeights(t - kStep)) / (2.0 * kStep);
    EXPECT_TRUE(nearlyEqual(bernsteinDerivativeWeights(t), numerical, 1e-8)) << "t = " << t;
    EXPECT_NEAR(bernsteinDerivativeWeights(t).sum(), 0.0, 1e-14);
  }
}

TEST(Bernstein, UniformWeightsAreColumnsAtUniformParameters) {
  const int m = 7;
  const Eigen::Matrix4Xd weights = uniformBernsteinWeights(m);
  ASSERT_EQ(weights.cols(), m);
  for (int k = 0; k < m; ++k) {
    EXPECT_TRUE(nearlyEqual(weights.col(k), bernsteinWeights(k / 6.0), 1e-15));
  }
  EXPECT_EQ(weights.col(m - 1), Eigen::Vector4d(0.0, 0.0, 0.0, 1.0));
  EXPECT_THROW(uniformBernsteinWeights(1), CheckError);
}

TEST(CubicBezier, EvaluatesExactlyToTheEndPoints) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 20; ++trial) {
    const CubicBezier cubic = randomCubic(rng);
    EXPECT_EQ(cubic.evaluate(0.0), cubic.control[0]);
    EXPECT_EQ(cubic.evaluate(1.0), cubic.control[3]);
  }
}

TEST(CubicBezier, EndDerivativesAreThreeTimesTheArms) {
  std::mt19937 rng(2);
  const CubicBezier cubic = randomCubic(rng);
  const std::array<Eigen::Vector3d, 4>& p = cubic.control;
  EXPECT_TRUE(nearlyEqual(cubic.derivative(0.0), 3.0 * (p[1] - p[0]), 1e-14));
  EXPECT_TRUE(nearlyEqual(cubic.derivative(1.0), 3.0 * (p[3] - p[2]), 1e-14));
}

TEST(CubicBezier, DerivativeMatchesCentralDifferences) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> parameter(0.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    const CubicBezier cubic = randomCubic(rng);
    const double t = parameter(rng);
    const Eigen::Vector3d numerical =
        (cubic.evaluate(t + kStep) - cubic.evaluate(t - kStep)) / (2.0 * kStep);
    EXPECT_TRUE(nearlyEqual(cubic.derivative(t), numerical, 1e-7)) << "t = " << t;
  }
}

TEST(BezierSegment, ControlPointsFollowTheCurveModel) {
  std::mt19937 rng(4);
  const BezierSegmentParams params = randomSegment(rng);
  const CubicBezier cubic = params.toCubic();
  EXPECT_EQ(cubic.control[0], params.q0);
  EXPECT_TRUE(nearlyEqual(cubic.control[1], params.q0 + params.d1 * params.v0.vector(), 1e-15));
  EXPECT_TRUE(nearlyEqual(cubic.control[2], params.q1 - params.d2 * params.v1.vector(), 1e-15));
  EXPECT_EQ(cubic.control[3], params.q1);
}

TEST(BezierSegment, EvaluateMatchesTheCubicWithAndWithoutJacobians) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> parameter(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const BezierSegmentParams params = randomSegment(rng);
    const SegmentEvaluator evaluator(params);
    const double t = parameter(rng);
    const Eigen::Vector4d w = bernsteinWeights(t);
    const Eigen::Vector3d expected = params.toCubic().evaluate(t);
    SegmentJacobians H;
    EXPECT_TRUE(nearlyEqual(evaluateSegment(params, w), expected, 1e-14));
    EXPECT_TRUE(nearlyEqual(evaluateSegment(params, w, &H), expected, 1e-14));
    EXPECT_TRUE(nearlyEqual(evaluator.evaluate(w), expected, 1e-14));
    // The derivative weights give the tangent B'(t), since B is linear in the weights.
    EXPECT_TRUE(nearlyEqual(evaluator.evaluate(bernsteinDerivativeWeights(t)),
                            params.toCubic().derivative(t), 1e-14));
  }
}

// Checks every Jacobian of evaluateSegment against central differences, the directions being
// perturbed through Direction::retract in their tangent space.
void expectJacobiansMatchNumerical(const BezierSegmentParams& params, const Eigen::Vector4d& w) {
  SegmentJacobians H;
  evaluateSegment(params, w, &H);
  constexpr double kTolerance = 1e-7;

  const auto at_q0 = [&](const Eigen::Vector3d& d) {
    BezierSegmentParams p = params;
    p.q0 += d;
    return evaluateSegment(p, w);
  };
  const auto at_q1 = [&](const Eigen::Vector3d& d) {
    BezierSegmentParams p = params;
    p.q1 += d;
    return evaluateSegment(p, w);
  };
  const auto at_v0 = [&](const Eigen::Vector2d& d) {
    BezierSegmentParams p = params;
    p.v0 = params.v0.retract(d);
    return evaluateSegment(p, w);
  };
  const auto at_v1 = [&](const Eigen::Vector2d& d) {
    BezierSegmentParams p = params;
    p.v1 = params.v1.retract(d);
    return evaluateSegment(p, w);
  };
  const auto at_d1 = [&](const Eigen::Matrix<double, 1, 1>& d) {
    BezierSegmentParams p = params;
    p.d1 += d[0];
    return evaluateSegment(p, w);
  };
  const auto at_d2 = [&](const Eigen::Matrix<double, 1, 1>& d) {
    BezierSegmentParams p = params;
    p.d2 += d[0];
    return evaluateSegment(p, w);
  };
  EXPECT_TRUE(nearlyEqual(H.H_q0(), numericalJacobian<3>(at_q0), kTolerance));
  EXPECT_TRUE(nearlyEqual(H.H_q1(), numericalJacobian<3>(at_q1), kTolerance));
  EXPECT_TRUE(nearlyEqual(H.H_v0, numericalJacobian<2>(at_v0), kTolerance));
  EXPECT_TRUE(nearlyEqual(H.H_v1, numericalJacobian<2>(at_v1), kTolerance));
  EXPECT_TRUE(nearlyEqual(H.H_d1, numericalJacobian<1>(at_d1), kTolerance));
  EXPECT_TRUE(nearlyEqual(H.H_d2, numericalJacobian<1>(at_d2), kTolerance));
}

TEST(BezierSegment, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> parameter(0.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    const BezierSegmentParams params = randomSegment(rng);
    for (const double t : {0.0, 1.0, parameter(rng), parameter(rng), parameter(rng)}) {
      SCOPED_TRACE("trial " + std::to_string(trial) + ", t = " + std::to_string(t));
      expectJacobiansMatchNumerical(params, bernsteinWeights(t));
      expectJacobiansMatchNumerical(params, bernsteinDerivativeWeights(t));
    }
  }
}

TEST(BezierSegment, EvaluatorJacobiansEqualFreeFunctionJacobians) {
  std::mt19937 rng(7);
  const BezierSegmentParams params = randomSegment(rng);
  const Eigen::Vector4d w = bernsteinWeights(0.3);
  SegmentJacobians expected;
  SegmentJacobians actual;
  evaluateSegment(params, w, &expected);
  SegmentEvaluator(params).evaluate(w, &actual);
  EXPECT_EQ(actual.scale_q0, expected.scale_q0);
  EXPECT_EQ(actual.scale_q1, expected.scale_q1);
  EXPECT_EQ(actual.H_v0, expected.H_v0);
  EXPECT_EQ(actual.H_v1, expected.H_v1);
  EXPECT_EQ(actual.H_d1, expected.H_d1);
  EXPECT_EQ(actual.H_d2, expected.H_d2);
}

TEST(BezierSegment, NonPositiveLengthsStayFinite) {
  BezierSegmentParams params;
  params.q1 = Eigen::Vector3d(1.0, 0.0, 0.0);
  params.d1 = 0.0;
  params.d2 = -1.0;
  SegmentJacobians H;
  EXPECT_TRUE(evaluateSegment(params, bernsteinWeights(0.4), &H).allFinite());
  EXPECT_TRUE(H.H_v0.allFinite() && H.H_v1.allFinite());
}

PolyBezier makeZigZagCurve() {
  std::vector<Eigen::Vector3d> points = {
      {0.0, 0.0, 0.0}, {1.0, 0.5, 0.0}, {2.0, -0.5, 0.2}, {3.0, 0.0, 0.4}};
  std::vector<Direction> directions = {
      Direction(Eigen::Vector3d(1.0, 0.3, 0.0)), Direction(Eigen::Vector3d(1.0, 0.0, 0.1)),
      Direction(Eigen::Vector3d(1.0, -0.2, 0.2)), Direction(Eigen::Vector3d(1.0, 0.4, 0.0))};
  std::vector<SegmentLengths> lengths = {{0.3, 0.4}, {0.5, 0.2}, {0.35, 0.35}};
  return PolyBezier(points, directions, lengths);
}

TEST(PolyBezier, ConstructorRejectsInconsistentSizes) {
  const std::vector<Eigen::Vector3d> two_points = {Eigen::Vector3d::Zero(),
                                                   Eigen::Vector3d::UnitX()};
  const std::vector<Direction> two_directions(2);
  const std::vector<SegmentLengths> one_pair(1);
  EXPECT_NO_THROW(PolyBezier(two_points, two_directions, one_pair));
  EXPECT_THROW(PolyBezier({Eigen::Vector3d::Zero()}, {Direction()}, {}), CheckError);
  EXPECT_THROW(PolyBezier(two_points, std::vector<Direction>(3), one_pair), CheckError);
  EXPECT_THROW(PolyBezier(two_points, two_directions, std::vector<SegmentLengths>(2)), CheckError);
}

TEST(PolyBezier, ConstructorRejectsBadValues) {
  const std::vector<Eigen::Vector3d> two_points = {Eigen::Vector3d::Zero(),
                                                   Eigen::Vector3d::UnitX()};
  const std::vector<Direction> two_directions(2);
  EXPECT_THROW(PolyBezier(two_points, two_directions, {{0.0, 1.0}}), CheckError);
  EXPECT_THROW(PolyBezier(two_points, two_directions, {{1.0, -1.0}}), CheckError);
  EXPECT_THROW(PolyBezier(two_points, two_directions, {{1.0, std::nan("")}}), CheckError);
  EXPECT_THROW(PolyBezier({Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(std::nan(""))},
                          two_directions, {{1.0, 1.0}}),
               CheckError);
}

TEST(PolyBezier, SettersAndIndicesAreChecked) {
  PolyBezier curve = makeZigZagCurve();
  EXPECT_THROW(curve.segment(3), CheckError);
  EXPECT_THROW(curve.segment(-1), CheckError);
  EXPECT_THROW(curve.evaluate(3, 0.5), CheckError);
  EXPECT_THROW(curve.setPoint(4, Eigen::Vector3d::Zero()), CheckError);
  EXPECT_THROW(curve.setLengths(0, {1.0, 0.0}), CheckError);
  curve.setPoint(3, Eigen::Vector3d(4.0, 0.0, 0.0));
  curve.setDirection(3, Direction(Eigen::Vector3d::UnitY()));
  curve.setLengths(2, {0.7, 0.8});
  const BezierSegmentParams last = curve.segment(2);
  EXPECT_EQ(last.q1, Eigen::Vector3d(4.0, 0.0, 0.0));
  EXPECT_EQ(last.v1.vector(), Eigen::Vector3d::UnitY());
  EXPECT_EQ(last.d1, 0.7);
  EXPECT_EQ(last.d2, 0.8);
}

TEST(PolyBezier, SegmentsShareEndPointsAndTangentDirections) {
  const PolyBezier curve = makeZigZagCurve();
  ASSERT_EQ(curve.numSegments(), 3);
  ASSERT_EQ(curve.numPoints(), 4);
  for (int i = 0; i + 1 < curve.numSegments(); ++i) {
    EXPECT_EQ(curve.evaluate(i, 1.0), curve.evaluate(i + 1, 0.0));
    const Eigen::Vector3d end_tangent = curve.derivative(i, 1.0);
    const Eigen::Vector3d start_tangent = curve.derivative(i + 1, 0.0);
    EXPECT_NEAR(end_tangent.normalized().dot(start_tangent.normalized()), 1.0, 1e-14);
  }
}

TEST(PolyBezier, SampleHasOnePointPerStepAndNoDuplicates) {
  const PolyBezier curve = makeZigZagCurve();
  const int s = 10;
  const std::vector<Eigen::Vector3d> samples = curve.sample(s);
  ASSERT_EQ(samples.size(), static_cast<size_t>(curve.numSegments() * s + 1));
  for (int i = 0; i < curve.numPoints(); ++i) EXPECT_EQ(samples[i * s], curve.points()[i]);
  for (size_t k = 1; k < samples.size(); ++k) {
    EXPECT_GT((samples[k] - samples[k - 1]).norm(), 1e-6) << "duplicate at " << k;
    EXPECT_LT((samples[k] - samples[k - 1]).norm(), 0.3) << "jump at " << k;
  }
  EXPECT_EQ(curve.sample(1), curve.points());
  EXPECT_THROW(curve.sample(0), CheckError);
}

TEST(PolyBezier, EndsGiveTheirPointOutwardTangentAndSegment) {
  const PolyBezier curve = makeZigZagCurve();
  EXPECT_EQ(endPoint(curve, CurveEnd::kFront), curve.points()[0]);
  EXPECT_EQ(endPoint(curve, CurveEnd::kBack), curve.points()[3]);
  EXPECT_EQ(endSegment(curve, CurveEnd::kFront), 0);
  EXPECT_EQ(endSegment(curve, CurveEnd::kBack), 2);
  // Outward: a step along it leaves the curve, i.e. opposes the direction of travel into it.
  EXPECT_LT(outwardTangent(curve, CurveEnd::kFront).dot(curve.derivative(0, 0.0)), 0.0);
  EXPECT_GT(outwardTangent(curve, CurveEnd::kBack).dot(curve.derivative(2, 1.0)), 0.0);
  EXPECT_NEAR(outwardTangent(curve, CurveEnd::kFront).norm(), 1.0, 1e-15);
}

TEST(PolyBezier, ReversedTracesTheSamePointsBackwards) {
  const PolyBezier curve = makeZigZagCurve();
  const PolyBezier back = reversed(curve);
  ASSERT_EQ(back.numSegments(), curve.numSegments());
  const int n = curve.numSegments();
  for (int i = 0; i < n; ++i) {
    for (const double t : {0.0, 0.2, 0.5, 0.9, 1.0}) {
      EXPECT_LT((back.evaluate(n - 1 - i, 1.0 - t) - curve.evaluate(i, t)).norm(), 1e-14)
          << "segment " << i << " t " << t;
    }
  }
  const PolyBezier twice = reversed(back);
  EXPECT_EQ(twice.points(), curve.points());
  for (int i = 0; i < n; ++i) EXPECT_EQ(twice.lengths()[i].d1, curve.lengths()[i].d1);
}

TEST(PolyBezier, ConcatenateKeepsHeadAndTailSegmentsAndTheHeadsJoin) {
  const PolyBezier curve = makeZigZagCurve();
  // Split at Q_1: head = segment 0, tail = segments 1-2; joining them gives the curve back.
  const PolyBezier head({curve.points()[0], curve.points()[1]},
                        {curve.directions()[0], curve.directions()[1]}, {curve.lengths()[0]});
  const PolyBezier tail({curve.points()[1], curve.points()[2], curve.points()[3]},
                        {curve.directions()[1], curve.directions()[2], curve.directions()[3]},
                        {curve.lengths()[1], curve.lengths()[2]});
  const PolyBezier joined = concatenate(head, tail);
  ASSERT_EQ(joined.numSegments(), 3);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(joined.evaluate(i, 0.3), curve.evaluate(i, 0.3));
  }
  // A tail that starts elsewhere is pulled onto head's end with head's tangent; its own
  // points and arm lengths stay.
  PolyBezier moved = tail;
  moved.setPoint(0, tail.points()[0] + Eigen::Vector3d(0.1, 0.2, 0.0));
  moved.setDirection(0, Direction(Eigen::Vector3d::UnitZ()));
  const PolyBezier pulled = concatenate(head, moved);
  EXPECT_EQ(pulled.points()[1], head.points()[1]);
  EXPECT_EQ(pulled.directions()[1].vector(), head.directions()[1].vector());
  EXPECT_EQ(pulled.points()[3], tail.points()[2]);
  EXPECT_EQ(pulled.lengths()[1].d1, tail.lengths()[0].d1);
}

}  // namespace
}  // namespace curvesfm
