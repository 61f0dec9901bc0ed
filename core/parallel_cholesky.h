#pragma once

#include <Eigen/Core>

namespace curvesfm {

/// Cholesky factorisation A = L L^T in place: reads the lower triangle of the symmetric
/// positive definite `a` and overwrites it with L; the strict upper triangle is scratch.
/// Right-looking and blocked, with each block step's panel solve and trailing update split
/// over `num_threads` threads (Eigen's own LLT runs on one), and the blocks in the dense
/// kernels (core/dense_kernels.h). False when `a` is not positive
/// definite; `a` is then undefined.
bool parallelCholesky(Eigen::Ref<Eigen::MatrixXd> a, int num_threads);

/// Solves L L^T x = b in place, L the lower triangle `parallelCholesky` left in `l`.
void choleskySolveInPlace(const Eigen::Ref<const Eigen::MatrixXd>& l, Eigen::VectorXd* b);

}  // namespace curvesfm
