#include "graph/robust_kernel.h"

#include <ceres/loss_function.h>
#include <gtest/gtest.h>

#include <memory>

#include "core/errors.h"

namespace curvesfm {
namespace {

struct KernelCase {
  RobustKernelType type;
  double width;
};

std::vector<KernelCase> allKernels() {
  return {{RobustKernelType::kNone, 1.0},   {RobustKernelType::kHuber, 1.0},
          {RobustKernelType::kHuber, 2.5},  {RobustKernelType::kCauchy, 1.0},
          {RobustKernelType::kCauchy, 0.3}, {RobustKernelType::kTukey, 1.0},
          {RobustKernelType::kTukey, 4.0}};
}

// s values away from the kernels' kinks at s = width^2, where derivatives jump.
std::vector<double> samplePoints(double width) {
  std::vector<double> s_values;
  for (double f : {0.01, 0.2, 0.5, 0.9, 1.1, 2.0, 5.0, 30.0}) s_values.push_back(f * width * width);
  return s_values;
}

TEST(RobustKernel, DerivativesMatchFiniteDifferences) {
  for (const KernelCase& c : allKernels()) {
    const RobustKernel kernel(c.type, c.width);
    for (double s : samplePoints(c.width)) {
      const double h = 1e-6 * std::max(1.0, s);
      double lo[3], mid[3], hi[3];
      kernel.evaluate(s - h, lo);
      kernel.evaluate(s, mid);
      kernel.evaluate(s + h, hi);
      EXPECT_NEAR(mid[1], (hi[0] - lo[0]) / (2 * h), 1e-6) << kernel.toString() << " s=" << s;
      EXPECT_NEAR(mid[2], (hi[1] - lo[1]) / (2 * h), 1e-5) << kernel.toString() << " s=" << s;
    }
  }
}

TEST(RobustKernel, IsQuadraticNearZeroAndContinuousAtTheKink) {
  for (const KernelCase& c : allKernels()) {
    const RobustKernel kernel(c.type, c.width);
    double out[3];
    kernel.evaluate(0.0, out);
    EXPECT_DOUBLE_EQ(out[0], 0.0);
    EXPECT_DOUBLE_EQ(out[1], 1.0) << kernel.toString();
    const double b = c.width * c.width;
    EXPECT_NEAR(kernel.rho(b * (1 - 1e-9)), kernel.rho(b * (1 + 1e-9)), 1e-6 * b);
  }
}

TEST(RobustKernel, AgreesWithCeresBuiltins) {
  const double a = 1.7;
  const std::pair<RobustKernelType, std::unique_ptr<ceres::LossFunction>> cases[] = {
      {RobustKernelType::kHuber, std::make_unique<ceres::HuberLoss>(a)},
      {RobustKernelType::kCauchy, std::make_unique<ceres::CauchyLoss>(a)},
      {RobustKernelType::kTukey, std::make_unique<ceres::TukeyLoss>(a)}};
  for (const auto& [type, ceres_loss] : cases) {
    const RobustKernel kernel(type, a);
    for (double s : samplePoints(a)) {
      double ours[3], theirs[3];
      kernel.evaluate(s, ours);
      ceres_loss->Evaluate(s, theirs);
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(ours[k], theirs[k], 1e-12 * std::max(1.0, std::abs(theirs[k])))
            << kernel.toString() << " s=" << s << " k=" << k;
      }
    }
  }
}

TEST(RobustKernel, RejectsNonPositiveWidthAndUnknownNames) {
  EXPECT_THROW(RobustKernel(RobustKernelType::kHuber, 0.0), InvalidOptions);
  EXPECT_THROW(RobustKernel(RobustKernelType::kCauchy, -1.0), InvalidOptions);
  EXPECT_NO_THROW(RobustKernel(RobustKernelType::kNone, 0.0));
  EXPECT_EQ(parseEnumName<RobustKernelType>("cauchy", "RobustKernel", "kernel"),
            RobustKernelType::kCauchy);
  try {
    parseEnumName<RobustKernelType>("hubber", "RobustKernel", "kernel");
    FAIL();
  } catch (const InvalidOptions& e) {
    EXPECT_NE(std::string(e.what()).find("hubber"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("huber"), std::string::npos);
  }
}

TEST(NoiseModel, CostWhitensThenAppliesKernel) {
  const NoiseModel noise{2.0, RobustKernel(RobustKernelType::kHuber, 1.0)};
  EXPECT_DOUBLE_EQ(noise.cost(1.0), 0.5 * 0.25);            // |r/sigma|^2 = 0.25 < 1
  EXPECT_DOUBLE_EQ(noise.cost(16.0), 0.5 * (2 * 2.0 - 1));  // |r/sigma| = 2 > 1
  EXPECT_THROW((NoiseModel{0.0, {}}.validate()), InvalidOptions);
}

}  // namespace
}  // namespace curvesfm
