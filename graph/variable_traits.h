#pragma once

#include <Eigen/Core>
#include <string>

#include "core/direction.h"
#include "core/pose3.h"

namespace curvesfm {

/// The variable types a factor graph holds. Points are Eigen::Vector3d, scalars double.
enum class VariableType { kPose3, kPoint3, kDirection, kScalar };

std::string toString(VariableType type);

/// Per-type facts the graph layer needs, in GTSAM's traits style:
///   kType, kTangentDim, kAmbientDim,
///   fromAmbient(const double*), toAmbient(value, double*),
///   retract(value, const double* delta), localCoordinates(a, b, double* delta).
/// The tangent space and ambient layout of each type are documented on the type itself.
template <class T>
struct VariableTraits;

template <>
struct VariableTraits<Pose3> {
  static constexpr VariableType kType = VariableType::kPose3;
  static constexpr int kTangentDim = Pose3::kTangentDim;
  static constexpr int kAmbientDim = Pose3::kAmbientDim;
  static Pose3 fromAmbient(const double* x) { return Pose3::fromAmbient(x); }
  static void toAmbient(const Pose3& v, double* x) { v.toAmbient(x); }
  static Pose3 retract(const Pose3& v, const double* d) { return v.retract(Vector6d::Map(d)); }
  static void localCoordinates(const Pose3& a, const Pose3& b, double* d) {
    Vector6d::Map(d) = a.localCoordinates(b);
  }
};

template <>
struct VariableTraits<Eigen::Vector3d> {
  static constexpr VariableType kType = VariableType::kPoint3;
  static constexpr int kTangentDim = 3;
  static constexpr int kAmbientDim = 3;
  static Eigen::Vector3d fromAmbient(const double* x) { return Eigen::Vector3d(x[0], x[1], x[2]); }
  static void toAmbient(const Eigen::Vector3d& v, double* x) { Eigen::Vector3d::Map(x) = v; }
  static Eigen::Vector3d retract(const Eigen::Vector3d& v, const double* d) {
    return v + Eigen::Vector3d::Map(d);
  }
  static void localCoordinates(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double* d) {
    Eigen::Vector3d::Map(d) = b - a;
  }
};

template <>
struct VariableTraits<Direction> {
  static constexpr VariableType kType = VariableType::kDirection;
  static constexpr int kTangentDim = Direction::kTangentDim;
  static constexpr int kAmbientDim = Direction::kAmbientDim;
  static Direction fromAmbient(const double* x) { return Direction::fromAmbient(x); }
  static void toAmbient(const Direction& v, double* x) { v.toAmbient(x); }
  static Direction retract(const Direction& v, const double* d) {
    return v.retract(Eigen::Vector2d::Map(d));
  }
  static void localCoordinates(const Direction& a, const Direction& b, double* d) {
    Eigen::Vector2d::Map(d) = a.localCoordinates(b);
  }
};

template <>
struct VariableTraits<double> {
  static constexpr VariableType kType = VariableType::kScalar;
  static constexpr int kTangentDim = 1;
  static constexpr int kAmbientDim = 1;
  static double fromAmbient(const double* x) { return x[0]; }
  static void toAmbient(double v, double* x) { x[0] = v; }
  static double retract(double v, const double* d) { return v + d[0]; }
  static void localCoordinates(double a, double b, double* d) { d[0] = b - a; }
};

/// Runtime versions of the traits' dimensions.
int tangentDim(VariableType type);
int ambientDim(VariableType type);
/// Runtime retract on ambient coordinates: out = retract(x, delta) for a variable of `type`
/// (delta has tangentDim(type) doubles; out may not alias x).
void retractAmbient(VariableType type, const double* x, const double* delta, double* out);

}  // namespace curvesfm
