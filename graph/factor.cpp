#include "graph/factor.h"

#include "core/check.h"

namespace curvesfm {
namespace {

// Ambient copies of a factor's variables, with the pointer array evaluateRaw() expects.
struct AmbientBlocks {
  AmbientBlocks(const Factor& factor, const Values& values) {
    const std::vector<VariableType> types = factor.variableTypes();
    const std::vector<Key>& keys = factor.keys();
    storage.resize(keys.size());
    for (std::size_t i = 0; i < keys.size(); ++i) {
      const VariableType stored = values.type(keys[i]);
      if (stored != types[i]) throw IncorrectType(keys[i], stored, types[i]);
      storage[i].resize(ambientDim(stored));
      values.toAmbient(keys[i], storage[i].data());
      pointers.push_back(storage[i].data());
    }
  }
  std::vector<std::vector<double>> storage;
  std::vector<const double*> pointers;
};

}  // namespace

Factor::Factor(std::vector<Key> keys, NoiseModel noise_model)
    : keys_(std::move(keys)), noise_model_(std::move(noise_model)) {
  noise_model_.validate();
}

Eigen::VectorXd Factor::unwhitenedError(const Values& values) const {
  const AmbientBlocks blocks(*this, values);
  Eigen::VectorXd error(residualDimension());
  std::vector<double*> no_jacobians(keys_.size(), nullptr);
  evaluateRaw(blocks.pointers.data(), error.data(), no_jacobians.data());
  return error;
}

Linearization Factor::linearize(const Values& values) const {
  const AmbientBlocks blocks(*this, values);
  const int rows = residualDimension();
  Linearization result;
  result.error.resize(rows);
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> row_major;
  std::vector<double*> pointers;
  for (Key key : keys_) {
    row_major.emplace_back(rows, tangentDim(values.type(key)));
  }
  for (auto& m : row_major) pointers.push_back(m.data());
  evaluateRaw(blocks.pointers.data(), result.error.data(), pointers.data());
  for (const auto& m : row_major) result.jacobians.emplace_back(m);
  return result;
}

double Factor::cost(const Values& values) const {
  return noise_model_.cost(unwhitenedError(values).squaredNorm());
}

}  // namespace curvesfm
