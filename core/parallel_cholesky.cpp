#include "core/parallel_cholesky.h"

#include <algorithm>
#include <vector>

#include "core/dense_kernels.h"
#include "core/parallel.h"

namespace curvesfm {
namespace {

// Big enough for GEMM to run near its peak, small enough that the serial factorisation of the
// diagonal blocks stays a few per cent of the work.
constexpr Eigen::Index kBlock = 128;
// Strips of the trailing update: narrow enough that the triangle above the diagonal each
// computes for nothing stays small, wide enough for GEMM.
constexpr Eigen::Index kUpdateWidth = 64;
// A step goes to the threads only when its trailing update is large enough to pay for handing
// it over: when each call started its threads, two took 2.3 ms at n = 600 against 1.5 ms on one;
// with the kept threads of core/parallel.h a bound of 256 or 128 still gains nothing at n = 600
// or 900 (1.6 and 4.3-4.9 ms on either), while 1,200 takes 9.4 ms on two against 12.5 on one.
constexpr Eigen::Index kMinParallelRest = 512;

// Column splits of an n x n lower triangle into runs of about equal area, one per thread,
// on multiples of 8 so that every thread's GEMM keeps whole register blocks.
std::vector<Eigen::Index> equalAreaColumns(Eigen::Index n, int num_threads) {
  std::vector<Eigen::Index> bounds{0};
  const double total = 0.5 * double(n) * double(n + 1);
  double area = 0.0;
  for (Eigen::Index c = 0; c < n && static_cast<int>(bounds.size()) < num_threads; ++c) {
    area += double(n - c);
    if (area * num_threads >= total * bounds.size() && (c + 1) % 8 == 0) bounds.push_back(c + 1);
  }
  while (static_cast<int>(bounds.size()) <= num_threads) bounds.push_back(n);
  return bounds;
}

}  // namespace

bool parallelCholesky(Eigen::Ref<Eigen::MatrixXd> a, int num_threads) {
  const Eigen::Index n = a.rows();
  num_threads = std::max(1, num_threads);
  for (Eigen::Index k = 0; k < n; k += kBlock) {
    const Eigen::Index kb = std::min(kBlock, n - k);
    const dense::MatrixSpan l11 = dense::blockSpan(a, k, k, kb, kb);
    if (!dense::factorLower(l11)) return false;
    const Eigen::Index rest = n - k - kb;
    if (rest == 0) break;
    const int threads = rest >= kMinParallelRest ? num_threads : 1;
    const auto panel = [&](Eigen::Index row, Eigen::Index rows) {
      return dense::blockSpan(a, k + kb + row, k, rows, kb);
    };
    // Panel: L21 = A21 L11^-T, rows split evenly.
    runInParallel(threads, [&](int t) {
      const Eigen::Index r0 = rest * t / threads, r1 = rest * (t + 1) / threads;
      if (r1 > r0) dense::solveLowerTransposedRight(l11, panel(r0, r1 - r0));
    });
    // Trailing: A22 -= L21 L21^T on the lower triangle, columns split by area, in strips of
    // kUpdateWidth columns from their diagonal down; what lands above the diagonal within a
    // strip is scratch.
    const std::vector<Eigen::Index> columns = equalAreaColumns(rest, threads);
    runInParallel(threads, [&](int t) {
      for (Eigen::Index c0 = columns[t]; c0 < columns[t + 1]; c0 += kUpdateWidth) {
        const Eigen::Index width = std::min(kUpdateWidth, columns[t + 1] - c0);
        dense::subtractProductTransposed(
            dense::blockSpan(a, k + kb + c0, k + kb + c0, rest - c0, width), panel(c0, rest - c0),
            panel(c0, width));
      }
    });
  }
  return true;
}

void choleskySolveInPlace(const Eigen::Ref<const Eigen::MatrixXd>& l, Eigen::VectorXd* b) {
  l.triangularView<Eigen::Lower>().solveInPlace(*b);
  l.triangularView<Eigen::Lower>().transpose().solveInPlace(*b);
}

}  // namespace curvesfm
