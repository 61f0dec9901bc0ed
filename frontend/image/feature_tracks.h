#pragma once

#include <Eigen/Core>
#include <memory>
#include <opencv2/core.hpp>
#include <set>
#include <utility>
#include <vector>

#include "frontend/image/feature_matching.h"
#include "frontend/image/point_tracks.h"

namespace curvesfm {

// The correspondences of a whole sequence as tracks, the input of the incremental point
// reconstruction (issue 13): KLT follows corners between consecutive frames (point_tracks.h), and
// descriptors (feature_matching.h) are matched between "matching frames" to re-find points over
// wider baselines and to bridge the frames where KLT loses its tracks (a fast motion, a blur, a
// wide-baseline still sequence). Both kinds of correspondence are joined into one track per scene
// point by union-find (COLMAP builds its tracks from its correspondence graph the same way):
//  - a KLT track is one node holding all its frames;
//  - a descriptor keypoint is a node of one observation, joined to the KLT point of its frame
//    within merge_radius_px (so a match carries the KLT track across the gap) and to the keypoint
//    it matches in another frame, once the pair's matches are verified by a fundamental matrix
//    or a homography (RANSAC), as COLMAP verifies its pairs.
// A track that ends up with two observations in one frame keeps the first (KLT before keypoints,
// lower ids first): the reconstruction's reprojection gates drop what is wrong.
//
// Matching frames: every match_interval-th frame, the last frame, and every frame where KLT kept
// fewer than min_tracked_fraction of the previous frame's tracks (a break; optionally the frame
// before it too). Each matching frame is matched with the previous match_overlap matching frames.
// On video, descriptors then cost one detection every match_interval frames; on a still sequence
// whose frames KLT cannot follow, every frame is matched with its match_overlap predecessors.
// A short sequence (at most exhaustive_max_frames frames) whose order does not follow the views
// (two consecutive matching frames share no verified match) has every pair of matching frames
// matched, as COLMAP's exhaustive matcher does for small image sets: templeSparseRing's 16 stills
// jump around the ring, so neighbours in the file order are often 50-120 deg apart. Ordered
// sequences keep the window alone: the extra pairs cost time (fountain-P11: 20 s to 46 s) and
// gain nothing there.
//
// Every matching frame's descriptors are kept in the result, with the track of each keypoint,
// so that the reconstruction can match pairs the window left out once it knows which frames see
// the same scene (the point initialiser's loop matches): about 0.5 MB a matching frame with 1000
// SIFT features.
//
// Pixels: undistorted pinhole pixels (as PointTracker's and detectFeatures' input), centres at
// integers. Deterministic: the same frames give the same tracks.

/// When descriptors are matched and how their keypoints join KLT tracks.
struct FeatureTrackOptions {
  /// Every this many frames is a matching frame (count; 1 matches every frame). In [1, 1000].
  int match_interval = 5;
  /// Each matching frame is matched with this many previous matching frames (count; 0: KLT only).
  /// In [0, 20].
  int match_overlap = 2;
  /// A sequence of at most this many frames whose order does not follow the views has every
  /// pair of its matching frames matched, in finish() (count; 0: never). Costs up to
  /// (n - 1)(n - 2)/2 more pair matches for n frames: 5 s for templeSparseRing's 16. In
  /// [0, 1000].
  int exhaustive_max_frames = 30;
  /// A frame where KLT kept less than this fraction of the previous frame's tracks becomes a
  /// matching frame (unitless). KITTI's forward motion loses 35-45 % of the tracks in every frame,
  /// so 0.6 made 47 of its 51 frames matching frames (0.5: 18), at no gain in ATE on the real
  /// sets (docs/benchmarks.md). In [0, 1].
  double min_tracked_fraction = 0.5;
  /// The frame before such a break is a matching frame too, so that the break is matched across
  /// directly rather than only from the last matching frame (up to match_interval - 1 frames
  /// earlier, whose KLT tracks may have died before the break). On the real sets off changed
  /// the ATE by a few per cent either way and saved a detection per isolated break (Pavilion: 44
  /// instead of 48 matching frames of 100), not enough to give up the direct bridge.
  bool match_frame_before_break = true;
  /// A keypoint joins the KLT track whose point in its frame lies within this distance (px).
  /// Finite, >= 0.
  double merge_radius_px = 1.5;
  /// Descriptor matches of a pair are kept only when a fundamental matrix or a homography fitted
  /// by RANSAC (whichever explains more) brings them within this distance (px). Finite, > 0.
  double verify_threshold_px = 2.0;
  /// A pair with fewer verified matches keeps none (count). >= 8.
  int min_verified_matches = 15;
  /// Throws InvalidOptions naming the first field outside its range.
  void validate() const;
};

/// One scene point's observations, by frame (one per frame), with the colour it was first seen in.
struct FeatureTrack {
  std::vector<TrackObservation> observations;
  cv::Vec3b colour_bgr = cv::Vec3b(0, 0, 0);
};

/// What building the tracks did in one frame.
struct FeatureTrackFrameStats {
  int klt_tracked = 0;          ///< KLT tracks followed from the previous frame.
  int klt_live = 0;             ///< KLT tracks live after this frame (followed + new).
  bool matching_frame = false;  ///< Descriptors were detected here.
  int features = 0;             ///< Descriptor keypoints detected (matching frames).
  int matches = 0;              ///< Descriptor matches with earlier matching frames.
  double klt_seconds = 0.0;     ///< KLT tracking and corner detection.
  double match_seconds = 0.0;   ///< Descriptor detection and matching.
};

/// A matching frame's descriptors, kept so that the reconstruction can match it with frames the
/// overlap window did not pair it with (the point initialiser's loop matches).
struct MatchingFrameFeatures {
  int frame = -1;
  FeatureSet features;
  /// Per keypoint, the track (index into FeatureTracks::tracks) that observes it at its pixel,
  /// or -1: a keypoint no match joined to anything, or one that lost its frame to another
  /// observation of its track.
  std::vector<int> track_of_keypoint;
};

/// Every track of a sequence.
struct FeatureTracks {
  int num_frames = 0;
  std::vector<FeatureTrack> tracks;  ///< Tracks seen in at least two frames.
  /// Per frame, the tracks observed in it (indices into `tracks`, ascending).
  std::vector<std::vector<int>> frame_tracks;
  std::vector<FeatureTrackFrameStats> frames;
  /// Every matching frame, in frame order.
  std::vector<MatchingFrameFeatures> matching_frames;
  /// The pairs of matching frames (earlier, later) whose descriptors were matched.
  std::set<std::pair<int, int>> matched_pairs;
  /// The pixel of track `track` in frame `frame`; nullptr if the track is not seen there.
  const Eigen::Vector2d* pixel(int track, int frame) const;
  /// Track `track`'s observation in frame `frame`; nullptr if the track is not seen there.
  const TrackObservation* observation(int track, int frame) const;
  /// Tracks observed in both frames.
  std::vector<int> sharedTracks(int frame_a, int frame_b) const;
};

/// The descriptor matches of two images that a fundamental matrix or a homography explains
/// within options.verify_threshold_px (RANSAC, whichever keeps more), as COLMAP verifies every
/// image pair before it builds tracks: one wrong match joins two scene points into one track.
/// Fewer than options.min_verified_matches survivors: none is kept. The track builder's pairs and
/// the point initialiser's loop matches both go through it. Deterministic (RANSAC draws from
/// OpenCV's generator, seeded here).
std::vector<FeatureMatch> verifiedMatches(const FeatureSet& a, const FeatureSet& b,
                                          const FeatureMatchingOptions& matching,
                                          const FeatureTrackOptions& options);

/// Builds the tracks frame by frame. Feed every frame of a sequence in order (8-bit BGR or grey,
/// undistorted, all of one size); not thread-safe.
class FeatureTrackBuilder {
 public:
  /// Throws InvalidOptions for invalid options of any of the three.
  FeatureTrackBuilder(const FeatureTrackOptions& options, const PointTrackerOptions& tracker,
                      const FeatureMatchingOptions& matching);
  ~FeatureTrackBuilder();
  void addFrame(const cv::Mat& image);
  /// Joins the correspondences into tracks; call once, after the last frame.
  FeatureTracks finish();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace curvesfm
