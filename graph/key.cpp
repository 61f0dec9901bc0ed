#include "graph/key.h"

#include "core/check.h"

namespace curvesfm {
namespace {
constexpr std::uint64_t kTwoIndexFlag = std::uint64_t{1} << 55;

std::uint64_t symbolBits(char symbol) {
  return static_cast<std::uint64_t>(static_cast<unsigned char>(symbol)) << 56;
}
}  // namespace

Key::Key(char symbol, std::uint64_t index) {
  CURVESFM_CHECK(index <= kMaxIndex) << "key index " << index << " too large";
  raw_ = symbolBits(symbol) | index;
}

Key::Key(char symbol, std::uint32_t major, std::uint32_t minor) {
  CURVESFM_CHECK(major <= kMaxMajor && minor <= kMaxMinor)
      << "key indices " << major << "." << minor << " too large";
  raw_ = symbolBits(symbol) | kTwoIndexFlag | (std::uint64_t{major} << 24) | minor;
}

std::uint64_t Key::index() const {
  return hasMinor() ? (raw_ >> 24) & kMaxMajor : raw_ & kMaxIndex;
}

std::string Key::toString() const {
  std::string text(1, symbol());
  text += std::to_string(index());
  if (hasMinor()) text += "." + std::to_string(minor());
  return text;
}

std::ostream& operator<<(std::ostream& os, Key key) { return os << key.toString(); }

VariableCategory categoryOf(Key key) {
  switch (key.symbol()) {
    case 'x': return VariableCategory::kPose;
    case 'l': return VariableCategory::kPoint;
    case 'q': return VariableCategory::kCurvePoint;
    case 'v': return VariableCategory::kDirection;
    case 'a':
    case 'b': return VariableCategory::kLength;
    case 'f': return VariableCategory::kIntrinsics;
    default: return VariableCategory::kOther;
  }
}

std::string toString(VariableCategory category) {
  switch (category) {
    case VariableCategory::kPose: return "pose";
    case VariableCategory::kPoint: return "point";
    case VariableCategory::kCurvePoint: return "curve_point";
    case VariableCategory::kDirection: return "direction";
    case VariableCategory::kLength: return "length";
    case VariableCategory::kIntrinsics: return "intrinsics";
    case VariableCategory::kOther: break;
  }
  return "other";
}

}  // namespace curvesfm
