#include "graph/key.h"

#include <gtest/gtest.h>

#include <unordered_set>

#include "core/errors.h"

namespace curvesfm {
namespace {

TEST(Key, PrintsSymbolAndIndices) {
  EXPECT_EQ(poseKey(3).toString(), "x3");
  EXPECT_EQ(curvePointKey(17, 2).toString(), "q17.2");
  EXPECT_EQ(directionKey(0, 0).toString(), "v0.0");
  EXPECT_EQ(pointKey(123456789).toString(), "l123456789");
}

TEST(Key, KeepsIndicesAtTheirLimits) {
  const Key single('x', Key::kMaxIndex);
  EXPECT_EQ(single.index(), Key::kMaxIndex);
  EXPECT_FALSE(single.hasMinor());
  const Key pair('q', Key::kMaxMajor, Key::kMaxMinor);
  EXPECT_EQ(pair.index(), Key::kMaxMajor);
  EXPECT_EQ(pair.minor(), Key::kMaxMinor);
  EXPECT_EQ(pair.symbol(), 'q');
}

TEST(Key, RejectsIndicesBeyondTheirLimits) {
  EXPECT_THROW(Key('x', Key::kMaxIndex + 1), CheckError);
  EXPECT_THROW(Key('q', Key::kMaxMajor + 1u, 0u), CheckError);
  EXPECT_THROW(Key('q', 0u, Key::kMaxMinor + 1u), CheckError);
}

TEST(Key, DistinguishesSingleAndTwoIndexKeys) {
  std::unordered_set<Key> keys = {Key('q', 0u, 1u), Key('q', 1), curvePointKey(1, 0),
                                  startLengthKey(1, 0), endLengthKey(1, 0)};
  EXPECT_EQ(keys.size(), 5u);
  EXPECT_NE(Key('q', 0u, 0u), Key('q', 0));
}

TEST(Key, CategoryFollowsSymbol) {
  EXPECT_EQ(categoryOf(poseKey(1)), VariableCategory::kPose);
  EXPECT_EQ(categoryOf(pointKey(1)), VariableCategory::kPoint);
  EXPECT_EQ(categoryOf(curvePointKey(1, 2)), VariableCategory::kCurvePoint);
  EXPECT_EQ(categoryOf(directionKey(1, 2)), VariableCategory::kDirection);
  EXPECT_EQ(categoryOf(startLengthKey(1, 2)), VariableCategory::kLength);
  EXPECT_EQ(categoryOf(endLengthKey(1, 2)), VariableCategory::kLength);
  EXPECT_EQ(categoryOf(Key('z', 0)), VariableCategory::kOther);
  EXPECT_EQ(toString(VariableCategory::kCurvePoint), "curve_point");
  EXPECT_EQ(categoryOf(focalScaleKey()), VariableCategory::kIntrinsics);
  EXPECT_EQ(toString(VariableCategory::kIntrinsics), "intrinsics");
}

}  // namespace
}  // namespace curvesfm
