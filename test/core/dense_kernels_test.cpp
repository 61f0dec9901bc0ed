#include "core/dense_kernels.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

namespace curvesfm {
namespace {

struct Copy {
  std::string name;
  std::function<bool(dense::MatrixSpan)> factor;
  std::function<void(dense::MatrixSpan, dense::MatrixSpan)> solve;
  std::function<void(dense::MatrixSpan, dense::MatrixSpan, dense::MatrixSpan)> product;
  std::function<void(dense::MatrixSpan, dense::MatrixSpan)> gram;
  std::function<void(const float*, long, const float*, long, long, float*)> product_float;
};

// The baseline copy always; the avx2 copy where this CPU runs it (the dispatch is then it).
std::vector<Copy> copies() {
  std::vector<Copy> all{
      {"baseline", dense::baseline::factorLower, dense::baseline::solveLowerTransposedRight,
       dense::baseline::subtractProductTransposed, dense::baseline::subtractGramLower,
       dense::baseline::productTransposedFloat}};
#if defined(CURVESFM_DENSE_AVX2)
  if (dense::avx2KernelsRun()) {
    all.push_back({"avx2", dense::avx2::factorLower, dense::avx2::solveLowerTransposedRight,
                   dense::avx2::subtractProductTransposed, dense::avx2::subtractGramLower,
                   dense::avx2::productTransposedFloat});
  }
#endif
  return all;
}

Eigen::MatrixXd randomSpd(int n) {
  const Eigen::MatrixXd b = Eigen::MatrixXd::Random(n, n + 3);
  return b * b.transpose() + Eigen::MatrixXd::Identity(n, n);
}

// Blocks inside a larger matrix, so that every kernel is checked with a stride.
TEST(DenseKernels, EveryCopyMatchesEigenOnStridedBlocks) {
  EXPECT_EQ(std::string(dense::kernelVariant()), dense::avx2KernelsRun() ? "avx2" : "baseline");
  for (const Copy& copy : copies()) {
    SCOPED_TRACE(copy.name);
    Eigen::MatrixXd outer = Eigen::MatrixXd::Random(60, 50);
    const Eigen::MatrixXd spd = randomSpd(23);
    outer.block(5, 7, 23, 23) = spd;
    ASSERT_TRUE(copy.factor(dense::blockSpan(outer, 5, 7, 23, 23)));
    const Eigen::MatrixXd l = outer.block(5, 7, 23, 23).triangularView<Eigen::Lower>();
    EXPECT_LT((l * l.transpose() - spd).norm(), 1e-10 * spd.norm());

    const Eigen::MatrixXd b = Eigen::MatrixXd::Random(17, 23);
    outer.block(30, 2, 17, 23) = b;
    copy.solve(dense::blockSpan(outer, 5, 7, 23, 23), dense::blockSpan(outer, 30, 2, 17, 23));
    EXPECT_LT((outer.block(30, 2, 17, 23) * l.transpose() - b).norm(), 1e-10 * b.norm());

    const Eigen::MatrixXd c = outer.block(0, 30, 9, 11), a = outer.block(10, 0, 9, 4),
                          bt = outer.block(40, 40, 11, 4);
    copy.product(dense::blockSpan(outer, 0, 30, 9, 11), dense::blockSpan(outer, 10, 0, 9, 4),
                 dense::blockSpan(outer, 40, 40, 11, 4));
    EXPECT_LT((outer.block(0, 30, 9, 11) - (c - a * bt.transpose())).norm(), 1e-12 * c.norm());

    const Eigen::MatrixXd square = outer.block(45, 20, 12, 12), rows = outer.block(48, 0, 12, 3);
    copy.gram(dense::blockSpan(outer, 45, 20, 12, 12), dense::blockSpan(outer, 48, 0, 12, 3));
    const Eigen::MatrixXd expected = square - rows * rows.transpose();
    const Eigen::MatrixXd got = outer.block(45, 20, 12, 12);
    EXPECT_LT((Eigen::MatrixXd(got.triangularView<Eigen::Lower>()) -
               Eigen::MatrixXd(expected.triangularView<Eigen::Lower>()))
                  .norm(),
              1e-12 * square.norm());
    EXPECT_EQ(Eigen::MatrixXd(got.triangularView<Eigen::StrictlyUpper>()),
              Eigen::MatrixXd(square.triangularView<Eigen::StrictlyUpper>()));
  }
}

TEST(DenseKernels, EveryCopyRefusesAMatrixThatIsNotPositiveDefinite) {
  for (const Copy& copy : copies()) {
    Eigen::MatrixXd a = randomSpd(8);
    a(7, 7) = -1.0;
    EXPECT_FALSE(copy.factor(dense::blockSpan(a, 0, 0, 8, 8))) << copy.name;
  }
}

// Whole numbers up to 255 in 128 columns, as OpenCV's SIFT descriptors: every dot product is an
// integer below 2^24, so each copy must give it exactly, as BLAS did (feature_matching.cpp relies
// on it for distances that do not depend on the copy).
TEST(DenseKernels, EveryCopyGivesExactDotProductsOfWholeNumberDescriptors) {
  using FloatRows = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const FloatRows a = (FloatRows::Random(37, 128).array() * 127.5f + 127.5f).round().matrix();
  const FloatRows b = (FloatRows::Random(53, 128).array() * 127.5f + 127.5f).round().matrix();
  const Eigen::MatrixXd expected = a.cast<double>() * b.cast<double>().transpose();
  std::vector<Copy> all = copies();
  all.push_back({"dispatch", {}, {}, {}, {}, dense::productTransposedFloat});
  for (const Copy& copy : all) {
    FloatRows c(37, 53);
    copy.product_float(a.data(), 37, b.data(), 53, 128, c.data());
    EXPECT_EQ(c.cast<double>(), expected) << copy.name;
  }
}

}  // namespace
}  // namespace curvesfm
