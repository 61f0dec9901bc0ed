#pragma once

#include <cstdint>
#include <functional>
#include <ostream>
#include <string>

namespace curvesfm {

/// Identifies one variable of a factor graph: a symbol character and one or two indices,
/// printed `x3` (pose 3) or `q17.2` (point 2 of curve 17). Packed in 64 bits:
///   symbol (8 bits) | two-index flag (1) | index (55)   or   ... | major (31) | minor (24).
/// Build keys through the helpers below (poseKey, curvePointKey, ...), never from raw integers.
class Key {
 public:
  static constexpr std::uint64_t kMaxIndex = (std::uint64_t{1} << 55) - 1;
  static constexpr std::uint32_t kMaxMajor = (std::uint32_t{1} << 31) - 1;
  static constexpr std::uint32_t kMaxMinor = (std::uint32_t{1} << 24) - 1;

  Key() = default;
  /// Single-index key; index <= kMaxIndex.
  Key(char symbol, std::uint64_t index);
  /// Two-index key (e.g. curve, point-in-curve); major <= kMaxMajor, minor <= kMaxMinor.
  Key(char symbol, std::uint32_t major, std::uint32_t minor);

  char symbol() const { return static_cast<char>(raw_ >> 56); }
  bool hasMinor() const { return (raw_ >> 55) & 1u; }
  /// The single index, or the major index of a two-index key.
  std::uint64_t index() const;
  /// The minor index of a two-index key (0 for a single-index key).
  std::uint32_t minor() const { return hasMinor() ? static_cast<std::uint32_t>(raw_ & kMaxMinor) : 0; }

  std::uint64_t raw() const { return raw_; }
  std::string toString() const;

  friend bool operator==(Key a, Key b) { return a.raw_ == b.raw_; }
  friend bool operator!=(Key a, Key b) { return a.raw_ != b.raw_; }
  friend bool operator<(Key a, Key b) { return a.raw_ < b.raw_; }

 private:
  std::uint64_t raw_ = 0;
};

std::ostream& operator<<(std::ostream& os, Key key);

/// What a variable is, read from its key's symbol. The scheduler fixes and frees variables by
/// category, never by factor type.
enum class VariableCategory {
  kPose,
  kPoint,
  kCurvePoint,
  kDirection,
  kLength,
  kIntrinsics,
  kOther
};

/// Category of `key` by symbol: x pose, l point, q curve point, v direction, a/b lengths,
/// f camera intrinsics.
VariableCategory categoryOf(Key key);
/// "pose", "point", "curve_point", "direction", "length", "intrinsics", "other".
std::string toString(VariableCategory category);

/// Camera pose j (cam_from_world).
inline Key poseKey(std::uint64_t j) { return Key('x', j); }
/// 3D point landmark l (point bundle adjustment).
inline Key pointKey(std::uint64_t l) { return Key('l', l); }
/// Point Q_i of curve c (segment i runs from Q_i to Q_{i+1}).
inline Key curvePointKey(std::uint32_t c, std::uint32_t i) { return Key('q', c, i); }
/// Unit tangent v_i of curve c at Q_i.
inline Key directionKey(std::uint32_t c, std::uint32_t i) { return Key('v', c, i); }
/// Length d1 of segment i of curve c (arm of the first inner control point).
inline Key startLengthKey(std::uint32_t c, std::uint32_t i) { return Key('a', c, i); }
/// Length d2 of segment i of curve c (arm of the second inner control point).
inline Key endLengthKey(std::uint32_t c, std::uint32_t i) { return Key('b', c, i); }
/// The factor on the camera's focal lengths shared by every image (FocalPointReprojectionFactor).
inline Key focalScaleKey() { return Key('f', 0); }

/// The keys of the variables of segment i of curve c, which runs from Q_i to Q_{i+1}.
struct SegmentKeys {
  Key q0;  ///< Start point Q_i.
  Key q1;  ///< End point Q_{i+1} (shared with segment i + 1).
  Key v0;  ///< Tangent v_i at the start.
  Key v1;  ///< Tangent v_{i+1} at the end (shared with segment i + 1).
  Key d1;  ///< Start arm length d1_i.
  Key d2;  ///< End arm length d2_i.
};

inline SegmentKeys segmentKeys(std::uint32_t c, std::uint32_t i) {
  return {curvePointKey(c, i), curvePointKey(c, i + 1), directionKey(c, i),
          directionKey(c, i + 1), startLengthKey(c, i),  endLengthKey(c, i)};
}

}  // namespace curvesfm

template <>
struct std::hash<curvesfm::Key> {
  std::size_t operator()(curvesfm::Key key) const noexcept {
    return std::hash<std::uint64_t>()(key.raw());
  }
};
