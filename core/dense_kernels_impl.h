// The bodies of core/dense_kernels.h, included by dense_kernels.cpp and
// dense_kernels_avx2.cpp with CURVESFM_DENSE_VARIANT naming the copy. No include guard: each
// translation unit includes it once, after its Eigen headers.

namespace curvesfm {
namespace dense {
namespace CURVESFM_DENSE_VARIANT {
namespace {

using Span = Eigen::Map<Eigen::MatrixXd, Eigen::Unaligned, Eigen::OuterStride<>>;

Span view(MatrixSpan m) { return Span(m.data, m.rows, m.cols, Eigen::OuterStride<>(m.stride)); }

}  // namespace

bool factorLower(MatrixSpan a) {
  Span matrix = view(a);
  Eigen::Ref<Eigen::MatrixXd, 0, Eigen::OuterStride<>> in_place(matrix);
  return Eigen::LLT<Eigen::Ref<Eigen::MatrixXd, 0, Eigen::OuterStride<>>>(in_place).info() ==
         Eigen::Success;
}

void solveLowerTransposedRight(MatrixSpan l, MatrixSpan b) {
  Span rhs = view(b);
  view(l).transpose().triangularView<Eigen::Upper>().solveInPlace<Eigen::OnTheRight>(rhs);
}

void subtractProductTransposed(MatrixSpan c, MatrixSpan a, MatrixSpan b) {
  view(c).noalias() -= view(a) * view(b).transpose();
}

void subtractGramLower(MatrixSpan c, MatrixSpan a) {
  view(c).selfadjointView<Eigen::Lower>().rankUpdate(view(a), -1.0);
}

void productTransposedFloat(const float* a, long m, const float* b, long n, long k, float* c) {
  using RowMajor = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  Eigen::Map<RowMajor>(c, m, n).noalias() =
      Eigen::Map<const RowMajor>(a, m, k) * Eigen::Map<const RowMajor>(b, n, k).transpose();
}

}  // namespace CURVESFM_DENSE_VARIANT
}  // namespace dense
}  // namespace curvesfm
