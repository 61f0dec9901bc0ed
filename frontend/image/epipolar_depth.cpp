#include "frontend/image/epipolar_depth.h"

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <sstream>
#include <string>

#include "core/check.h"
#include "core/errors.h"
#include "core/parallel.h"

namespace curvesfm {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadPerDeg = kPi / 180.0;

// Compile-time bounds of the option ranges, so that patches and windows live on the stack.
constexpr int kMaxHalfSize = 10;
constexpr int kMaxPatch1d = 2 * kMaxHalfSize + 1;
constexpr int kMaxPatch2d = kMaxPatch1d * kMaxPatch1d;
constexpr int kMaxCandidates = 8;
constexpr int kMaxHalfWindow = 15;
constexpr int kMaxWindow = 2 * kMaxHalfWindow + 1;
// Reference pixels per keyframe pixel along the epipolar line are clamped to this range: beyond
// it the views differ so much in scale that the patches would not correspond anyway.
constexpr double kMinStep = 0.5;
constexpr double kMaxStep = 2.0;
// A point must lie this far in front of the reference camera (in units of rho * z_ref) to project:
// it keeps the epipolar segment finite.
constexpr double kMinFrontDepth = 1e-6;
// rankReferenceFrames scores at most this many chain pixels per candidate.
constexpr int kRankingSamples = 1024;

// ------------------------------------------------------------------------------------------------
// Options.

// Written as positive comparisons so that NaN fails.
bool inClosed(double value, double low, double high) { return value >= low && value <= high; }
bool inOpenClosed(double value, double low, double high) { return value > low && value <= high; }

double midInverseDepth(const EpipolarDepthOptions& options) {
  return 0.5 * (1.0 / options.min_depth + 1.0 / options.max_depth);
}

double minGradientCosine(const EpipolarDepthOptions& options) {
  return std::cos(options.max_gradient_epipolar_angle_deg * kRadPerDeg);
}

// ------------------------------------------------------------------------------------------------
// Two-view geometry in inverse depth. A keyframe pixel p at inverse depth rho lands in the
// reference at the dehomogenised g = A + rho b with A = K R K^-1 (p, 1) and b = K t, (R, t) =
// ref_from_key: the epipolar segment is linear in homogeneous coordinates.

struct ReferenceGeometry {
  Eigen::Matrix3d M = Eigen::Matrix3d::Identity();  // K R K^-1.
  Eigen::Vector3d b = Eigen::Vector3d::Zero();      // K t.
  ReferenceCandidate candidate;
};

ReferenceGeometry referenceGeometry(int index, const Pose3& key_cam_from_world,
                                    const Pose3& ref_cam_from_world, const Camera& camera,
                                    const EpipolarDepthOptions& options) {
  const Pose3 ref_from_key = ref_cam_from_world * key_cam_from_world.inverse();
  const Eigen::Matrix3d K = camera.K();
  const Eigen::Matrix3d R = ref_from_key.rotationMatrix();
  ReferenceGeometry geometry;
  geometry.M = K * R * K.inverse();
  geometry.b = K * ref_from_key.translation();
  ReferenceCandidate& candidate = geometry.candidate;
  candidate.index = index;
  // The keyframe's centre in the reference frame is t, so |t| is the baseline.
  candidate.baseline = ref_from_key.translation().norm();
  candidate.parallax_deg = std::atan(candidate.baseline * midInverseDepth(options)) / kRadPerDeg;
  candidate.optical_axis_angle_deg = std::acos(std::clamp(R(2, 2), -1.0, 1.0)) / kRadPerDeg;
  candidate.eligible = candidate.parallax_deg >= options.min_parallax_deg &&
                       candidate.optical_axis_angle_deg <= options.max_optical_axis_angle_deg;
  return geometry;
}

Eigen::Vector2d projectAt(const Eigen::Vector3d& A, const Eigen::Vector3d& b, double rho) {
  const Eigen::Vector3d g = A + rho * b;
  return g.head<2>() / g.z();
}

// The inverse depth whose projection is `x`, a point on the segment with unit direction `u`;
// only the component along u carries information, which keeps the division well conditioned.
double inverseDepthAt(const Eigen::Vector3d& A, const Eigen::Vector3d& b, const Eigen::Vector2d& x,
                      const Eigen::Vector2d& u) {
  const double ux = u.dot(x);
  return (ux * A.z() - u.dot(A.head<2>())) / (u.dot(b.head<2>()) - ux * b.z());
}

// d x / d rho (px per m^-1).
Eigen::Vector2d disparityRate(const Eigen::Vector3d& A, const Eigen::Vector3d& b, double rho) {
  const Eigen::Vector3d g = A + rho * b;
  return (b.head<2>() - (g.head<2>() / g.z()) * b.z()) / g.z();
}

// d x_ref / d p at fixed depth: the local affine map of the fronto-parallel plane at 1 / rho.
Eigen::Matrix2d localAffine(const Eigen::Matrix3d& M, const Eigen::Vector3d& A,
                            const Eigen::Vector3d& b, double rho) {
  const Eigen::Vector3d g = A + rho * b;
  Eigen::Matrix<double, 2, 3> d_x_d_g;
  d_x_d_g << 1.0, 0.0, -g.x() / g.z(), 0.0, 1.0, -g.y() / g.z();
  return d_x_d_g * M.leftCols<2>() / g.z();
}

// Shrinks [*lo, *hi] to the inverse depths in front of the reference camera (g_z > 0, linear in
// rho); false if none are.
bool clipToFront(double a_z, double b_z, double* lo, double* hi) {
  if (b_z > 0.0) {
    *lo = std::max(*lo, (kMinFrontDepth - a_z) / b_z);
  } else if (b_z < 0.0) {
    *hi = std::min(*hi, (kMinFrontDepth - a_z) / b_z);
  } else if (a_z <= kMinFrontDepth) {
    return false;
  }
  return *lo <= *hi;
}

// Liang-Barsky: the part [*t0, *t1] of x0 + t d, t in [0, 1], inside [lo, hi] per coordinate.
bool clipToBox(const Eigen::Vector2d& x0, const Eigen::Vector2d& d, const Eigen::Vector2d& lo,
               const Eigen::Vector2d& hi, double* t0, double* t1) {
  *t0 = 0.0;
  *t1 = 1.0;
  for (int k = 0; k < 2; ++k) {
    if (d[k] == 0.0) {
      if (x0[k] < lo[k] || x0[k] > hi[k]) return false;
      continue;
    }
    double enter = (lo[k] - x0[k]) / d[k];
    double leave = (hi[k] - x0[k]) / d[k];
    if (enter > leave) std::swap(enter, leave);
    *t0 = std::max(*t0, enter);
    *t1 = std::min(*t1, leave);
  }
  return *t0 <= *t1;
}

// The searchable part of one pixel's epipolar segment in one reference.
struct EpipolarSegment {
  Eigen::Vector3d A = Eigen::Vector3d::Zero();
  Eigen::Vector2d start = Eigen::Vector2d::Zero();    // The far end (smallest rho), px.
  Eigen::Vector2d dir_ref = Eigen::Vector2d::Zero();  // Unit, towards larger rho.
  double length = 0.0;                                // px.
  Eigen::Vector2d dir_key = Eigen::Vector2d::Zero();  // Unit; maps onto +dir_ref.
  double step = 1.0;       // Reference px per keyframe px along the line.
  double cos_angle = 0.0;  // |cos| of the gradient-epipolar angle.
  double score = 0.0;      // Cross-edge parallax at the mid-range depth (px).
};

// The whole segment of [1 / max_depth, 1 / min_depth] (clipped to the front of the
// reference) from x0 (far) to x0 + d (near), and the local affine map J in its middle; false if
// it lies behind the reference or is a point (the pixel is the epipole).
bool fullSegment(const ReferenceGeometry& geometry, const Eigen::Vector3d& A,
                 const EpipolarDepthOptions& options, Eigen::Vector2d* x0, Eigen::Vector2d* d,
                 Eigen::Matrix2d* J) {
  double lo = 1.0 / options.max_depth;
  double hi = 1.0 / options.min_depth;
  if (!clipToFront(A.z(), geometry.b.z(), &lo, &hi)) return false;
  *x0 = projectAt(A, geometry.b, lo);
  *d = projectAt(A, geometry.b, hi) - *x0;
  *J = localAffine(geometry.M, A, geometry.b, 0.5 * (lo + hi));
  return d->norm() > 1e-9 && std::abs(J->determinant()) > 1e-12;
}

// The part of pixel `p`'s segment (see fullSegment) that leaves room for h samples of patch
// context in the reference image; false if there is none.
bool epipolarSegment(const ReferenceGeometry& geometry, const Eigen::Vector2d& p,
                     const Eigen::Vector2f& normal, const Camera& camera,
                     const EpipolarDepthOptions& options, EpipolarSegment* segment) {
  const Eigen::Vector3d A = geometry.M * p.homogeneous();
  Eigen::Vector2d x0;
  Eigen::Vector2d d;
  Eigen::Matrix2d J;
  if (!fullSegment(geometry, A, options, &x0, &d, &J)) return false;
  const Eigen::Vector2d u = d.normalized();
  // Points of the keyframe's epipolar line stay on the reference's, so J^-1 u is along the
  // keyframe's line, and oriented so that both patches run the same way.
  const Eigen::Vector2d w = J.inverse() * u;
  const double step = std::clamp(1.0 / w.norm(), kMinStep, kMaxStep);
  const double margin = options.patch_half_size_1d * step + 1.0;  // + 1: bilinear neighbour.
  double t0 = 0.0;
  double t1 = 0.0;
  if (!clipToBox(x0, d, Eigen::Vector2d(margin, margin),
                 Eigen::Vector2d(camera.width() - 1 - margin, camera.height() - 1 - margin), &t0,
                 &t1)) {
    return false;
  }
  segment->A = A;
  segment->start = x0 + t0 * d;
  segment->dir_ref = u;
  segment->length = (t1 - t0) * d.norm();
  segment->dir_key = w.normalized();
  segment->step = step;
  segment->cos_angle = std::abs(segment->dir_key.dot(normal.cast<double>()));
  const double rho_visible = inverseDepthAt(A, geometry.b, x0 + 0.5 * (t0 + t1) * d, u);
  segment->score = segment->cos_angle * disparityRate(A, geometry.b, rho_visible).norm() *
                   midInverseDepth(options);
  return true;
}

// ------------------------------------------------------------------------------------------------
// Image sampling, on CV_32FC1 copies of the images (no integer conversion per sample). Callers
// keep (x, y) in [0, cols - 2] x [0, rows - 2].

inline float bilinear(const cv::Mat& image, float x, float y) {
  const int x0 = static_cast<int>(x);
  const int y0 = static_cast<int>(y);
  const float ax = x - static_cast<float>(x0);
  const float ay = y - static_cast<float>(y0);
  const float* top = image.ptr<float>(y0) + x0;
  const float* bottom = image.ptr<float>(y0 + 1) + x0;
  const float upper = top[0] + ax * (top[1] - top[0]);
  const float lower = bottom[0] + ax * (bottom[1] - bottom[0]);
  return upper + ay * (lower - upper);
}

// A CV_32FC1 image is taken as it is (shared, not copied).
cv::Mat toFloat(const cv::Mat& grey) {
  if (grey.type() == CV_32FC1) return grey;
  cv::Mat image;
  grey.convertTo(image, CV_32F);
  return image;
}

// Mean of `values` if patches are compared mean-free, else 0.
float patchMean(const float* values, int n, bool mean_free) {
  if (!mean_free) return 0.0f;
  float sum = 0.0f;
  for (int k = 0; k < n; ++k) sum += values[k];
  return sum / static_cast<float>(n);
}

// ------------------------------------------------------------------------------------------------
// The per-pixel search.

struct RawDepth {
  double rho = 0.0;
  double rho_variance = 0.0;
  int reference = -1;
  DepthStatus status = DepthStatus::kNotSearched;
  bool searched = false;
};

// One local minimum of the 1D cost, refined by a parabola through it and its neighbours.
struct Candidate {
  int index = 0;
  double curvature = 0.0;                       // C'' of the 1D cost (grey^2 per sample^2).
  double cost_1d = 0.0;                         // The parabola's vertex value.
  Eigen::Vector2d x = Eigen::Vector2d::Zero();  // Refined reference pixel.
  double rho = 0.0;
  float cost_2d = 0.0f;
};

// The reference being searched and the pixel's segment in it.
struct SearchTarget {
  const cv::Mat* image = nullptr;  // CV_32FC1.
  const ReferenceGeometry* geometry = nullptr;
  EpipolarSegment segment;
};

class DepthSearcher {
 public:
  DepthSearcher(const cv::Mat& keyframe_image, const std::vector<DepthReferenceView>& references,
                std::vector<ReferenceGeometry> geometries, const Camera& camera,
                const EpipolarDepthOptions& options)
      : key_(toFloat(keyframe_image)),
        geometries_(std::move(geometries)),
        camera_(camera),
        options_(options),
        n1_(2 * options.patch_half_size_1d + 1),
        n2_((2 * options.patch_half_size_2d + 1) * (2 * options.patch_half_size_2d + 1)) {
    for (std::size_t r = 0; r < references.size(); ++r) {
      const bool used = geometries_[r].candidate.eligible;
      references_.push_back(used ? toFloat(references[r].image) : cv::Mat());
      any_eligible_ = any_eligible_ || used;
    }
    // The longest clipped segment is the image diagonal, sampled at kMinStep.
    const double diagonal = std::hypot(camera.width(), camera.height());
    const std::size_t samples = static_cast<std::size_t>(diagonal / kMinStep) + n1_ + 4;
    for (std::vector<float>* buffer : {&samples_, &costs_, &sums_, &squares_}) {
      buffer->resize(samples);
    }
    minima_.resize(samples);
  }

  RawDepth search(const Eigen::Vector2i& pixel, const Eigen::Vector2f& normal) {
    RawDepth raw;
    raw.searched = true;
    if (!any_eligible_) {
      raw.status = DepthStatus::kNoReference;
      return raw;
    }
    const int margin = std::max(options_.patch_half_size_1d + 1, options_.patch_half_size_2d);
    if (pixel.x() < margin || pixel.y() < margin || pixel.x() > key_.cols - 1 - margin ||
        pixel.y() > key_.rows - 1 - margin) {
      raw.status = DepthStatus::kAtImageBorder;
      return raw;
    }
    SearchTarget target;
    raw.status = chooseReference(pixel.cast<double>(), normal, &target, &raw.reference);
    if (raw.status != DepthStatus::kValid) return raw;
    raw.status = match(pixel, target, &raw);
    return raw;
  }

 private:
  DepthStatus chooseReference(const Eigen::Vector2d& p, const Eigen::Vector2f& normal,
                              SearchTarget* best, int* best_index) const {
    const double min_cos = minGradientCosine(options_);
    bool any_visible = false;
    EpipolarSegment segment;
    for (std::size_t r = 0; r < geometries_.size(); ++r) {
      if (!geometries_[r].candidate.eligible) continue;
      if (!epipolarSegment(geometries_[r], p, normal, camera_, options_, &segment)) continue;
      any_visible = true;
      if (segment.cos_angle < min_cos) continue;
      if (*best_index < 0 || segment.score > best->segment.score) {
        best->segment = segment;
        best->geometry = &geometries_[r];
        best->image = &references_[r];
        *best_index = static_cast<int>(r);
      }
    }
    if (*best_index >= 0) return DepthStatus::kValid;
    return any_visible ? DepthStatus::kEdgeAlongEpipolar : DepthStatus::kOutOfView;
  }

  // Steps 2-5 of estimateChainDepths: 1D search, candidates, 2D check, refinement, variance.
  DepthStatus match(const Eigen::Vector2i& pixel, const SearchTarget& target, RawDepth* raw) {
    const EpipolarSegment& segment = target.segment;
    const int count = static_cast<int>(segment.length / segment.step) + 1;
    sampleKeyframe(pixel, segment.dir_key);
    sampleSegment(*target.image, segment, count);
    costs1d(count);
    Candidate candidates[kMaxCandidates];
    const int num_minima = bestMinima(count, candidates);
    if (num_minima == 0) return DepthStatus::kNoMinimum;
    const int num_candidates = plausibleCandidates(target, num_minima, candidates);
    if (num_candidates == 0) return DepthStatus::kHighCost;
    for (int k = 0; k < num_candidates; ++k) {
      candidates[k].cost_2d = cost2d(target, candidates[k].x, candidates[k].rho);
    }
    std::sort(candidates, candidates + num_candidates,
              [](const Candidate& a, const Candidate& b) { return a.cost_2d < b.cost_2d; });
    const Candidate& best = candidates[0];
    if (!std::isfinite(best.cost_2d)) return DepthStatus::kAtImageBorder;
    if (num_candidates > 1 && std::isfinite(candidates[1].cost_2d) &&
        best.cost_2d > options_.max_ambiguity_ratio * candidates[1].cost_2d) {
      return DepthStatus::kAmbiguous;
    }
    if (best.cost_2d > n2_ * maxSquare()) return DepthStatus::kHighCost;
    return setVariance(best, target, raw);
  }

  double maxSquare() const { return options_.max_patch_rms_grey * options_.max_patch_rms_grey; }

  // Refines the minima and keeps, in order, those whose 1D patch matches within
  // max_patch_rms_grey: a worse one is no match, nor a rival of one, and need not pay for a 2D
  // comparison. Returns how many are kept.
  int plausibleCandidates(const SearchTarget& target, int num_minima, Candidate* candidates) const {
    int kept = 0;
    for (int k = 0; k < num_minima; ++k) {
      refine1d(target, &candidates[k]);
      if (candidates[k].cost_1d <= n1_ * maxSquare()) candidates[kept++] = candidates[k];
    }
    return kept;
  }

  // Parabola through the 1D costs around the minimum: its vertex is the match and its curvature
  // C'' the photometric precision (an SSD has C'' = 2 sum g^2 and the vertex the variance
  // 2 sigma^2 / sum g^2 = 4 sigma^2 / C'', sigma^2 of noise in each image).
  void refine1d(const SearchTarget& target, Candidate* candidate) const {
    const int index = candidate->index;
    const double before = costs_[index - 1];
    const double at = costs_[index];
    const double after = costs_[index + 1];
    candidate->curvature = before - 2.0 * at + after;  // > 0 at a strict local minimum.
    const double offset = 0.5 * (before - after) / candidate->curvature;
    candidate->cost_1d = std::max(0.0, at - 0.25 * (before - after) * offset);
    const EpipolarSegment& segment = target.segment;
    candidate->x = segment.start + (index + offset) * segment.step * segment.dir_ref;
    candidate->rho = inverseDepthAt(segment.A, target.geometry->b, candidate->x, segment.dir_ref);
  }

  DepthStatus setVariance(const Candidate& best, const SearchTarget& target, RawDepth* raw) const {
    const EpipolarSegment& segment = target.segment;
    const double noise = options_.image_noise_sigma_grey;
    const double photometric = 4.0 * noise * noise / best.curvature * segment.step * segment.step;
    const double geometric = options_.epipolar_sigma_px * options_.epipolar_sigma_px /
                             (segment.cos_angle * segment.cos_angle);
    const double rate = disparityRate(segment.A, target.geometry->b, best.rho).norm();
    raw->rho = best.rho;
    raw->rho_variance = (photometric + geometric) / (rate * rate);
    const double max_sigma = options_.max_relative_inverse_depth_sigma * best.rho;
    // Also rejects rho <= 0 (at or beyond infinity) and non-finite results.
    if (!(best.rho > 0.0 && raw->rho_variance <= max_sigma * max_sigma)) {
      return DepthStatus::kHighVariance;
    }
    return DepthStatus::kValid;
  }

  void sampleKeyframe(const Eigen::Vector2i& pixel, const Eigen::Vector2d& dir_key) {
    const int h = options_.patch_half_size_1d;
    for (int s = -h; s <= h; ++s) {
      key1d_[s + h] = bilinear(key_, static_cast<float>(pixel.x() + s * dir_key.x()),
                               static_cast<float>(pixel.y() + s * dir_key.y()));
    }
    key1d_mean_ = patchMean(key1d_, n1_, options_.subtract_patch_mean);
    const int h2 = options_.patch_half_size_2d;
    int k = 0;
    for (int dy = -h2; dy <= h2; ++dy) {
      const float* row = key_.ptr<float>(pixel.y() + dy) + pixel.x();
      for (int dx = -h2; dx <= h2; ++dx) key2d_[k++] = row[dx];
    }
    key2d_mean_ = patchMean(key2d_, n2_, options_.subtract_patch_mean);
  }

  // Samples count + 2h reference values, the first h and the last h being patch context.
  void sampleSegment(const cv::Mat& reference, const EpipolarSegment& segment, int count) {
    const int h = options_.patch_half_size_1d;
    const Eigen::Vector2d delta = segment.step * segment.dir_ref;
    const Eigen::Vector2d first = segment.start - h * delta;
    const float x0 = static_cast<float>(first.x());
    const float y0 = static_cast<float>(first.y());
    const float dx = static_cast<float>(delta.x());
    const float dy = static_cast<float>(delta.y());
    for (int j = 0; j < count + 2 * h; ++j) {
      samples_[j] = bilinear(reference, x0 + j * dx, y0 + j * dy);
    }
  }

  // All window sums at once, patch sample by patch sample, so that the inner loops run over
  // contiguous arrays and vectorise: SSD = sum k^2 + sum r^2 - 2 sum k r, and mean-free
  // SSD = sum k'^2 + sum r^2 - (sum r)^2 / n - 2 sum k' r with k' = k - mean(k).
  void costs1d(int count) {
    float* cross = costs_.data();
    float* sum = sums_.data();
    float* squares = squares_.data();
    std::fill(cross, cross + count, 0.0f);
    std::fill(sum, sum + count, 0.0f);
    std::fill(squares, squares + count, 0.0f);
    float key_squares = 0.0f;
    for (int s = 0; s < n1_; ++s) {
      const float k = key1d_[s] - key1d_mean_;
      key_squares += k * k;
      const float* r = samples_.data() + s;
      for (int i = 0; i < count; ++i) {
        cross[i] += k * r[i];
        sum[i] += r[i];
        squares[i] += r[i] * r[i];
      }
    }
    const float inverse_n = options_.subtract_patch_mean ? 1.0f / static_cast<float>(n1_) : 0.0f;
    for (int i = 0; i < count; ++i) {
      const float cost = key_squares + squares[i] - sum[i] * sum[i] * inverse_n - 2.0f * cross[i];
      costs_[i] = std::max(0.0f, cost);  // Rounding can take a perfect match below zero.
    }
  }

  // The best interior local minima, greedily, each more than h samples from those taken.
  int bestMinima(int count, Candidate* candidates) {
    int num_minima = 0;
    for (int i = 1; i + 1 < count; ++i) {
      if (costs_[i] < costs_[i - 1] && costs_[i] <= costs_[i + 1]) minima_[num_minima++] = i;
    }
    const int radius = options_.patch_half_size_1d;
    int taken = 0;
    while (taken < options_.max_candidates) {
      int best = -1;
      for (int m = 0; m < num_minima; ++m) {
        const int i = minima_[m];
        if (i < 0 || (best >= 0 && costs_[i] >= costs_[best])) continue;
        best = i;
      }
      if (best < 0) break;
      candidates[taken++].index = best;
      for (int m = 0; m < num_minima; ++m) {
        if (minima_[m] >= 0 && std::abs(minima_[m] - best) <= radius) minima_[m] = -1;
      }
    }
    return taken;
  }

  // SSD (mean-free if asked) of the keyframe's 2D patch against the reference around `x` (a
  // refined candidate, so that the patches are aligned), warped by the local affine map at
  // inverse depth `rho`; +infinity if the warped patch leaves the image.
  float cost2d(const SearchTarget& target, const Eigen::Vector2d& x, double rho) const {
    const Eigen::Matrix2d J =
        localAffine(target.geometry->M, target.segment.A, target.geometry->b, rho);
    const cv::Mat& reference = *target.image;
    const int h = options_.patch_half_size_2d;
    const double reach_x = h * (std::abs(J(0, 0)) + std::abs(J(0, 1)));
    const double reach_y = h * (std::abs(J(1, 0)) + std::abs(J(1, 1)));
    if (!(x.x() - reach_x >= 0.0 && x.y() - reach_y >= 0.0 &&
          x.x() + reach_x <= reference.cols - 2 && x.y() + reach_y <= reference.rows - 2)) {
      return std::numeric_limits<float>::infinity();
    }
    float warped[kMaxPatch2d];
    const Eigen::Vector2f along_x = J.col(0).cast<float>();
    const Eigen::Vector2f along_y = J.col(1).cast<float>();
    Eigen::Vector2f row_start = (x - h * (J.col(0) + J.col(1))).cast<float>();
    int k = 0;
    for (int dy = -h; dy <= h; ++dy, row_start += along_y) {
      Eigen::Vector2f q = row_start;
      for (int dx = -h; dx <= h; ++dx, q += along_x)
        warped[k++] = bilinear(reference, q.x(), q.y());
    }
    const float mean = patchMean(warped, n2_, options_.subtract_patch_mean);
    float cost = 0.0f;
    for (int m = 0; m < n2_; ++m) {
      const float r = (key2d_[m] - key2d_mean_) - (warped[m] - mean);
      cost += r * r;
    }
    return cost;
  }

  cv::Mat key_;                      // CV_32FC1.
  std::vector<cv::Mat> references_;  // CV_32FC1, empty for ineligible references.
  std::vector<ReferenceGeometry> geometries_;
  const Camera& camera_;
  const EpipolarDepthOptions& options_;
  const int n1_;
  const int n2_;
  bool any_eligible_ = false;
  float key1d_[kMaxPatch1d] = {};
  float key2d_[kMaxPatch2d] = {};
  float key1d_mean_ = 0.0f;
  float key2d_mean_ = 0.0f;
  std::vector<float> samples_;
  std::vector<float> costs_;
  std::vector<float> sums_;
  std::vector<float> squares_;
  std::vector<int> minima_;
};

// ------------------------------------------------------------------------------------------------
// Robust averaging along a chain.

struct WindowStats {
  int count = 0;  // Searched depths in the window.
  double median = 0.0;
  int inliers = 0;
  double mean = 0.0;      // Inverse-variance weighted mean of the inliers.
  double variance = 0.0;  // Harmonic mean of the inliers' variances.
};

// Within outlier_sigmas standard deviations of the window's median.
bool consistent(double rho, double variance, double median, const EpipolarDepthOptions& options) {
  const double deviation = rho - median;
  return deviation * deviation <= options.outlier_sigmas * options.outlier_sigmas * variance;
}

// The valid searched depths of the window around `centre` (wrapping around a loop) into
// rho[] / variance[]; returns their number.
int gatherWindow(const std::vector<RawDepth>& raw, int centre, bool closed,
                 const EpipolarDepthOptions& options, double* rho, double* variance) {
  const int n = static_cast<int>(raw.size());
  int half = options.smoothing_half_window;
  if (closed) half = std::min(half, (n - 1) / 2);  // Each pixel of a short loop counts once.
  int count = 0;
  for (int k = -half; k <= half; ++k) {
    const int j = closed ? ((centre + k) % n + n) % n : centre + k;
    if (j < 0 || j >= n || raw[j].status != DepthStatus::kValid) continue;
    rho[count] = raw[j].rho;
    variance[count++] = raw[j].rho_variance;
  }
  return count;
}

WindowStats windowStats(const std::vector<RawDepth>& raw, int centre, bool closed,
                        const EpipolarDepthOptions& options) {
  double rho[kMaxWindow];
  double variance[kMaxWindow];
  WindowStats stats;
  stats.count = gatherWindow(raw, centre, closed, options, rho, variance);
  if (stats.count == 0) return stats;
  double sorted[kMaxWindow];
  std::copy(rho, rho + stats.count, sorted);
  std::nth_element(sorted, sorted + stats.count / 2, sorted + stats.count);
  stats.median = sorted[stats.count / 2];
  double weights = 0.0;
  double weighted = 0.0;
  for (int m = 0; m < stats.count; ++m) {
    if (!consistent(rho[m], variance[m], stats.median, options)) continue;
    ++stats.inliers;
    weights += 1.0 / variance[m];
    weighted += rho[m] / variance[m];
  }
  if (stats.inliers > 0) {
    stats.mean = weighted / weights;
    stats.variance = stats.inliers / weights;
  }
  return stats;
}

void setDepth(double rho, double rho_variance, PixelDepth* out) {
  out->status = DepthStatus::kValid;
  out->depth = 1.0 / rho;
  out->inverse_depth_variance = rho_variance;
  const double depth_squared = out->depth * out->depth;
  out->depth_variance = rho_variance * depth_squared * depth_squared;
}

PixelDepth smoothPixel(const std::vector<RawDepth>& raw, int i, bool closed,
                       const EpipolarDepthOptions& options) {
  const RawDepth& own = raw[i];
  PixelDepth out;
  out.reference = own.reference;
  out.status = own.status;
  if (own.searched && own.status != DepthStatus::kValid) return out;
  if (options.smoothing_half_window == 0) {
    if (own.searched) setDepth(own.rho, own.rho_variance, &out);
    return out;
  }
  const WindowStats stats = windowStats(raw, i, closed, options);
  if (own.searched && !consistent(own.rho, own.rho_variance, stats.median, options)) {
    out.status = DepthStatus::kOutlier;
    return out;
  }
  if (stats.inliers < options.min_window_support) {
    out.status = own.searched ? DepthStatus::kUnsupported : DepthStatus::kNotSearched;
    return out;
  }
  setDepth(stats.mean, stats.variance, &out);
  out.interpolated = !own.searched;
  return out;
}

// ReferenceCandidate::score: the mean cross-edge parallax over up to kRankingSamples chain
// pixels spread evenly over all chains.
double meanScore(const ReferenceGeometry& geometry, const std::vector<EdgeChain>& chains,
                 const Camera& camera, const EpipolarDepthOptions& options) {
  std::size_t total = 0;
  for (const EdgeChain& chain : chains) total += chain.pixels.size();
  const std::size_t stride =
      std::max<std::size_t>(1, (total + kRankingSamples - 1) / kRankingSamples);
  const double min_cos = minGradientCosine(options);
  double sum = 0.0;
  std::size_t sampled = 0;
  std::size_t k = 0;
  EpipolarSegment segment;
  for (const EdgeChain& chain : chains) {
    for (std::size_t i = 0; i < chain.pixels.size(); ++i, ++k) {
      if (k % stride != 0) continue;
      ++sampled;
      if (epipolarSegment(geometry, chain.pixels[i].cast<double>(), chain.normals[i], camera,
                          options, &segment) &&
          segment.cos_angle >= min_cos) {
        sum += segment.score;
      }
    }
  }
  return sampled > 0 ? sum / static_cast<double>(sampled) : 0.0;
}

void checkChains(const std::vector<EdgeChain>& chains) {
  for (std::size_t c = 0; c < chains.size(); ++c) {
    CURVESFM_CHECK(chains[c].pixels.size() == chains[c].normals.size())
        << "chain " << c << " has " << chains[c].pixels.size() << " pixels but "
        << chains[c].normals.size() << " normals";
  }
}

void checkImage(const cv::Mat& image, const Camera& camera, const char* what) {
  CURVESFM_CHECK((image.type() == CV_8UC1 || image.type() == CV_32FC1) &&
                 image.cols == camera.width() && image.rows == camera.height())
      << what << " must be CV_8UC1 or CV_32FC1 of the camera size " << camera.width() << "x"
      << camera.height() << ", got type " << image.type() << " size " << image.cols << "x"
      << image.rows;
}

void checkInputs(const Camera& camera, const std::vector<EdgeChain>& chains,
                 const EpipolarDepthOptions& options) {
  options.validate();
  CURVESFM_CHECK(!camera.hasDistortion())
      << "epipolar depth needs undistorted images and their pinhole camera "
         "(ImageUndistorter::camera())";
  checkChains(chains);
}

}  // namespace

void EpipolarDepthOptions::validate() const {
  const OptionCheck require("EpipolarDepthOptions");
  require(std::isfinite(min_depth) && min_depth > 0.0, "min_depth", min_depth,
          "must be finite and > 0");
  require(max_depth > min_depth, "max_depth", max_depth, "must be > min_depth (may be infinity)");
  require(min_parallax_deg >= 0.0 && min_parallax_deg < 90.0, "min_parallax_deg", min_parallax_deg,
          "in [0, 90)");
  require(inOpenClosed(max_optical_axis_angle_deg, 0.0, 180.0), "max_optical_axis_angle_deg",
          max_optical_axis_angle_deg, "in (0, 180]");
  require(max_gradient_epipolar_angle_deg >= 0.0 && max_gradient_epipolar_angle_deg < 90.0,
          "max_gradient_epipolar_angle_deg", max_gradient_epipolar_angle_deg, "in [0, 90)");
  require(inClosed(patch_half_size_1d, 1, kMaxHalfSize), "patch_half_size_1d", patch_half_size_1d,
          "in [1, 10]");
  require(inClosed(patch_half_size_2d, 1, kMaxHalfSize), "patch_half_size_2d", patch_half_size_2d,
          "in [1, 10]");
  require(inClosed(max_candidates, 1, kMaxCandidates), "max_candidates", max_candidates,
          "in [1, 8]");
  require(inOpenClosed(max_patch_rms_grey, 0.0, 255.0), "max_patch_rms_grey", max_patch_rms_grey,
          "in (0, 255]");
  require(inOpenClosed(max_ambiguity_ratio, 0.0, 1.0), "max_ambiguity_ratio", max_ambiguity_ratio,
          "in (0, 1]");
  require(inOpenClosed(image_noise_sigma_grey, 0.0, 255.0), "image_noise_sigma_grey",
          image_noise_sigma_grey, "in (0, 255]");
  require(inOpenClosed(epipolar_sigma_px, 0.0, 100.0), "epipolar_sigma_px", epipolar_sigma_px,
          "in (0, 100]");
  require(inOpenClosed(max_relative_inverse_depth_sigma, 0.0, 10.0),
          "max_relative_inverse_depth_sigma", max_relative_inverse_depth_sigma, "in (0, 10]");
  require(inClosed(pixel_step, 1, 16), "pixel_step", pixel_step, "in [1, 16]");
  require(inClosed(smoothing_half_window, 0, kMaxHalfWindow), "smoothing_half_window",
          smoothing_half_window, "in [0, 15]");
  require(inClosed(min_window_support, 1, 2 * smoothing_half_window + 1), "min_window_support",
          min_window_support, "in [1, 2 * smoothing_half_window + 1]");
  require(inOpenClosed(outlier_sigmas, 0.0, 100.0), "outlier_sigmas", outlier_sigmas,
          "in (0, 100]");
  require(inClosed(num_threads, 1, 64), "num_threads", num_threads, "in [1, 64]");
}

static_assert(static_cast<int>(DepthStatus::kUnsupported) + 1 == kNumDepthStatuses,
              "kNumDepthStatuses must count every DepthStatus");

int DepthCounts::total() const {
  int sum = 0;
  for (int count : by_status) sum += count;
  return sum;
}

std::vector<ReferenceCandidate> rankReferenceFrames(
    const Pose3& keyframe_cam_from_world, const std::vector<Pose3>& candidate_cam_from_world,
    const Camera& camera, const std::vector<EdgeChain>& chains,
    const EpipolarDepthOptions& options) {
  checkInputs(camera, chains, options);
  std::vector<ReferenceCandidate> ranked;
  for (std::size_t r = 0; r < candidate_cam_from_world.size(); ++r) {
    const ReferenceGeometry geometry = referenceGeometry(
        static_cast<int>(r), keyframe_cam_from_world, candidate_cam_from_world[r], camera, options);
    ranked.push_back(geometry.candidate);
    if (ranked.back().eligible) ranked.back().score = meanScore(geometry, chains, camera, options);
  }
  std::stable_sort(ranked.begin(), ranked.end(),
                   [](const ReferenceCandidate& a, const ReferenceCandidate& b) {
                     if (a.eligible != b.eligible) return a.eligible;
                     return a.eligible && a.score > b.score;
                   });
  return ranked;
}

namespace {

// No run under this many chain pixels (a search takes about 2 us a pixel): a small keyframe then
// hands its few pixels to fewer threads, each a few microseconds to wake (core/parallel.h).
constexpr std::size_t kMinPixelsPerRun = 256;

// Where each of up to `runs` runs of consecutive chains starts, with about as many pixels each,
// then chains.size().
std::vector<std::size_t> splitByPixels(const std::vector<EdgeChain>& chains, std::size_t runs) {
  std::size_t total = 0;
  for (const EdgeChain& chain : chains) total += chain.pixels.size();
  runs = std::clamp<std::size_t>(total / kMinPixelsPerRun, 1, runs);
  std::vector<std::size_t> first = {0};
  std::size_t seen = 0;
  for (std::size_t c = 0; c < chains.size() && first.size() < runs; ++c) {
    seen += chains[c].pixels.size();
    if (seen * runs >= total * first.size()) first.push_back(c + 1);
  }
  if (first.back() != chains.size()) first.push_back(chains.size());  // No empty last run.
  return first;
}

}  // namespace

ChainDepths estimateChainDepths(const cv::Mat& keyframe_image, const Pose3& keyframe_cam_from_world,
                                const std::vector<EdgeChain>& chains,
                                const std::vector<DepthReferenceView>& references,
                                const Camera& camera, const EpipolarDepthOptions& options) {
  checkInputs(camera, chains, options);
  checkImage(keyframe_image, camera, "keyframe_image");
  std::vector<ReferenceGeometry> geometries;
  for (std::size_t r = 0; r < references.size(); ++r) {
    checkImage(references[r].image, camera, "reference image");
    geometries.push_back(referenceGeometry(static_cast<int>(r), keyframe_cam_from_world,
                                           references[r].cam_from_world, camera, options));
  }
  const DepthSearcher searcher(keyframe_image, references, std::move(geometries), camera, options);
  ChainDepths result;
  result.chains.resize(chains.size());
  // Several runs a thread, taken as the threads come free: a thread may share its core with
  // other work (the pipeline's image stage ahead), and a fixed split would wait for it.
  constexpr std::size_t kRunsPerThread = 8;
  const std::vector<std::size_t> first =
      splitByPixels(chains, kRunsPerThread * static_cast<std::size_t>(options.num_threads));
  const int runs = static_cast<int>(first.size()) - 1;
  std::vector<DepthCounts> counts(options.num_threads);
  std::vector<std::optional<DepthSearcher>> own(options.num_threads);  // Shares the images.
  std::vector<std::vector<RawDepth>> raw(options.num_threads);
  forEachInParallel(options.num_threads, runs, 1, [&](int t, int run) {
    if (!own[t]) own[t].emplace(searcher);  // Its own scratch buffers.
    for (std::size_t c = first[run]; c < first[run + 1]; ++c) {
      const EdgeChain& chain = chains[c];
      const int n = static_cast<int>(chain.pixels.size());
      raw[t].assign(n, RawDepth());
      for (int i = 0; i < n; i += options.pixel_step) {
        raw[t][i] = own[t]->search(chain.pixels[i], chain.normals[i]);
      }
      std::vector<PixelDepth>& out = result.chains[c];
      out.resize(n);
      for (int i = 0; i < n; ++i) {
        out[i] = smoothPixel(raw[t], i, chain.closed, options);
        ++counts[t].by_status[static_cast<int>(out[i].status)];
      }
    }
  });
  for (const DepthCounts& part : counts) {
    for (int s = 0; s < kNumDepthStatuses; ++s) result.counts.by_status[s] += part.by_status[s];
  }
  return result;
}

}  // namespace curvesfm
