#include "frontend/image/colour_map.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/check.h"

namespace curvesfm {
namespace {

constexpr int kSteps = 256;

// applyColorMap works on images only: the map as a one-row table, built once.
const cv::Mat& colourTable() {
  static const cv::Mat table = [] {
    cv::Mat ramp(1, kSteps, CV_8UC1);
    for (int i = 0; i < kSteps; ++i) ramp.at<uchar>(0, i) = static_cast<uchar>(i);
    cv::Mat bgr;
    cv::applyColorMap(ramp, bgr, cv::COLORMAP_TURBO);
    return bgr;
  }();
  return table;
}

// Sizes for a 640 px wide image, scaled with the width so that the legend covers about the same
// share of any image and stays legible.
struct LegendLayout {
  int margin, pad, gap, bar_width, bar_height, thickness;
  double font_scale;
};

LegendLayout layoutFor(int image_width) {
  const double s = std::clamp(image_width / 640.0, 0.5, 3.0);
  const auto px = [s](double size) { return std::max(1, static_cast<int>(std::lround(size * s))); };
  return {px(8), px(6), px(5), px(200), px(12), px(1), 0.45 * s};
}

cv::Size textSize(const std::string& text, const LegendLayout& l) {
  int baseline = 0;
  return cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, l.font_scale, l.thickness, &baseline);
}

void putText(cv::Mat* image, const std::string& text, cv::Point bottom_left,
             const LegendLayout& l) {
  cv::putText(*image, text, bottom_left, cv::FONT_HERSHEY_SIMPLEX, l.font_scale,
              cv::Scalar(255, 255, 255), l.thickness, cv::LINE_AA);
}

// Solid columns (no anti-aliasing), so the bar's ends are exactly the map's end colours.
void drawBar(cv::Mat* image, cv::Point top_left, const LegendLayout& l) {
  for (int i = 0; i < l.bar_width; ++i) {
    const cv::Point top = top_left + cv::Point(i, 0);
    cv::line(*image, top, top + cv::Point(0, l.bar_height - 1),
             colourMapBgr(static_cast<double>(i) / std::max(1, l.bar_width - 1)), 1, cv::LINE_8);
  }
}

}  // namespace

cv::Scalar colourMapBgr(double fraction) {
  const double clipped = std::isnan(fraction) ? 0.0 : std::clamp(fraction, 0.0, 1.0);
  const cv::Vec3b c = colourTable().at<cv::Vec3b>(0, cvRound(clipped * (kSteps - 1)));
  return cv::Scalar(c[0], c[1], c[2]);
}

cv::Rect drawColourLegend(cv::Mat* image_bgr, const ColourLegend& legend) {
  CURVESFM_CHECK(image_bgr && image_bgr->type() == CV_8UC3) << "expected a CV_8UC3 image";
  const LegendLayout l = layoutFor(image_bgr->cols);
  const cv::Size title = textSize(legend.title, l);
  const cv::Size low = textSize(legend.low_label, l);
  const cv::Size high = textSize(legend.high_label, l);
  const int label_height = std::max(low.height, high.height);
  const int inner_width = std::max({l.bar_width, title.width, low.width + l.gap + high.width});
  const cv::Rect box(l.margin, l.margin, inner_width + 2 * l.pad,
                     2 * l.pad + title.height + l.bar_height + label_height + 3 * l.gap);
  const cv::Rect visible = box & cv::Rect(0, 0, image_bgr->cols, image_bgr->rows);
  if (visible.empty()) return visible;
  // Darken rather than fill: the keyframe stays visible behind the legend.
  cv::Mat background = (*image_bgr)(visible);
  background.convertTo(background, -1, 0.3);

  const cv::Point origin(box.x + l.pad, box.y + l.pad);
  putText(image_bgr, legend.title, origin + cv::Point(0, title.height), l);
  const cv::Point bar = origin + cv::Point(0, title.height + l.gap);
  drawBar(image_bgr, bar, l);
  const int label_baseline = bar.y + l.bar_height + l.gap + label_height;
  putText(image_bgr, legend.low_label, {bar.x, label_baseline}, l);
  putText(image_bgr, legend.high_label, {bar.x + l.bar_width - high.width, label_baseline}, l);
  return visible;
}

}  // namespace curvesfm
