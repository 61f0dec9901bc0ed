#include "frontend/image/correspondence_checks.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/angles.h"
#include "core/check.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

// Image tangents shorter than this (px per unit t) give no usable normal: the segment is seen
// end-on, and its band shrinks to the sample itself.
constexpr double kMinImageTangent = 1e-9;
// Mirrors CurveReprojectionFactor::kMaxSamples, so a check samples no finer than BA can.
constexpr int kMaxSamples = 65;
constexpr int kMaxHalfWidth = 50;
// Neighbouring pixels of an 8-connected edge are 1 to sqrt(2) px apart, so each stands for up to
// sqrt(2) px of edge.
constexpr double kEdgePieceHalfLength = 0.5 * M_SQRT2;

// ------------------------------------------------------------------------------------------------
// Options.

// ------------------------------------------------------------------------------------------------
// Sampling.

double sampleParameter(int k, int num_samples) {
  return static_cast<double>(k) / static_cast<double>(num_samples - 1);
}

// One sample of the segment seen from the new camera.
struct CameraSample {
  Eigen::Vector3d point_in_cam;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
  bool projected = false;  // In front of the camera (the pixel may still be off the image).
};

class SegmentProjector {
 public:
  SegmentProjector(const BezierSegmentParams& segment, const Pose3& cam_from_world,
                   const Camera* camera)
      : evaluator_(segment),
        R_(cam_from_world.rotationMatrix()),
        t_(cam_from_world.translation()),
        camera_(camera) {}

  // Sample at t; with `image_normal`, also the unit normal of the projected curve there (zero if
  // the curve is seen end-on or the sample does not project).
  CameraSample sample(double t, Eigen::Vector2d* image_normal = nullptr) const {
    CameraSample out;
    out.point_in_cam = R_ * evaluator_.evaluate(bernsteinWeights(t)) + t_;
    if (camera_ == nullptr) return out;
    Matrix23d d_pixel_d_point;
    out.projected = camera_->project(out.point_in_cam, &out.pixel, &d_pixel_d_point);
    if (image_normal != nullptr) {
      const Eigen::Vector2d tangent =
          d_pixel_d_point * (R_ * evaluator_.evaluate(bernsteinDerivativeWeights(t)));
      const double length = tangent.norm();
      *image_normal = (out.projected && length > kMinImageTangent)
                          ? Eigen::Vector2d(-tangent.y() / length, tangent.x() / length)
                          : Eigen::Vector2d::Zero();
    }
    return out;
  }

 private:
  SegmentEvaluator evaluator_;
  Eigen::Matrix3d R_;
  Eigen::Vector3d t_;
  const Camera* camera_;
};

// ------------------------------------------------------------------------------------------------
// Colour.

struct Hsv {
  double hue_deg = 0.0;
  double saturation = 0.0;
  double value = 0.0;
};

// OpenCV's floating-point BGR -> HSV formulas (cv::cvtColor, COLOR_BGR2HSV on [0, 1] input).
Hsv bgrToHsv(const cv::Vec3b& bgr) {
  const double b = bgr[0] / 255.0;
  const double g = bgr[1] / 255.0;
  const double r = bgr[2] / 255.0;
  const double max = std::max({r, g, b});
  const double delta = max - std::min({r, g, b});
  Hsv hsv;
  hsv.value = max;
  if (delta <= 0.0) return hsv;
  hsv.saturation = delta / max;
  if (max == r) {
    hsv.hue_deg = 60.0 * (g - b) / delta;
  } else if (max == g) {
    hsv.hue_deg = 120.0 + 60.0 * (b - r) / delta;
  } else {
    hsv.hue_deg = 240.0 + 60.0 * (r - g) / delta;
  }
  if (hsv.hue_deg < 0.0) hsv.hue_deg += 360.0;
  return hsv;
}

// Hue is averaged as saturation-weighted unit vectors: an arithmetic mean would put the mean of
// 350 and 10 degrees at cyan, and grey pixels carry no hue.
class HsvAccumulator {
 public:
  void add(const cv::Vec3b& bgr) {
    const Hsv hsv = bgrToHsv(bgr);
    const double angle = hsv.hue_deg / kRadToDeg;
    hue_x_ += hsv.saturation * std::cos(angle);
    hue_y_ += hsv.saturation * std::sin(angle);
    saturation_ += hsv.saturation;
    value_ += hsv.value;
    ++count_;
  }

  HsvAppearance mean() const {
    HsvAppearance out;
    out.num_pixels = count_;
    if (count_ == 0) return out;
    out.saturation = saturation_ / count_;
    out.value = value_ / count_;
    if (hue_x_ != 0.0 || hue_y_ != 0.0) {
      out.hue_deg = std::atan2(hue_y_, hue_x_) * kRadToDeg;
      if (out.hue_deg < 0.0) out.hue_deg += 360.0;
      if (out.hue_deg >= 360.0) out.hue_deg = 0.0;
    }
    return out;
  }

 private:
  double hue_x_ = 0.0;
  double hue_y_ = 0.0;
  double saturation_ = 0.0;
  double value_ = 0.0;
  int count_ = 0;
};

// Adds the band of 2w + 1 pixels centred on `centre` along `normal` (a zero normal adds the
// centre pixel only).
void addBand(const cv::Mat& image_bgr, const Eigen::Vector2d& centre, const Eigen::Vector2d& normal,
             int half_width, HsvAccumulator* accumulator) {
  const int reach = normal.isZero() ? 0 : half_width;
  for (int offset = -reach; offset <= reach; ++offset) {
    const Eigen::Vector2d pixel = centre + offset * normal;
    const int column = static_cast<int>(std::lround(pixel.x()));
    const int row = static_cast<int>(std::lround(pixel.y()));
    if (column < 0 || row < 0 || column >= image_bgr.cols || row >= image_bgr.rows) continue;
    accumulator->add(image_bgr.at<cv::Vec3b>(row, column));
  }
}

// The distance from `pixel` to the piece of edge line that `edge` stands for: through its sub-pixel
// position, across its gradient, kEdgePieceHalfLength to either side. The plain distance to the
// edge point would add up to half a pixel of quantisation along a continuous edge; the distance
// to the infinite line would call a sample beyond the end of an edge a perfect match.
double distanceToEdgePiece(const Eigen::Vector2d& pixel, const EdgePixel& edge) {
  const Eigen::Vector2d offset = pixel - edge.subpixel.cast<double>();
  const Eigen::Vector2d normal = edge.normal.cast<double>();
  const double across = offset.dot(normal);
  const double along = (offset - across * normal).norm();
  return std::hypot(across, std::max(0.0, along - kEdgePieceHalfLength));
}

double degrees(double radians) { return radians * kRadToDeg; }

}  // namespace

void CorrespondenceOptions::validate() const {
  const OptionCheck require("CorrespondenceOptions");
  require(samples_per_segment >= 2 && samples_per_segment <= kMaxSamples, "samples_per_segment",
          samples_per_segment, "in [2, 65]");
  require(std::isfinite(min_depth) && min_depth >= Camera::kMinDepth, "min_depth", min_depth,
          "must be finite and >= Camera::kMinDepth (1e-6)");
  require(std::isfinite(max_mean_edge_distance_px) && max_mean_edge_distance_px > 0.0,
          "max_mean_edge_distance_px", max_mean_edge_distance_px, "must be finite and > 0");
  require(appearance_half_width_px >= 0 && appearance_half_width_px <= kMaxHalfWidth,
          "appearance_half_width_px", appearance_half_width_px, "in [0, 50]");
  require(std::isfinite(hue_weight) && hue_weight >= 0.0, "hue_weight", hue_weight,
          "must be finite and >= 0");
  require(std::isfinite(max_appearance_error) && max_appearance_error > 0.0, "max_appearance_error",
          max_appearance_error, "must be finite and > 0");
  require(max_viewing_angle_deg > 0.0 && max_viewing_angle_deg <= 180.0, "max_viewing_angle_deg",
          max_viewing_angle_deg, "in (0, 180]");
}

CheckResult checkPositiveDepth(const BezierSegmentParams& segment, const Pose3& cam_from_world,
                               const CorrespondenceOptions& options) {
  options.validate();
  const SegmentProjector projector(segment, cam_from_world, nullptr);
  double min_depth = std::numeric_limits<double>::infinity();
  for (int k = 0; k < options.samples_per_segment; ++k) {
    const double t = sampleParameter(k, options.samples_per_segment);
    min_depth = std::min(min_depth, projector.sample(t).point_in_cam.z());
  }
  // Written as a positive comparison so that a NaN depth fails.
  return {min_depth >= options.min_depth, min_depth};
}

CheckResult checkEdgeDistance(const BezierSegmentParams& segment, const Pose3& cam_from_world,
                              const Camera& camera, const NearestEdgeField& field,
                              const CorrespondenceOptions& options) {
  options.validate();
  const SegmentProjector projector(segment, cam_from_world, &camera);
  const double cap = field.maxDistance();
  double sum = 0.0;
  for (int k = 0; k < options.samples_per_segment; ++k) {
    const CameraSample sample = projector.sample(sampleParameter(k, options.samples_per_segment));
    const EdgePixel* edge =
        sample.projected ? field.nearest(sample.pixel.x(), sample.pixel.y()) : nullptr;
    sum += edge == nullptr ? cap : std::min(cap, distanceToEdgePiece(sample.pixel, *edge));
  }
  const double mean = sum / options.samples_per_segment;
  return {mean <= options.max_mean_edge_distance_px, mean};
}

Eigen::Vector3d viewingDirection(const BezierSegmentParams& segment,
                                 const Eigen::Vector3d& camera_centre_in_world) {
  const Eigen::Vector3d ray =
      evaluateSegment(segment, bernsteinWeights(0.5)) - camera_centre_in_world;
  const double length = ray.norm();
  return length > 0.0 ? Eigen::Vector3d(ray / length) : Eigen::Vector3d::Zero();
}

void ViewingDirectionMean::add(const Eigen::Vector3d& direction_in_world) {
  const double length = direction_in_world.norm();
  if (!(length > 0.0)) return;
  sum_ += direction_in_world / length;
  ++count_;
}

Eigen::Vector3d ViewingDirectionMean::mean() const {
  const double length = sum_.norm();
  return length > 0.0 ? Eigen::Vector3d(sum_ / length) : Eigen::Vector3d::Zero();
}

CheckResult checkViewingDirection(const BezierSegmentParams& segment,
                                  const Eigen::Vector3d& camera_centre_in_world,
                                  const Eigen::Vector3d& mean_direction_in_world,
                                  const CorrespondenceOptions& options) {
  options.validate();
  const double mean_length = mean_direction_in_world.norm();
  if (!(mean_length > 0.0)) return {true, 0.0};
  const Eigen::Vector3d direction = viewingDirection(segment, camera_centre_in_world);
  // A camera at the segment centre has no viewing direction at all.
  if (direction.isZero()) return {false, 180.0};
  // atan2 of |cross| and dot stays accurate near 0 and 180 degrees, unlike acos.
  const Eigen::Vector3d mean = mean_direction_in_world / mean_length;
  const double angle = degrees(std::atan2(direction.cross(mean).norm(), direction.dot(mean)));
  return {angle <= options.max_viewing_angle_deg, angle};
}

HsvAppearance appearanceOf(const BezierSegmentParams& segment, const Pose3& cam_from_world,
                           const Camera& camera, const cv::Mat& image_bgr,
                           const CorrespondenceOptions& options, const NearestEdgeField* field) {
  options.validate();
  CURVESFM_CHECK(image_bgr.type() == CV_8UC3)
      << "appearanceOf needs a CV_8UC3 BGR image, got type " << image_bgr.type();
  CURVESFM_CHECK(image_bgr.cols == camera.width() && image_bgr.rows == camera.height())
      << "image " << image_bgr.cols << "x" << image_bgr.rows << " does not match the camera's "
      << camera.width() << "x" << camera.height();
  const SegmentProjector projector(segment, cam_from_world, &camera);
  HsvAccumulator accumulator;
  for (int k = 0; k < options.samples_per_segment; ++k) {
    Eigen::Vector2d normal;
    const CameraSample sample =
        projector.sample(sampleParameter(k, options.samples_per_segment), &normal);
    if (!sample.projected || !camera.isInImage(sample.pixel)) continue;
    Eigen::Vector2d centre = sample.pixel;
    const EdgePixel* edge = field == nullptr ? nullptr : field->nearest(centre.x(), centre.y());
    if (edge != nullptr) {
      centre = edge->subpixel.cast<double>();
      normal = edge->normal.cast<double>();
    }
    addBand(image_bgr, centre, normal, options.appearance_half_width_px, &accumulator);
  }
  return accumulator.mean();
}

double appearanceError(const HsvAppearance& a, const HsvAppearance& b, double hue_weight) {
  const double hue_gap = std::fabs(a.hue_deg - b.hue_deg);
  const double hue_difference = std::min(hue_gap, 360.0 - hue_gap) / 180.0;
  return hue_weight * 0.5 * (a.saturation + b.saturation) * hue_difference +
         std::fabs(a.value - b.value);
}

CheckResult checkAppearance(const HsvAppearance& reference, const HsvAppearance& candidate,
                            const CorrespondenceOptions& options) {
  options.validate();
  if (!reference.valid() || !candidate.valid()) {
    return {false, std::numeric_limits<double>::infinity()};
  }
  const double error = appearanceError(reference, candidate, options.hue_weight);
  return {error <= options.max_appearance_error, error};
}

CorrespondenceVerdict registerSegment(const BezierSegmentParams& segment, const KeyframeView& view,
                                      const SegmentHistory& history,
                                      const CorrespondenceOptions& options) {
  options.validate();
  CorrespondenceVerdict verdict;
  const auto fail = [&verdict](CorrespondenceCheck check) {
    verdict.failed_check = check;
    return verdict;
  };

  const CheckResult depth = checkPositiveDepth(segment, view.cam_from_world, options);
  verdict.min_depth = depth.value;
  if (!depth.passed) return fail(CorrespondenceCheck::kDepth);

  const CheckResult distance =
      checkEdgeDistance(segment, view.cam_from_world, view.camera, view.field, options);
  verdict.mean_edge_distance_px = distance.value;
  if (!distance.passed) return fail(CorrespondenceCheck::kEdgeDistance);

  const Eigen::Vector3d camera_centre = view.cam_from_world.inverseTranslation();
  verdict.viewing_direction_in_world = viewingDirection(segment, camera_centre);
  const CheckResult angle = checkViewingDirection(segment, camera_centre,
                                                  history.mean_viewing_direction_in_world, options);
  verdict.viewing_angle_deg = angle.value;
  if (!angle.passed) return fail(CorrespondenceCheck::kViewingDirection);

  verdict.appearance =
      appearanceOf(segment, view.cam_from_world, view.camera, view.image_bgr, options, &view.field);
  const CheckResult appearance =
      checkAppearance(history.reference_appearance, verdict.appearance, options);
  verdict.appearance_error = appearance.value;
  if (!appearance.passed) return fail(CorrespondenceCheck::kAppearance);

  verdict.registered = true;
  return verdict;
}

}  // namespace curvesfm
