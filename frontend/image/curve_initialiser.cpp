#include "frontend/image/curve_initialiser.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>

#include "core/bezier_fit.h"
#include "core/check.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

// A cubic has four control points: fewer points leave the fit undetermined.
constexpr int kMinSegmentPoints = 4;

// Written as positive comparisons so that NaN fails.
bool inClosed(double value, double low, double high) { return value >= low && value <= high; }
bool inOpenClosed(double value, double low, double high) { return value > low && value <= high; }

// Consecutive lifted pixels of one chain that are fitted together.
struct Run {
  std::vector<Eigen::Vector3d> points;  // World frame.
  std::vector<int> pixels;              // Chain index of each point.
  double last_depth = 0.0;

  int size() const { return static_cast<int>(points.size()); }
};

bool usableDepth(const PixelDepth& depth) {
  return depth.valid() && std::isfinite(depth.depth) && depth.depth > Camera::kMinDepth;
}

bool isDepthJump(double a, double b, double max_relative_jump) {
  return std::abs(a - b) > max_relative_jump * std::min(a, b);
}

// Cuts one chain into runs of lifted pixels (steps 1 and 2 of initialise()).
class RunBuilder {
 public:
  RunBuilder(const Camera& camera, const Pose3& world_from_cam,
             const CurveInitialiserOptions& options, CurveInitialisationCounts* counts)
      : camera_(camera), world_from_cam_(world_from_cam), options_(options), counts_(counts) {}

  std::vector<Run> build(const EdgeChain& chain, const std::vector<PixelDepth>& depths) {
    runs_.clear();
    current_ = Run();
    for (int i = 0; i < static_cast<int>(depths.size()); ++i) {
      ++counts_->pixels;
      if (!usableDepth(depths[i])) continue;
      ++counts_->pixels_lifted;
      add(i, chain.pixels[i], depths[i].depth);
    }
    close();
    return std::move(runs_);
  }

 private:
  void add(int index, const Eigen::Vector2i& pixel, double depth) {
    if (!current_.pixels.empty()) {
      const bool gap = index - current_.pixels.back() - 1 > options_.max_gap_px;
      const bool jump = isDepthJump(current_.last_depth, depth, options_.max_relative_depth_jump);
      if (jump && !gap) ++counts_->depth_jumps;
      if (gap || jump) close();
    }
    current_.points.push_back(world_from_cam_ * camera_.unproject(pixel.cast<double>(), depth));
    current_.pixels.push_back(index);
    current_.last_depth = depth;
  }

  void close() {
    if (current_.size() >= kMinSegmentPoints) {
      ++counts_->runs;
      runs_.push_back(std::move(current_));
    } else if (current_.size() > 0) {
      ++counts_->runs_too_short;
    }
    current_ = Run();
  }

  const Camera& camera_;
  const Pose3& world_from_cam_;
  const CurveInitialiserOptions& options_;
  CurveInitialisationCounts* counts_;
  std::vector<Run> runs_;
  Run current_;
};

// Point indices j = 0..k of the segment boundaries of a run of n >= 4 points.
std::vector<int> segmentBoundaries(int n, int pixels_per_segment) {
  const int wanted = std::max(1, static_cast<int>(std::lround(double(n) / pixels_per_segment)));
  // Equal shares of n - 1 intervals: k segments hold at least floor((n - 1) / k) + 1 points.
  const int k = std::min(wanted, (n - 1) / (kMinSegmentPoints - 1));
  std::vector<int> boundaries(k + 1);
  for (int j = 0; j <= k; ++j) {
    boundaries[j] = static_cast<int>(std::lround(double(j) * (n - 1) / k));
  }
  return boundaries;
}

double rmsResidual(const CubicBezier& cubic, const Eigen::Vector3d* points, int m) {
  double sum = 0.0;
  for (int k = 0; k < m; ++k) {
    sum += (cubic.evaluate(double(k) / (m - 1)) - points[k]).squaredNorm();
  }
  return std::sqrt(sum / m);
}

// A loop or cusp shows as an arm that is long, or points backwards, compared with the chord.
bool isLoop(const CubicBezier& cubic, const Eigen::Vector3d& chord, double max_arm_to_chord) {
  const Eigen::Vector3d start_arm = cubic.control[1] - cubic.control[0];
  const Eigen::Vector3d end_arm = cubic.control[3] - cubic.control[2];
  const double max_arm = max_arm_to_chord * chord.norm();
  return start_arm.norm() > max_arm || end_arm.norm() > max_arm || start_arm.dot(chord) < 0.0 ||
         end_arm.dot(chord) < 0.0;
}

// Judges a fitted segment and counts the verdict; true if it is accepted. The chord comes first
// because the other tests are relative to it.
bool accept(const CubicBezier& cubic, const Eigen::Vector3d* points, int m,
            const CurveInitialiserOptions& options, CurveInitialisationCounts* counts) {
  const Eigen::Vector3d chord = cubic.control[3] - cubic.control[0];
  const double length = chord.norm();
  int* rejected_by = nullptr;
  if (!(length >= options.min_chord) || length == 0.0) {
    rejected_by = &counts->segments_short_chord;
  } else if (isLoop(cubic, chord, options.max_arm_to_chord)) {
    rejected_by = &counts->segments_loop;
  } else if (!(rmsResidual(cubic, points, m) <= options.max_rms_residual_rel_chord * length)) {
    rejected_by = &counts->segments_bad_fit;
  }
  ++(rejected_by != nullptr ? *rejected_by : counts->segments_accepted);
  return rejected_by == nullptr;
}

// Accepted segments waiting to be linked into one curve.
struct PendingCurve {
  std::vector<CubicBezier> fitted;
  std::vector<PixelRange> pixels;
};

// Fits, judges and links the segments of one run (steps 3 to 6 of initialise()).
void initialiseRun(const Run& run, int chain, const CurveInitialiserOptions& options,
                   CurveInitialisation* result) {
  CurveInitialisationCounts& counts = result->counts;
  PendingCurve pending;
  const auto flush = [&]() {
    if (pending.fitted.empty()) return;
    if (static_cast<int>(pending.fitted.size()) >= options.min_segments) {
      result->curves.push_back({linkSegments(pending.fitted), chain, std::move(pending.pixels)});
      ++counts.curves;
    } else {
      ++counts.curves_too_few_segments;
    }
    pending = PendingCurve();
  };

  const std::vector<int> boundaries = segmentBoundaries(run.size(), options.pixels_per_segment);
  for (size_t j = 0; j + 1 < boundaries.size(); ++j) {
    const Eigen::Vector3d* first = run.points.data() + boundaries[j];
    const int m = boundaries[j + 1] - boundaries[j] + 1;
    const CubicBezier cubic = BezierFitter::shared().fit(first, m);
    if (!accept(cubic, first, m, options, &counts)) {
      flush();
      continue;
    }
    pending.fitted.push_back(cubic);
    pending.pixels.push_back({run.pixels[boundaries[j]], run.pixels[boundaries[j + 1]]});
  }
  flush();
}

}  // namespace

void CurveInitialiserOptions::validate() const {
  const struct {
    const char* field;
    double value;
    bool ok;
    const char* constraint;
  } checks[] = {
      {"pixels_per_segment", double(pixels_per_segment),
       inClosed(pixels_per_segment, kMinSegmentPoints, 10000), "in [4, 10000]"},
      {"min_segments", double(min_segments), inClosed(min_segments, 1, 10000), "in [1, 10000]"},
      {"max_gap_px", double(max_gap_px), inClosed(max_gap_px, 0, 100), "in [0, 100]"},
      {"max_relative_depth_jump", max_relative_depth_jump,
       inOpenClosed(max_relative_depth_jump, 0.0, 100.0), "in (0, 100]"},
      {"max_rms_residual_rel_chord", max_rms_residual_rel_chord,
       inOpenClosed(max_rms_residual_rel_chord, 0.0, 100.0), "in (0, 100]"},
      {"min_chord", min_chord, inClosed(min_chord, 0.0, 1e6), "in [0, 1e6]"},
      {"max_arm_to_chord", max_arm_to_chord, inOpenClosed(max_arm_to_chord, 0.0, 100.0),
       "in (0, 100]"},
  };
  const OptionCheck require("CurveInitialiserOptions");
  for (const auto& check : checks) require(check.ok, check.field, check.value, check.constraint);
}

CurveInitialiser::CurveInitialiser(const CurveInitialiserOptions& options) : options_(options) {
  options_.validate();
}

CurveInitialisation CurveInitialiser::initialise(const Camera& camera, const Pose3& cam_from_world,
                                                 const std::vector<EdgeChain>& chains,
                                                 const ChainDepths& depths) const {
  CURVESFM_CHECK(depths.chains.size() == chains.size())
      << "depths for " << depths.chains.size() << " chains, but " << chains.size() << " chains";
  CurveInitialisation result;
  const Pose3 world_from_cam = cam_from_world.inverse();
  RunBuilder builder(camera, world_from_cam, options_, &result.counts);
  for (int c = 0; c < static_cast<int>(chains.size()); ++c) {
    CURVESFM_CHECK(depths.chains[c].size() == chains[c].pixels.size())
        << "chain " << c << " has " << chains[c].pixels.size() << " pixels but "
        << depths.chains[c].size() << " depths";
    for (const Run& run : builder.build(chains[c], depths.chains[c])) {
      initialiseRun(run, c, options_, &result);
    }
  }
  return result;
}

}  // namespace curvesfm
