#include "frontend/image/colour_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/errors.h"

namespace curvesfm {
namespace {

cv::Scalar turbo(int value) {
  cv::Mat grey(1, 1, CV_8UC1, cv::Scalar(value));
  cv::Mat bgr;
  cv::applyColorMap(grey, bgr, cv::COLORMAP_TURBO);
  const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
  return cv::Scalar(c[0], c[1], c[2]);
}

bool contains(const cv::Mat& image, const cv::Scalar& colour) {
  const cv::Vec3b wanted(colour[0], colour[1], colour[2]);
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) {
      if (image.at<cv::Vec3b>(r, c) == wanted) return true;
    }
  }
  return false;
}

TEST(ColourMap, EndsAreTurbosEndsAndValuesBeyondThemAreClipped) {
  EXPECT_EQ(colourMapBgr(0.0), turbo(0));
  EXPECT_EQ(colourMapBgr(1.0), turbo(255));
  EXPECT_EQ(colourMapBgr(0.5), turbo(128));
  EXPECT_NE(colourMapBgr(0.0), colourMapBgr(1.0));
  EXPECT_EQ(colourMapBgr(-0.5), colourMapBgr(0.0));
  EXPECT_EQ(colourMapBgr(7.0), colourMapBgr(1.0));
  EXPECT_EQ(colourMapBgr(std::nan("")), colourMapBgr(0.0));
  EXPECT_EQ(colourMapBgr(INFINITY), colourMapBgr(1.0));
}

TEST(ColourLegend, DrawsTheBarInTheTopLeftCornerAndLeavesTheRestAlone) {
  const cv::Mat before(480, 640, CV_8UC3, cv::Scalar(100, 100, 100));
  cv::Mat image = before.clone();
  const cv::Rect box = drawColourLegend(&image, {"residual rms (px)", "0", ">=3"});
  EXPECT_GT(box.area(), 0);
  EXPECT_LT(box.x + box.width, 320);
  EXPECT_LT(box.y + box.height, 240);
  cv::Mat changed;
  cv::cvtColor(image != before, changed, cv::COLOR_BGR2GRAY);
  const int changed_total = cv::countNonZero(changed);
  EXPECT_EQ(cv::countNonZero(changed(box)), changed_total) << "drawn outside its box";
  EXPECT_GT(changed_total, box.area() / 2);  // The box is darkened.
  // The bar runs over the whole map, its ends exactly the map's end colours.
  EXPECT_TRUE(contains(image(box), colourMapBgr(0.0)));
  EXPECT_TRUE(contains(image(box), colourMapBgr(1.0)));
}

TEST(ColourLegend, IsCutOffOnASmallImageAndNeedsAColourImage) {
  cv::Mat small(30, 40, CV_8UC3, cv::Scalar(100, 100, 100));
  const cv::Rect box = drawColourLegend(&small, {"track length (keyframes)", "<=2", ">=20"});
  EXPECT_EQ(box & cv::Rect(0, 0, 40, 30), box);
  EXPECT_GT(box.area(), 0);
  cv::Mat grey(30, 40, CV_8UC1);
  EXPECT_THROW(drawColourLegend(&grey, {"t", "0", "1"}), CheckError);
}

}  // namespace
}  // namespace curvesfm
