#include "graph/values.h"

#include <gtest/gtest.h>

#include <random>

#include "core/so3.h"

namespace curvesfm {
namespace {

Values makeValues() {
  Values values;
  values.insert(poseKey(0), Pose3(so3::exp(Eigen::Vector3d(0.1, -0.2, 0.3)),
                                  Eigen::Vector3d(1, 2, 3)));
  values.insert(pointKey(0), Eigen::Vector3d(4, 5, 6));
  values.insert(directionKey(0, 0), Direction(Eigen::Vector3d(1, 1, 0)));
  values.insert(startLengthKey(0, 0), 0.5);
  return values;
}

TEST(Values, TypedAccessReturnsWhatWasInserted) {
  const Values values = makeValues();
  EXPECT_EQ(values.size(), 4u);
  EXPECT_TRUE(values.at<Eigen::Vector3d>(pointKey(0)).isApprox(Eigen::Vector3d(4, 5, 6)));
  EXPECT_DOUBLE_EQ(values.at<double>(startLengthKey(0, 0)), 0.5);
  EXPECT_EQ(values.type(directionKey(0, 0)), VariableType::kDirection);
  EXPECT_EQ(values.keys().size(), 4u);
}

TEST(Values, MissingKeyNamesTheKey) {
  const Values values = makeValues();
  try {
    values.at<Pose3>(poseKey(7));
    FAIL() << "expected KeyDoesNotExist";
  } catch (const KeyDoesNotExist& e) {
    EXPECT_NE(std::string(e.what()).find("x7"), std::string::npos) << e.what();
  }
}

TEST(Values, WrongTypeNamesBothTypes) {
  const Values values = makeValues();
  try {
    values.at<Pose3>(pointKey(0));
    FAIL() << "expected IncorrectType";
  } catch (const IncorrectType& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("l0"), std::string::npos) << message;
    EXPECT_NE(message.find("Point3"), std::string::npos) << message;
    EXPECT_NE(message.find("Pose3"), std::string::npos) << message;
  }
  Values copy = values;
  EXPECT_THROW(copy.update(pointKey(0), 1.0), IncorrectType);
}

TEST(Values, InsertTwiceAndUpdateMissingThrow) {
  Values values = makeValues();
  EXPECT_THROW(values.insert(pointKey(0), Eigen::Vector3d::Zero()), KeyAlreadyExists);
  EXPECT_THROW(values.update(pointKey(9), Eigen::Vector3d::Zero()), KeyDoesNotExist);
  EXPECT_THROW(values.erase(pointKey(9)), KeyDoesNotExist);
  values.update(pointKey(0), Eigen::Vector3d(7, 8, 9));
  EXPECT_TRUE(values.at<Eigen::Vector3d>(pointKey(0)).isApprox(Eigen::Vector3d(7, 8, 9)));
}

TEST(Values, AmbientRoundTripKeepsEveryType) {
  const Values values = makeValues();
  Values copy = values;
  for (const Key key : values.keys()) {
    double ambient[7];
    values.toAmbient(key, ambient);
    copy.setFromAmbient(key, ambient);
  }
  EXPECT_TRUE(copy.at<Pose3>(poseKey(0)).translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_TRUE(copy.at<Pose3>(poseKey(0)).rotation().isApprox(
      values.at<Pose3>(poseKey(0)).rotation()));
  EXPECT_TRUE(copy.at<Direction>(directionKey(0, 0))
                  .vector()
                  .isApprox(values.at<Direction>(directionKey(0, 0)).vector()));
}

TEST(Values, RetractMovesOnlyTheGivenKey) {
  const Values values = makeValues();
  const Values moved = values.retract(pointKey(0), Eigen::Vector3d(1, 0, 0));
  EXPECT_TRUE(moved.at<Eigen::Vector3d>(pointKey(0)).isApprox(Eigen::Vector3d(5, 5, 6)));
  EXPECT_DOUBLE_EQ(moved.at<double>(startLengthKey(0, 0)), 0.5);
  EXPECT_THROW(values.retract(pointKey(0), Eigen::Vector2d(1, 0)), CheckError);
  const Values turned = values.retract(directionKey(0, 0), Eigen::Vector2d(0.1, 0.0));
  EXPECT_NEAR(values.at<Direction>(directionKey(0, 0))
                  .angleTo(turned.at<Direction>(directionKey(0, 0))),
              0.1, 1e-12);
}

TEST(Values, RetractAmbientIsTheRetractOfEveryType) {
  const Values values = makeValues();
  const double delta[6] = {0.1, -0.2, 0.05, 0.3, -0.1, 0.2};
  for (const Key key : values.keys()) {
    const VariableType type = values.type(key);
    double x[7];
    double out[7];
    double expected[7];
    values.toAmbient(key, x);
    retractAmbient(type, x, delta, out);
    Values moved = values;
    moved.retractInPlace(key, delta);
    moved.toAmbient(key, expected);
    for (int i = 0; i < ambientDim(type); ++i) EXPECT_DOUBLE_EQ(out[i], expected[i]) << key;
  }
}

}  // namespace
}  // namespace curvesfm
