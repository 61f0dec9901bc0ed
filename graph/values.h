#pragma once

#include <Eigen/Core>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <variant>
#include <vector>

#include "core/errors.h"
#include "graph/key.h"
#include "graph/variable_traits.h"

namespace curvesfm {

/// Thrown when a key is looked up that Values does not hold.
class KeyDoesNotExist : public Error {
 public:
  KeyDoesNotExist(Key key, const std::string& operation);
};

/// Thrown when a key holds a variable of another type than requested.
class IncorrectType : public Error {
 public:
  IncorrectType(Key key, VariableType stored, VariableType requested);
};

/// Thrown by insert() for a key that is already present.
class KeyAlreadyExists : public Error {
 public:
  explicit KeyAlreadyExists(Key key);
};

/// The type a value is stored as: Eigen expressions (e.g. Eigen::Vector3d::Zero()) as points.
template <class T>
using StoredType =
    std::conditional_t<std::is_base_of_v<Eigen::EigenBase<T>, T>, Eigen::Vector3d, T>;

/// The variables of a factor graph, by key. Each holds one of Pose3, Eigen::Vector3d (point),
/// Direction or double (scalar); VariableTraits says how each is stored and perturbed.
class Values {
 public:
  using Variable = std::variant<Pose3, Eigen::Vector3d, Direction, double>;

  /// Adds a new variable; throws KeyAlreadyExists if `key` is taken.
  template <class T>
  void insert(Key key, const T& value) {
    if (!variables_.emplace(key, Variable(StoredType<T>(value))).second) {
      throw KeyAlreadyExists(key);
    }
  }
  /// Replaces an existing variable of the same type; throws KeyDoesNotExist / IncorrectType.
  template <class T>
  void update(Key key, const T& value) {
    mutableAt<StoredType<T>>(key) = value;
  }
  /// Typed read access; throws KeyDoesNotExist / IncorrectType.
  template <class T>
  const T& at(Key key) const {
    const Variable& variable = find(key, "at");
    const T* value = std::get_if<T>(&variable);
    if (!value) throw IncorrectType(key, typeOf(variable), VariableTraits<T>::kType);
    return *value;
  }

  bool exists(Key key) const { return variables_.count(key) > 0; }
  std::size_t size() const { return variables_.size(); }
  bool empty() const { return variables_.empty(); }
  void erase(Key key);
  /// All keys, sorted.
  std::vector<Key> keys() const;
  VariableType type(Key key) const { return typeOf(find(key, "type")); }

  /// Ambient coordinates of `key` into `out` (ambientDim(type(key)) doubles), and back.
  void toAmbient(Key key, double* out) const;
  void setFromAmbient(Key key, const double* in);
  /// Moves `key` along its tangent: value = retract(value, delta); delta has tangentDim doubles.
  void retractInPlace(Key key, const double* delta);
  /// Copy with `key` retracted by `delta` (size tangentDim); for numerical differentiation.
  Values retract(Key key, const Eigen::VectorXd& delta) const;

  auto begin() const { return variables_.begin(); }
  auto end() const { return variables_.end(); }

 private:
  static VariableType typeOf(const Variable& variable);
  const Variable& find(Key key, const char* operation) const;
  Variable& find(Key key, const char* operation);
  template <class T>
  T& mutableAt(Key key) {
    Variable& variable = find(key, "update");
    T* value = std::get_if<T>(&variable);
    if (!value) throw IncorrectType(key, typeOf(variable), VariableTraits<T>::kType);
    return *value;
  }

  std::unordered_map<Key, Variable> variables_;
};

}  // namespace curvesfm
