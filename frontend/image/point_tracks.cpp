#include "frontend/image/point_tracks.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "core/check.h"
#include "core/errors.h"

namespace curvesfm {

void PointTrackerOptions::validate() const {
  const OptionCheck require("PointTrackerOptions");
  require(grid_cols >= 1 && grid_cols <= 64, "grid_cols", grid_cols, "in [1, 64]");
  require(grid_rows >= 1 && grid_rows <= 64, "grid_rows", grid_rows, "in [1, 64]");
  require(corners_per_cell >= 1 && corners_per_cell <= 1000, "corners_per_cell", corners_per_cell,
          "in [1, 1000]");
  require(quality_level > 0.0 && quality_level < 1.0, "quality_level", quality_level, "in (0, 1)");
  require(image_quality_level >= 0.0 && image_quality_level < 1.0, "image_quality_level",
          image_quality_level, "in [0, 1)");
  require.nonNegative("min_distance_px", min_distance_px);
  require(corner_block_size >= 3 && corner_block_size <= 31 && corner_block_size % 2 == 1,
          "corner_block_size", corner_block_size, "odd, in [3, 31]");
  require(window_size_px >= 5 && window_size_px <= 101 && window_size_px % 2 == 1, "window_size_px",
          window_size_px, "odd, in [5, 101]");
  require(pyramid_levels >= 0 && pyramid_levels <= 8, "pyramid_levels", pyramid_levels,
          "in [0, 8]");
  require(max_iterations >= 1 && max_iterations <= 1000, "max_iterations", max_iterations,
          "in [1, 1000]");
  require.positive("epsilon_px", epsilon_px);
  require.positive("min_eigen_threshold", min_eigen_threshold);
  require.positive("max_forward_backward_px", max_forward_backward_px);
  require.nonNegative("border_px", border_px);
  require(min_live_tracks >= 0 && min_live_tracks <= 1000000, "min_live_tracks", min_live_tracks,
          "in [0, 1000000]");
}

namespace {

cv::Mat toGrey(const cv::Mat& image) {
  CURVESFM_CHECK(!image.empty()) << "PointTracker needs an image, got an empty one";
  CURVESFM_CHECK(image.type() == CV_8UC1 || image.type() == CV_8UC3)
      << "PointTracker takes 8-bit grey (CV_8UC1) or BGR (CV_8UC3) images, got type "
      << image.type() << " with " << image.channels() << " channel(s)";
  if (image.type() == CV_8UC1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

// The bucketing grid: cell c of n over `extent` pixels spans [begin(c), begin(c + 1)).
struct Grid {
  cv::Size size;
  int cols, rows;

  int begin(int c, int n, int extent) const {
    return static_cast<int>(std::lround(static_cast<double>(c) * extent / n));
  }
  cv::Rect cell(int col, int row) const {
    const int x0 = begin(col, cols, size.width), y0 = begin(row, rows, size.height);
    return {x0, y0, begin(col + 1, cols, size.width) - x0, begin(row + 1, rows, size.height) - y0};
  }
  int index(const Eigen::Vector2d& p) const {
    const int col = std::clamp(static_cast<int>((p.x() + 0.5) * cols / size.width), 0, cols - 1);
    const int row = std::clamp(static_cast<int>((p.y() + 0.5) * rows / size.height), 0, rows - 1);
    return row * cols + col;
  }
};

}  // namespace

PointTracker::PointTracker(const PointTrackerOptions& options) : options_(options) {
  options_.validate();
}

bool PointTracker::inside(const cv::Point2f& p) const {
  const double b = options_.border_px;
  return p.x >= b && p.y >= b && p.x <= size_.width - 1 - b && p.y <= size_.height - 1 - b;
}

PointFrame PointTracker::track(const cv::Mat& image) {
  const cv::Mat grey = toGrey(image);
  if (next_frame_ == 0) size_ = grey.size();
  CURVESFM_CHECK(grey.size() == size_)
      << "PointTracker: frame " << next_frame_ << " is " << grey.cols << "x" << grey.rows
      << " px, the sequence started at " << size_.width << "x" << size_.height << " px";

  const cv::Size window(options_.window_size_px, options_.window_size_px);
  std::vector<cv::Mat> pyramid;
  cv::buildOpticalFlowPyramid(grey, pyramid, window, options_.pyramid_levels);

  PointFrame out;
  out.frame = next_frame_;
  if (!live_.empty()) follow(pyramid, &out);
  out.tracked = static_cast<int>(out.points.size());
  if (out.tracked < options_.min_live_tracks || out.points.empty()) detect(grey, &out);

  live_ = out.points;
  previous_pyramid_ = std::move(pyramid);
  ++next_frame_;
  return out;
}

void PointTracker::follow(const std::vector<cv::Mat>& pyramid, PointFrame* out) const {
  std::vector<cv::Point2f> start, ahead, back;
  start.reserve(live_.size());
  for (const TrackedPoint& t : live_) start.emplace_back(t.pixel.x(), t.pixel.y());

  const cv::Size window(options_.window_size_px, options_.window_size_px);
  const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                              options_.max_iterations, options_.epsilon_px);
  std::vector<unsigned char> ok_ahead, ok_back;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(previous_pyramid_, pyramid, start, ahead, ok_ahead, error, window,
                           options_.pyramid_levels, stop, 0, options_.min_eigen_threshold);
  // Tracking back from where the point landed must return to where it started; a track that slid
  // along an edge or locked onto a repeated pattern does not come back.
  cv::calcOpticalFlowPyrLK(pyramid, previous_pyramid_, ahead, back, ok_back, error, window,
                           options_.pyramid_levels, stop, 0, options_.min_eigen_threshold);

  const double max_fb2 = options_.max_forward_backward_px * options_.max_forward_backward_px;
  for (std::size_t i = 0; i < live_.size(); ++i) {
    if (!ok_ahead[i]) {
      ++out->lost.flow_failed;
    } else if (!inside(ahead[i])) {
      ++out->lost.outside_image;
    } else if (!ok_back[i]) {
      ++out->lost.flow_failed;
    } else if (cv::Point2d(back[i] - start[i]).dot(cv::Point2d(back[i] - start[i])) > max_fb2) {
      ++out->lost.forward_backward;
    } else {
      out->points.push_back({live_[i].track, Eigen::Vector2d(ahead[i].x, ahead[i].y)});
    }
  }
}

void PointTracker::detect(const cv::Mat& grey, PointFrame* out) {
  out->detection_ran = true;
  const PointTrackerOptions& o = options_;
  // One corner response for the whole image gives the floor that keeps flat cells empty: the
  // per-cell quality level alone would hand each cell its strongest noise.
  cv::Mat response;
  cv::cornerMinEigenVal(grey, response, o.corner_block_size, 3);
  double strongest = 0.0;
  cv::minMaxLoc(response, nullptr, &strongest);
  if (!(strongest > 0.0)) return;  // No texture at all (a black frame).
  const double floor = o.image_quality_level * strongest;

  // Free pixels: inside the border and farther than min_distance_px from every live track.
  cv::Mat free(grey.size(), CV_8UC1, cv::Scalar(0));
  const int border = static_cast<int>(std::ceil(o.border_px));
  const cv::Rect interior(border, border, grey.cols - 2 * border, grey.rows - 2 * border);
  if (interior.width <= 0 || interior.height <= 0) return;
  free(interior).setTo(255);
  const int radius = static_cast<int>(std::ceil(o.min_distance_px));
  const auto block = [&](const Eigen::Vector2d& p) {
    cv::circle(
        free, cv::Point(static_cast<int>(std::lround(p.x())), static_cast<int>(std::lround(p.y()))),
        radius, cv::Scalar(0), cv::FILLED);
  };

  const Grid grid{grey.size(), o.grid_cols, o.grid_rows};
  std::vector<int> count(static_cast<std::size_t>(o.grid_cols * o.grid_rows), 0);
  for (const TrackedPoint& t : out->points) {
    ++count[grid.index(t.pixel)];
    block(t.pixel);
  }

  // Cells in row-major order, corners within a cell strongest first: deterministic.
  std::vector<cv::Point2f> corners;
  for (int row = 0; row < o.grid_rows; ++row) {
    for (int col = 0; col < o.grid_cols; ++col) {
      const int wanted = o.corners_per_cell - count[row * o.grid_cols + col];
      const cv::Rect cell = grid.cell(col, row);
      if (wanted <= 0 || cell.empty() || cv::countNonZero(free(cell)) == 0) continue;
      cv::goodFeaturesToTrack(grey(cell), corners, wanted, o.quality_level, o.min_distance_px,
                              free(cell), o.corner_block_size);
      for (const cv::Point2f& c : corners) {
        const cv::Point at(cell.x + static_cast<int>(std::lround(c.x)),
                           cell.y + static_cast<int>(std::lround(c.y)));
        // A corner of the neighbouring cell found just now may sit within min_distance_px.
        if (response.at<float>(at) < floor || free.at<unsigned char>(at) == 0) continue;
        const Eigen::Vector2d pixel(at.x, at.y);
        out->points.push_back({next_id_++, pixel});
        ++out->detected;
        block(pixel);
      }
    }
  }
}

void PointTracks::add(const PointFrame& frame) {
  CURVESFM_CHECK(frame.frame > last_frame_)
      << "PointTracks::add takes frames in increasing order, got frame " << frame.frame
      << " after frame " << last_frame_;
  last_frame_ = frame.frame;
  for (const TrackedPoint& p : frame.points) tracks_[p.track].push_back({frame.frame, p.pixel});
}

namespace {

const TrackObservation* find(const std::vector<TrackObservation>& track, int frame) {
  const auto it = std::lower_bound(track.begin(), track.end(), frame,
                                   [](const TrackObservation& o, int f) { return o.frame < f; });
  return it != track.end() && it->frame == frame ? &*it : nullptr;
}

}  // namespace

std::vector<PointCorrespondence> PointTracks::correspondences(int frame_a, int frame_b) const {
  std::vector<PointCorrespondence> pairs;
  for (const auto& [id, track] : tracks_) {
    const TrackObservation* a = find(track, frame_a);
    const TrackObservation* b = find(track, frame_b);
    if (a && b) pairs.push_back({id, a->pixel, b->pixel});
  }
  return pairs;
}

const std::vector<TrackObservation>& PointTracks::observations(int id) const {
  static const std::vector<TrackObservation> kNone;
  const auto it = tracks_.find(id);
  return it == tracks_.end() ? kNone : it->second;
}

}  // namespace curvesfm
