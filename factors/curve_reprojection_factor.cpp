#include "factors/curve_reprojection_factor.h"

#include <array>

#include "core/bezier.h"
#include "core/check.h"

namespace curvesfm {
namespace {

enum class SampleOutcome { kOnField, kBehindCamera, kOutsideImage, kBeyondReach };

// The nearest edge of one projected sample, or why there is none.
struct SampleHit {
  SampleOutcome outcome = SampleOutcome::kOnField;
  const EdgePixel* edge = nullptr;
};

SampleHit locateSample(const Camera& camera, const NearestEdgeField& field,
                       const Eigen::Vector3d& point_in_cam, Eigen::Vector2d* pixel,
                       Matrix23d* d_pixel_d_cam) {
  if (!camera.project(point_in_cam, pixel, d_pixel_d_cam)) {
    return {SampleOutcome::kBehindCamera, nullptr};
  }
  const EdgePixel* edge = field.nearest((*pixel)[0], (*pixel)[1]);
  if (edge) return {SampleOutcome::kOnField, edge};
  return {field.contains((*pixel)[0], (*pixel)[1]) ? SampleOutcome::kBeyondReach
                                                   : SampleOutcome::kOutsideImage,
          nullptr};
}

BezierSegmentParams segmentParams(const Eigen::Vector3d& q0, const Eigen::Vector3d& q1,
                                  const Direction& v0, const Direction& v1, double d1,
                                  double d2) {
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

CurveSampleCounts& CurveSampleCounts::operator+=(const CurveSampleCounts& other) {
  on_field += other.on_field;
  behind_camera += other.behind_camera;
  outside_image += other.outside_image;
  beyond_reach += other.beyond_reach;
  return *this;
}

CurveReprojectionFactor::CurveReprojectionFactor(
    Key pose_key, const SegmentKeys& segment, std::shared_ptr<const NearestEdgeField> field,
    std::shared_ptr<const Camera> camera, std::shared_ptr<const Eigen::Matrix4Xd> sample_weights,
    bool use_subpixel_edges, NoiseModel noise_model)
    : Base({pose_key, segment.q0, segment.q1, segment.v0, segment.v1, segment.d1, segment.d2},
           std::move(noise_model), sample_weights ? static_cast<int>(sample_weights->cols()) : 0),
      field_(std::move(field)),
      camera_(std::move(camera)),
      weights_(std::move(sample_weights)),
      use_subpixel_edges_(use_subpixel_edges) {
  CURVESFM_CHECK(field_ && camera_ && weights_)
      << "CurveReprojectionFactor needs a field, a camera and sample weights";
  CURVESFM_CHECK(weights_->cols() >= 1 && weights_->cols() <= kMaxSamples)
      << "CurveReprojectionFactor: " << weights_->cols() << " samples, expected 1.."
      << kMaxSamples;
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

  // Three passes: projections, then field look-ups, then residuals and Jacobians. The
  // look-ups are independent cache misses into a field of about a megabyte per keyframe; in a
  // loop of their own the CPU overlaps them instead of waiting for each in turn (this halves
  // the cost per sample, see curve_factor_bench).
  const Eigen::Matrix3d R = cam_from_world.rotationMatrix();
  const SegmentEvaluator segment(segmentParams(q0, q1, v0, v1, d1, d2));
  std::array<Eigen::Vector3d, kMaxSamples> rotated;
  std::array<Eigen::Vector2d, kMaxSamples> pixel;
  std::array<Matrix23d, kMaxSamples> d_pixel_d_cam;
  std::array<bool, kMaxSamples> in_front;
  for (int k = 0; k < num_samples; ++k) {
    rotated[k] = R * segment.evaluate(weights_->col(k));
    in_front[k] = camera_->project(rotated[k] + cam_from_world.translation(), &pixel[k],
                                   wants_jacobians ? &d_pixel_d_cam[k] : nullptr);
  }
  std::array<const EdgePixel*, kMaxSamples> edge;
  for (int k = 0; k < num_samples; ++k) {
    edge[k] = in_front[k] ? field_->nearest(pixel[k][0], pixel[k][1]) : nullptr;
    __builtin_prefetch(edge[k]);
  }

  Error error(num_samples);
  SegmentJacobians d_B;
  for (int k = 0; k < num_samples; ++k) {
    if (!edge[k]) {
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
    const Eigen::Vector2d normal = edge[k]->normal.cast<double>();
    const Eigen::Vector2d edge_position =
        (use_subpixel_edges_ ? edge[k]->subpixel : edge[k]->pixel).cast<double>();
    error[k] = (pixel[k] - edge_position).dot(normal);
    if (!wants_jacobians) continue;

    segment.evaluate(weights_->col(k), &d_B);
    const Eigen::RowVector3d d_r_d_cam = normal.transpose() * d_pixel_d_cam[k];
    const Eigen::RowVector3d d_r_d_point = d_r_d_cam * R;
    if (H_pose) {
      // d(exp(w) R p + t + u)/d[w; u] = [-[R p]x, I], and -a^T [b]x = (b x a)^T.
      H_pose->row(k).head<3>() = rotated[k].cross(d_r_d_cam.transpose()).transpose();
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
  const SegmentEvaluator segment(segmentParams(
      values.at<Eigen::Vector3d>(keys()[1]), values.at<Eigen::Vector3d>(keys()[2]),
      values.at<Direction>(keys()[3]), values.at<Direction>(keys()[4]),
      values.at<double>(keys()[5]), values.at<double>(keys()[6])));
  CurveSampleCounts counts;
  Eigen::Vector2d pixel;
  for (int k = 0; k < numSamples(); ++k) {
    const Eigen::Vector3d point_in_cam = cam_from_world * segment.evaluate(weights_->col(k));
    switch (locateSample(*camera_, *field_, point_in_cam, &pixel, nullptr).outcome) {
      case SampleOutcome::kOnField: ++counts.on_field; break;
      case SampleOutcome::kBehindCamera: ++counts.behind_camera; break;
      case SampleOutcome::kOutsideImage: ++counts.outside_image; break;
      case SampleOutcome::kBeyondReach: ++counts.beyond_reach; break;
    }
  }
  return counts;
}

}  // namespace curvesfm
