#pragma once

#include <Eigen/Core>
#include <memory>

#include "core/camera.h"
#include "core/direction.h"
#include "core/nearest_edge_field.h"
#include "core/pose3.h"
#include "graph/factor.h"

namespace curvesfm {

/// How a curve sample ended up in one evaluation (see CurveReprojectionFactor).
struct CurveSampleCounts {
  int on_field = 0;       ///< Projected within the field's reach of an edge: a live residual.
  int behind_camera = 0;  ///< Depth <= Camera::kMinDepth: capped.
  int outside_image = 0;  ///< Projected outside the image: capped.
  int beyond_reach = 0;   ///< Inside the image but farther than R from every edge: capped.

  int capped() const { return behind_camera + outside_image + beyond_reach; }
  int total() const { return on_field + capped(); }
  CurveSampleCounts& operator+=(const CurveSampleCounts& other);
};

/// The geometric term E_geo of one (segment, keyframe) pair (paper §3.1, eq. 6): samples
/// B(t_k), k = 0..s, of the segment are projected into the keyframe and each gives the residual
///   r_k = (x_k - eta(x_k))^T g(eta(x_k))     (pixels)
/// with x_k the projection, eta the nearest edge pixel from the keyframe's NearestEdgeField (its
/// sub-pixel position, or its pixel centre if `use_subpixel_edges` is off) and g the unit image
/// gradient there. eta and g are constant within one evaluation: the residual measures distance
/// across the edge only, so a sample may slide along it, which is what keeps a partly observed
/// curve unbiased.
///
/// A sample that projects behind the camera, outside the image, or farther than the field's
/// reach R from every edge gets the capped residual R (px) with zero Jacobians: it costs what the
/// worst live sample could, never pulls, and never produces NaN. sampleCounts() counts them.
///
/// Keys: the keyframe pose (Pose3, cam_from_world), then the segment's Q_i, Q_{i+1} (points),
/// v_i, v_{i+1} (Direction), d1_i, d2_i (scalars): segmentKeys(c, i).
/// Residual rows: s + 1 (the columns of `sample_weights`), at most kMaxSamples.
class CurveReprojectionFactor
    : public NoiseModelFactorBase<Eigen::Dynamic, 65, Pose3, Eigen::Vector3d, Eigen::Vector3d,
                                  Direction, Direction, double, double> {
  using Base = NoiseModelFactorBase<Eigen::Dynamic, 65, Pose3, Eigen::Vector3d, Eigen::Vector3d,
                                    Direction, Direction, double, double>;

 public:
  static constexpr int kMaxSamples = 65;

  /// `sample_weights`: 4 x (s+1) Bernstein weights of the sample parameters (columns), e.g.
  /// uniformBernsteinWeights(s + 1); shared by all factors with the same sampling. 1 <= s + 1 <=
  /// kMaxSamples. `field` and `camera` belong to the keyframe. Throws CheckError on null
  /// pointers or a bad sample count.
  CurveReprojectionFactor(Key pose_key, const SegmentKeys& segment,
                          std::shared_ptr<const NearestEdgeField> field,
                          std::shared_ptr<const Camera> camera,
                          std::shared_ptr<const Eigen::Matrix4Xd> sample_weights,
                          bool use_subpixel_edges, NoiseModel noise_model);

  Error evaluateError(const Pose3& cam_from_world, const Eigen::Vector3d& q0,
                      const Eigen::Vector3d& q1, const Direction& v0, const Direction& v1,
                      const double& d1, const double& d2, Jacobian<Pose3>* H_pose,
                      Jacobian<Eigen::Vector3d>* H_q0, Jacobian<Eigen::Vector3d>* H_q1,
                      Jacobian<Direction>* H_v0, Jacobian<Direction>* H_v1,
                      Jacobian<double>* H_d1, Jacobian<double>* H_d2) const override;

  const char* typeName() const override { return "curve_reprojection"; }

  /// Where each sample falls at `values` (for reports; allocates nothing but is not meant for
  /// the solver's inner loop).
  CurveSampleCounts sampleCounts(const Values& values) const;

  /// The residual of a capped sample (px): the field's reach.
  double cappedResidual() const { return field_->maxDistance(); }
  int numSamples() const { return static_cast<int>(weights_->cols()); }
  const NearestEdgeField& field() const { return *field_; }
  const Camera& camera() const { return *camera_; }

 private:
  std::shared_ptr<const NearestEdgeField> field_;
  std::shared_ptr<const Camera> camera_;
  std::shared_ptr<const Eigen::Matrix4Xd> weights_;
  bool use_subpixel_edges_;
};

}  // namespace curvesfm
