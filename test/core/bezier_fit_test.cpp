#include "core/bezier_fit.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <thread>
#include <vector>

#include "core/errors.h"

namespace curvesfm {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Vector3d randomVector(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> uniform(-scale, scale);
  return Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng));
}

CubicBezier randomCubic(std::mt19937& rng) {
  return CubicBezier{{randomVector(rng, 5.0), randomVector(rng, 5.0), randomVector(rng, 5.0),
                      randomVector(rng, 5.0)}};
}

std::vector<Eigen::Vector3d> sampleUniformly(const CubicBezier& cubic, int m) {
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k < m; ++k) points.push_back(cubic.evaluate(k / static_cast<double>(m - 1)));
  return points;
}

double maxControlPointError(const CubicBezier& a, const CubicBezier& b) {
  double error = 0.0;
  for (int j = 0; j < 4; ++j) error = std::max(error, (a.control[j] - b.control[j]).norm());
  return error;
}

// Helix of radius 1 around z, rising `pitch` per radian.
Eigen::Vector3d helix(double angle, double pitch) {
  return Eigen::Vector3d(std::cos(angle), std::sin(angle), pitch * angle);
}

Eigen::Vector3d helixTangent(double angle, double pitch) {
  return Eigen::Vector3d(-std::sin(angle), std::cos(angle), pitch).normalized();
}

double distanceToPolyline(const Eigen::Vector3d& x, const std::vector<Eigen::Vector3d>& line) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k + 1 < line.size(); ++k) {
    const Eigen::Vector3d edge = line[k + 1] - line[k];
    const double s = std::clamp((x - line[k]).dot(edge) / edge.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (x - (line[k] + s * edge)).norm());
  }
  return best;
}

TEST(BezierFitter, RecoversControlPointsFromExactSamples) {
  std::mt19937 rng(11);
  const BezierFitter fitter;
  for (const int m : {4, 10, 100}) {
    for (int trial = 0; trial < 10; ++trial) {
      const CubicBezier truth = randomCubic(rng);
      const CubicBezier fitted = fitter.fit(sampleUniformly(truth, m));
      EXPECT_LT(maxControlPointError(fitted, truth), 1e-11) << "m = " << m;
    }
  }
}

TEST(BezierFitter, RecoversControlPointsApproximatelyFromNoisySamples) {
  std::mt19937 rng(12);
  std::normal_distribution<double> noise(0.0, 1e-3);
  const int m = 200;
  const CubicBezier truth = randomCubic(rng);
  std::vector<Eigen::Vector3d> points = sampleUniformly(truth, m);
  for (Eigen::Vector3d& p : points) p += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  const CubicBezier fitted = BezierFitter::shared().fit(points);
  // The inner control points are the least constrained; their standard deviation here is a few
  // times the noise, so 1e-2 is a loose bound that still catches a wrong basis.
  EXPECT_LT(maxControlPointError(fitted, truth), 1e-2);
  double squared_residual = 0.0;
  for (int k = 0; k < m; ++k) {
    squared_residual += (fitted.evaluate(k / static_cast<double>(m - 1)) - points[k]).squaredNorm();
  }
  EXPECT_LT(std::sqrt(squared_residual / m), 2e-3);  // About sqrt(3) * 1e-3 per point.
}

TEST(BezierFitter, OperatorIsALeftInverseOfTheBasis) {
  const BezierFitter fitter;
  for (const int m : {4, 5, 37, 500}) {
    const Eigen::MatrixXd product =
        fitter.solutionOperator(m) * uniformBernsteinWeights(m).transpose();
    EXPECT_TRUE(product.isApprox(Eigen::Matrix4d::Identity(), 1e-12)) << "m = " << m;
  }
}

TEST(BezierFitter, CachesOneOperatorPerPointCount) {
  const BezierFitter fitter;
  EXPECT_EQ(fitter.cacheSize(), 0);
  const auto* first = &fitter.solutionOperator(20);
  const auto* second = &fitter.solutionOperator(20);
  EXPECT_EQ(first, second);
  EXPECT_EQ(fitter.cacheSize(), 1);
  fitter.solutionOperator(21);
  EXPECT_EQ(fitter.cacheSize(), 2);
  EXPECT_EQ(&fitter.solutionOperator(20), first);  // Still valid after another insertion.
  EXPECT_EQ(first->cols(), 20);
}

TEST(BezierFitter, ConcurrentCallersGetTheSameOperators) {
  const BezierFitter fitter;
  constexpr int kThreads = 4;
  constexpr int kMaxM = 60;
  std::vector<std::vector<const Eigen::Matrix<double, 4, Eigen::Dynamic>*>> seen(kThreads);
  std::vector<std::thread> threads;
  for (int i = 0; i < kThreads; ++i) {
    threads.emplace_back([&fitter, &seen, i] {
      for (int m = 4; m <= kMaxM; ++m) seen[i].push_back(&fitter.solutionOperator(m));
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(fitter.cacheSize(), kMaxM - 3);
  for (int i = 1; i < kThreads; ++i) EXPECT_EQ(seen[i], seen[0]);
}

TEST(BezierFitter, RejectsFewerThanFourPoints) {
  const BezierFitter fitter;
  const std::vector<Eigen::Vector3d> three(3, Eigen::Vector3d::Zero());
  EXPECT_THROW(fitter.fit(three), CheckError);
  EXPECT_THROW(fitter.fit(three.data(), 3), CheckError);
  EXPECT_THROW(fitter.fit(std::vector<Eigen::Vector3d>()), CheckError);
  EXPECT_THROW(fitter.solutionOperator(3), CheckError);
  EXPECT_EQ(fitter.cacheSize(), 0);
}

TEST(BezierFitter, SubRangeFitEqualsVectorFit) {
  std::mt19937 rng(13);
  std::vector<Eigen::Vector3d> chain;
  for (int k = 0; k < 30; ++k) chain.push_back(randomVector(rng, 1.0));
  const BezierFitter fitter;
  const std::vector<Eigen::Vector3d> middle(chain.begin() + 10, chain.begin() + 22);
  EXPECT_EQ(maxControlPointError(fitter.fit(chain.data() + 10, 12), fitter.fit(middle)), 0.0);
}

// A helix of 6 quarter turns split into pieces that share their boundary samples, as a chain
// of lifted edge pixels would be.
struct HelixPieces {
  static constexpr double kPitch = 0.2;
  static constexpr int kPieces = 6;
  static constexpr int kPointsPerPiece = 40;
  std::vector<double> angles;
  std::vector<Eigen::Vector3d> samples;
  std::vector<CubicBezier> fitted;

  HelixPieces() {
    const int intervals = kPieces * (kPointsPerPiece - 1);
    for (int k = 0; k <= intervals; ++k) {
      angles.push_back(3.0 * kPi * k / intervals);
      samples.push_back(helix(angles.back(), kPitch));
    }
    for (int i = 0; i < kPieces; ++i) {
      fitted.push_back(
          BezierFitter::shared().fit(samples.data() + i * (kPointsPerPiece - 1), kPointsPerPiece));
    }
  }
};

TEST(LinkSegments, HelixPiecesBecomeAContinuousSmoothCurve) {
  const HelixPieces helix_pieces;
  const PolyBezier curve = linkSegments(helix_pieces.fitted);
  ASSERT_EQ(curve.numSegments(), HelixPieces::kPieces);
  for (int i = 1; i < curve.numSegments(); ++i) {
    const CubicBezier previous = curve.controlPoints(i - 1);
    const CubicBezier next = curve.controlPoints(i);
    // C0: the shared point is exactly the previous fit's last control point.
    EXPECT_EQ(previous.control[3], next.control[0]);
    EXPECT_EQ(next.control[0], helix_pieces.fitted[i - 1].control[3]);
    // G1: the arms on both sides of the joint point the same way.
    const Eigen::Vector3d end_arm = (previous.control[3] - previous.control[2]).normalized();
    const Eigen::Vector3d start_arm = (next.control[1] - next.control[0]).normalized();
    EXPECT_NEAR(end_arm.dot(start_arm), 1.0, 1e-14) << "joint " << i;
    // The averaged tangent is the helix tangent at the joint.
    const double joint_angle = helix_pieces.angles[i * (HelixPieces::kPointsPerPiece - 1)];
    EXPECT_LT(
        curve.directions()[i].angleTo(Direction(helixTangent(joint_angle, HelixPieces::kPitch))),
        1e-2)
        << "joint " << i;
  }
  // A cubic fitted with uniform t is about 3e-3 off a quarter turn of radius 1, and replacing
  // the fitted end tangents by their mean bends each segment a little more (7e-3 observed).
  const std::vector<Eigen::Vector3d> dense = curve.sample(200);
  for (const Eigen::Vector3d& x : helix_pieces.samples) {
    EXPECT_LT(distanceToPolyline(x, dense), 1e-2);
  }
}

TEST(LinkSegments, FollowsThePaperFormulasOnHandMadePieces) {
  const CubicBezier first{{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                           Eigen::Vector3d(2, 1, 0), Eigen::Vector3d(3, 1, 0)}};
  const CubicBezier second{{Eigen::Vector3d(3.1, 1, 0), Eigen::Vector3d(3.1, 3, 0),
                            Eigen::Vector3d(4, 4, 0), Eigen::Vector3d(5, 4, 0)}};
  const PolyBezier curve = linkSegments({first, second});
  EXPECT_EQ(curve.points()[0], first.control[0]);
  EXPECT_EQ(curve.points()[1], first.control[3]);  // Not second.control[0].
  EXPECT_EQ(curve.points()[2], second.control[3]);
  const Eigen::Vector3d mean =
      0.5 * (Eigen::Vector3d(1, 0, 0) + Eigen::Vector3d(0, 1, 0));  // (P3-P2), (P1-P0) unit.
  EXPECT_TRUE(curve.directions()[0].vector().isApprox(Eigen::Vector3d::UnitX()));
  EXPECT_TRUE(curve.directions()[1].vector().isApprox(mean.normalized()));
  EXPECT_TRUE(curve.directions()[2].vector().isApprox(Eigen::Vector3d::UnitX()));
  EXPECT_DOUBLE_EQ(curve.lengths()[0].d1, 1.0);
  EXPECT_DOUBLE_EQ(curve.lengths()[0].d2, 1.0);
  EXPECT_DOUBLE_EQ(curve.lengths()[1].d1, 2.0);
  EXPECT_DOUBLE_EQ(curve.lengths()[1].d2, 1.0);
}

TEST(LinkSegments, SingleExactSegmentIsReproduced) {
  std::mt19937 rng(14);
  const CubicBezier cubic = randomCubic(rng);
  const PolyBezier curve = linkSegments({cubic});
  EXPECT_LT(maxControlPointError(curve.controlPoints(0), cubic), 1e-12);
}

TEST(LinkSegments, ZeroLengthArmFallsBackToTheChord) {
  const CubicBezier cubic{{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, 0),
                           Eigen::Vector3d(2, 1, 0), Eigen::Vector3d(2, 0, 0)}};
  const PolyBezier curve = linkSegments({cubic});
  EXPECT_TRUE(curve.directions()[0].vector().isApprox(Eigen::Vector3d::UnitX()));
  EXPECT_DOUBLE_EQ(curve.lengths()[0].d1, 1e-3 * 2.0);  // The documented floor.
  EXPECT_DOUBLE_EQ(curve.lengths()[0].d2, 1.0);
}

TEST(LinkSegments, OppositeTangentsFallBackToTheCentralChord) {
  // Segment 0 arrives at (1, 0, 0) heading +x; segment 1 leaves it heading -x (a cusp).
  const CubicBezier first{{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.3, 0, 0),
                           Eigen::Vector3d(0.7, 0, 0), Eigen::Vector3d(1, 0, 0)}};
  const CubicBezier second{{Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0.7, 0, 0),
                            Eigen::Vector3d(0.5, 1, 0), Eigen::Vector3d(0.5, 2, 0)}};
  const PolyBezier curve = linkSegments({first, second});
  const Eigen::Vector3d central = Eigen::Vector3d(0.5, 2, 0).normalized();
  EXPECT_TRUE(curve.directions()[1].vector().isApprox(central));
  for (const Eigen::Vector3d& x : curve.sample(20)) EXPECT_TRUE(x.allFinite());
}

TEST(LinkSegments, CollapsedSegmentsGiveAValidCurve) {
  const Eigen::Vector3d a(1, 2, 3);
  const CubicBezier point_like{{a, a, a, a}};
  const PolyBezier single = linkSegments({point_like});
  EXPECT_TRUE(single.directions()[0].vector().isApprox(Eigen::Vector3d::UnitX()));
  EXPECT_GT(single.lengths()[0].d1, 0.0);
  EXPECT_GT(single.lengths()[0].d2, 0.0);

  // A collapsed middle segment takes the whole curve's chord.
  const Eigen::Vector3d b(1, 2, 5);
  const CubicBezier before{
      {Eigen::Vector3d(1, 2, 0), Eigen::Vector3d(1, 2, 1), Eigen::Vector3d(1, 2, 2), a}};
  const CubicBezier after{{a, Eigen::Vector3d(1, 2, 3.5), Eigen::Vector3d(1, 2, 4), b}};
  const PolyBezier chain = linkSegments({before, point_like, after});
  for (const Direction& v : chain.directions()) {
    EXPECT_TRUE(v.vector().isApprox(Eigen::Vector3d::UnitZ())) << v.vector().transpose();
  }
}

TEST(LinkSegments, RejectsEmptyOrNonFiniteInput) {
  EXPECT_THROW(linkSegments({}), CheckError);
  const Eigen::Vector3d nan = Eigen::Vector3d::Constant(std::nan(""));
  const CubicBezier bad{
      {Eigen::Vector3d::Zero(), nan, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()}};
  EXPECT_THROW(linkSegments({bad}), CheckError);
}

TEST(LinkSegments, FittedNoisyHelixStaysCloseToTheSamples) {
  std::mt19937 rng(15);
  std::normal_distribution<double> noise(0.0, 5e-4);
  HelixPieces helix_pieces;
  std::vector<Eigen::Vector3d> noisy = helix_pieces.samples;
  for (Eigen::Vector3d& p : noisy) p += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  std::vector<CubicBezier> fitted;
  for (int i = 0; i < HelixPieces::kPieces; ++i) {
    fitted.push_back(BezierFitter::shared().fit(
        noisy.data() + i * (HelixPieces::kPointsPerPiece - 1), HelixPieces::kPointsPerPiece));
  }
  const std::vector<Eigen::Vector3d> dense = linkSegments(fitted).sample(200);
  for (const Eigen::Vector3d& x : helix_pieces.samples) {
    EXPECT_LT(distanceToPolyline(x, dense), 1.2e-2);
  }
}

}  // namespace
}  // namespace curvesfm
