#pragma once

#include <Eigen/Core>
#include <memory>

#include "core/bezier.h"
#include "core/camera.h"
#include "core/direction.h"
#include "core/nearest_edge_field.h"
#include "core/pose3.h"
#include "graph/factor.h"

namespace curvesfm {

/// How a curve sample ended up in one evaluation (see CurveReprojectionFactor).
struct CurveSampleCounts {
  int on_field = 0;           ///< Projected within the field's reach of an edge: a live residual.
  int behind_camera = 0;      ///< Depth <= Camera::kMinDepth: capped.
  int outside_image = 0;      ///< Projected outside the image: capped.
  int beyond_reach = 0;       ///< Inside the image but farther than R from every edge: capped.
  int wrong_orientation = 0;  ///< Nearest edge not normal to the curve there: capped.

  int capped() const { return behind_camera + outside_image + beyond_reach + wrong_orientation; }
  int total() const { return on_field + capped(); }
  CurveSampleCounts& operator+=(const CurveSampleCounts& other);
};

/// How CurveReprojectionFactors sample their segment and which edge matches they accept. Built
/// once and shared by every factor that samples alike.
struct CurveSampling {
  /// `num_samples` = s + 1 samples at t_k = k / s (uniformBernsteinWeights), 2 <= s + 1 <=
  /// CurveReprojectionFactor::kMaxSamples; 0 < max_normal_angle_deg <= 90. Throws CheckError.
  CurveSampling(int num_samples, bool use_subpixel_edges, double max_normal_angle_deg = 90.0,
                bool interpolate_edges = false);

  int numSamples() const { return static_cast<int>(point_weights.cols()); }

  Eigen::Matrix4Xd point_weights;    ///< Bernstein weights of B(t_k), one column per sample.
  Eigen::Matrix4Xd tangent_weights;  ///< Bernstein weights of the tangent B'(t_k).
  /// Measure from the edge's sub-pixel position, else from its pixel centre.
  bool use_subpixel_edges = true;
  /// A sample is matched only if the edge normal g is within this angle (deg) of the normal of
  /// the projected curve there; otherwise it is capped. The nearest edge pixel of a sample whose
  /// own edge is hidden is often the end of the visible part, where g points along the curve and
  /// would pull the sample along it: a partly hidden curve would shrink towards its visible part.
  /// 90 accepts every match.
  double max_normal_angle_deg = 90.0;
  double sin_max_normal_angle = 1.0;  ///< sin(max_normal_angle_deg), for the inner loop.
  /// Blend the residuals to the nearest edges of the four pixel centres around the sample,
  /// bilinearly, instead of using the one nearest pixel's edge. The nearest edge pixel changes
  /// as a sample crosses a pixel boundary, and with it the residual jumps by up to a fraction of
  /// a pixel: a solver that converges tightly parks samples on the favourable side of such
  /// jumps, and then every step of a later joint solve looks worse. Blended, the residual is
  /// continuous along an edge. Only corners whose edge continues the sample's nearest edge
  /// blend: the signed distances to two edges a pixel apart would blend to a false zero between
  /// them. Where the nearest edge itself changes to another edge the residual still jumps.
  bool interpolate_edges = false;
};

/// The geometric term E_geo of one (segment, keyframe) pair (paper §3.1, eq. 6): samples
/// B(t_k), k = 0..s, of the segment are projected into the keyframe and each gives the residual
///   r_k = (x_k - eta(x_k))^T g(eta(x_k))     (pixels)
/// with x_k the projection, eta the nearest edge pixel from the keyframe's NearestEdgeField (its
/// sub-pixel position, or its pixel centre if `use_subpixel_edges` is off) and g the unit image
/// gradient there. eta and g are constant within one evaluation: the residual measures distance
/// across the edge only, so a sample may slide along it, which is what keeps a partly observed
/// curve unbiased. With CurveSampling::interpolate_edges the residual is the bilinear blend of
/// the residuals to the nearest edges of the four pixel centres around x_k, where those continue
/// the line of the sample's own nearest edge (else its residual stands in), and its Jacobian
/// includes the weights' derivatives.
///
/// A sample that projects behind the camera, outside the image, farther than the field's reach R
/// from every edge, or onto an edge of the wrong orientation (CurveSampling::max_normal_angle_deg)
/// gets the capped residual R (px) with zero Jacobians: it costs what the worst live sample
/// could, never pulls, and never produces NaN. sampleCounts() counts them.
///
/// Keys: the keyframe pose (Pose3, cam_from_world), then the segment's Q_i, Q_{i+1} (points),
/// v_i, v_{i+1} (Direction), d1_i, d2_i (scalars): segmentKeys(c, i).
/// Residual rows: s + 1 (CurveSampling::numSamples()), at most kMaxSamples.
class CurveReprojectionFactor
    : public NoiseModelFactorBase<Eigen::Dynamic, 65, Pose3, Eigen::Vector3d, Eigen::Vector3d,
                                  Direction, Direction, double, double> {
  using Base = NoiseModelFactorBase<Eigen::Dynamic, 65, Pose3, Eigen::Vector3d, Eigen::Vector3d,
                                    Direction, Direction, double, double>;

 public:
  static constexpr int kMaxSamples = 65;

  /// `field` and `camera` belong to the keyframe; `sampling` is shared by all factors that
  /// sample alike. Throws CheckError on null pointers.
  CurveReprojectionFactor(Key pose_key, const SegmentKeys& segment,
                          std::shared_ptr<const NearestEdgeField> field,
                          std::shared_ptr<const Camera> camera,
                          std::shared_ptr<const CurveSampling> sampling, NoiseModel noise_model);

  Error evaluateError(const Pose3& cam_from_world, const Eigen::Vector3d& q0,
                      const Eigen::Vector3d& q1, const Direction& v0, const Direction& v1,
                      const double& d1, const double& d2, Jacobian<Pose3>* H_pose,
                      Jacobian<Eigen::Vector3d>* H_q0, Jacobian<Eigen::Vector3d>* H_q1,
                      Jacobian<Direction>* H_v0, Jacobian<Direction>* H_v1, Jacobian<double>* H_d1,
                      Jacobian<double>* H_d2) const override;

  const char* typeName() const override { return "curve_reprojection"; }

  /// Where each sample falls at `values` (for reports; allocates nothing but is not meant for
  /// the solver's inner loop).
  CurveSampleCounts sampleCounts(const Values& values) const;

  /// The residual of a capped sample (px): the field's reach.
  double cappedResidual() const { return field_->maxDistance(); }
  int numSamples() const { return sampling_->numSamples(); }
  const NearestEdgeField& field() const { return *field_; }
  const Camera& camera() const { return *camera_; }

 private:
  struct SampleBatch;
  /// Projects every sample and finds its edge match (with d pixel / d point_in_cam if asked).
  void locateSamples(const Pose3& cam_from_world, const Eigen::Matrix3d& R,
                     const SegmentEvaluator& segment, bool with_jacobians,
                     SampleBatch* batch) const;
  /// Caps sample k if its edge normal is too far from the projected curve's normal.
  void checkOrientation(int k, const Eigen::Matrix3d& R, const SegmentEvaluator& segment,
                        SampleBatch* batch) const;
  /// The residual of a sample at `pixel` whose nearest edge pixel is `nearest`, and its
  /// derivative with respect to the pixel (CurveSampling::interpolate_edges).
  void measureSample(const Eigen::Vector2d& pixel, const EdgePixel& nearest, double* residual,
                     Eigen::Vector2d* gradient) const;
  Eigen::Vector2d edgePosition(const EdgePixel& edge) const;
  /// Whether `edge` lies on the line of the edge at `position` with unit `normal` (a neighbour
  /// pixel of the same edge), so that their residuals may be blended.
  bool continuesEdge(const EdgePixel& edge, const Eigen::Vector2d& position,
                     const Eigen::Vector2d& normal) const;

  std::shared_ptr<const NearestEdgeField> field_;
  std::shared_ptr<const Camera> camera_;
  std::shared_ptr<const CurveSampling> sampling_;
};

}  // namespace curvesfm
