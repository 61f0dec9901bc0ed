#include "core/dense_kernels.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>

#define CURVESFM_DENSE_VARIANT baseline
#include "core/dense_kernels_impl.h"

namespace curvesfm {
namespace dense {

namespace {

bool useAvx2() {
#if defined(CURVESFM_DENSE_AVX2)
  static const bool supported = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return supported;
#else
  return false;
#endif
}

}  // namespace

#if defined(CURVESFM_DENSE_AVX2)
#define CURVESFM_DISPATCH(call) return useAvx2() ? avx2::call : baseline::call
#else
#define CURVESFM_DISPATCH(call) return baseline::call
#endif

bool factorLower(MatrixSpan a) { CURVESFM_DISPATCH(factorLower(a)); }

void solveLowerTransposedRight(MatrixSpan l, MatrixSpan b) {
  CURVESFM_DISPATCH(solveLowerTransposedRight(l, b));
}

void subtractProductTransposed(MatrixSpan c, MatrixSpan a, MatrixSpan b) {
  CURVESFM_DISPATCH(subtractProductTransposed(c, a, b));
}

void subtractGramLower(MatrixSpan c, MatrixSpan a) { CURVESFM_DISPATCH(subtractGramLower(c, a)); }

void productTransposedFloat(const float* a, long m, const float* b, long n, long k, float* c) {
  CURVESFM_DISPATCH(productTransposedFloat(a, m, b, n, k, c));
}

bool avx2KernelsRun() { return useAvx2(); }

const char* kernelVariant() { return useAvx2() ? "avx2" : "baseline"; }

}  // namespace dense
}  // namespace curvesfm
