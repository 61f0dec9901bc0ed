#include "graph/robust_kernel.h"

#include <cmath>
#include <sstream>

#include "core/errors.h"

namespace curvesfm {

RobustKernel::RobustKernel(RobustKernelType type, double width) : type_(type), width_(width) {
  if (type != RobustKernelType::kNone && !(width > 0.0 && std::isfinite(width))) {
    throw InvalidOptions("RobustKernel", "width", std::to_string(width),
                         "must be > 0 and finite for kernel " + curvesfm::toString(type));
  }
}

void RobustKernel::evaluate(double s, double out[3]) const {
  const double b = width_ * width_;
  switch (type_) {
    case RobustKernelType::kNone:
      out[0] = s, out[1] = 1.0, out[2] = 0.0;
      return;
    case RobustKernelType::kHuber:
      if (s <= b) {
        out[0] = s, out[1] = 1.0, out[2] = 0.0;
      } else {
        const double r = std::sqrt(s);
        out[0] = 2.0 * width_ * r - b;
        out[1] = width_ / r;
        out[2] = -0.5 * out[1] / s;
      }
      return;
    case RobustKernelType::kCauchy: {
      const double inv = 1.0 / (1.0 + s / b);
      out[0] = b * std::log1p(s / b);
      out[1] = inv;
      out[2] = -inv * inv / b;
      return;
    }
    case RobustKernelType::kTukey:
      if (s <= b) {
        const double u = 1.0 - s / b;
        out[0] = b / 3.0 * (1.0 - u * u * u);
        out[1] = u * u;
        out[2] = -2.0 * u / b;
      } else {
        out[0] = b / 3.0, out[1] = 0.0, out[2] = 0.0;
      }
      return;
  }
}

double RobustKernel::rho(double s) const {
  double out[3] = {s, 1.0, 0.0};
  evaluate(s, out);
  return out[0];
}

std::string RobustKernel::toString() const {
  if (type_ == RobustKernelType::kNone) return "none";
  std::ostringstream os;
  os << curvesfm::toString(type_) << "(" << width_ << ")";
  return os.str();
}

void NoiseModel::validate() const {
  if (!(sigma > 0.0 && std::isfinite(sigma))) {
    throw InvalidOptions("NoiseModel", "sigma", std::to_string(sigma), "must be > 0 and finite");
  }
}

}  // namespace curvesfm
