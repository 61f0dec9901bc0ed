#include "frontend/image/curve_extension.h"

#include <cmath>

#include "core/angles.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

std::optional<Eigen::Vector2d> projectWorld(const Eigen::Vector3d& point_in_world,
                                            const Pose3& cam_from_world, const Camera& camera) {
  Eigen::Vector2d pixel;
  if (!camera.project(cam_from_world * point_in_world, &pixel)) return std::nullopt;
  return pixel;
}

// An end of a curve in the image.
struct ImageEnd {
  Eigen::Vector2d pixel;
  Eigen::Vector2d outward;  // Unit direction in which the projection leaves the curve there.
};

// The direction comes from the last tenth of the end segment, so it follows the projection
// (perspective and distortion included). Nothing when either point is behind the camera or both
// project to one pixel.
std::optional<ImageEnd> imageEnd(const PolyBezier& curve, CurveEnd end, const Pose3& cam_from_world,
                                 const Camera& camera) {
  const double inner_t = end == CurveEnd::kFront ? 0.1 : 0.9;
  const std::optional<Eigen::Vector2d> pixel =
      projectWorld(endPoint(curve, end), cam_from_world, camera);
  const std::optional<Eigen::Vector2d> inner =
      projectWorld(curve.evaluate(endSegment(curve, end), inner_t), cam_from_world, camera);
  if (!pixel || !inner) return std::nullopt;
  const Eigen::Vector2d step = *pixel - *inner;
  if (!(step.norm() > 1e-9)) return std::nullopt;
  return ImageEnd{*pixel, step.normalized()};
}

// The pixel gap between the new curve's end `new_end` (seen as `seen`) and `open` if the two join
// smoothly by every check of `options`; nothing if not.
std::optional<double> smoothGap(const PolyBezier& candidate, CurveEnd new_end, const ImageEnd& seen,
                                const OpenEnd& open, const CurveExtensionOptions& options) {
  const Eigen::Vector2d gap = seen.pixel - open.pixel;
  const double along = gap.dot(open.pixel_outward);
  const double lateral = (gap - along * open.pixel_outward).norm();
  if (gap.norm() > options.max_gap_px || lateral > options.max_lateral_px ||
      along < -options.max_lateral_px) {
    return std::nullopt;
  }
  // The new curve leaves the join against its own outward direction at that end.
  if (-open.pixel_outward.dot(seen.outward) < std::cos(options.max_angle_deg * kDegToRad)) {
    return std::nullopt;
  }
  const double gap_3d = (endPoint(candidate, new_end) - open.point).norm();
  if (gap_3d > options.max_relative_depth_gap * open.depth) return std::nullopt;
  return gap.norm();
}

}  // namespace

void CurveExtensionOptions::validate() const {
  const OptionCheck require("CurveExtensionOptions");
  require(std::isfinite(max_gap_px) && max_gap_px > 0.0, "max_gap_px", max_gap_px,
          "must be finite and > 0");
  require(std::isfinite(max_lateral_px) && max_lateral_px >= 0.0, "max_lateral_px", max_lateral_px,
          "must be finite and >= 0");
  require(std::isfinite(max_relative_depth_gap) && max_relative_depth_gap > 0.0,
          "max_relative_depth_gap", max_relative_depth_gap, "must be finite and > 0");
  require(max_angle_deg > 0.0 && max_angle_deg <= 180.0, "max_angle_deg", max_angle_deg,
          "in (0, 180]");
}

std::optional<OpenEnd> openEnd(int id, const PolyBezier& curve, CurveEnd end,
                               const Pose3& cam_from_world, const Camera& camera) {
  const std::optional<ImageEnd> seen = imageEnd(curve, end, cam_from_world, camera);
  if (!seen) return std::nullopt;
  const double depth = (cam_from_world * endPoint(curve, end)).z();
  return OpenEnd{id, end, endPoint(curve, end), depth, seen->pixel, seen->outward};
}

std::optional<CurveJoin> findJoin(const PolyBezier& candidate, const std::vector<OpenEnd>& ends,
                                  const Pose3& cam_from_world, const Camera& camera,
                                  const CurveExtensionOptions& options) {
  std::optional<CurveJoin> best;
  for (const CurveEnd new_end : {CurveEnd::kFront, CurveEnd::kBack}) {
    const std::optional<ImageEnd> seen = imageEnd(candidate, new_end, cam_from_world, camera);
    if (!seen) continue;
    for (std::size_t i = 0; i < ends.size(); ++i) {
      const std::optional<double> gap = smoothGap(candidate, new_end, *seen, ends[i], options);
      if (gap && (!best || *gap < best->gap_px)) {
        best = CurveJoin{static_cast<int>(i), new_end, *gap};
      }
    }
  }
  return best;
}

ExtendedCurve extendCurve(const PolyBezier& existing, CurveEnd existing_end,
                          const PolyBezier& addition, CurveEnd addition_end) {
  const int m = existing.numSegments();
  const int n = addition.numSegments();
  // Orient the addition to run away from the join: it follows the existing curve at the back,
  // precedes it at the front.
  const CurveEnd touching_end_needed =
      existing_end == CurveEnd::kBack ? CurveEnd::kFront : CurveEnd::kBack;
  const bool keep_order = addition_end == touching_end_needed;
  const PolyBezier oriented = keep_order ? addition : reversed(addition);
  ExtendedCurve result{existing, {}};
  if (existing_end == CurveEnd::kBack) {
    result.curve = concatenate(existing, oriented);
  } else {
    PolyBezier head = oriented;
    head.setPoint(n, existing.points().front());
    head.setDirection(n, existing.directions().front());
    result.curve = concatenate(head, existing);
  }
  const int base = existing_end == CurveEnd::kBack ? m : 0;
  for (int i = 0; i < n; ++i) result.added_segments.push_back(base + (keep_order ? i : n - 1 - i));
  return result;
}

}  // namespace curvesfm
