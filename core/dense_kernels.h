#pragma once

// The dense products and factorisations of our own Schur complement (graph/schur_solver.cpp),
// of parallelCholesky and of descriptor matching (frontend/image/feature_matching.cpp), compiled
// twice: for the build's baseline (SSE2 on x86-64) and, where
// the compiler can, with AVX2 and FMA, chosen once at run time by what the CPU supports. Eigen
// picks its SIMD at compile time, so the AVX2 copy lives in its own translation unit with Eigen
// in a namespace of its own (dense_kernels_avx2.cpp says why). This header holds no Eigen
// type, so that nothing crosses between the two builds but plain pointers.

namespace curvesfm {
namespace dense {

/// A column-major matrix someone else owns: element (r, c) at data[r + c * stride].
struct MatrixSpan {
  double* data = nullptr;
  long rows = 0;
  long cols = 0;
  long stride = 0;
};

/// Block (row, col) of size rows x cols of a column-major matrix `m` (an Eigen matrix, block or
/// Ref with inner stride 1).
template <typename Matrix>
MatrixSpan blockSpan(Matrix& m, long row, long col, long rows, long cols) {
  return {m.data() + row + col * static_cast<long>(m.outerStride()), rows, cols,
          static_cast<long>(m.outerStride())};
}

/// Cholesky factorisation in place: reads the lower triangle of the symmetric `a`, writes L
/// there. False when `a` is not positive definite.
bool factorLower(MatrixSpan a);

/// b <- b L^-T, L the lower triangle of `l` (the panel step of a blocked Cholesky, and
/// W L^-T in a Schur complement).
void solveLowerTransposedRight(MatrixSpan l, MatrixSpan b);

/// c <- c - a b^T.
void subtractProductTransposed(MatrixSpan c, MatrixSpan a, MatrixSpan b);

/// The lower triangle of c <- c - a a^T (c square; its strict upper triangle is left alone).
void subtractGramLower(MatrixSpan c, MatrixSpan a);

/// c = a b^T for row-major single-precision matrices without gaps between rows: a is m x k, b
/// n x k, c m x n (the dot products of two descriptor sets).
void productTransposedFloat(const float* a, long m, const float* b, long n, long k, float* c);

/// Whether the calls above run the avx2 copy.
bool avx2KernelsRun();

/// "avx2" or "baseline": the copy the calls above run.
const char* kernelVariant();

// The two copies, for the dispatch and the tests; the avx2 one exists where the build defines
// CURVESFM_DENSE_AVX2, and runs only on a CPU with AVX2 and FMA.
#define CURVESFM_DENSE_KERNELS_OF_ONE_COPY                                  \
  bool factorLower(MatrixSpan a);                                           \
  void solveLowerTransposedRight(MatrixSpan l, MatrixSpan b);               \
  void subtractProductTransposed(MatrixSpan c, MatrixSpan a, MatrixSpan b); \
  void subtractGramLower(MatrixSpan c, MatrixSpan a);                       \
  void productTransposedFloat(const float* a, long m, const float* b, long n, long k, float* c);
namespace baseline {
CURVESFM_DENSE_KERNELS_OF_ONE_COPY
}
namespace avx2 {
CURVESFM_DENSE_KERNELS_OF_ONE_COPY
}
#undef CURVESFM_DENSE_KERNELS_OF_ONE_COPY

}  // namespace dense
}  // namespace curvesfm
