#pragma once

// Ceres-side checks shared by the graph and factor tests (they link Ceres; the layers do not).

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <vector>

#include "graph/factor.h"
#include "graph/values.h"

namespace curvesfm::testing {

/// Ambient copies of a factor's variables, with the pointer array Ceres' Evaluate expects.
struct AmbientBlocks {
  AmbientBlocks(const Factor& factor, const Values& values) {
    for (Key key : factor.keys()) {
      storage.emplace_back(ambientDim(values.type(key)));
      values.toAmbient(key, storage.back().data());
    }
    for (const auto& block : storage) pointers.push_back(block.data());
  }
  std::vector<std::vector<double>> storage;
  std::vector<const double*> pointers;
};

/// Probes `checker` at `blocks` and compares its user and numeric Jacobians (tangent and
/// ambient) within `tolerance` relative to each Jacobian's scale (absolute below 1). Probe's own
/// verdict is purely relative, so it flags structural zeros such as the diagonal of [R p]x
/// (1e-17 against 1e-14); this mixed tolerance does not.
inline void expectProbeAgrees(const ceres::GradientChecker& checker, const AmbientBlocks& blocks,
                              double tolerance) {
  ceres::GradientChecker::ProbeResults results;
  checker.Probe(blocks.pointers.data(), tolerance, &results);
  ASSERT_TRUE(results.return_value);
  for (std::size_t i = 0; i < blocks.pointers.size(); ++i) {
    const auto& local = results.local_numeric_jacobians[i];
    EXPECT_LT((results.local_jacobians[i] - local).cwiseAbs().maxCoeff(),
              tolerance * std::max(1.0, local.cwiseAbs().maxCoeff()))
        << "block " << i << "\n" << results.error_log;
    const auto& ambient = results.numeric_jacobians[i];
    EXPECT_LT((results.jacobians[i] - ambient).cwiseAbs().maxCoeff(),
              tolerance * std::max(1.0, ambient.cwiseAbs().maxCoeff()))
        << "ambient block " << i;
  }
}

}  // namespace curvesfm::testing
