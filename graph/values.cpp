#include "graph/values.h"

#include <algorithm>

#include "core/check.h"

namespace curvesfm {

std::string toString(VariableType type) {
  switch (type) {
    case VariableType::kPose3: return "Pose3";
    case VariableType::kPoint3: return "Point3";
    case VariableType::kDirection: return "Direction";
    case VariableType::kScalar: return "Scalar";
  }
  return "unknown";
}

int tangentDim(VariableType type) {
  switch (type) {
    case VariableType::kPose3: return VariableTraits<Pose3>::kTangentDim;
    case VariableType::kPoint3: return VariableTraits<Eigen::Vector3d>::kTangentDim;
    case VariableType::kDirection: return VariableTraits<Direction>::kTangentDim;
    case VariableType::kScalar: return VariableTraits<double>::kTangentDim;
  }
  return 0;
}

int ambientDim(VariableType type) {
  switch (type) {
    case VariableType::kPose3: return VariableTraits<Pose3>::kAmbientDim;
    case VariableType::kPoint3: return VariableTraits<Eigen::Vector3d>::kAmbientDim;
    case VariableType::kDirection: return VariableTraits<Direction>::kAmbientDim;
    case VariableType::kScalar: return VariableTraits<double>::kAmbientDim;
  }
  return 0;
}

void retractAmbient(VariableType type, const double* x, const double* delta, double* out) {
  switch (type) {
    case VariableType::kPose3:
      VariableTraits<Pose3>::retract(Pose3::fromAmbient(x), delta).toAmbient(out);
      return;
    case VariableType::kDirection:
      VariableTraits<Direction>::retract(Direction::fromAmbient(x), delta).toAmbient(out);
      return;
    case VariableType::kPoint3:
    case VariableType::kScalar:
      for (int i = 0; i < ambientDim(type); ++i) out[i] = x[i] + delta[i];
      return;
  }
}

KeyDoesNotExist::KeyDoesNotExist(Key key, const std::string& operation)
    : Error("KeyDoesNotExist: Values::" + operation + ": no variable with key " +
            key.toString()) {}

IncorrectType::IncorrectType(Key key, VariableType stored, VariableType requested)
    : Error("IncorrectType: variable " + key.toString() + " holds a " + toString(stored) +
            ", requested a " + toString(requested)) {}

KeyAlreadyExists::KeyAlreadyExists(Key key)
    : Error("KeyAlreadyExists: Values::insert: key " + key.toString() + " is already present") {}

VariableType Values::typeOf(const Variable& variable) {
  return std::visit([](const auto& v) { return VariableTraits<std::decay_t<decltype(v)>>::kType; },
                    variable);
}

const Values::Variable& Values::find(Key key, const char* operation) const {
  const auto it = variables_.find(key);
  if (it == variables_.end()) throw KeyDoesNotExist(key, operation);
  return it->second;
}

Values::Variable& Values::find(Key key, const char* operation) {
  const auto it = variables_.find(key);
  if (it == variables_.end()) throw KeyDoesNotExist(key, operation);
  return it->second;
}

void Values::erase(Key key) {
  if (variables_.erase(key) == 0) throw KeyDoesNotExist(key, "erase");
}

std::vector<Key> Values::keys() const {
  std::vector<Key> keys;
  keys.reserve(variables_.size());
  for (const auto& entry : variables_) keys.push_back(entry.first);
  std::sort(keys.begin(), keys.end());
  return keys;
}

void Values::toAmbient(Key key, double* out) const {
  std::visit([out](const auto& v) { VariableTraits<std::decay_t<decltype(v)>>::toAmbient(v, out); },
             find(key, "toAmbient"));
}

void Values::setFromAmbient(Key key, const double* in) {
  std::visit([in](auto& v) { v = VariableTraits<std::decay_t<decltype(v)>>::fromAmbient(in); },
             find(key, "setFromAmbient"));
}

void Values::retractInPlace(Key key, const double* delta) {
  std::visit([delta](auto& v) { v = VariableTraits<std::decay_t<decltype(v)>>::retract(v, delta); },
             find(key, "retract"));
}

Values Values::retract(Key key, const Eigen::VectorXd& delta) const {
  CURVESFM_CHECK(delta.size() == tangentDim(type(key)))
      << "delta of size " << delta.size() << " for " << key << " of type " << toString(type(key));
  Values result = *this;
  result.retractInPlace(key, delta.data());
  return result;
}

}  // namespace curvesfm
