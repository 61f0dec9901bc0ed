// The AVX2 + FMA copy of core/dense_kernels.h: the build passes -mavx2 -mfma to this file
// alone (core/CMakeLists.txt) and defines CURVESFM_DENSE_AVX2 when it does.
//
// Eigen's templates compiled here differ from the same templates compiled elsewhere in the
// program (wider packets, another alignment), but would carry the same symbol names: the
// linker would keep one copy of each for the whole program, and code on a CPU without AVX2
// could end up running this one. Renaming Eigen's namespace for this file keeps every
// instantiation here its own. Nothing here may include a header that includes Eigen under its
// own name, and nothing leaves but the plain pointers of MatrixSpan. To check after a change:
// `nm -C` of this object must list no weak (W, V) code symbol outside curvesfm_eigen_avx2 and
// curvesfm::dense::avx2 (a standard-library template instantiated here would be shared too).
#if defined(CURVESFM_DENSE_AVX2)

#define Eigen curvesfm_eigen_avx2
#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "core/dense_kernels.h"

#define CURVESFM_DENSE_VARIANT avx2
#include "core/dense_kernels_impl.h"

#endif
