#include "core/parallel_cholesky.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>

namespace curvesfm {
namespace {

Eigen::MatrixXd randomSpd(int n, unsigned seed) {
  std::srand(seed);
  const Eigen::MatrixXd b = Eigen::MatrixXd::Random(n, n + 5);
  return b * b.transpose() + 1e-3 * Eigen::MatrixXd::Identity(n, n);
}

// Sizes around the block size (128) and its multiples, where the panels and the area split of
// the trailing update change shape, and 700, whose first steps are large enough to go to the
// threads; 1 to 3 threads.
TEST(ParallelCholesky, MatchesEigensFactorAndSolvesOnAnyThreadCount) {
  for (const int n : {1, 7, 127, 128, 129, 300, 700}) {
    const Eigen::MatrixXd a = randomSpd(n, 17 + n);
    const Eigen::MatrixXd expected = Eigen::LLT<Eigen::MatrixXd>(a).matrixL();
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
    for (const int threads : {1, 2, 3}) {
      Eigen::MatrixXd factor = a;
      ASSERT_TRUE(parallelCholesky(factor, threads)) << n << " " << threads;
      const Eigen::MatrixXd l = factor.triangularView<Eigen::Lower>();
      EXPECT_LT((l - expected).norm(), 1e-9 * expected.norm()) << n << " " << threads;
      Eigen::VectorXd x = b;
      choleskySolveInPlace(factor, &x);
      EXPECT_LT((a * x - b).norm(), 1e-8 * b.norm() * a.norm()) << n << " " << threads;
    }
  }
}

TEST(ParallelCholesky, ReadsOnlyTheLowerTriangle) {
  Eigen::MatrixXd a = randomSpd(200, 3);
  const Eigen::MatrixXd expected = Eigen::LLT<Eigen::MatrixXd>(a).matrixL();
  a.triangularView<Eigen::StrictlyUpper>().setConstant(1e6);
  ASSERT_TRUE(parallelCholesky(a, 2));
  EXPECT_LT((Eigen::MatrixXd(a.triangularView<Eigen::Lower>()) - expected).norm(), 1e-9 * expected.norm());
}

TEST(ParallelCholesky, RefusesAMatrixThatIsNotPositiveDefinite) {
  for (const int n : {5, 200}) {  // The failing pivot in the first block, then in a later one.
    Eigen::MatrixXd a = randomSpd(n, 5);
    a(n - 1, n - 1) = -1.0;
    EXPECT_FALSE(parallelCholesky(a, 2)) << n;
  }
}

}  // namespace
}  // namespace curvesfm
