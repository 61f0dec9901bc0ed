#include "factors/curve_reprojection_factor.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/check.h"

namespace curvesfm {
namespace {

enum class SampleOutcome {
  kOnField,
  kBehindCamera,
  kOutsideImage,
  kBeyondReach,
  kWrongOrientation
};

BezierSegmentParams segmentParams(const Eigen::Vector3d& q0, const Eigen::Vector3d& q1,
                                  const Direction& v0, const Direction& v1, double d1, double d2) {
  BezierSegmentParams params;
  params.q0 = q0;
  params.q1 = q1;
  params.v0 = v0;
  params.v1 = v1;
  params.d1 = d1;
  params.d2 = d2;
  return params;
}

}  // namespace

CurveSampling::CurveSampling(int num_samples, bool use_subpixel_edges, double max_normal_angle_deg,
                             const EdgeBlending& blending, double border_margin_px)
    : point_weights(4, num_samples),
      tangent_weights(4, num_samples),
      use_subpixel_edges(use_subpixel_edges),
      max_normal_angle_deg(max_normal_angle_deg),
      sin_max_normal_angle(std::sin(max_normal_angle_deg * M_PI / 180.0)),
      blending(blending),
      border_margin_px(border_margin_px),
      blend_min_normal_cosine(std::cos(blending.max_normal_angle_deg * M_PI / 180.0)) {
  CURVESFM_CHECK(num_samples >= 2 && num_samples <= CurveReprojectionFactor::kMaxSamples)
      << "CurveSampling: " << num_samples << " samples, expected 2.."
      << CurveReprojectionFactor::kMaxSamples;
  CURVESFM_CHECK(max_normal_angle_deg > 0.0 && max_normal_angle_deg <= 90.0)
      << "CurveSampling: max_normal_angle_deg " << max_normal_angle_deg << ", expected (0, 90]";
  CURVESFM_CHECK(blending.max_line_offset_px >= 0.0)
      << "CurveSampling: blending.max_line_offset_px " << blending.max_line_offset_px
      << ", expected >= 0";
  CURVESFM_CHECK(blending.max_normal_angle_deg >= 0.0 && blending.max_normal_angle_deg <= 90.0)
      << "CurveSampling: blending.max_normal_angle_deg " << blending.max_normal_angle_deg
      << ", expected [0, 90]";
  CURVESFM_CHECK(border_margin_px >= 0.0)
      << "CurveSampling: border_margin_px " << border_margin_px << ", expected >= 0";
  point_weights = uniformBernsteinWeights(num_samples);
  for (int k = 0; k < num_samples; ++k) {
    const double t = static_cast<double>(k) / (num_samples - 1);
    tangent_weights.col(k) = bernsteinDerivativeWeights(t);
  }
}

CurveSampleCounts& CurveSampleCounts::operator+=(const CurveSampleCounts& other) {
  on_field += other.on_field;
  behind_camera += other.behind_camera;
  outside_image += other.outside_image;
  beyond_reach += other.beyond_reach;
  wrong_orientation += other.wrong_orientation;
  return *this;
}

CurveReprojectionFactor::CurveReprojectionFactor(Key pose_key, const SegmentKeys& segment,
                                                 std::shared_ptr<const NearestEdgeField> field,
                                                 std::shared_ptr<const Camera> camera,
                                                 std::shared_ptr<const CurveSampling> sampling,
                                                 NoiseModel noise_model)
    : Base({pose_key, segment.q0, segment.q1, segment.v0, segment.v1, segment.d1, segment.d2},
           std::move(noise_model), sampling ? sampling->numSamples() : 0),
      field_(std::move(field)),
      camera_(std::move(camera)),
      sampling_(std::move(sampling)) {
  CURVESFM_CHECK(field_ && camera_ && sampling_)
      << "CurveReprojectionFactor needs a field, a camera and a sampling";
}

// Per-sample intermediate results of one evaluation, on the stack.
struct CurveReprojectionFactor::SampleBatch {
  std::array<Eigen::Vector3d, kMaxSamples> in_cam;  // R * B(t_k) + t
  std::array<Eigen::Vector2d, kMaxSamples> pixel;
  std::array<Matrix23d, kMaxSamples> d_pixel_d_cam;
  std::array<const EdgePixel*, kMaxSamples> edge;  // null unless kOnField
  std::array<SampleOutcome, kMaxSamples> outcome;
  std::array<double, kMaxSamples> residual;           // r_k (px), where kOnField
  std::array<Eigen::Vector2d, kMaxSamples> gradient;  // dr_k / d pixel, where kOnField
};

Eigen::Vector2d CurveReprojectionFactor::edgePosition(const EdgePixel& edge) const {
  return (sampling_->use_subpixel_edges ? edge.subpixel : edge.pixel).cast<double>();
}

void CurveReprojectionFactor::measureSample(const Eigen::Vector2d& pixel, const EdgePixel& nearest,
                                            double* residual, Eigen::Vector2d* gradient) const {
  const Eigen::Vector2d normal = nearest.normal.cast<double>();
  *residual = (pixel - edgePosition(nearest)).dot(normal);
  *gradient = normal;
  if (!sampling_->blending.enabled) return;

  // Corners (x0, y0), (x0 + 1, y0), (x0, y0 + 1), (x0 + 1, y0 + 1): pixel centres at integers.
  const double x0 = std::floor(pixel.x()), y0 = std::floor(pixel.y());
  const std::array<const EdgePixel*, 4> corner = {
      field_->nearest(x0, y0), field_->nearest(x0 + 1.0, y0), field_->nearest(x0, y0 + 1.0),
      field_->nearest(x0 + 1.0, y0 + 1.0)};
  const double fx = pixel.x() - x0, fy = pixel.y() - y0;
  const std::array<double, 4> weight = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
  const std::array<Eigen::Vector2d, 4> d_weight = {
      Eigen::Vector2d(-(1 - fy), -(1 - fx)), Eigen::Vector2d(1 - fy, -fx),
      Eigen::Vector2d(-fy, 1 - fx), Eigen::Vector2d(fy, fx)};

  // The corners split into groups that lie on one edge; the blend runs over the heaviest group
  // with its weights renormalised. A group keeps its members however the sample moves within
  // the cell, so the blend changes continuously; it jumps only where another group becomes the
  // heavier, near where the sample's nearest edge becomes another edge anyway. Blending across
  // groups would make a false zero between two edges.
  std::array<unsigned, 4> group{};  // Bit j of group[i]: corners i and j lie on one edge.
  for (int i = 0; i < 4; ++i) {
    if (!corner[i]) continue;
    group[i] |= 1u << i;
    for (int j = i + 1; j < 4; ++j) {
      if (corner[j] && (corner[j] == corner[i] || sameEdge(*corner[i], *corner[j]))) {
        group[i] |= 1u << j;
        group[j] |= 1u << i;
      }
    }
  }
  int anchor = -1;
  double anchor_weight = 0.0;
  for (int i = 0; i < 4; ++i) {
    double w = 0.0;
    for (int j = 0; j < 4; ++j) {
      if (group[i] & (1u << j)) w += weight[j];
    }
    if (group[i] && w > anchor_weight) {
      anchor = i;
      anchor_weight = w;
    }
  }
  // No corner in the image and within reach (a sample past the border): the nearest edge alone.
  if (anchor < 0) return;
  const Eigen::Vector2d anchor_normal = corner[anchor]->normal.cast<double>();
  double blended = 0.0, total = 0.0;
  Eigen::Vector2d d_blended = Eigen::Vector2d::Zero(), d_total = Eigen::Vector2d::Zero();
  for (int i = 0; i < 4; ++i) {
    if (!(group[anchor] & (1u << i))) continue;
    // One sign for the group: a normal's sign is the contrast's, not the edge's.
    Eigen::Vector2d n = corner[i]->normal.cast<double>();
    if (n.dot(anchor_normal) < 0.0) n = -n;
    const double r = (pixel - edgePosition(*corner[i])).dot(n);
    blended += weight[i] * r;
    d_blended += weight[i] * n + r * d_weight[i];
    total += weight[i];
    d_total += d_weight[i];
  }
  // total >= the largest corner weight >= 1/4.
  *residual = blended / total;
  *gradient = (d_blended - *residual * d_total) / total;
}

const EdgePixel* CurveReprojectionFactor::nearestPastBorder(const Eigen::Vector2d& pixel) const {
  const double margin = sampling_->border_margin_px;
  if (margin <= 0.0) return nullptr;
  const double right = field_->width() - 1.0, bottom = field_->height() - 1.0;
  const double x = std::clamp(pixel.x(), 0.0, right), y = std::clamp(pixel.y(), 0.0, bottom);
  if ((pixel - Eigen::Vector2d(x, y)).norm() > margin) return nullptr;
  return field_->nearest(x, y);
}

bool CurveReprojectionFactor::sameEdge(const EdgePixel& a, const EdgePixel& b) const {
  // Each within max_line_offset_px of the other's line, normals within max_normal_angle_deg
  // either way; symmetric, so the groups do not depend on which corner asks.
  const Eigen::Vector2d na = a.normal.cast<double>(), nb = b.normal.cast<double>();
  const Eigen::Vector2d offset = edgePosition(b) - edgePosition(a);
  const double max_offset = sampling_->blending.max_line_offset_px;
  return std::abs(offset.dot(na)) <= max_offset && std::abs(offset.dot(nb)) <= max_offset &&
         std::abs(na.dot(nb)) >= sampling_->blend_min_normal_cosine;
}

void CurveReprojectionFactor::locateSamples(const Pose3& cam_from_world, const Eigen::Matrix3d& R,
                                            const SegmentEvaluator& segment, bool with_jacobians,
                                            SampleBatch* batch) const {
  // Three passes: projections, then field look-ups, then the orientation check. The look-ups
  // are independent cache misses into a field of about a megabyte per keyframe; in a loop of
  // their own the CPU overlaps them instead of waiting for each in turn (this halves the cost
  // per sample, see curve_factor_bench).
  const int num_samples = numSamples();
  const bool check_orientation = sampling_->sin_max_normal_angle < 1.0;
  SampleBatch& b = *batch;
  for (int k = 0; k < num_samples; ++k) {
    b.in_cam[k] =
        R * segment.evaluate(sampling_->point_weights.col(k)) + cam_from_world.translation();
    const bool in_front =
        camera_->project(b.in_cam[k], &b.pixel[k],
                         with_jacobians || check_orientation ? &b.d_pixel_d_cam[k] : nullptr);
    b.outcome[k] = in_front ? SampleOutcome::kOnField : SampleOutcome::kBehindCamera;
    if (in_front) field_->prefetch(b.pixel[k][0], b.pixel[k][1]);
  }
  for (int k = 0; k < num_samples; ++k) {
    b.edge[k] = b.outcome[k] == SampleOutcome::kOnField
                    ? field_->nearest(b.pixel[k][0], b.pixel[k][1])
                    : nullptr;
    __builtin_prefetch(b.edge[k]);
  }
  for (int k = 0; k < num_samples; ++k) {
    if (b.outcome[k] != SampleOutcome::kOnField) continue;
    if (!b.edge[k] && !field_->contains(b.pixel[k][0], b.pixel[k][1])) {
      b.edge[k] = nearestPastBorder(b.pixel[k]);
      if (!b.edge[k]) {
        b.outcome[k] = SampleOutcome::kOutsideImage;
        continue;
      }
    }
    if (!b.edge[k]) {
      b.outcome[k] = SampleOutcome::kBeyondReach;
      continue;
    }
    if (check_orientation) checkOrientation(k, R, segment, &b);
    if (b.outcome[k] == SampleOutcome::kOnField) {
      measureSample(b.pixel[k], *b.edge[k], &b.residual[k], &b.gradient[k]);
    }
  }
}

void CurveReprojectionFactor::checkOrientation(int k, const Eigen::Matrix3d& R,
                                               const SegmentEvaluator& segment,
                                               SampleBatch* batch) const {
  // The edge normal must be (nearly) normal to the projected tangent t: |g . t| <= sin * |t|.
  SampleBatch& b = *batch;
  const Eigen::Vector2d tangent =
      b.d_pixel_d_cam[k] * (R * segment.evaluate(sampling_->tangent_weights.col(k)));
  if (std::abs(b.edge[k]->normal.cast<double>().dot(tangent)) >
      sampling_->sin_max_normal_angle * tangent.norm()) {
    b.outcome[k] = SampleOutcome::kWrongOrientation;
    b.edge[k] = nullptr;
  }
}

CurveReprojectionFactor::Error CurveReprojectionFactor::evaluateError(
    const Pose3& cam_from_world, const Eigen::Vector3d& q0, const Eigen::Vector3d& q1,
    const Direction& v0, const Direction& v1, const double& d1, const double& d2,
    Jacobian<Pose3>* H_pose, Jacobian<Eigen::Vector3d>* H_q0, Jacobian<Eigen::Vector3d>* H_q1,
    Jacobian<Direction>* H_v0, Jacobian<Direction>* H_v1, Jacobian<double>* H_d1,
    Jacobian<double>* H_d2) const {
  const int num_samples = numSamples();
  const bool wants_jacobians = H_pose || H_q0 || H_q1 || H_v0 || H_v1 || H_d1 || H_d2;
  // Sized, not cleared: every row is written below, the rows of capped samples with zeros.
  if (H_pose) H_pose->resize(num_samples, 6);
  if (H_q0) H_q0->resize(num_samples, 3);
  if (H_q1) H_q1->resize(num_samples, 3);
  if (H_v0) H_v0->resize(num_samples, 2);
  if (H_v1) H_v1->resize(num_samples, 2);
  if (H_d1) H_d1->resize(num_samples);
  if (H_d2) H_d2->resize(num_samples);

  const Eigen::Matrix3d R = cam_from_world.rotationMatrix();
  const SegmentEvaluator segment(segmentParams(q0, q1, v0, v1, d1, d2));
  SampleBatch batch;
  locateSamples(cam_from_world, R, segment, wants_jacobians, &batch);

  Error error(num_samples);
  SegmentJacobians d_B;
  for (int k = 0; k < num_samples; ++k) {
    const EdgePixel* edge = batch.edge[k];
    if (!edge) {
      error[k] = cappedResidual();
      if (H_pose) H_pose->row(k).setZero();
      if (H_q0) H_q0->row(k).setZero();
      if (H_q1) H_q1->row(k).setZero();
      if (H_v0) H_v0->row(k).setZero();
      if (H_v1) H_v1->row(k).setZero();
      if (H_d1) (*H_d1)[k] = 0.0;
      if (H_d2) (*H_d2)[k] = 0.0;
      continue;
    }
    error[k] = batch.residual[k];
    if (!wants_jacobians) continue;

    segment.evaluate(sampling_->point_weights.col(k), &d_B);
    const Eigen::RowVector3d d_r_d_cam = batch.gradient[k].transpose() * batch.d_pixel_d_cam[k];
    const Eigen::RowVector3d d_r_d_point = d_r_d_cam * R;
    if (H_pose) {
      // d(exp(w) x + u)/d[w; u] = [-[x]x, I] for x = R p + t, and -a^T [b]x = (b x a)^T.
      H_pose->row(k).head<3>() = batch.in_cam[k].cross(d_r_d_cam.transpose()).transpose();
      H_pose->row(k).tail<3>() = d_r_d_cam;
    }
    if (H_q0) H_q0->row(k) = d_B.scale_q0 * d_r_d_point;
    if (H_q1) H_q1->row(k) = d_B.scale_q1 * d_r_d_point;
    if (H_v0) H_v0->row(k).noalias() = d_r_d_point * d_B.H_v0;
    if (H_v1) H_v1->row(k).noalias() = d_r_d_point * d_B.H_v1;
    if (H_d1) (*H_d1)[k] = d_r_d_point.dot(d_B.H_d1);
    if (H_d2) (*H_d2)[k] = d_r_d_point.dot(d_B.H_d2);
  }
  return error;
}

CurveSampleCounts CurveReprojectionFactor::sampleCounts(const Values& values) const {
  const Pose3& cam_from_world = values.at<Pose3>(keys()[0]);
  const SegmentEvaluator segment(
      segmentParams(values.at<Eigen::Vector3d>(keys()[1]), values.at<Eigen::Vector3d>(keys()[2]),
                    values.at<Direction>(keys()[3]), values.at<Direction>(keys()[4]),
                    values.at<double>(keys()[5]), values.at<double>(keys()[6])));
  SampleBatch batch;
  locateSamples(cam_from_world, cam_from_world.rotationMatrix(), segment, false, &batch);
  CurveSampleCounts counts;
  for (int k = 0; k < numSamples(); ++k) {
    switch (batch.outcome[k]) {
      case SampleOutcome::kOnField:
        ++counts.on_field;
        break;
      case SampleOutcome::kBehindCamera:
        ++counts.behind_camera;
        break;
      case SampleOutcome::kOutsideImage:
        ++counts.outside_image;
        break;
      case SampleOutcome::kBeyondReach:
        ++counts.beyond_reach;
        break;
      case SampleOutcome::kWrongOrientation:
        ++counts.wrong_orientation;
        break;
    }
  }
  return counts;
}

}  // namespace curvesfm
