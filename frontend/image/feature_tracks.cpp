#include "frontend/image/feature_tracks.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/check.h"
#include "core/clock.h"
#include "core/errors.h"
#include "core/union_find.h"

namespace curvesfm {

void FeatureTrackOptions::validate() const {
  const OptionCheck require("FeatureTrackOptions");
  require(match_interval >= 1 && match_interval <= 1000, "match_interval", match_interval,
          "in [1, 1000]");
  require(match_overlap >= 0 && match_overlap <= 20, "match_overlap", match_overlap, "in [0, 20]");
  require(exhaustive_max_frames >= 0 && exhaustive_max_frames <= 1000, "exhaustive_max_frames",
          exhaustive_max_frames, "in [0, 1000]");
  require(min_tracked_fraction >= 0.0 && min_tracked_fraction <= 1.0, "min_tracked_fraction",
          min_tracked_fraction, "in [0, 1]");
  require.nonNegative("merge_radius_px", merge_radius_px);
  require.positive("verify_threshold_px", verify_threshold_px);
  require(min_verified_matches >= 8, "min_verified_matches", min_verified_matches, ">= 8");
}

const TrackObservation* FeatureTracks::observation(int track, int frame) const {
  const std::vector<TrackObservation>& obs = tracks[track].observations;
  const auto it = std::lower_bound(obs.begin(), obs.end(), frame,
                                   [](const TrackObservation& o, int f) { return o.frame < f; });
  return it != obs.end() && it->frame == frame ? &*it : nullptr;
}

const Eigen::Vector2d* FeatureTracks::pixel(int track, int frame) const {
  const TrackObservation* o = observation(track, frame);
  return o != nullptr ? &o->pixel : nullptr;
}

std::vector<int> FeatureTracks::sharedTracks(int frame_a, int frame_b) const {
  std::vector<int> shared;
  std::set_intersection(frame_tracks[frame_a].begin(), frame_tracks[frame_a].end(),
                        frame_tracks[frame_b].begin(), frame_tracks[frame_b].end(),
                        std::back_inserter(shared));
  return shared;
}

namespace {

// A node of the correspondence graph before the KLT ids are all known: a KLT track id (>= 0) or
// keypoint k as -(k + 1).
using NodeRef = int;
NodeRef keypointRef(int k) { return -(k + 1); }

cv::Vec3b colourAt(const cv::Mat& image, const Eigen::Vector2d& pixel) {
  const int x = std::clamp(static_cast<int>(std::lround(pixel.x())), 0, image.cols - 1);
  const int y = std::clamp(static_cast<int>(std::lround(pixel.y())), 0, image.rows - 1);
  if (image.type() == CV_8UC1) {
    const uchar v = image.at<uchar>(y, x);
    return cv::Vec3b(v, v, v);
  }
  return image.at<cv::Vec3b>(y, x);
}

constexpr double kVerifyConfidence = 0.999;
constexpr int kMaxFundamentalSamples = 1000;  // OpenCV's default.
constexpr int kMaxHomographySamples = 2000;

// The samples within which RANSAC draws, at the verification's confidence, an all-inlier sample
// of `sample_size` distinct matches from a model that explains `needed` of `n` matches, if one
// exists: log(1 - confidence) / log(1 - P), P = C(needed, size) / C(n, size), at most `cap`. (P is
// the draw without replacement, as OpenCV draws: (needed / n)^size overstates it at a few dozen
// matches, 0.0128 against 0.0054 for 15 of 28 and 7 points.) A model with fewer inliers would not
// be kept, and OpenCV's RANSAC lowers its own count below this bound as soon as it finds one with
// more, so the bound changes the result only in the (1 - confidence) of pairs where no such
// sample comes up in time.
int samplesToFind(int needed, int n, int sample_size, int cap) {
  if (needed >= n) return 1;
  double all_inliers = 1.0;
  for (int i = 0; i < sample_size; ++i) {
    all_inliers *= std::max(0.0, static_cast<double>(needed - i) / (n - i));
  }
  if (all_inliers <= 0.0) return cap;
  const double samples = std::log(1.0 - kVerifyConfidence) / std::log1p(-all_inliers);
  return static_cast<int>(std::clamp(std::ceil(samples), 1.0, double(cap)));
}

// The matches a fundamental matrix or a homography explains (see the header's verifiedMatches).
std::vector<FeatureMatch> verifiedMatches(const std::vector<FeatureMatch>& matches,
                                          double threshold_px, int min_matches) {
  if (static_cast<int>(matches.size()) < min_matches) return {};
  std::vector<cv::Point2f> a, b;
  for (const FeatureMatch& m : matches) {
    a.emplace_back(static_cast<float>(m.pixel_a.x()), static_cast<float>(m.pixel_a.y()));
    b.emplace_back(static_cast<float>(m.pixel_b.x()), static_cast<float>(m.pixel_b.y()));
  }
  cv::theRNG().state = 0x2545F491;  // RANSAC draws from OpenCV's global generator.
  const auto count = [](const std::vector<uchar>& mask) {
    return static_cast<int>(std::count(mask.begin(), mask.end(), 1));
  };
  std::vector<uchar> f_mask, h_mask;
  // A pair is kept with at least min_matches inliers; the homography decides it only when it
  // explains more matches than the fundamental matrix. Unrelated views (most of the pairs of a
  // still set matched exhaustively: 90 of templeSparseRing's 119) have neither, and each sample
  // costs a 9 x 9 SVD (F) or eigenproblem (H), so RANSAC draws only the samples that would find
  // a model worth keeping.
  const int n = static_cast<int>(matches.size());
  cv::findFundamentalMat(a, b, cv::FM_RANSAC, threshold_px, kVerifyConfidence,
                         samplesToFind(min_matches, n, 7, kMaxFundamentalSamples), f_mask);
  const int f_inliers = count(f_mask);
  if (f_inliers < n) {
    cv::findHomography(
        a, b, cv::RANSAC, threshold_px, h_mask,
        samplesToFind(std::max(f_inliers + 1, min_matches), n, 4, kMaxHomographySamples),
        kVerifyConfidence);
  }
  const std::vector<uchar>& mask = count(h_mask) > f_inliers ? h_mask : f_mask;
  if (count(mask) < min_matches) return {};
  std::vector<FeatureMatch> kept;
  for (std::size_t i = 0; i < matches.size(); ++i) {
    if (mask[i]) kept.push_back(matches[i]);
  }
  return kept;
}

}  // namespace

std::vector<FeatureMatch> verifiedMatches(const FeatureSet& a, const FeatureSet& b,
                                          const FeatureMatchingOptions& matching,
                                          const FeatureTrackOptions& options) {
  return verifiedMatches(matchFeatures(a, b, matching), options.verify_threshold_px,
                         options.min_verified_matches);
}

namespace {

struct Keypoint {
  int frame = -1;
  Eigen::Vector2d pixel;
  double size = 0.0;
  cv::Vec3b colour;
};

struct MatchingFrame {
  int frame = -1;
  FeatureSet features;
  int first_keypoint = 0;  // Index of its keypoint 0 among all keypoints.
};

}  // namespace

struct FeatureTrackBuilder::State {
  FeatureTrackOptions options;
  FeatureMatchingOptions matching;
  PointTracker tracker;
  PointTracks klt;
  std::vector<std::vector<TrackedPoint>> klt_frames;  // Live KLT points of every frame.
  std::vector<cv::Vec3b> klt_colours;                 // By KLT track id.
  std::vector<Keypoint> keypoints;
  std::vector<std::pair<NodeRef, NodeRef>> links;
  std::vector<MatchingFrame> matching_frames;  // Every matching frame, in frame order.
  std::set<std::pair<int, int>> matched_pairs;
  // Two consecutive matching frames share no verified match: the order does not follow the views.
  bool out_of_order = false;
  std::vector<FeatureTrackFrameStats> stats;
  cv::Mat previous_image;
  int last_matching_frame = -1;

  State(const FeatureTrackOptions& o, const PointTrackerOptions& t, const FeatureMatchingOptions& m)
      : options(o), matching(m), tracker(t) {
    options.validate();
    matching.validate();
  }

  int numFrames() const { return static_cast<int>(klt_frames.size()); }

  void trackKlt(const cv::Mat& image) {
    const Clock::time_point start = Clock::now();
    const PointFrame frame = tracker.track(image);
    klt.add(frame);
    for (std::size_t i = static_cast<std::size_t>(frame.tracked); i < frame.points.size(); ++i) {
      const TrackedPoint& p = frame.points[i];
      if (p.track >= static_cast<int>(klt_colours.size())) klt_colours.resize(p.track + 1);
      klt_colours[p.track] = colourAt(image, p.pixel);
    }
    klt_frames.push_back(frame.points);
    FeatureTrackFrameStats s;
    s.klt_tracked = frame.tracked;
    s.klt_live = static_cast<int>(frame.points.size());
    s.klt_seconds = secondsSince(start);
    stats.push_back(s);
  }

  // The KLT track nearest to `pixel` in `frame` within merge_radius_px, or -1.
  int nearestKltTrack(int frame, const Eigen::Vector2d& pixel) const {
    int best = -1;
    double best_distance = options.merge_radius_px;
    for (const TrackedPoint& p : klt_frames[frame]) {
      const double d = (p.pixel - pixel).norm();
      if (d <= best_distance) {
        best = p.track;
        best_distance = d;
      }
    }
    return best;
  }

  // Links the verified descriptor matches of `earlier` and `later` (a later matching frame).
  void matchPair(const MatchingFrame& earlier, const MatchingFrame& later) {
    const std::vector<FeatureMatch> matches =
        verifiedMatches(earlier.features, later.features, matching, options);
    for (const FeatureMatch& match : matches) {
      links.emplace_back(keypointRef(earlier.first_keypoint + match.index_a),
                         keypointRef(later.first_keypoint + match.index_b));
    }
    stats[later.frame].matches += static_cast<int>(matches.size());
    matched_pairs.emplace(earlier.frame, later.frame);
    if (matches.empty() && &earlier == &matching_frames[matching_frames.size() - 2])
      out_of_order = true;
  }

  // Matches the pairs of matching frames that the overlap window left out (exhaustive matching
  // of a short sequence).
  void matchRemainingPairs() {
    if (!out_of_order || numFrames() > options.exhaustive_max_frames) return;
    const Clock::time_point start = Clock::now();
    const int n = static_cast<int>(matching_frames.size());
    for (int j = 0; j < n; ++j) {
      // The window matched frame j with its match_overlap predecessors already.
      for (int i = 0; i + options.match_overlap < j; ++i)
        matchPair(matching_frames[i], matching_frames[j]);
    }
    if (n > 0) stats[matching_frames.back().frame].match_seconds += secondsSince(start);
  }

  void makeMatchingFrame(int frame, const cv::Mat& image) {
    const Clock::time_point start = Clock::now();
    MatchingFrame m;
    m.frame = frame;
    m.features = detectFeatures(image, matching);
    m.first_keypoint = static_cast<int>(keypoints.size());
    for (int k = 0; k < m.features.size(); ++k) {
      const Eigen::Vector2d& pixel = m.features.pixels[k];
      keypoints.push_back({frame, pixel, m.features.sizes[k], colourAt(image, pixel)});
      const int klt_track = nearestKltTrack(frame, pixel);
      if (klt_track >= 0) links.emplace_back(klt_track, keypointRef(m.first_keypoint + k));
    }
    FeatureTrackFrameStats& s = stats[frame];
    s.matching_frame = true;
    s.features = m.features.size();
    matching_frames.push_back(std::move(m));
    const int later = static_cast<int>(matching_frames.size()) - 1;
    for (int earlier = std::max(0, later - options.match_overlap); earlier < later; ++earlier)
      matchPair(matching_frames[earlier], matching_frames[later]);
    last_matching_frame = frame;
    s.match_seconds += secondsSince(start);
  }

  void addFrame(const cv::Mat& image) {
    const int frame = numFrames();
    const int previous_live = frame > 0 ? stats.back().klt_live : 0;
    trackKlt(image);
    // A frame after one without any live track is broken too: nothing could be followed.
    const bool broken =
        frame > 0 && (previous_live == 0 ||
                      stats.back().klt_tracked < options.min_tracked_fraction * previous_live);
    if (broken && options.match_frame_before_break && last_matching_frame < frame - 1) {
      makeMatchingFrame(frame - 1, previous_image);
    }
    if (frame % options.match_interval == 0 || broken) makeMatchingFrame(frame, image);
    previous_image = image.clone();
  }

  // Moves the matching frames' features into `out`, each keypoint with its track (index into
  // out->tracks) where that track observes it at its pixel.
  void keepMatchingFrames(const std::vector<int>& track_of_keypoint, FeatureTracks* out) {
    for (MatchingFrame& m : matching_frames) {
      MatchingFrameFeatures kept{m.frame, std::move(m.features), {}};
      for (int k = 0; k < kept.features.size(); ++k) {
        const int track = track_of_keypoint[m.first_keypoint + k];
        // The frame's observation may be the KLT point the keypoint joined (within the merge
        // radius) or another one that won the frame.
        const bool observed_here =
            track >= 0 && (*out->pixel(track, m.frame) - kept.features.pixels[k]).norm() <=
                              options.merge_radius_px;
        kept.track_of_keypoint.push_back(observed_here ? track : -1);
      }
      out->matching_frames.push_back(std::move(kept));
    }
  }

  FeatureTracks finish() {
    const int frames = numFrames();
    if (frames > 0 && last_matching_frame < frames - 1) {
      makeMatchingFrame(frames - 1, previous_image);
    }
    matchRemainingPairs();
    const int num_klt = static_cast<int>(klt_colours.size());
    const int num_nodes = num_klt + static_cast<int>(keypoints.size());
    const auto node = [num_klt](NodeRef ref) { return ref >= 0 ? ref : num_klt - ref - 1; };
    UnionFind sets(num_nodes);
    for (const auto& [a, b] : links) sets.join(node(a), node(b));

    // Observations per set, in node order: KLT tracks' first, so they win a frame conflict.
    std::vector<int> track_of_root(num_nodes, -1);
    std::vector<FeatureTrack> joined;
    const auto trackOf = [&](int n, const cv::Vec3b& colour) -> FeatureTrack& {
      const int root = sets.find(n);
      if (track_of_root[root] < 0) {
        track_of_root[root] = static_cast<int>(joined.size());
        joined.push_back({{}, colour});
      }
      return joined[track_of_root[root]];
    };
    for (const auto& [id, observations] : klt.tracks()) {
      FeatureTrack& track = trackOf(id, klt_colours[id]);
      track.observations.insert(track.observations.end(), observations.begin(), observations.end());
    }
    for (int k = 0; k < static_cast<int>(keypoints.size()); ++k) {
      const Keypoint& kp = keypoints[k];
      trackOf(num_klt + k, kp.colour)
          .observations.push_back({kp.frame, kp.pixel, /*keypoint=*/true, kp.size});
    }

    FeatureTracks out;
    out.num_frames = frames;
    out.frame_tracks.resize(frames);
    out.frames = stats;
    out.matched_pairs = std::move(matched_pairs);
    std::vector<int> kept_index(joined.size(), -1);
    for (std::size_t j = 0; j < joined.size(); ++j) {
      FeatureTrack& track = joined[j];
      std::vector<TrackObservation>& obs = track.observations;
      std::stable_sort(
          obs.begin(), obs.end(),
          [](const TrackObservation& a, const TrackObservation& b) { return a.frame < b.frame; });
      obs.erase(std::unique(obs.begin(), obs.end(),
                            [](const TrackObservation& a, const TrackObservation& b) {
                              return a.frame == b.frame;
                            }),
                obs.end());
      if (obs.size() < 2) continue;
      const int index = static_cast<int>(out.tracks.size());
      kept_index[j] = index;
      for (const TrackObservation& o : obs) out.frame_tracks[o.frame].push_back(index);
      out.tracks.push_back(std::move(track));
    }
    std::vector<int> track_of_keypoint(keypoints.size());
    for (std::size_t k = 0; k < keypoints.size(); ++k)
      track_of_keypoint[k] = kept_index[track_of_root[sets.find(num_klt + static_cast<int>(k))]];
    keepMatchingFrames(track_of_keypoint, &out);
    return out;
  }
};

FeatureTrackBuilder::FeatureTrackBuilder(const FeatureTrackOptions& options,
                                         const PointTrackerOptions& tracker,
                                         const FeatureMatchingOptions& matching)
    : state_(std::make_unique<State>(options, tracker, matching)) {}

FeatureTrackBuilder::~FeatureTrackBuilder() = default;

void FeatureTrackBuilder::addFrame(const cv::Mat& image) { state_->addFrame(image); }

FeatureTracks FeatureTrackBuilder::finish() { return state_->finish(); }

}  // namespace curvesfm
