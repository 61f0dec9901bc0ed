#include "sim/curve_scene.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <locale>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>
#include <string>
#include <utility>

#include "core/angles.h"
#include "core/bezier_fit.h"
#include "core/check.h"
#include "core/curve_export.h"
#include "core/errors.h"
#include "core/so3.h"
#include "core/trajectory_evaluation.h"
#include "sim/synthetic_dataset.h"

namespace curvesfm {
namespace {

constexpr double kBackground = 128.0;
// Dense samples per segment (shared end samples included) fitted by BezierFitter.
constexpr int kFitSamplesPerSegment = 32;
// Samples per segment for the placement checks, the observations and the error metrics.
// Powers of two, so that the estimate's samples (16) are exactly samples of the truth's (64).
constexpr int kCheckSamplesPerSegment = 16;
constexpr int kErrorSamplesPerSegment = 16;
constexpr int kTruthSamplesPerSegment = 64;
constexpr int kMaxPlacementAttempts = 1000;
// Samples closer to the camera plane than this (m) are neither drawn nor observed.
constexpr double kMinDepth = 0.05;
// Samples whose pinhole projection leaves the image enlarged by this factor of its size on each
// side are dropped: far outside the field of view the distortion polynomial may fold back.
constexpr double kGuardFraction = 1.0;
// Target spacing (px) of the projected polyline that is rendered; its chord error on a curve of
// radius rho px is spacing^2 / (8 rho), 0.04 px at rho = 30 px.
constexpr double kRenderSpacingPx = 3.0;
constexpr int kCoarseSamplesPerSegment = 8;
constexpr int kMaxPiecesPerSegment = 2048;
// The erf step is drawn out to this many sigma, then returns linearly to the background.
constexpr double kStepHalfWidthSigmas = 3.0;
// Minimum length (px, and in sigma) of that return and of the fade at curve ends: it keeps their
// Sobel magnitude below 4 * contrast / 8, well under the step's peak 4 * contrast * erf(...).
constexpr double kReturnLengthPx = 8.0;
constexpr double kReturnLengthSigmas = 8.0;
constexpr double kProfileTableStepPx = 1.0 / 32.0;
constexpr double kStripOverlapPx = 1e-3;
constexpr double kMinHiddenFraction = 0.3;
constexpr double kMaxHiddenFraction = 0.5;
constexpr double kMinClutterLengthPx = 40.0;
constexpr double kMaxClutterLengthPx = 200.0;
constexpr int kClutterSamples = 64;
// Helix radius floor (m) so that a helix does not degenerate into a tiny spiral.
constexpr double kMinHelixRadius = 0.1;
// Random streams: changing one group of options leaves the other groups' draws unchanged.
constexpr unsigned kCurveStream = 1;
constexpr unsigned kStartStream = 2;
constexpr unsigned kRenderStream = 3;

// ------------------------------------------------------------------------------------------
// Options.

bool inRange(double value, double low, double high) { return value >= low && value <= high; }

// ------------------------------------------------------------------------------------------
// Randomness.

std::mt19937 makeRng(unsigned seed, unsigned stream, unsigned index = 0) {
  std::seed_seq sequence{seed, stream, index};
  return std::mt19937(sequence);
}

// Standard normal draws scaled afterwards: std::normal_distribution requires sigma > 0.
double standardNormal(std::mt19937& rng) { return std::normal_distribution<double>()(rng); }

double uniform(std::mt19937& rng, double low, double high) {
  return std::uniform_real_distribution<double>(low, high)(rng);
}

Eigen::Vector3d gaussian3(std::mt19937& rng, double sigma) {
  const double x = standardNormal(rng);
  const double y = standardNormal(rng);
  const double z = standardNormal(rng);
  return sigma * Eigen::Vector3d(x, y, z);
}

Eigen::Matrix3d randomRotation(std::mt19937& rng) {
  const double w = standardNormal(rng);
  const Eigen::Vector3d xyz = gaussian3(rng, 1.0);
  return Eigen::Quaterniond(w, xyz.x(), xyz.y(), xyz.z()).normalized().toRotationMatrix();
}

// ------------------------------------------------------------------------------------------
// Cameras.

// Camera at `centre` looking along `forward`, image y along world +y ("down") as far as possible.
Pose3 lookAlong(const Eigen::Vector3d& centre, const Eigen::Vector3d& forward) {
  const Eigen::Vector3d z = forward.normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized();
  Eigen::Matrix3d world_from_cam_rotation;
  world_from_cam_rotation << x, z.cross(x), z;
  return Pose3(world_from_cam_rotation, centre).inverse();
}

std::vector<Pose3> makeOrbit(const CurveSceneOptions& options) {
  const double arc = options.arc_degrees * kDegToRad;
  const double radius = options.camera_distance;
  // A full orbit ends one step short of where it began: a last keyframe at the first one's
  // pose would be a duplicate view, not a loop.
  const int steps =
      options.arc_degrees >= 360.0 ? options.num_keyframes : options.num_keyframes - 1;
  std::vector<Pose3> poses;
  for (int i = 0; i < options.num_keyframes; ++i) {
    const double angle = -0.5 * arc + arc * i / steps;
    const Eigen::Vector3d centre(radius * std::sin(angle), -0.1 * radius * std::cos(3.0 * angle),
                                 -radius * std::cos(angle));
    poses.push_back(lookAlong(centre, -centre));
  }
  return poses;
}

std::vector<Pose3> makeForwardWalk(const CurveSceneOptions& options) {
  const double wiggle_angle = 2.0 * kDegToRad;
  std::vector<Pose3> poses;
  for (int i = 0; i < options.num_keyframes; ++i) {
    const double s = static_cast<double>(i) / (options.num_keyframes - 1);
    // Incommensurate frequencies keep the centres off one plane and the rotations distinct.
    const Eigen::Vector3d centre(
        0.1 * std::sin(2.0 * M_PI * s + 0.3), 0.05 * std::sin(3.0 * M_PI * s),
        -(options.camera_distance + options.walk_length) + options.walk_length * s);
    const Eigen::Vector3d forward(std::tan(wiggle_angle * std::sin(2.0 * M_PI * s)),
                                  std::tan(wiggle_angle * std::cos(3.0 * M_PI * s)), 1.0);
    poses.push_back(lookAlong(centre, forward));
  }
  return poses;
}

std::vector<Pose3> makeSidewaysWalk(const CurveSceneOptions& options) {
  const double wiggle_angle = 2.0 * kDegToRad;
  std::vector<Pose3> poses;
  for (int i = 0; i < options.num_keyframes; ++i) {
    const double s = static_cast<double>(i) / (options.num_keyframes - 1);
    // The forward walk's wiggle, slowed down to about one period per 10 m so that it stays
    // gentle between keyframes however long the walk.
    const double phase = s * std::max(1.0, options.walk_length / 10.0);
    const Eigen::Vector3d centre(
        options.walk_length * (s - 0.5), 0.05 * std::sin(3.0 * M_PI * phase),
        -options.camera_distance + 0.1 * std::sin(2.0 * M_PI * phase + 0.3));
    const Eigen::Vector3d forward(std::tan(wiggle_angle * std::sin(2.0 * M_PI * phase)),
                                  std::tan(wiggle_angle * std::cos(3.0 * M_PI * phase)), 1.0);
    poses.push_back(lookAlong(centre, forward));
  }
  return poses;
}

std::vector<Pose3> makeCameraPath(const CurveSceneOptions& options) {
  switch (options.camera_path) {
    case CameraPath::kOrbit:
      return makeOrbit(options);
    case CameraPath::kForwardWalk:
      return makeForwardWalk(options);
    case CameraPath::kSidewaysWalk:
      return makeSidewaysWalk(options);
  }
  CURVESFM_CHECK(false) << "unknown camera path " << static_cast<int>(options.camera_path);
  return {};
}

// ------------------------------------------------------------------------------------------
// Curves.

// Constant-speed samples s = k / (count-1) of a shape of arc length `length`, in a local frame.
std::vector<Eigen::Vector3d> lineSamples(double length, int count) {
  std::vector<Eigen::Vector3d> samples;
  for (int k = 0; k < count; ++k) {
    const double s = static_cast<double>(k) / (count - 1) - 0.5;
    samples.emplace_back(s * length, 0.0, 0.0);
  }
  return samples;
}

std::vector<Eigen::Vector3d> arcSamples(double length, int count, std::mt19937& rng) {
  const double angle = uniform(rng, 60.0, 180.0) * kDegToRad;
  const double radius = length / angle;
  std::vector<Eigen::Vector3d> samples;
  for (int k = 0; k < count; ++k) {
    const double phi = (static_cast<double>(k) / (count - 1) - 0.5) * angle;
    samples.emplace_back(radius * std::cos(phi), radius * std::sin(phi), 0.0);
  }
  return samples;
}

std::vector<Eigen::Vector3d> helixSamples(double length, int count, std::mt19937& rng) {
  const double slope = uniform(rng, 20.0, 40.0) * kDegToRad;
  const double planar_length = length * std::cos(slope);
  // Half a turn to a full turn, fewer turns where the radius would drop below its floor.
  const double max_angle = std::max(M_PI, std::min(2.0 * M_PI, planar_length / kMinHelixRadius));
  const double angle = uniform(rng, M_PI, max_angle);
  const double radius = planar_length / angle;
  const double rise = length * std::sin(slope);
  std::vector<Eigen::Vector3d> samples;
  for (int k = 0; k < count; ++k) {
    const double s = static_cast<double>(k) / (count - 1) - 0.5;
    samples.emplace_back(radius * std::cos(s * angle), radius * std::sin(s * angle), s * rise);
  }
  return samples;
}

std::vector<Eigen::Vector3d> shapeSamples(CurveKind kind, double length, int count,
                                          std::mt19937& rng) {
  switch (kind) {
    case CurveKind::kLine:
      return lineSamples(length, count);
    case CurveKind::kArc:
      return arcSamples(length, count, rng);
    default:
      return helixSamples(length, count, rng);
  }
}

// Fits every run of kFitSamplesPerSegment consecutive samples (neighbouring runs share their
// end sample) and links the cubics: the result is the ground truth the curve model can represent.
PolyBezier fitPolyBezier(const std::vector<Eigen::Vector3d>& samples, int num_segments) {
  std::vector<CubicBezier> fitted;
  for (int i = 0; i < num_segments; ++i) {
    fitted.push_back(BezierFitter::shared().fit(&samples[i * (kFitSamplesPerSegment - 1)],
                                                kFitSamplesPerSegment));
  }
  return linkSegments(fitted);
}

bool isPlaceable(const PolyBezier& curve, const CurveSceneOptions& options,
                 const std::vector<Eigen::Vector3d>& camera_centres) {
  const double min_distance_sq = options.min_camera_distance * options.min_camera_distance;
  for (const Eigen::Vector3d& point : curve.sample(kCheckSamplesPerSegment)) {
    if ((point.cwiseAbs() - options.volume_half_extents).maxCoeff() > 0.0) return false;
    for (const Eigen::Vector3d& centre : camera_centres) {
      if ((point - centre).squaredNorm() < min_distance_sq) return false;
    }
  }
  return true;
}

PolyBezier placeCurve(CurveKind kind, const CurveSceneOptions& options,
                      const std::vector<Eigen::Vector3d>& camera_centres, std::mt19937& rng) {
  const int count = options.segments_per_curve * (kFitSamplesPerSegment - 1) + 1;
  const Eigen::Vector3d& half = options.volume_half_extents;
  for (int attempt = 0; attempt < kMaxPlacementAttempts; ++attempt) {
    const double length = uniform(rng, options.min_curve_length, options.max_curve_length);
    std::vector<Eigen::Vector3d> samples = shapeSamples(kind, length, count, rng);
    const Eigen::Matrix3d rotation = randomRotation(rng);
    const Eigen::Vector3d centre(uniform(rng, -half.x(), half.x()),
                                 uniform(rng, -half.y(), half.y()),
                                 uniform(rng, -half.z(), half.z()));
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& sample : samples) centroid += sample / count;
    for (Eigen::Vector3d& sample : samples) sample = rotation * (sample - centroid) + centre;
    PolyBezier curve = fitPolyBezier(samples, options.segments_per_curve);
    if (isPlaceable(curve, options, camera_centres)) return curve;
  }
  throw InvalidOptions("CurveSceneOptions", "min_camera_distance",
                       formatOptionValue(options.min_camera_distance),
                       "no curve fits in the volume this far from every keyframe after " +
                           std::to_string(kMaxPlacementAttempts) + " attempts");
}

CurveKind pickKind(CurveKind requested, std::mt19937& rng) {
  if (requested != CurveKind::kMixed) return requested;
  const int pick = std::uniform_int_distribution<int>(0, 2)(rng);
  return pick == 0 ? CurveKind::kLine : (pick == 1 ? CurveKind::kArc : CurveKind::kHelix);
}

// ------------------------------------------------------------------------------------------
// Starting guess.

// Rotation about the camera's own axes and a shift of its centre in the world.
Pose3 perturbPose(const Pose3& cam_from_world, double rotation_sigma, double centre_sigma,
                  std::mt19937& rng) {
  const Pose3 world_from_cam = cam_from_world.inverse();
  const Eigen::Quaterniond rotation =
      world_from_cam.rotation() * so3::exp(gaussian3(rng, rotation_sigma));
  const Eigen::Vector3d centre = world_from_cam.translation() + gaussian3(rng, centre_sigma);
  return Pose3(rotation, centre).inverse();
}

// Moves the centre of `pose` along the line from `anchor` so that it lies `distance` from it.
Pose3 withCentreDistance(const Pose3& pose, const Eigen::Vector3d& anchor, double distance) {
  const Pose3 world_from_cam = pose.inverse();
  const Eigen::Vector3d offset = world_from_cam.translation() - anchor;
  if (!(offset.norm() > 0.0)) return pose;
  return Pose3(world_from_cam.rotation(), anchor + distance * offset.normalized()).inverse();
}

PolyBezier perturbCurve(const PolyBezier& curve, const CurveSceneOptions& options,
                        std::mt19937& rng) {
  PolyBezier perturbed = curve;
  const double tangent_sigma = options.curve_tangent_noise_deg * kDegToRad;
  for (int i = 0; i < curve.numPoints(); ++i) {
    perturbed.setPoint(i, curve.points()[i] + gaussian3(rng, options.curve_point_noise));
    const double a = standardNormal(rng);
    const double b = standardNormal(rng);
    perturbed.setDirection(i, curve.directions()[i].retract(tangent_sigma * Eigen::Vector2d(a, b)));
  }
  for (int i = 0; i < curve.numSegments(); ++i) {
    const double f1 = std::exp(options.curve_length_noise * standardNormal(rng));
    const double f2 = std::exp(options.curve_length_noise * standardNormal(rng));
    perturbed.setLengths(i, {curve.lengths()[i].d1 * f1, curve.lengths()[i].d2 * f2});
  }
  return perturbed;
}

// ------------------------------------------------------------------------------------------
// Projection.

// Distorted pixel of a world point, or false if it is too close to (or behind) the camera plane
// or so far outside the field of view that the distortion model is not trusted there.
bool projectGuarded(const Camera& camera, const Pose3& cam_from_world,
                    const Eigen::Vector3d& point_in_world, Eigen::Vector2d* pixel) {
  const Eigen::Vector3d point = cam_from_world * point_in_world;
  if (!(point.z() > kMinDepth)) return false;
  const double u = camera.fx() * point.x() / point.z() + camera.cx();
  const double v = camera.fy() * point.y() / point.z() + camera.cy();
  const double guard_x = kGuardFraction * camera.width();
  const double guard_y = kGuardFraction * camera.height();
  if (u < -guard_x || u > camera.width() + guard_x || v < -guard_y ||
      v > camera.height() + guard_y) {
    return false;
  }
  return camera.project(point, pixel);
}

using Polyline2d = std::vector<Eigen::Vector2d>;

// Number of render pieces for segment i over [t0, t1], from a coarse projection.
int renderPieces(const Camera& camera, const Pose3& cam_from_world, const CubicBezier& cubic,
                 double t0, double t1) {
  double length = 0.0;
  Eigen::Vector2d previous = Eigen::Vector2d::Zero();
  bool previous_ok = false;
  for (int k = 0; k <= kCoarseSamplesPerSegment; ++k) {
    const double t = t0 + (t1 - t0) * k / kCoarseSamplesPerSegment;
    Eigen::Vector2d pixel;
    const bool ok = projectGuarded(camera, cam_from_world, cubic.evaluate(t), &pixel);
    if (ok && previous_ok) length += (pixel - previous).norm();
    previous = pixel;
    previous_ok = ok;
  }
  const double pieces = std::ceil(length / kRenderSpacingPx);
  return static_cast<int>(std::clamp(pieces, 1.0, static_cast<double>(kMaxPiecesPerSegment)));
}

// The projection of the curve part g in [g0, g1] (g = segment + t) as polylines about
// kRenderSpacingPx apart, split wherever a sample cannot be projected.
std::vector<Polyline2d> projectCurvePart(const Camera& camera, const Pose3& cam_from_world,
                                         const PolyBezier& curve, double g0, double g1) {
  std::vector<Polyline2d> runs(1);
  bool first_sample = true;
  for (int i = 0; i < curve.numSegments(); ++i) {
    const double t0 = std::max(g0 - i, 0.0);
    const double t1 = std::min(g1 - i, 1.0);
    if (!(t1 > t0)) continue;
    const CubicBezier cubic = curve.controlPoints(i);
    const int pieces = renderPieces(camera, cam_from_world, cubic, t0, t1);
    // Each segment after the first starts at the previous one's last sample.
    for (int k = first_sample ? 0 : 1; k <= pieces; ++k) {
      const double t = k == pieces ? t1 : t0 + (t1 - t0) * k / pieces;
      Eigen::Vector2d pixel;
      if (projectGuarded(camera, cam_from_world, cubic.evaluate(t), &pixel)) {
        runs.back().push_back(pixel);
      } else if (!runs.back().empty()) {
        runs.emplace_back();
      }
    }
    first_sample = false;
  }
  runs.erase(std::remove_if(runs.begin(), runs.end(),
                            [](const Polyline2d& run) { return run.size() < 2; }),
             runs.end());
  return runs;
}

// The parameter intervals of curve `c` drawn in a keyframe: [0, n] minus its hidden part.
std::vector<std::pair<double, double>> drawnIntervals(const CurveKeyframe& keyframe, int c,
                                                      int num_segments) {
  for (const HiddenCurvePart& hidden : keyframe.hidden_parts) {
    if (hidden.curve_index != c) continue;
    std::vector<std::pair<double, double>> intervals;
    if (hidden.begin > 0.0) intervals.emplace_back(0.0, hidden.begin);
    if (hidden.end < num_segments) intervals.emplace_back(hidden.end, num_segments);
    return intervals;
  }
  return {{0.0, static_cast<double>(num_segments)}};
}

// ------------------------------------------------------------------------------------------
// Rendering.

// Accumulates blurred step edges along image polylines and turns them into an 8-bit image.
//
// Each curve adds contrast/2 * side * profile(d) * fade(s) to the background, with d the signed
// distance (px) to its polyline and s the arc length along it. profile is erf(d / (sqrt(2)
// sigma)) out to 3 sigma, then returns linearly to 0 over the return length L; fade ramps the
// whole profile linearly over L at each end, so that no edge appears across or beyond the ends:
// centred on each end when L is the automatic max(8 sigma, 8 px), inside the curve for a given
// L (a long, gentle return; the edge then fades out a few px before the end, a subset of the
// curve, rather than running on past it). Different curves add up; within one curve the nearest
// piece wins. The work is O(polyline length * band width): every piece visits only the pixels of
// its own strip, bounded by the bisectors at its ends.
class StepEdgeRenderer {
 public:
  StepEdgeRenderer(int width, int height, double sigma, double contrast, double return_length)
      : width_(width),
        height_(height),
        half_contrast_(0.5 * contrast),
        fade_inside_(return_length > 0.0),
        return_length_(fade_inside_ ? return_length
                                    : std::max(kReturnLengthPx, kReturnLengthSigmas * sigma)),
        step_half_width_(kStepHalfWidthSigmas * sigma),
        band_(step_half_width_ + return_length_),
        offset_(static_cast<std::size_t>(width) * height, 0.0f),
        nearest_(offset_.size()) {
    const int entries = static_cast<int>(std::ceil(band_ / kProfileTableStepPx)) + 2;
    for (int k = 0; k < entries; ++k) {
      const double r = k * kProfileTableStepPx;
      const double ramp = std::clamp(1.0 - (r - step_half_width_) / return_length_, 0.0, 1.0);
      profile_.push_back(static_cast<float>(std::erf(r / (std::sqrt(2.0) * sigma)) * ramp));
    }
  }

  /// Adds the edge of one polyline (pixels); side = +1 puts the bright side towards the normal
  /// (-dy, dx) of the direction of travel, -1 the other way.
  void addCurve(const Polyline2d& polyline, double side) {
    const Polyline2d points = withoutRepeats(polyline);
    if (points.size() < 2) return;
    const int num_pieces = static_cast<int>(points.size()) - 1;
    std::vector<Eigen::Vector2d> directions(num_pieces);
    std::vector<double> lengths(num_pieces), starts(num_pieces);
    double total = 0.0;
    for (int k = 0; k < num_pieces; ++k) {
      const Eigen::Vector2d chord = points[k + 1] - points[k];
      lengths[k] = chord.norm();
      directions[k] = chord / lengths[k];
      starts[k] = total;
      total += lengths[k];
    }
    const std::vector<Eigen::Vector2d> vertex_normals = vertexNormals(directions);
    ++current_stamp_;
    touched_.clear();
    for (int k = 0; k < num_pieces; ++k) {
      Piece piece{points[k], directions[k], normal(directions[k]), lengths[k],
                  starts[k], k == 0,        k == num_pieces - 1};
      rasterisePiece(piece, vertex_normals[k], vertex_normals[k + 1]);
    }
    for (const int index : touched_) {
      const Nearest& nearest = nearest_[index];
      offset_[index] +=
          static_cast<float>(half_contrast_ * side * signedProfile(nearest.signed_distance) *
                             fade(nearest.along, total));
    }
  }

  /// The rendered image with Gaussian noise of std dev `noise` (drawn by cv::RNG(noise_seed)),
  /// rounded and clamped to 8 bits.
  cv::Mat finish(double noise, std::uint64_t noise_seed) const {
    cv::Mat1f image(height_, width_);
    for (int row = 0; row < height_; ++row) {
      for (int column = 0; column < width_; ++column) {
        image(row, column) = static_cast<float>(kBackground) +
                             offset_[static_cast<std::size_t>(row) * width_ + column];
      }
    }
    if (noise > 0.0) {
      cv::Mat1f noise_image(height_, width_);
      cv::RNG rng(noise_seed);
      rng.fill(noise_image, cv::RNG::NORMAL, 0.0, noise);
      image += noise_image;
    }
    cv::Mat image8;
    image.convertTo(image8, CV_8U);  // Rounds and saturates.
    return image8;
  }

 private:
  // The nearest piece of the curve being drawn, per pixel (one cache line holds four pixels).
  struct Nearest {
    float distance = 0.0f;         // |d| (px).
    float signed_distance = 0.0f;  // d, positive towards the piece normal (px).
    float along = 0.0f;            // Arc length of the nearest point (px).
    int stamp = -1;                // The curve that wrote it.
  };

  struct Piece {
    Eigen::Vector2d start;
    Eigen::Vector2d direction;
    Eigen::Vector2d normal;
    double length;
    double along;  // Arc length of the polyline at `start`.
    bool first;
    bool last;
  };

  static Eigen::Vector2d normal(const Eigen::Vector2d& direction) {
    return Eigen::Vector2d(-direction.y(), direction.x());
  }

  static Polyline2d withoutRepeats(const Polyline2d& polyline) {
    Polyline2d points;
    for (const Eigen::Vector2d& point : polyline) {
      if (points.empty() || (point - points.back()).norm() > 1e-9) points.push_back(point);
    }
    return points;
  }

  // Bisector normals at the vertices; at a cusp the piece normal stands in.
  static std::vector<Eigen::Vector2d> vertexNormals(
      const std::vector<Eigen::Vector2d>& directions) {
    const int num_pieces = static_cast<int>(directions.size());
    std::vector<Eigen::Vector2d> normals(num_pieces + 1);
    normals[0] = normal(directions[0]);
    normals[num_pieces] = normal(directions[num_pieces - 1]);
    for (int k = 1; k < num_pieces; ++k) {
      const Eigen::Vector2d sum = normal(directions[k - 1]) + normal(directions[k]);
      normals[k] = sum.norm() > 1e-6 ? Eigen::Vector2d(sum.normalized()) : normal(directions[k]);
    }
    return normals;
  }

  // Visits the pixel centres of the piece's strip: between the bisectors at its ends, out to
  // the band on both sides, and past the polyline's ends by the fade length.
  void rasterisePiece(const Piece& piece, const Eigen::Vector2d& start_normal,
                      const Eigen::Vector2d& end_normal) {
    // A sliver of overlap between neighbouring strips, so that rounding cannot drop a pixel
    // centre lying on their common bisector.
    const double beyond_ends = fade_inside_ ? 0.0 : 0.5 * return_length_ + 1.0;
    const double before = piece.first ? beyond_ends : kStripOverlapPx;
    const double after = piece.last ? beyond_ends : kStripOverlapPx;
    const double reach = band_ + 1.0;
    const Eigen::Vector2d a = piece.start - before * piece.direction;
    const Eigen::Vector2d b = piece.start + (piece.length + after) * piece.direction;
    const std::array<Eigen::Vector2d, 4> corners = {a + reach * start_normal,
                                                    b + reach * end_normal, b - reach * end_normal,
                                                    a - reach * start_normal};
    double y_min = corners[0].y(), y_max = corners[0].y();
    for (const Eigen::Vector2d& corner : corners) {
      y_min = std::min(y_min, corner.y());
      y_max = std::max(y_max, corner.y());
    }
    const int row_begin = std::max(0, static_cast<int>(std::ceil(y_min)));
    const int row_end = std::min(height_ - 1, static_cast<int>(std::floor(y_max)));
    for (int row = row_begin; row <= row_end; ++row) {
      double x_min = 0.0;
      double x_max = 0.0;
      if (!rowSpan(corners, row, &x_min, &x_max)) continue;
      const int column_begin = std::max(0, static_cast<int>(std::ceil(x_min)));
      const int column_end = std::min(width_ - 1, static_cast<int>(std::floor(x_max)));
      for (int column = column_begin; column <= column_end; ++column) {
        visitPixel(piece, column, row);
      }
    }
  }

  // The x-range where row `row` crosses the quadrilateral; false if it misses it.
  static bool rowSpan(const std::array<Eigen::Vector2d, 4>& corners, int row, double* x_min,
                      double* x_max) {
    *x_min = std::numeric_limits<double>::infinity();
    *x_max = -*x_min;
    for (int e = 0; e < 4; ++e) {
      const Eigen::Vector2d& p = corners[e];
      const Eigen::Vector2d& q = corners[(e + 1) % 4];
      if (row < std::min(p.y(), q.y()) || row > std::max(p.y(), q.y())) continue;
      const double x0 = p.y() == q.y() ? std::min(p.x(), q.x())
                                       : p.x() + (q.x() - p.x()) * (row - p.y()) / (q.y() - p.y());
      const double x1 = p.y() == q.y() ? std::max(p.x(), q.x()) : x0;
      *x_min = std::min(*x_min, x0);
      *x_max = std::max(*x_max, x1);
    }
    return *x_min <= *x_max;
  }

  // Distance (perpendicular beyond the polyline's ends, so the fade can act there) and arc
  // length of the pixel's nearest point on the piece; keeps it if it beats the curve's best.
  void visitPixel(const Piece& piece, int column, int row) {
    const Eigen::Vector2d offset = Eigen::Vector2d(column, row) - piece.start;
    const double u = offset.dot(piece.direction);
    const double v = offset.dot(piece.normal);
    double distance = std::abs(v);
    double along = piece.along + u;
    if (u < 0.0 && !piece.first) {
      distance = offset.norm();
      along = piece.along;
    } else if (u > piece.length && !piece.last) {
      distance = std::sqrt((u - piece.length) * (u - piece.length) + v * v);
      along = piece.along + piece.length;
    }
    if (distance >= band_) return;
    const std::size_t index = static_cast<std::size_t>(row) * width_ + column;
    Nearest& nearest = nearest_[index];
    if (nearest.stamp != current_stamp_) {
      nearest.stamp = current_stamp_;
      touched_.push_back(static_cast<int>(index));
    } else if (distance >= nearest.distance) {
      return;
    }
    nearest.distance = static_cast<float>(distance);
    nearest.signed_distance = static_cast<float>(v >= 0.0 ? distance : -distance);
    nearest.along = static_cast<float>(along);
  }

  double signedProfile(double d) const {
    const double position = std::abs(d) / kProfileTableStepPx;
    const std::size_t k = static_cast<std::size_t>(position);
    if (k + 1 >= profile_.size()) return 0.0;
    const double w = position - static_cast<double>(k);
    const double value = (1.0 - w) * profile_[k] + w * profile_[k + 1];
    return d < 0.0 ? -value : value;
  }

  double fade(double along, double total) const {
    const double half = fade_inside_ ? 0.0 : 0.5 * return_length_;
    const double from_start = std::clamp((along + half) / return_length_, 0.0, 1.0);
    const double from_end = std::clamp((total - along + half) / return_length_, 0.0, 1.0);
    return from_start * from_end;
  }

  int width_;
  int height_;
  double half_contrast_;
  bool fade_inside_;      // The fade ends at the polyline's ends rather than straddling them.
  // Of the return to the background beside the curve, and of the fade at each end (px).
  double return_length_;
  double step_half_width_;
  double band_;
  std::vector<float> profile_;    // profile(r) at r = k * kProfileTableStepPx.
  std::vector<float> offset_;     // Intensity added to the background, row-major.
  std::vector<Nearest> nearest_;  // Row-major; valid where stamp == current_stamp_.
  int current_stamp_ = 0;
  std::vector<int> touched_;
};

// A smooth random 2D cubic of 40-200 px somewhere in the image.
Polyline2d clutterCurve(int width, int height, std::mt19937& rng) {
  const Eigen::Vector2d start(uniform(rng, 0.0, width - 1.0), uniform(rng, 0.0, height - 1.0));
  const double length = uniform(rng, kMinClutterLengthPx, kMaxClutterLengthPx);
  const double heading = uniform(rng, -M_PI, M_PI);
  const double bend_start = uniform(rng, -0.8, 0.8);
  const double bend_end = uniform(rng, -0.8, 0.8);
  auto unit = [](double angle) { return Eigen::Vector2d(std::cos(angle), std::sin(angle)); };
  const Eigen::Vector2d end = start + length * unit(heading);
  std::array<Eigen::Vector2d, 4> control = {start,
                                            start + length / 3.0 * unit(heading + bend_start),
                                            end - length / 3.0 * unit(heading + bend_end), end};
  Polyline2d polyline;
  for (int k = 0; k <= kClutterSamples; ++k) {
    const Eigen::Vector4d w = bernsteinWeights(static_cast<double>(k) / kClutterSamples);
    polyline.push_back(w[0] * control[0] + w[1] * control[1] + w[2] * control[2] +
                       w[3] * control[3]);
  }
  return polyline;
}

// ------------------------------------------------------------------------------------------
// Observations and keyframes.

struct SegmentVisibility {
  int inside = 0;       // Samples projecting inside the shrunk image.
  double length = 0.0;  // Projected length over consecutive projectable samples (px).
};

SegmentVisibility segmentVisibility(const Camera& camera, const Pose3& cam_from_world,
                                    const CubicBezier& cubic, double margin) {
  SegmentVisibility visibility;
  Eigen::Vector2d previous = Eigen::Vector2d::Zero();
  bool previous_ok = false;
  for (int k = 0; k <= kCheckSamplesPerSegment; ++k) {
    Eigen::Vector2d pixel;
    const bool ok =
        projectGuarded(camera, cam_from_world,
                       cubic.evaluate(static_cast<double>(k) / kCheckSamplesPerSegment), &pixel);
    if (ok && camera.isInImage(pixel, margin)) ++visibility.inside;
    if (ok && previous_ok) visibility.length += (pixel - previous).norm();
    previous = pixel;
    previous_ok = ok;
  }
  return visibility;
}

std::vector<CurveObservation> observeKeyframe(const CurveScene& scene,
                                              const CurveSceneOptions& options, int keyframe) {
  std::vector<CurveObservation> observations;
  const Pose3& pose = scene.true_cam_from_world[keyframe];
  const double required = options.min_visible_fraction * (kCheckSamplesPerSegment + 1);
  for (int c = 0; c < static_cast<int>(scene.true_curves.size()); ++c) {
    const PolyBezier& curve = scene.true_curves[c];
    for (int i = 0; i < curve.numSegments(); ++i) {
      const SegmentVisibility visibility = segmentVisibility(
          *scene.camera, pose, curve.controlPoints(i), options.visibility_margin_px);
      if (visibility.inside >= required - 1e-9 &&
          visibility.length >= options.min_projected_length_px) {
        observations.push_back({c, i, keyframe, 0.0});
      }
    }
  }
  return observations;
}

// Chooses the hidden parts of the observed curves. Draws the same numbers whatever the options'
// occlusion fraction and whatever is observed, so occlusion changes nothing else in the scene.
std::vector<HiddenCurvePart> chooseHiddenParts(const CurveScene& scene, double fraction,
                                               const std::vector<CurveObservation>& observations,
                                               std::mt19937& rng) {
  std::vector<bool> observed(scene.true_curves.size(), false);
  for (const CurveObservation& observation : observations) observed[observation.curve_index] = true;
  std::vector<HiddenCurvePart> hidden;
  for (int c = 0; c < static_cast<int>(scene.true_curves.size()); ++c) {
    const double draw = uniform(rng, 0.0, 1.0);
    const double hidden_length = uniform(rng, kMinHiddenFraction, kMaxHiddenFraction);
    const bool at_start = uniform(rng, 0.0, 1.0) < 0.5;
    if (!observed[c] || !(draw < fraction)) continue;
    const double n = scene.true_curves[c].numSegments();
    hidden.push_back(at_start ? HiddenCurvePart{c, 0.0, hidden_length * n}
                              : HiddenCurvePart{c, n - hidden_length * n, n});
  }
  return hidden;
}

void setHiddenFractions(const std::vector<HiddenCurvePart>& hidden_parts,
                        std::vector<CurveObservation>* observations) {
  for (CurveObservation& observation : *observations) {
    for (const HiddenCurvePart& hidden : hidden_parts) {
      if (hidden.curve_index != observation.curve_index) continue;
      const double begin = std::max(hidden.begin, static_cast<double>(observation.segment_index));
      const double end = std::min(hidden.end, observation.segment_index + 1.0);
      observation.hidden_fraction = std::max(0.0, end - begin);
    }
  }
}

void renderKeyframe(const CurveScene& scene, const CurveSceneOptions& options, int k,
                    const std::vector<double>& bright_sides, std::mt19937& rng,
                    CurveKeyframe* keyframe) {
  const Camera& camera = *scene.camera;
  StepEdgeRenderer renderer(camera.width(), camera.height(), options.edge_blur_sigma_px,
                            options.step_contrast, options.edge_return_length_px);
  for (int c = 0; c < static_cast<int>(scene.true_curves.size()); ++c) {
    const PolyBezier& curve = scene.true_curves[c];
    for (const auto& [g0, g1] : drawnIntervals(*keyframe, c, curve.numSegments())) {
      for (const Polyline2d& run :
           projectCurvePart(camera, scene.true_cam_from_world[k], curve, g0, g1)) {
        renderer.addCurve(run, bright_sides[c]);
      }
    }
  }
  for (int j = 0; j < options.num_clutter_edges; ++j) {
    const Polyline2d clutter = clutterCurve(camera.width(), camera.height(), rng);
    renderer.addCurve(clutter, uniform(rng, 0.0, 1.0) < 0.5 ? -1.0 : 1.0);
  }
  const std::uint64_t noise_seed = (static_cast<std::uint64_t>(rng()) << 32) | rng();
  keyframe->image = renderer.finish(options.pixel_noise, noise_seed);
  cv::Sobel(keyframe->image, keyframe->grad_x, CV_16S, 1, 0, 3);
  cv::Sobel(keyframe->image, keyframe->grad_y, CV_16S, 0, 1, 3);
  cv::Canny(keyframe->grad_x, keyframe->grad_y, keyframe->edges, options.canny_low_threshold,
            options.canny_high_threshold, true);
}

// Observations, hidden parts and images of keyframe k; independent of every other keyframe.
std::vector<CurveObservation> buildKeyframe(const CurveScene& scene,
                                            const CurveSceneOptions& options, int k,
                                            const std::vector<double>& bright_sides,
                                            CurveKeyframe* keyframe) {
  std::mt19937 rng = makeRng(options.seed, kRenderStream, static_cast<unsigned>(k));
  std::vector<CurveObservation> observations = observeKeyframe(scene, options, k);
  keyframe->hidden_parts = chooseHiddenParts(scene, options.occlusion_fraction, observations, rng);
  setHiddenFractions(keyframe->hidden_parts, &observations);
  renderKeyframe(scene, options, k, bright_sides, rng, keyframe);
  return observations;
}

// ------------------------------------------------------------------------------------------
// Errors.

double distanceToPolyline(const Eigen::Vector3d& point, const std::vector<Eigen::Vector3d>& line) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k + 1 < line.size(); ++k) {
    const Eigen::Vector3d chord = line[k + 1] - line[k];
    const double length_sq = chord.squaredNorm();
    const double t =
        length_sq > 0.0 ? std::clamp((point - line[k]).dot(chord) / length_sq, 0.0, 1.0) : 0.0;
    best = std::min(best, (line[k] + t * chord - point).squaredNorm());
  }
  return std::sqrt(best);
}

double bilinear(const cv::Mat1f& image, double x, double y) {
  const int x0 = std::clamp(static_cast<int>(std::floor(x)), 0, image.cols - 2);
  const int y0 = std::clamp(static_cast<int>(std::floor(y)), 0, image.rows - 2);
  const double fx = x - x0;
  const double fy = y - y0;
  return (1.0 - fy) * ((1.0 - fx) * image(y0, x0) + fx * image(y0, x0 + 1)) +
         fy * ((1.0 - fx) * image(y0 + 1, x0) + fx * image(y0 + 1, x0 + 1));
}

}  // namespace

void CurveSceneOptions::validate() const {
  const OptionCheck require("CurveSceneOptions");
  require(num_keyframes >= 2, "num_keyframes", num_keyframes, "must be >= 2");
  require(camera_path == CameraPath::kOrbit || camera_path == CameraPath::kForwardWalk ||
              camera_path == CameraPath::kSidewaysWalk,
          "camera_path", static_cast<int>(camera_path),
          "must be kOrbit, kForwardWalk or kSidewaysWalk");
  require(camera_distance > 0.0 && std::isfinite(camera_distance), "camera_distance",
          camera_distance, "must be finite and > 0");
  require(arc_degrees > 0.0 && arc_degrees <= 360.0, "arc_degrees", arc_degrees,
          "must be in (0, 360]");
  require(walk_length > 0.0 && std::isfinite(walk_length), "walk_length", walk_length,
          "must be finite and > 0");
  intrinsics.validate();
  require(num_curves >= 1, "num_curves", num_curves, "must be >= 1");
  require(curve_kind == CurveKind::kLine || curve_kind == CurveKind::kArc ||
              curve_kind == CurveKind::kHelix || curve_kind == CurveKind::kMixed,
          "curve_kind", static_cast<int>(curve_kind), "must be kLine, kArc, kHelix or kMixed");
  require(segments_per_curve >= 1 && segments_per_curve <= 64, "segments_per_curve",
          segments_per_curve, "must be in [1, 64]");
  require(min_curve_length > 0.0 && std::isfinite(min_curve_length), "min_curve_length",
          min_curve_length, "must be finite and > 0");
  require(max_curve_length >= min_curve_length && std::isfinite(max_curve_length),
          "max_curve_length", max_curve_length, "must be finite and >= min_curve_length");
  const char* axes[3] = {"volume_half_extents.x", "volume_half_extents.y", "volume_half_extents.z"};
  for (int a = 0; a < 3; ++a) {
    require(volume_half_extents[a] > 0.0 && std::isfinite(volume_half_extents[a]), axes[a],
            volume_half_extents[a], "must be finite and > 0");
  }
  require(max_curve_length <= 2.0 * volume_half_extents.minCoeff(), "max_curve_length",
          max_curve_length, "must be <= 2 * the smallest volume_half_extents");
  require(min_camera_distance >= 0.0, "min_camera_distance", min_camera_distance, "must be >= 0");
  require(inRange(edge_blur_sigma_px, 0.3, 5.0), "edge_blur_sigma_px", edge_blur_sigma_px,
          "must be in [0.3, 5]");
  require(step_contrast > 0.0 && step_contrast <= 255.0, "step_contrast", step_contrast,
          "must be in (0, 255]");
  require(edge_return_length_px == 0.0 || inRange(edge_return_length_px, 1.0, 200.0),
          "edge_return_length_px", edge_return_length_px, "must be 0 or in [1, 200]");
  require(pixel_noise >= 0.0 && std::isfinite(pixel_noise), "pixel_noise", pixel_noise,
          "must be finite and >= 0");
  require(canny_low_threshold > 0.0 && std::isfinite(canny_low_threshold), "canny_low_threshold",
          canny_low_threshold, "must be finite and > 0");
  require(canny_high_threshold >= canny_low_threshold && std::isfinite(canny_high_threshold),
          "canny_high_threshold", canny_high_threshold,
          "must be finite and >= canny_low_threshold");
  require(num_clutter_edges >= 0, "num_clutter_edges", num_clutter_edges, "must be >= 0");
  require(inRange(occlusion_fraction, 0.0, 1.0), "occlusion_fraction", occlusion_fraction,
          "must be in [0, 1]");
  require(min_visible_fraction > 0.0 && min_visible_fraction <= 1.0, "min_visible_fraction",
          min_visible_fraction, "must be in (0, 1]");
  require(visibility_margin_px >= 0.0 && std::isfinite(visibility_margin_px),
          "visibility_margin_px", visibility_margin_px, "must be finite and >= 0");
  require(min_projected_length_px >= 0.0 && std::isfinite(min_projected_length_px),
          "min_projected_length_px", min_projected_length_px, "must be finite and >= 0");
  require(pose_noise_translation >= 0.0 && std::isfinite(pose_noise_translation),
          "pose_noise_translation", pose_noise_translation, "must be finite and >= 0");
  require(pose_noise_rotation_deg >= 0.0 && std::isfinite(pose_noise_rotation_deg),
          "pose_noise_rotation_deg", pose_noise_rotation_deg, "must be finite and >= 0");
  require(curve_point_noise >= 0.0 && std::isfinite(curve_point_noise), "curve_point_noise",
          curve_point_noise, "must be finite and >= 0");
  require(inRange(curve_tangent_noise_deg, 0.0, 30.0), "curve_tangent_noise_deg",
          curve_tangent_noise_deg, "must be in [0, 30]");
  require(inRange(curve_length_noise, 0.0, 1.0), "curve_length_noise", curve_length_noise,
          "must be in [0, 1]");
}

CurveScene makeCurveScene(const CurveSceneOptions& options) {
  options.validate();
  CurveScene scene;
  scene.camera = std::make_shared<const Camera>(options.intrinsics);
  scene.true_cam_from_world = makeCameraPath(options);
  std::vector<Eigen::Vector3d> centres;
  for (const Pose3& pose : scene.true_cam_from_world) centres.push_back(pose.inverseTranslation());

  std::mt19937 curve_rng = makeRng(options.seed, kCurveStream);
  std::vector<double> bright_sides;
  for (int c = 0; c < options.num_curves; ++c) {
    const CurveKind kind = pickKind(options.curve_kind, curve_rng);
    scene.curve_kinds.push_back(kind);
    scene.true_curves.push_back(placeCurve(kind, options, centres, curve_rng));
    bright_sides.push_back(uniform(curve_rng, 0.0, 1.0) < 0.5 ? -1.0 : 1.0);
  }

  std::mt19937 start_rng = makeRng(options.seed, kStartStream);
  scene.initial_cam_from_world = scene.true_cam_from_world;
  for (int i = 1; i < options.num_keyframes; ++i) {
    scene.initial_cam_from_world[i] =
        perturbPose(scene.true_cam_from_world[i], options.pose_noise_rotation_deg * kDegToRad,
                    options.pose_noise_translation, start_rng);
  }
  scene.initial_cam_from_world[1] =
      withCentreDistance(scene.initial_cam_from_world[1], centres[0], scene.trueScaleDistance());
  for (const PolyBezier& curve : scene.true_curves) {
    scene.initial_curves.push_back(perturbCurve(curve, options, start_rng));
  }

  // Keyframes are independent (each has its own random stream), so they render in parallel
  // and the result does not depend on the number of threads.
  scene.keyframes.resize(options.num_keyframes);
  std::vector<std::vector<CurveObservation>> observations(options.num_keyframes);
  cv::parallel_for_(cv::Range(0, options.num_keyframes), [&](const cv::Range& range) {
    for (int k = range.start; k < range.end; ++k) {
      observations[k] = buildKeyframe(scene, options, k, bright_sides, &scene.keyframes[k]);
    }
  });
  for (const std::vector<CurveObservation>& keyframe_observations : observations) {
    scene.observations.insert(scene.observations.end(), keyframe_observations.begin(),
                              keyframe_observations.end());
  }
  return scene;
}

double CurveScene::trueScaleDistance() const {
  return cameraCentreDistance(true_cam_from_world[1], true_cam_from_world[0]);
}

CurveSceneErrors evaluateCurveScene(const CurveScene& scene,
                                    const std::vector<Pose3>& cam_from_world,
                                    const std::vector<PolyBezier>& curves) {
  CURVESFM_CHECK(cam_from_world.size() == scene.true_cam_from_world.size())
      << "expected " << scene.true_cam_from_world.size() << " poses, got " << cam_from_world.size();
  CURVESFM_CHECK(curves.size() == scene.true_curves.size())
      << "expected " << scene.true_curves.size() << " curves, got " << curves.size();
  const TrajectoryErrors trajectory = evaluateTrajectory(scene.true_cam_from_world, cam_from_world);
  CurveSceneErrors errors;
  errors.position_rmse = trajectory.position_rmse;
  errors.position_ate_sim3 = trajectory.position_ate_sim3;
  errors.rotation_mean_deg = trajectory.rotation_mean_deg;
  const Sim3 truth_from_estimated =
      alignCameraFrames(scene.true_cam_from_world, cam_from_world, 1.0);
  std::size_t count = 0;
  for (std::size_t c = 0; c < curves.size(); ++c) {
    const std::vector<Eigen::Vector3d> truth = scene.true_curves[c].sample(kTruthSamplesPerSegment);
    for (const Eigen::Vector3d& point : curves[c].sample(kErrorSamplesPerSegment)) {
      const double distance = distanceToPolyline(point, truth);
      errors.curve_mean_error += distance;
      errors.curve_max_error = std::max(errors.curve_max_error, distance);
      errors.curve_mean_error_aligned += distanceToPolyline(truth_from_estimated * point, truth);
      ++count;
    }
  }
  errors.curve_mean_error /= std::max<std::size_t>(count, 1);
  errors.curve_mean_error_aligned /= std::max<std::size_t>(count, 1);
  return errors;
}

EdgeAgreement measureEdgeAgreement(const CurveScene& scene, int keyframe, double max_distance_px) {
  CURVESFM_CHECK(keyframe >= 0 && keyframe < static_cast<int>(scene.keyframes.size()))
      << "keyframe " << keyframe << " outside [0, " << scene.keyframes.size() << ")";
  CURVESFM_CHECK(max_distance_px > 0.0) << "max_distance_px must be > 0, got " << max_distance_px;
  const CurveKeyframe& data = scene.keyframes[keyframe];
  const Camera& camera = *scene.camera;
  cv::Mat1f to_edge;
  cv::distanceTransform(data.edges == 0, to_edge, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  cv::Mat curve_mask = cv::Mat::zeros(camera.height(), camera.width(), CV_8U);
  constexpr int kShift = 4;  // Sub-pixel bits of cv::polylines.
  EdgeAgreement agreement;
  double sum = 0.0;
  int on_edges = 0;
  for (int c = 0; c < static_cast<int>(scene.true_curves.size()); ++c) {
    const PolyBezier& curve = scene.true_curves[c];
    for (const auto& [g0, g1] : drawnIntervals(data, c, curve.numSegments())) {
      for (const Polyline2d& run :
           projectCurvePart(camera, scene.true_cam_from_world[keyframe], curve, g0, g1)) {
        std::vector<cv::Point> points;
        for (const Eigen::Vector2d& pixel : run) {
          points.emplace_back(cvRound(pixel.x() * (1 << kShift)),
                              cvRound(pixel.y() * (1 << kShift)));
          if (!camera.isInImage(pixel, 2.0)) continue;
          const double distance =
              std::min(bilinear(to_edge, pixel.x(), pixel.y()), max_distance_px);
          sum += distance;
          on_edges += distance <= 1.0 ? 1 : 0;
          ++agreement.num_curve_samples;
        }
        cv::polylines(curve_mask, points, false, cv::Scalar(255), 1, cv::LINE_8, kShift);
      }
    }
  }
  if (agreement.num_curve_samples > 0) {
    agreement.mean_curve_to_edge_px = sum / agreement.num_curve_samples;
    agreement.curve_samples_on_edges = static_cast<double>(on_edges) / agreement.num_curve_samples;
  }
  cv::Mat1f to_curve;
  cv::distanceTransform(curve_mask == 0, to_curve, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  int near = 0;
  for (int row = 0; row < data.edges.rows; ++row) {
    for (int column = 0; column < data.edges.cols; ++column) {
      if (data.edges.at<std::uint8_t>(row, column) == 0) continue;
      ++agreement.num_edge_pixels;
      near += to_curve(row, column) <= max_distance_px ? 1 : 0;
    }
  }
  if (agreement.num_edge_pixels > 0) {
    agreement.edge_pixels_near_curves = static_cast<double>(near) / agreement.num_edge_pixels;
  }
  return agreement;
}

void writeCurveDataset(const std::string& dir, const CurveScene& scene, bool with_initial_poses) {
  CURVESFM_CHECK(scene.camera) << "a curve scene needs a camera";
  constexpr double kFramePeriod = 1.0 / 30.0;  // As a 30 Hz camera, the TUM sets' rate.
  constexpr int kGroundTruthSamplesPerSegment = 64;
  std::vector<double> timestamps;
  SyntheticSequence sequence;
  for (std::size_t k = 0; k < scene.keyframes.size(); ++k) {
    timestamps.push_back(static_cast<double>(k) * kFramePeriod);
    sequence.images.push_back(scene.keyframes[k].image);
  }
  sequence.camera = scene.camera.get();
  sequence.timestamps = &timestamps;
  sequence.true_cam_from_world = &scene.true_cam_from_world;
  if (with_initial_poses) sequence.initial_cam_from_world = &scene.initial_cam_from_world;
  writeSyntheticDataset(dir, sequence);
  writeCurvesObj((std::filesystem::path(dir) / "gt_curves.obj").string(), scene.true_curves,
                 kGroundTruthSamplesPerSegment);
}

}  // namespace curvesfm
