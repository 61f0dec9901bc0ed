#pragma once

#include <Eigen/Core>
#include <map>
#include <opencv2/core.hpp>
#include <vector>

namespace curvesfm {

// Point tracks between consecutive video frames, the first half of the point-based initialiser's
// correspondences (issue 13): Shi-Tomasi corners bucketed over a grid so that they cover the
// whole image (SVO's grid, ORB-SLAM's cells), followed by pyramidal Lucas-Kanade between each
// frame and the next, with a forward-backward check (track back from the new frame and require
// the start point again) that drops tracks which slid along an edge or jumped to a look-alike.
// Plain data in (8-bit images), plain data out (track ids and pixels); no randomness, so the
// same frames always give the same tracks.
//
// Pixels: centres at integers, (0, 0) the centre of the top-left pixel (as Camera::project and
// OpenCV's corner and flow functions).

/// How corners are found and followed. Defaults suit 640x480 video at 30 Hz.
struct PointTrackerOptions {
  /// Columns of the bucketing grid; each cell is topped up with corners on its own, so that
  /// texture in one part of the image does not take every track. In [1, 64].
  int grid_cols = 8;
  /// Rows of the bucketing grid (80 x 80 px cells at 640x480 with the defaults). In [1, 64].
  int grid_rows = 6;
  /// Live tracks a cell should hold: cells with fewer get new corners, up to this many (a full
  /// grid is 8 x 6 x 6 = 288 tracks with the defaults). Tracks that move into a full cell are
  /// kept, so more may live: about 370 when detecting in every frame of the planar orbit.
  /// In [1, 1000].
  int corners_per_cell = 6;
  /// Shi-Tomasi quality level: a new corner's minimum eigenvalue must reach this fraction of
  /// the strongest in its cell (unitless). In (0, 1).
  double quality_level = 0.01;
  /// ...and this fraction of the strongest in the whole image, so that a cell of flat paint or
  /// sensor noise stays empty instead of taking its best noise (unitless). In [0, 1).
  double image_quality_level = 0.001;
  /// Shortest distance between a new corner and any live track or other new corner (px).
  /// Finite, >= 0.
  double min_distance_px = 10.0;
  /// Side of the window over which the corner response is summed (px). Odd, in [3, 31].
  int corner_block_size = 3;
  /// Side of the Lucas-Kanade window at each pyramid level (px). KLT fits a translation only,
  /// so a view that rolls by theta (rad) between frames moves the fitted point off the true one
  /// by roughly theta x a quarter of the window, and frame-to-frame tracking adds these up: on
  /// the planar orbit at 1.5 deg of roll per frame tracks drifted 0.08 px a frame with 11 px,
  /// 0.15 px with 21 px (OpenCV's default), with the same survival, also at 5% intensity noise.
  /// Odd, in [5, 101].
  int window_size_px = 11;
  /// Pyramid levels above the full image (0: the image only). Each level doubles the motion KLT
  /// can follow: about window / 2 x 2^levels px, some 90 px with the defaults. In [0, 8].
  int pyramid_levels = 4;
  /// Most Lucas-Kanade iterations per pyramid level. In [1, 1000].
  int max_iterations = 30;
  /// Lucas-Kanade stops once an iteration moves the point less than this (px). Finite, > 0.
  double epsilon_px = 0.01;
  /// OpenCV's minEigThreshold: KLT gives up on a point whose window's gradient matrix has a
  /// smaller minimum eigenvalue, divided by the window's pixel count (OpenCV's normalised
  /// units): the window is flat and the track is lost. Finite, > 0.
  double min_eigen_threshold = 1e-4;
  /// Largest distance between a track's point in the previous frame and where tracking its new
  /// position back into the previous frame lands (px). Finite, > 0.
  double max_forward_backward_px = 0.5;
  /// Tracks closer than this to the image border are dropped, and no corner starts there (px):
  /// the KLT window would reach outside the image. Finite, >= 0.
  double border_px = 8.0;
  /// Detect new corners only while fewer tracks than this are live; 0 detects only on the first
  /// frame (and after every track is lost), a number above the grid's capacity in every frame.
  /// Corner detection is the costliest step (on one core at 640x480: 2.8 ms a frame with the
  /// default, 10 ms detecting in every frame), and a track that starts later is shorter.
  /// In [0, 1000000].
  int min_live_tracks = 230;

  /// Throws InvalidOptions naming the first field outside its range.
  void validate() const;
};

/// Why a track ended in a frame.
struct PointTrackLosses {
  int flow_failed = 0;       ///< KLT did not converge, or the window was flat (either way).
  int outside_image = 0;     ///< The new position lies within border_px of the border or beyond.
  int forward_backward = 0;  ///< Tracked back, it missed its start by > max_forward_backward_px.

  int total() const { return flow_failed + outside_image + forward_backward; }
};

/// One live track in one frame.
struct TrackedPoint {
  int track = -1;                                   ///< Stable id, unique over the sequence.
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  ///< Position in this frame (px).
};

/// The output of PointTracker::track for one frame.
struct PointFrame {
  int frame = -1;  ///< Index of the frame in the sequence given to the tracker (0, 1, ...).
  /// Every live track: those followed from the previous frame, in their earlier order, then the
  /// new ones; ids are ascending.
  std::vector<TrackedPoint> points;
  int tracked = 0;             ///< Tracks followed from the previous frame.
  PointTrackLosses lost;       ///< Tracks of the previous frame that ended here, by reason.
  int detected = 0;            ///< New tracks started in this frame.
  bool detection_ran = false;  ///< Whether corners were detected in this frame.
};

/// Follows points through consecutive frames. Feed every frame of a sequence in order; a tracker
/// holds the previous frame's pyramid and live tracks, so use one per sequence (not thread-safe).
class PointTracker {
 public:
  /// Throws InvalidOptions (via validate) for invalid options.
  explicit PointTracker(const PointTrackerOptions& options = {});

  /// Tracks the live points into `image` (CV_8UC1 grey, or CV_8UC3 BGR, converted to grey) and
  /// tops up the grid cells that hold fewer than corners_per_cell tracks. A frame without
  /// texture (all black) loses its tracks, counted in `lost`, and starts none. Throws CheckError
  /// for an empty image, another type, or a size that differs from the first frame's.
  PointFrame track(const cv::Mat& image);

  const PointTrackerOptions& options() const { return options_; }
  /// Frames tracked so far.
  int numFrames() const { return next_frame_; }

 private:
  void follow(const std::vector<cv::Mat>& pyramid, PointFrame* out) const;
  void detect(const cv::Mat& grey, PointFrame* out);
  bool inside(const cv::Point2f& p) const;

  PointTrackerOptions options_;
  cv::Size size_;
  std::vector<cv::Mat> previous_pyramid_;
  std::vector<TrackedPoint> live_;
  int next_frame_ = 0;
  int next_id_ = 0;
};

/// One observation of a track.
struct TrackObservation {
  int frame = -1;                                   ///< Frame index (PointFrame::frame).
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  ///< Position (px).
  /// Detected in this frame on its own (a descriptor keypoint), not followed from the frame
  /// before (KLT, whose template drift carries each error into the next frames).
  bool keypoint = false;
  /// A keypoint's diameter (px; FeatureSet::sizes), the scale it was detected at; 0 for KLT.
  double keypoint_size = 0.0;
};

/// One track seen in two frames.
struct PointCorrespondence {
  int track = -1;                                     ///< Track id.
  Eigen::Vector2d pixel_a = Eigen::Vector2d::Zero();  ///< Position in frame a (px).
  Eigen::Vector2d pixel_b = Eigen::Vector2d::Zero();  ///< Position in frame b (px).
};

/// Every track of a sequence, accumulated from the tracker's per-frame output: the input of
/// two-view geometry and triangulation. Tracks are ordered by id, observations by frame.
class PointTracks {
 public:
  /// Appends the frame's observations. Throws CheckError unless frames come in increasing order.
  void add(const PointFrame& frame);

  /// The tracks seen in both frame_a and frame_b, ordered by track id; empty if either frame
  /// was not added.
  std::vector<PointCorrespondence> correspondences(int frame_a, int frame_b) const;

  /// Observations of track `id`, by frame; empty for an unknown id.
  const std::vector<TrackObservation>& observations(int id) const;
  const std::map<int, std::vector<TrackObservation>>& tracks() const { return tracks_; }
  int numTracks() const { return static_cast<int>(tracks_.size()); }

 private:
  std::map<int, std::vector<TrackObservation>> tracks_;
  int last_frame_ = -1;
};

}  // namespace curvesfm
