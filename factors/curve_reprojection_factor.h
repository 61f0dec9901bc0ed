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
  int outside_image = 0;      ///< Outside the image, beyond the border margin: capped.
  int beyond_reach = 0;       ///< Inside the image but farther than R from every edge: capped.
  int wrong_orientation = 0;  ///< Nearest edge not normal to the curve there: capped.

  int capped() const { return behind_camera + outside_image + beyond_reach + wrong_orientation; }
  int total() const { return on_field + capped(); }
  CurveSampleCounts& operator+=(const CurveSampleCounts& other);
};

/// Whether and what CurveReprojectionFactor blends over the four pixel centres around a sample
/// (CurveSampling::blending).
struct EdgeBlending {
  bool enabled = false;
  /// Two corners' edge pixels lie on one edge if each lies within this distance (px) of the
  /// other's line...
  double max_line_offset_px = 0.5;
  /// ...and their normals are within this angle (deg), either sign.
  double max_normal_angle_deg = 45.0;
};

/// How CurveReprojectionFactors sample their segment and which edge matches they accept. Built
/// once and shared by every factor that samples alike.
struct CurveSampling {
  /// `num_samples` = s + 1 samples at t_k = k / s (uniformBernsteinWeights), 2 <= s + 1 <=
  /// CurveReprojectionFactor::kMaxSamples; 0 < max_normal_angle_deg <= 90; a blend's
  /// max_line_offset_px >= 0 and its max_normal_angle_deg in [0, 90]. Throws CheckError.
  CurveSampling(int num_samples, bool use_subpixel_edges, double max_normal_angle_deg = 90.0,
                const EdgeBlending& blending = {}, double border_margin_px = 0.0);

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
  /// With blending.enabled, blend the residuals to the nearest edges of the four pixel centres
  /// around the sample, bilinearly, instead of using the one nearest pixel's edge. The nearest
  /// edge pixel changes as a sample crosses a pixel boundary, and with it the residual jumps by
  /// up to a fraction of a pixel: a solver that converges tightly parks samples on the
  /// favourable side of such jumps, and then every step of a later joint solve looks worse.
  /// Blended, the residual is continuous along an edge. The four corners' edge pixels split into
  /// groups on one edge (EdgeBlending's line offset and angle) and only the heaviest group
  /// blends, its weights renormalised: the signed distances to two edges a pixel apart would
  /// blend to a false zero between them. Where another group becomes the heavier, near where
  /// the nearest edge itself becomes another edge, the residual still jumps.
  EdgeBlending blending;
  /// A sample that projects outside the image, but within this distance (px) of it, is measured
  /// against the nearest edge of the closest image pixel, extending that edge's line past the
  /// border, instead of taking the capped residual: a sample of a curve that leaves the image
  /// then does not jump from a small residual to the cap as it crosses the border. 0: capped.
  double border_margin_px = 0.0;
  double blend_min_normal_cosine = 0.0;  ///< cos(blending.max_normal_angle_deg).
};

/// The geometric term E_geo of one (segment, keyframe) pair (paper §3.1, eq. 6): samples
/// B(t_k), k = 0..s, of the segment are projected into the keyframe and each gives the residual
///   r_k = (x_k - eta(x_k))^T g(eta(x_k))     (pixels)
/// with x_k the projection, eta the nearest edge pixel from the keyframe's NearestEdgeField (its
/// sub-pixel position, or its pixel centre if `use_subpixel_edges` is off) and g the unit image
/// gradient there. eta and g are constant within one evaluation: the residual measures distance
/// across the edge only, so a sample may slide along it, which is what keeps a partly observed
/// curve unbiased. With CurveSampling::blending the residual is the bilinear blend of
/// the residuals to the nearest edges of the four pixel centres around x_k that lie on one edge
/// (the heaviest such group, weights renormalised), and its Jacobian includes the weights'
/// derivatives.
///
/// A sample that projects behind the camera, outside the image (farther than
/// CurveSampling::border_margin_px from it), farther than the field's reach R
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
  /// derivative with respect to the pixel (CurveSampling::blending).
  void measureSample(const Eigen::Vector2d& pixel, const EdgePixel& nearest, double* residual,
                     Eigen::Vector2d* gradient) const;
  Eigen::Vector2d edgePosition(const EdgePixel& edge) const;
  /// For a sample outside the image: the nearest edge of the closest image pixel if the sample
  /// lies within CurveSampling::border_margin_px of the image, else null.
  const EdgePixel* nearestPastBorder(const Eigen::Vector2d& pixel) const;
  /// Whether two edge pixels lie on one edge (each on the other's line, normals alike), so that
  /// their residuals may be blended.
  bool sameEdge(const EdgePixel& a, const EdgePixel& b) const;

  std::shared_ptr<const NearestEdgeField> field_;
  std::shared_ptr<const Camera> camera_;
  std::shared_ptr<const CurveSampling> sampling_;
};

}  // namespace curvesfm
