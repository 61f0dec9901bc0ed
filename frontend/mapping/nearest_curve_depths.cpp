#include "frontend/mapping/nearest_curve_depths.h"

#include <algorithm>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "core/check.h"

namespace curvesfm {

NearestCurveDepths::NearestCurveDepths(int width, int height, int half_width,
                                       double occluder_depth_ratio)
    : depth_(height, width, std::numeric_limits<float>::infinity()),
      half_width_(half_width),
      occluder_depth_ratio_(occluder_depth_ratio) {
  CURVESFM_CHECK(width > 0 && height > 0 && half_width >= 0)
      << "NearestCurveDepths: size " << width << " x " << height << ", half width " << half_width;
  CURVESFM_CHECK(occluder_depth_ratio > 0.0 && occluder_depth_ratio <= 1.0)
      << "NearestCurveDepths: occluder depth ratio " << occluder_depth_ratio
      << " must be in (0, 1]";
}

void NearestCurveDepths::add(const std::vector<cv::Point>& polyline,
                             const std::vector<double>& depths) {
  CURVESFM_CHECK(polyline.size() == depths.size())
      << "NearestCurveDepths: " << polyline.size() << " vertices, " << depths.size() << " depths";
  const cv::Rect stamped(-half_width_, -half_width_, depth_.cols + 2 * half_width_,
                         depth_.rows + 2 * half_width_);
  for (std::size_t v = 0; v + 1 < polyline.size(); ++v) {
    const cv::Point a = polyline[v], b = polyline[v + 1];
    cv::Point from = a, to = b;
    if (!cv::clipLine(stamped, from, to)) continue;
    const double length = cv::norm(b - a);
    const auto depthOnPiece = [&](const cv::Point& p) {
      const double t = length > 0.0 ? cv::norm(p - a) / length : 0.0;
      return (1.0 - t) * depths[v] + t * depths[v + 1];
    };
    const double depth_from = depthOnPiece(from), depth_to = depthOnPiece(to);
    cv::LineIterator line(from, to, 8);
    const int steps = std::max(line.count - 1, 1);
    for (int j = 0; j < line.count; ++j, ++line) {
      const double t = static_cast<double>(j) / steps;
      stamp(line.pos(), static_cast<float>((1.0 - t) * depth_from + t * depth_to));
    }
  }
}

double NearestCurveDepths::fractionOccluded(const std::vector<cv::Point>& polyline,
                                            const std::vector<double>& depths) const {
  CURVESFM_CHECK(polyline.size() == depths.size())
      << "NearestCurveDepths: " << polyline.size() << " vertices, " << depths.size() << " depths";
  if (polyline.empty()) return 0.0;
  int hidden = 0;
  for (std::size_t v = 0; v < polyline.size(); ++v) {
    const cv::Point& p = polyline[v];
    hidden += p.x >= 0 && p.y >= 0 && p.x < depth_.cols && p.y < depth_.rows &&
              depth_(p) < occluder_depth_ratio_ * depths[v];
  }
  return static_cast<double>(hidden) / static_cast<double>(polyline.size());
}

void NearestCurveDepths::stamp(const cv::Point& centre, float depth) {
  const int x0 = std::max(centre.x - half_width_, 0);
  const int x1 = std::min(centre.x + half_width_, depth_.cols - 1);
  const int y0 = std::max(centre.y - half_width_, 0);
  const int y1 = std::min(centre.y + half_width_, depth_.rows - 1);
  for (int y = y0; y <= y1; ++y) {
    float* row = depth_[y];
    for (int x = x0; x <= x1; ++x) row[x] = std::min(row[x], depth);
  }
}

}  // namespace curvesfm
