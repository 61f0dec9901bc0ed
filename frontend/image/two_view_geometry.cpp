#include "frontend/image/two_view_geometry.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <functional>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "core/angles.h"
#include "core/check.h"
#include "core/errors.h"
#include "core/so3.h"

namespace curvesfm {

void TwoViewOptions::validate() const {
  const OptionCheck require("TwoViewOptions");
  require(min_matches >= 8, "min_matches", min_matches, ">= 8");
  require.positive("ransac_threshold_px", ransac_threshold_px);
  require(confidence > 0.0 && confidence < 1.0, "confidence", confidence, "in (0, 1)");
  require(max_iterations >= 1, "max_iterations", max_iterations, ">= 1");
  require(seed >= 0, "seed", seed, ">= 0");
  require.positive("score_sigma_px", score_sigma_px);
  require(homography_score_ratio >= 0.0 && homography_score_ratio <= 1.0, "homography_score_ratio",
          homography_score_ratio, "in [0, 1]");
  require.positive("homography_inlier_ratio", homography_inlier_ratio);
  require(pure_rotation_fraction > 0.0 && pure_rotation_fraction <= 1.0, "pure_rotation_fraction",
          pure_rotation_fraction, "in (0, 1]");
  require(clear_winner_ratio > 0.0 && clear_winner_ratio < 1.0, "clear_winner_ratio",
          clear_winner_ratio, "in (0, 1)");
  require(min_triangulated_points >= 1, "min_triangulated_points", min_triangulated_points, ">= 1");
  require(min_triangulated_fraction >= 0.0 && min_triangulated_fraction <= 1.0,
          "min_triangulated_fraction", min_triangulated_fraction, "in [0, 1]");
  require.positive("max_reprojection_error_px", max_reprojection_error_px);
  require(parallax_rank >= 1, "parallax_rank", parallax_rank, ">= 1");
  require(min_parallax_deg >= 0.0 && min_parallax_deg < 90.0, "min_parallax_deg", min_parallax_deg,
          "in [0, 90)");
  require(min_median_parallax_deg >= 0.0 && min_median_parallax_deg < 90.0,
          "min_median_parallax_deg", min_median_parallax_deg, "in [0, 90)");
}

namespace {

// ORB-SLAM's chi-square bounds (95 %) for one and two degrees of freedom. E's point-to-line
// distance has one, H's transfer error two; both are scored against the two-dof bound so that
// their scores compare (Initializer.cc, CheckFundamental / CheckHomography).
constexpr double kChi2OneDof = 3.841;
constexpr double kChi2TwoDof = 5.991;

struct Fit {
  bool ok = false;
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Zero();
};

// A model's ORB-SLAM score and the inliers it defines. The inliers come from the score, not from
// USAC's mask, so that E and H count inliers under one noise model (sigma) and COLMAP's inlier
// ratio compares like with like.
struct Score {
  double score = 0.0;
  std::vector<std::uint8_t> inliers;
  int num_inliers = 0;
};

// One decomposition hypothesis and what its triangulation kept.
struct Hypothesis {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();  // Unit norm (or zero for a degenerate one).
  std::vector<Eigen::Vector3d> points;
  std::vector<int> indices;
  std::vector<double> angles_deg;
};

std::vector<cv::Point2d> toCv(const std::vector<Eigen::Vector2d>& pixels) {
  std::vector<cv::Point2d> out;
  out.reserve(pixels.size());
  for (const Eigen::Vector2d& p : pixels) out.emplace_back(p.x(), p.y());
  return out;
}

cv::UsacParams usacParams(const TwoViewOptions& options) {
  cv::UsacParams params;
  params.confidence = options.confidence;
  params.maxIterations = options.max_iterations;
  params.randomGeneratorState = options.seed;
  params.threshold = options.ransac_threshold_px;
  params.score = options.robust_score == TwoViewRobustScore::kMagsac ? cv::SCORE_METHOD_MAGSAC
                                                                     : cv::SCORE_METHOD_MSAC;
  params.isParallel = false;  // Threads would make the sampling order, and so the result, vary.
  return params;
}

// OpenCV signals a degenerate sample set by an empty matrix or by throwing cv::Exception; both
// become a failed fit so that degenerate data is counted, never thrown.
Fit runFit(const std::function<cv::Mat(cv::Mat*)>& estimate) {
  Fit fit;
  cv::Mat mask, model;  // USAC's mask is not used: see Score.
  try {
    model = estimate(&mask);
  } catch (const cv::Exception&) {
    return fit;
  }
  if (model.rows < 3 || model.cols != 3) return fit;
  // The five-point solver may stack several 3x3 solutions; USAC returns its best first.
  cv::cv2eigen(cv::Mat(model.rowRange(0, 3)), fit.matrix);
  fit.ok = fit.matrix.allFinite();
  return fit;
}

Eigen::Vector2d transfer(const Eigen::Matrix3d& H, const Eigen::Vector2d& p) {
  return (H * p.homogeneous()).hnormalized();
}

// Adds one match's two chi-square values to an ORB-SLAM score: each direction under `bound`
// adds 5.991 - chi^2; the match is an inlier when both are under it.
void addToScore(double chi2_b, double chi2_a, double bound, Score* score) {
  bool inlier = true;
  for (const double chi2 : {chi2_b, chi2_a}) {
    if (chi2 < bound) {
      score->score += kChi2TwoDof - chi2;
    } else {
      inlier = false;  // Also NaN.
    }
  }
  score->inliers.push_back(inlier ? 1 : 0);
  score->num_inliers += inlier ? 1 : 0;
}

// ORB-SLAM's symmetric transfer score of H over every match.
Score homographyScore(const Eigen::Matrix3d& H, const std::vector<Eigen::Vector2d>& a,
                      const std::vector<Eigen::Vector2d>& b, double sigma) {
  const Eigen::Matrix3d H_inv = H.inverse();
  const double inv_var = 1.0 / (sigma * sigma);
  Score score;
  for (size_t i = 0; i < a.size(); ++i) {
    addToScore((b[i] - transfer(H, a[i])).squaredNorm() * inv_var,
               (a[i] - transfer(H_inv, b[i])).squaredNorm() * inv_var, kChi2TwoDof, &score);
  }
  return score;
}

double squaredLineDistance(const Eigen::Vector3d& line, const Eigen::Vector2d& p) {
  const double n2 = line.head<2>().squaredNorm();
  return n2 > 0.0 ? std::pow(line.dot(p.homogeneous()), 2) / n2
                  : std::numeric_limits<double>::infinity();
}

// ORB-SLAM's score of F = K^-T E K^-1: point-to-epipolar-line distance in both images, inlier
// bound of one dof, scored on the two-dof scale.
Score essentialScore(const Eigen::Matrix3d& E, const Eigen::Matrix3d& K,
                     const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b,
                     double sigma) {
  const Eigen::Matrix3d K_inv = K.inverse();
  const Eigen::Matrix3d F = K_inv.transpose() * E * K_inv;
  const double inv_var = 1.0 / (sigma * sigma);
  Score score;
  for (size_t i = 0; i < a.size(); ++i) {
    addToScore(squaredLineDistance(F * a[i].homogeneous(), b[i]) * inv_var,
               squaredLineDistance(F.transpose() * b[i].homogeneous(), a[i]) * inv_var, kChi2OneDof,
               &score);
  }
  return score;
}

// The rotation nearest (Frobenius) to K^-1 H K, whose scale and sign are arbitrary.
Eigen::Matrix3d nearestRotation(const Eigen::Matrix3d& H, const Eigen::Matrix3d& K) {
  Eigen::Matrix3d Hn = K.inverse() * H * K;
  if (Hn.determinant() < 0.0) Hn = -Hn;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(Hn, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * svd.matrixV().transpose();
}

// COLMAP's "panoramic" case found from the pixels: a rotation alone moves the inliers where
// they are seen, so the baseline is below the noise.
bool isPureRotation(const Fit& homography, const Eigen::Matrix3d& K,
                    const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b,
                    const std::vector<std::uint8_t>& inliers, int num_inliers,
                    const TwoViewOptions& options) {
  if (!homography.ok || num_inliers == 0) return false;
  const Eigen::Matrix3d H_rot = K * nearestRotation(homography.matrix, K) * K.inverse();
  // H's own inlier bound: with 0.5 px noise a 1.5 px bound keeps only ~90 % of a rotation's
  // matches, too few for a 0.9 fraction; 2.45 sigma keeps ~99.7 % at sigma = 1 px.
  const double bound2 = kChi2TwoDof * options.score_sigma_px * options.score_sigma_px;
  int explained = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (inliers[i] && (b[i] - transfer(H_rot, a[i])).squaredNorm() <= bound2) ++explained;
  }
  return explained >= options.pure_rotation_fraction * num_inliers;
}

// Linear triangulation (DLT) of normalized rays xa, xb with cam_a = [I | 0], cam_b = [R | t].
Eigen::Vector3d triangulate(const Eigen::Vector2d& xa, const Eigen::Vector2d& xb,
                            const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Eigen::Matrix<double, 3, 4> Pb;
  Pb << R, t;
  Eigen::Matrix4d A;
  A.row(0) << -1.0, 0.0, xa.x(), 0.0;
  A.row(1) << 0.0, -1.0, xa.y(), 0.0;
  A.row(2) = xb.x() * Pb.row(2) - Pb.row(0);
  A.row(3) = xb.y() * Pb.row(2) - Pb.row(1);
  const Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d X = svd.matrixV().col(3);
  return X.head<3>() / X.w();  // Inf or NaN for a point at infinity; the gates drop it.
}

// Triangulates the inliers under one hypothesis and keeps the points that pass the gates:
// finite, in front of both cameras, reprojected within the bound in both images.
void triangulateHypothesis(const Eigen::Matrix3d& K, const std::vector<Eigen::Vector2d>& a,
                           const std::vector<Eigen::Vector2d>& b,
                           const std::vector<std::uint8_t>& inliers, double max_error_px,
                           Hypothesis* h) {
  const Eigen::Matrix3d K_inv = K.inverse();
  const Eigen::Vector3d centre_b = -h->R.transpose() * h->t;
  const double bound2 = max_error_px * max_error_px;
  for (size_t i = 0; i < a.size(); ++i) {
    if (!inliers[i]) continue;
    const Eigen::Vector2d xa = (K_inv * a[i].homogeneous()).hnormalized();
    const Eigen::Vector2d xb = (K_inv * b[i].homogeneous()).hnormalized();
    const Eigen::Vector3d p = triangulate(xa, xb, h->R, h->t);
    const Eigen::Vector3d p_b = h->R * p + h->t;
    if (!p.allFinite() || p.z() <= Camera::kMinDepth || p_b.z() <= Camera::kMinDepth) continue;
    if ((a[i] - (K * p).hnormalized()).squaredNorm() > bound2) continue;
    if ((b[i] - (K * p_b).hnormalized()).squaredNorm() > bound2) continue;
    const double cos_angle = p.normalized().dot((p - centre_b).normalized());
    h->angles_deg.push_back(std::acos(std::clamp(cos_angle, -1.0, 1.0)) * kRadToDeg);
    h->points.push_back(p);
    h->indices.push_back(static_cast<int>(i));
  }
}

std::vector<Hypothesis> essentialHypotheses(const Eigen::Matrix3d& E) {
  cv::Mat E_cv, R1, R2, t;
  cv::eigen2cv(E, E_cv);
  cv::decomposeEssentialMat(E_cv, R1, R2, t);
  Eigen::Matrix3d R1e, R2e;
  Eigen::Vector3d te;
  cv::cv2eigen(R1, R1e);
  cv::cv2eigen(R2, R2e);
  cv::cv2eigen(t, te);
  te.normalize();
  std::vector<Hypothesis> out(4);
  out[0].R = R1e, out[0].t = te;
  out[1].R = R1e, out[1].t = -te;
  out[2].R = R2e, out[2].t = te;
  out[3].R = R2e, out[3].t = -te;
  return out;
}

std::vector<Hypothesis> homographyHypotheses(const Eigen::Matrix3d& H, const Eigen::Matrix3d& K) {
  cv::Mat H_cv, K_cv;
  cv::eigen2cv(H, H_cv);
  cv::eigen2cv(K, K_cv);
  std::vector<cv::Mat> rotations, translations, normals;
  cv::decomposeHomographyMat(H_cv, K_cv, rotations, translations, normals);
  std::vector<Hypothesis> out(rotations.size());
  for (size_t k = 0; k < rotations.size(); ++k) {
    cv::cv2eigen(rotations[k], out[k].R);
    cv::cv2eigen(translations[k], out[k].t);
    // t / d of the plane; a near-zero norm has no direction and triangulates nothing.
    const double norm = out[k].t.norm();
    out[k].t = norm > 1e-12 ? Eigen::Vector3d(out[k].t / norm) : Eigen::Vector3d::Zero();
  }
  return out;
}

// Sampson errors (px, through `focal`) of normalized matches xa <-> xb under E = [t]x R.
Eigen::VectorXd sampsonErrors(const std::vector<Eigen::Vector3d>& xa,
                              const std::vector<Eigen::Vector3d>& xb, const Eigen::Matrix3d& R,
                              const Eigen::Vector3d& t, double focal) {
  const Eigen::Matrix3d E = so3::hat(t) * R;
  Eigen::VectorXd r(xa.size());
  for (size_t i = 0; i < xa.size(); ++i) {
    const Eigen::Vector3d Ea = E * xa[i], Etb = E.transpose() * xb[i];
    const double norm2 = Ea.head<2>().squaredNorm() + Etb.head<2>().squaredNorm();
    r[i] = norm2 > 0.0 ? focal * xb[i].dot(Ea) / std::sqrt(norm2) : 0.0;
  }
  return r;
}

// The minimal-sample model is only as good as its five or four points; a few damped Gauss-Newton
// steps on the Sampson error of the winner's points use all of them. Parameters: a rotation on
// the left and a step of t in the plane orthogonal to it (t stays unit). Numerical Jacobian: five
// columns over a few hundred points, cheap beside the fits.
void refineMotion(const Eigen::Matrix3d& K, const std::vector<Eigen::Vector2d>& a,
                  const std::vector<Eigen::Vector2d>& b, const std::vector<int>& indices,
                  Eigen::Matrix3d* R, Eigen::Vector3d* t) {
  if (indices.size() < 6) return;
  const Eigen::Matrix3d K_inv = K.inverse();
  std::vector<Eigen::Vector3d> xa, xb;
  for (const int i : indices) {
    xa.push_back(K_inv * a[i].homogeneous());
    xb.push_back(K_inv * b[i].homogeneous());
  }
  const double focal = 0.5 * (K(0, 0) + K(1, 1));
  using Vector5d = Eigen::Matrix<double, 5, 1>;
  const auto apply = [](const Eigen::Matrix3d& R0, const Eigen::Vector3d& t0, const Vector5d& d,
                        Eigen::Matrix3d* R1, Eigen::Vector3d* t1) {
    const Eigen::Vector3d u = t0.unitOrthogonal(), v = t0.cross(u);
    *R1 = so3::exp(d.head<3>()).toRotationMatrix() * R0;
    *t1 = (t0 + d[3] * u + d[4] * v).normalized();
  };
  Eigen::VectorXd r = sampsonErrors(xa, xb, *R, *t, focal);
  double lambda = 1e-4;
  for (int iteration = 0; iteration < 10; ++iteration) {
    Eigen::MatrixXd J(r.size(), 5);
    for (int k = 0; k < 5; ++k) {
      const double h = 1e-7;
      Eigen::Matrix3d Rp, Rm;
      Eigen::Vector3d tp, tm;
      apply(*R, *t, h * Vector5d::Unit(k), &Rp, &tp);
      apply(*R, *t, -h * Vector5d::Unit(k), &Rm, &tm);
      J.col(k) =
          (sampsonErrors(xa, xb, Rp, tp, focal) - sampsonErrors(xa, xb, Rm, tm, focal)) / (2.0 * h);
    }
    Eigen::Matrix<double, 5, 5> A = J.transpose() * J;
    A.diagonal() *= 1.0 + lambda;
    const Vector5d step = A.ldlt().solve(-J.transpose() * r);
    Eigen::Matrix3d R_new;
    Eigen::Vector3d t_new;
    apply(*R, *t, step, &R_new, &t_new);
    const Eigen::VectorXd r_new = sampsonErrors(xa, xb, R_new, t_new, focal);
    if (!step.allFinite() || !(r_new.squaredNorm() < r.squaredNorm())) {
      lambda *= 10.0;
      continue;
    }
    *R = R_new, *t = t_new, r = r_new;
    lambda = std::max(lambda / 10.0, 1e-8);
    if (step.norm() < 1e-10) break;
  }
}

// The median and the rank-th largest angle (the smallest when there are fewer).
void parallaxStatistics(std::vector<double> angles, int rank, TwoViewGeometry* out) {
  if (angles.empty()) return;
  std::sort(angles.begin(), angles.end(), std::greater<double>());
  out->median_parallax_deg = angles[angles.size() / 2];
  out->ranked_parallax_deg = angles[std::min<size_t>(rank - 1, angles.size() - 1)];
}

TwoViewGeometry reject(TwoViewGeometry out, TwoViewRejection reason) {
  out.accepted = false;
  out.rejection = reason;
  return out;
}

// The decomposition's cheirality vote and the acceptance gates (steps 5 and 6 of the header).
TwoViewGeometry decomposeAndGate(const Eigen::Matrix3d& K, const Eigen::Matrix3d& model_matrix,
                                 const std::vector<Eigen::Vector2d>& a,
                                 const std::vector<Eigen::Vector2d>& b,
                                 const TwoViewOptions& options, TwoViewGeometry out) {
  std::vector<Hypothesis> hypotheses = out.model == TwoViewModel::kEssential
                                           ? essentialHypotheses(model_matrix)
                                           : homographyHypotheses(model_matrix, K);
  size_t best = 0;
  for (size_t k = 0; k < hypotheses.size(); ++k) {
    triangulateHypothesis(K, a, b, out.inliers, options.max_reprojection_error_px, &hypotheses[k]);
    out.hypothesis_votes.push_back(static_cast<int>(hypotheses[k].points.size()));
    if (hypotheses[k].points.size() > hypotheses[best].points.size()) best = k;
  }
  if (hypotheses.empty()) return reject(std::move(out), TwoViewRejection::kNoModel);
  // Refined and re-triangulated; kept only if it keeps at least as many points.
  Hypothesis refined{hypotheses[best].R, hypotheses[best].t, {}, {}, {}};
  refineMotion(K, a, b, hypotheses[best].indices, &refined.R, &refined.t);
  triangulateHypothesis(K, a, b, out.inliers, options.max_reprojection_error_px, &refined);
  Hypothesis& winner =
      refined.points.size() >= hypotheses[best].points.size() ? refined : hypotheses[best];
  out.cam_b_from_cam_a = Pose3(winner.R, winner.t);
  parallaxStatistics(winner.angles_deg, options.parallax_rank, &out);
  out.points_in_cam_a = std::move(winner.points);
  out.point_indices = std::move(winner.indices);

  const int num_best = static_cast<int>(out.points_in_cam_a.size());
  const double needed = std::max<double>(options.min_triangulated_points,
                                         options.min_triangulated_fraction * out.num_inliers);
  if (num_best == 0 || num_best < needed)
    return reject(std::move(out), TwoViewRejection::kTooFewPoints);
  for (size_t k = 0; k < hypotheses.size(); ++k) {
    if (k != best &&
        out.hypothesis_votes[k] > options.clear_winner_ratio * out.hypothesis_votes[best]) {
      return reject(std::move(out), TwoViewRejection::kAmbiguousDecomposition);
    }
  }
  if (out.ranked_parallax_deg < options.min_parallax_deg ||
      out.median_parallax_deg < options.min_median_parallax_deg) {
    return reject(std::move(out), TwoViewRejection::kLowParallax);
  }
  out.accepted = true;
  out.rejection = TwoViewRejection::kNone;
  return out;
}

// Scores both fits and selects one (steps 2 and 3 of the header): H by ORB-SLAM's score ratio or
// COLMAP's inlier ratio, else E. Fills the scores, counts and model of `out`; returns the
// selected model's score with its inliers.
Score selectModel(const Fit& essential, const Fit& homography, const Eigen::Matrix3d& K,
                  const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b,
                  const TwoViewOptions& options, TwoViewGeometry* out) {
  const double sigma = options.score_sigma_px;
  Score e_score = essential.ok ? essentialScore(essential.matrix, K, a, b, sigma) : Score{};
  Score h_score = homography.ok ? homographyScore(homography.matrix, a, b, sigma) : Score{};
  out->essential_score = e_score.score;
  out->homography_score = h_score.score;
  out->num_essential_inliers = e_score.num_inliers;
  out->num_homography_inliers = h_score.num_inliers;
  const double score_sum = e_score.score + h_score.score;
  const bool h_by_score =
      score_sum > 0.0 && h_score.score / score_sum > options.homography_score_ratio;
  const bool h_by_inliers =
      h_score.num_inliers > options.homography_inlier_ratio * e_score.num_inliers;
  const bool use_h = homography.ok && (!essential.ok || h_by_score || h_by_inliers);
  out->model = use_h ? TwoViewModel::kHomography : TwoViewModel::kEssential;
  return use_h ? std::move(h_score) : std::move(e_score);
}

}  // namespace

TwoViewGeometry estimateTwoViewGeometry(const Camera& camera, const std::vector<Eigen::Vector2d>& a,
                                        const std::vector<Eigen::Vector2d>& b,
                                        const TwoViewOptions& options) {
  options.validate();
  CURVESFM_CHECK(a.size() == b.size())
      << "matches need as many pixels in b as in a: " << a.size() << " vs " << b.size();
  TwoViewGeometry out;
  out.inliers.assign(a.size(), 0);
  if (static_cast<int>(a.size()) < options.min_matches) {
    return reject(std::move(out), TwoViewRejection::kTooFewMatches);
  }

  const Eigen::Matrix3d K = camera.K();
  cv::Mat K_cv;
  cv::eigen2cv(K, K_cv);
  const std::vector<cv::Point2d> a_cv = toCv(a), b_cv = toCv(b);
  const cv::UsacParams params = usacParams(options);
  const Fit essential = runFit([&](cv::Mat* mask) {
    return cv::findEssentialMat(a_cv, b_cv, K_cv, K_cv, cv::noArray(), cv::noArray(), *mask,
                                params);
  });
  const Fit homography =
      runFit([&](cv::Mat* mask) { return cv::findHomography(a_cv, b_cv, *mask, params); });
  if (!essential.ok && !homography.ok) return reject(std::move(out), TwoViewRejection::kNoModel);

  const Score selected = selectModel(essential, homography, K, a, b, options, &out);
  out.inliers = selected.inliers;
  out.num_inliers = selected.num_inliers;

  if (isPureRotation(homography, K, a, b, out.inliers, out.num_inliers, options)) {
    return reject(std::move(out), TwoViewRejection::kPureRotation);
  }
  const bool use_h = out.model == TwoViewModel::kHomography;
  return decomposeAndGate(K, (use_h ? homography : essential).matrix, a, b, options,
                          std::move(out));
}

}  // namespace curvesfm
