#include "apps/run_command.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <string>
#include <vector>

#include "apps/cli_options.h"
#include "apps/config_file.h"
#include "core/curve_export.h"
#include "core/dataset_io.h"
#include "core/errors.h"
#include "core/trajectory_evaluation.h"

namespace curvesfm {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// ---------------------------------------------------------------------------------------------
// Options: one table row per PipelineOptions field gives its flag (and so its --config key) and
// its report.json entry, so the two cannot drift apart.

struct OptionField {
  std::string group;  // JSON pointer below "options" in report.json, e.g. "local_ba/optimizer".
  std::string field;  // The struct field.
  std::function<void(CLI::App*)> add;
  std::function<nlohmann::json()> value;
};
using OptionFields = std::vector<OptionField>;

template <class T>
OptionField number(const std::string& group, const std::string& field, const std::string& flag,
                   T* target, const std::string& description) {
  return {
      group, field,
      [=](CLI::App* c) { c->add_option("--" + flag, *target, description)->capture_default_str(); },
      [target] { return nlohmann::json(*target); }};
}

OptionField boolean(const std::string& group, const std::string& field, const std::string& flag,
                    bool* target, const std::string& description) {
  return {group, field, [=](CLI::App* c) { addBoolFlag(c, flag, target, description); },
          [target] { return nlohmann::json(*target); }};
}

template <class Enum>
OptionField enumeration(const std::string& group, const std::string& field, const std::string& flag,
                        Enum* target, Enum (*parse)(const std::string&, const std::string&),
                        const std::string& description) {
  return {group, field, [=](CLI::App* c) { addEnumFlag(c, flag, target, parse, description); },
          [target] { return nlohmann::json(toString(*target)); }};
}

void append(OptionFields* fields, OptionFields more) {
  fields->insert(fields->end(), more.begin(), more.end());
}

OptionFields imageFields(PipelineOptions* o) {
  const std::string u = "undistort", e = "edges", c = "chains";
  EdgeDetectorOptions* edges = &o->edges;
  return {
      number(u, "valid_margin_px", "undistort-valid-margin", &o->undistort.valid_margin_px,
             "Band along the border of the undistorted data ignored by edge detection (px)"),
      number(e, "blur_sigma_px", "edges-blur-sigma", &edges->blur_sigma_px,
             "Gaussian blur before differentiation (px); 0 disables it"),
      number(e, "sobel_aperture", "edges-sobel-aperture", &edges->sobel_aperture,
             "Sobel aperture: 3 or 5"),
      number(e, "canny_low_threshold", "edges-canny-low", &edges->canny_low_threshold,
             "Canny low threshold (grey levels/px); 0 = auto-low-ratio x high"),
      number(e, "canny_high_threshold", "edges-canny-high", &edges->canny_high_threshold,
             "Canny high threshold (grey levels/px); 0 = automatic"),
      number(e, "auto_noise_factor", "edges-auto-noise-factor", &edges->auto_noise_factor,
             "Automatic high threshold in gradient noise std devs"),
      number(e, "auto_max_seed_fraction", "edges-auto-max-seed-fraction",
             &edges->auto_max_seed_fraction,
             "Largest fraction of pixels above the automatic high threshold"),
      number(e, "auto_min_high_threshold", "edges-auto-min-high", &edges->auto_min_high_threshold,
             "Floor of the automatic high threshold (grey levels/px)"),
      number(e, "auto_low_ratio", "edges-auto-low-ratio", &edges->auto_low_ratio,
             "Automatic low threshold as a fraction of the high one"),
      number(c, "min_length_px", "chains-min-length", &o->chains.min_length_px,
             "Chains with fewer pixels are dropped (px)"),
      number(c, "max_turn_deg", "chains-max-turn", &o->chains.max_turn_deg,
             "Split a chain where it turns by more than this over the turn window (deg)"),
      number(c, "turn_window_px", "chains-turn-window", &o->chains.turn_window_px,
             "Window of the turn measure (chain pixels)"),
      number("field", "max_distance_px", "field-max-distance", &o->field.max_distance_px,
             "Reach of the nearest-edge field (px)"),
  };
}

OptionFields depthFields(EpipolarDepthOptions* d) {
  const std::string g = "depth";
  return {
      number(g, "min_depth_m", "depth-min", &d->min_depth_m, "Nearest depth searched (m)"),
      number(g, "max_depth_m", "depth-max", &d->max_depth_m,
             "Farthest depth searched (m); inf searches to the vanishing point"),
      number(g, "min_parallax_deg", "depth-min-parallax", &d->min_parallax_deg,
             "Least parallax of a reference frame at the mid-range depth (deg)"),
      number(g, "max_optical_axis_angle_deg", "depth-max-axis-angle",
             &d->max_optical_axis_angle_deg,
             "Largest angle between the optical axes of keyframe and reference (deg)"),
      number(g, "max_gradient_epipolar_angle_deg", "depth-max-gradient-epipolar-angle",
             &d->max_gradient_epipolar_angle_deg,
             "Largest angle between a pixel's gradient and its epipolar line (deg)"),
      number(g, "patch_half_size_1d", "depth-patch-1d", &d->patch_half_size_1d,
             "Half size of the 1D patch along the epipolar line (samples)"),
      number(g, "patch_half_size_2d", "depth-patch-2d", &d->patch_half_size_2d,
             "Half size of the square 2D check patch (px)"),
      number(g, "max_candidates", "depth-max-candidates", &d->max_candidates,
             "Best 1D minima kept for the 2D check"),
      boolean(g, "subtract_patch_mean", "depth-subtract-patch-mean", &d->subtract_patch_mean,
              "Compare patches after subtracting their means"),
      number(g, "max_patch_rms_grey", "depth-max-patch-rms", &d->max_patch_rms_grey,
             "Largest RMS patch difference of a match (grey levels)"),
      number(g, "max_ambiguity_ratio", "depth-max-ambiguity-ratio", &d->max_ambiguity_ratio,
             "Best 2D cost at most this fraction of the next best"),
      number(g, "image_noise_sigma_grey", "depth-image-noise", &d->image_noise_sigma_grey,
             "Image noise std dev (grey levels)"),
      number(g, "epipolar_sigma_px", "depth-epipolar-sigma", &d->epipolar_sigma_px,
             "Std dev of the epipolar line position from pose error (px)"),
      number(g, "max_relative_inverse_depth_sigma", "depth-max-relative-sigma",
             &d->max_relative_inverse_depth_sigma,
             "Largest inverse-depth std dev as a fraction of the inverse depth"),
      number(g, "pixel_step", "depth-pixel-step", &d->pixel_step,
             "Search every k-th chain pixel (px)"),
      number(g, "smoothing_half_window", "depth-smoothing-half-window", &d->smoothing_half_window,
             "Half window of the robust average along a chain (pixels); 0 turns it off"),
      number(g, "min_window_support", "depth-min-window-support", &d->min_window_support,
             "Least consistent depths in a pixel's window"),
      number(g, "outlier_sigmas", "depth-outlier-sigmas", &d->outlier_sigmas,
             "Outlier distance from the window median (std devs)"),
  };
}

OptionFields initialiserFields(CurveInitialiserOptions* i) {
  const std::string g = "initialiser";
  return {
      number(g, "pixels_per_segment", "init-pixels-per-segment", &i->pixels_per_segment,
             "Target lifted pixels per Bezier segment"),
      number(g, "min_segments", "init-min-segments", &i->min_segments,
             "Curves with fewer segments are dropped"),
      number(g, "max_gap_px", "init-max-gap", &i->max_gap_px,
             "Longest bridged run of pixels without depth (chain pixels)"),
      number(g, "max_relative_depth_jump", "init-max-depth-jump", &i->max_relative_depth_jump,
             "A run ends at a relative depth jump above this"),
      number(g, "max_rms_residual_rel_chord", "init-max-rms-residual",
             &i->max_rms_residual_rel_chord,
             "Reject a segment whose RMS fit residual exceeds this fraction of its chord"),
      number(g, "min_chord_m", "init-min-chord", &i->min_chord_m,
             "Reject segments with a shorter chord (m)"),
      number(g, "max_arm_to_chord", "init-max-arm-to-chord", &i->max_arm_to_chord,
             "Reject a segment whose arm exceeds this multiple of its chord"),
  };
}

OptionFields matchAndMapFields(CorrespondenceOptions* c, CurveMapOptions* m) {
  const std::string g = "correspondence", h = "map";
  return {
      number(g, "samples_per_segment", "match-samples-per-segment", &c->samples_per_segment,
             "Samples per segment of the checks"),
      number(g, "min_depth_m", "match-min-depth", &c->min_depth_m,
             "Least depth of every sample in the new camera (m)"),
      number(g, "max_mean_edge_distance_px", "match-max-edge-distance",
             &c->max_mean_edge_distance_px, "Largest mean distance to the nearest edge (px)"),
      number(g, "appearance_half_width_px", "match-appearance-half-width",
             &c->appearance_half_width_px, "Half width of the appearance band (px)"),
      number(g, "hue_weight", "match-hue-weight", &c->hue_weight,
             "Weight lambda of the hue term of the appearance error"),
      number(g, "max_appearance_error", "match-max-appearance-error", &c->max_appearance_error,
             "Largest HSV appearance error"),
      number(g, "max_viewing_angle_deg", "match-max-viewing-angle", &c->max_viewing_angle_deg,
             "Largest angle to the mean earlier viewing direction (deg)"),
      number(h, "promotion_observations", "map-promotion-observations", &m->promotion_observations,
             "Keyframes that move a temporary curve to the global map"),
      number(h, "disable_window_keyframes", "map-disable-window", &m->disable_window_keyframes,
             "Recent keyframes over which a curve must stay visible"),
      number(h, "disable_unseen_fraction", "map-disable-unseen-fraction",
             &m->disable_unseen_fraction,
             "Disable a curve when more of its segments than this went unseen in the window"),
      number(h, "min_keyframe_translation", "map-keyframe-translation",
             &m->min_keyframe_translation,
             "New keyframe when the initial camera centre moved more than this (pose units)"),
      number(h, "min_keyframe_rotation_deg", "map-keyframe-rotation", &m->min_keyframe_rotation_deg,
             "... or turned more than this (deg)"),
  };
}

OptionFields objectiveFields(CurveBundleAdjustmentOptions* b) {
  const std::string g = "ba";
  return {
      number(g, "samples_per_segment", "ba-samples-per-segment", &b->samples_per_segment,
             "s: residuals per (segment, keyframe) pair are s + 1"),
      boolean(g, "use_subpixel_edges", "ba-subpixel-edges", &b->use_subpixel_edges,
              "Measure against the sub-pixel edge position"),
      number(g, "max_normal_angle_deg", "ba-max-normal-angle", &b->max_normal_angle_deg,
             "Match only edges whose normal is within this angle of the curve's (deg)"),
      number(g, "pixel_sigma", "ba-pixel-sigma", &b->pixel_sigma,
             "Std dev of an edge residual (px)"),
      enumeration(g, "kernel", "ba-kernel", &b->kernel, parseRobustKernelType,
                  "Robust kernel on edge residuals: none, huber, cauchy, tukey"),
      number(g, "kernel_width", "ba-kernel-width", &b->kernel_width, "Kernel width (sigmas)"),
      number(g, "lambda1", "ba-lambda1", &b->lambda1, "Weight of the segment-length term"),
      number(g, "lambda2", "ba-lambda2", &b->lambda2, "Weight of the tangent term"),
      boolean(g, "fix_first_pose", "ba-fix-first-pose", &b->fix_first_pose,
              "Hold keyframe 0 constant (rotation and translation gauge)"),
      boolean(g, "fix_scale", "ba-fix-scale", &b->fix_scale,
              "Hold the distance between keyframes 0 and 1 (scale gauge)"),
      number(g, "scale_sigma", "ba-scale-sigma", &b->scale_sigma,
             "Std dev of that distance constraint (pose units)"),
  };
}

// `what` names the solve in the descriptions, e.g. "local BA".
OptionFields optimizerFields(const std::string& group, const std::string& prefix,
                             const std::string& what, OptimizerOptions* o) {
  const std::string g = group + "/optimizer", p = prefix;
  return {
      enumeration(g, "linear_solver", p + "linear-solver", &o->linear_solver, parseLinearSolver,
                  what + ": linear solver (sparse_schur, dense_schur, iterative_schur, "
                         "sparse_normal_cholesky)"),
      enumeration(g, "trust_region", p + "trust-region", &o->trust_region, parseTrustRegion,
                  what + ": levenberg_marquardt or dogleg"),
      number(g, "max_iterations", p + "max-iterations", &o->max_iterations,
             what + ": most solver iterations per solve"),
      number(g, "num_threads", p + "threads", &o->num_threads, what + ": solver threads"),
      number(g, "function_tolerance", p + "function-tolerance", &o->function_tolerance,
             what + ": relative cost change to stop at"),
      number(g, "gradient_tolerance", p + "gradient-tolerance", &o->gradient_tolerance,
             what + ": max gradient to stop at"),
      number(g, "parameter_tolerance", p + "parameter-tolerance", &o->parameter_tolerance,
             what + ": relative step to stop at"),
      boolean(g, "structure_first_ordering", p + "structure-first", &o->structure_first_ordering,
              what + ": Schur order structure first (false: Ceres chooses)"),
      boolean(g, "use_inner_iterations", p + "inner-iterations", &o->use_inner_iterations,
              what + ": Ceres inner iterations"),
      boolean(g, "verbose", p + "verbose", &o->verbose, what + ": print Ceres' iteration log"),
  };
}

OptionFields schedulerFields(const std::string& group, const std::string& prefix,
                             const std::string& what, SchedulerOptions* s) {
  OptionFields fields = {
      enumeration(group, "strategy", prefix + "strategy", &s->strategy, parseStrategy,
                  what + ": joint, alternating or inner_iterations"),
      enumeration(group, "scope", prefix + "scope", &s->scope, parseScope,
                  what + ": global (all variables) or local (the last keyframes)"),
      number(group, "local_window", prefix + "local-window", &s->local_window,
             what + ": free keyframes in local scope"),
      number(group, "max_rounds", prefix + "max-rounds", &s->max_rounds,
             what + ": most alternating rounds"),
      number(group, "round_tolerance", prefix + "round-tolerance", &s->round_tolerance,
             what + ": stop alternating when a round gains less than this fraction"),
      boolean(group, "fix_first_pose", prefix + "fix-first-pose", &s->fix_first_pose,
              what + ": hold the first keyframe constant"),
  };
  append(&fields, optimizerFields(group, prefix, what, &s->optimizer));
  return fields;
}

OptionFields pipelineFields(PipelineOptions* o) {
  const std::string g = "pipeline";
  OptionFields fields = imageFields(o);
  append(&fields, depthFields(&o->depth));
  append(&fields, initialiserFields(&o->initialiser));
  append(&fields, matchAndMapFields(&o->correspondence, &o->map));
  append(&fields, objectiveFields(&o->ba));
  append(&fields, schedulerFields("local_ba", "local-ba-", "local BA", &o->local_ba));
  append(&fields, schedulerFields("global_ba", "global-ba-", "global BA", &o->global_ba));
  append(&fields, optimizerFields("tracking", "track-", "pose tracking", &o->tracking));
  append(
      &fields,
      {
          boolean(g, "run_global_ba", "run-global-ba", &o->run_global_ba,
                  "Run global BA after the last frame"),
          number(g, "reassociation_rounds", "reassociation-rounds", &o->reassociation_rounds,
                 "After global BA: rounds of re-registering every curve in every keyframe, each "
                 "followed by global BA (0: none)"),
          number(g, "depth_reference_candidates", "depth-reference-candidates",
                 &o->depth_reference_candidates, "Recent keyframes considered as depth references"),
          boolean(g, "track_keyframe_pose", "track-keyframe-pose", &o->track_keyframe_pose,
                  "Refine a new keyframe's starting pose against the map before registration"),
          number(g, "explained_radius_px", "explained-radius", &o->explained_radius_px,
                 "Chain pixels this close to a registered segment seed no new curve (px)"),
      });
  return fields;
}

nlohmann::json overlayOptionsToJson(const CurveOverlayOptions& o) {
  return {{"samples_per_segment", o.samples_per_segment},
          {"thickness_px", o.thickness_px},
          {"point_radius_px", o.point_radius_px}};
}

// Every field of every stage, enums by name.
nlohmann::json pipelineOptionsToJson(PipelineOptions options) {
  nlohmann::json json = nlohmann::json::object();
  for (const OptionField& f : pipelineFields(&options)) {
    json[nlohmann::json::json_pointer("/" + f.group + "/" + f.field)] = f.value();
  }
  return json;
}

// ---------------------------------------------------------------------------------------------
// Input.

struct Frame {
  double timestamp = 0.0;
  std::string image_path;
  Pose3 initial_cam_from_world;
};

struct Dataset {
  std::string camera_path, rgb_path, init_poses_path, ground_truth_path;
  std::optional<Camera> camera;
  int images = 0;                         // Listed in rgb.txt.
  std::vector<Frame> frames;              // Images with an initial pose, in rgb.txt order.
  std::vector<StampedPose> ground_truth;  // Empty without groundtruth.txt.
};

std::string joinPath(const std::string& dir, const std::string& name) {
  return (fs::path(dir) / name).string();
}

// DIR/init_poses.txt unless --init-poses names a file; until an automatic initialiser exists
// a run cannot start without one.
std::string initPosesPath(const std::string& dataset_dir, const std::string& flag) {
  if (!flag.empty()) return flag;
  const std::string fallback = joinPath(dataset_dir, "init_poses.txt");
  if (fs::exists(fallback)) return fallback;
  throw IoError(fallback,
                "no such file and no --init-poses given; an automatic initialiser is not "
                "available yet: pass --init-poses FILE, a TUM trajectory "
                "'timestamp tx ty tz qx qy qz qw' (camera-to-world) covering the images");
}

std::string timeSpan(const std::vector<double>& times) {
  char text[64];
  const auto [low, high] = std::minmax_element(times.begin(), times.end());
  std::snprintf(text, sizeof(text), "%.6f .. %.6f s", *low, *high);
  return text;
}

std::vector<Frame> matchFrames(const std::vector<ImageEntry>& images,
                               const std::vector<StampedPose>& poses, double max_dt,
                               const Dataset& d) {
  std::vector<StampedPose> image_times(images.size());
  std::vector<double> image_stamps, pose_stamps;
  for (std::size_t i = 0; i < images.size(); ++i) {
    image_times[i].timestamp = images[i].timestamp;
    image_stamps.push_back(images[i].timestamp);
  }
  for (const StampedPose& pose : poses) pose_stamps.push_back(pose.timestamp);
  std::vector<Frame> frames;
  for (const TimestampMatch& m : associateByTimestamp(image_times, poses, max_dt)) {
    const ImageEntry& image = images[m.estimate_index];
    frames.push_back(
        {image.timestamp, image.path, poses[m.ground_truth_index].world_from_cam.inverse()});
  }
  if (frames.empty()) {
    char within[32];
    std::snprintf(within, sizeof(within), "%g", max_dt);
    throw ParseError(
        d.init_poses_path, 0,
        "poses within " + std::string(within) + " s of the images of " + d.rgb_path + " (" +
            timeSpan(image_stamps) + ")",
        "none of its " + std::to_string(poses.size()) + " poses (" + timeSpan(pose_stamps) + ")");
  }
  return frames;
}

// A missing file or one whose header names no format OpenCV reads fails here, before any
// work, with readColorImage()'s message; decoding waits for the run.
void checkImageFile(const std::string& path) {
  if (!fs::exists(path) || !cv::haveImageReader(path)) readColorImage(path);
}

// Reads every file but the images, so that a bad one fails before any work; images are
// checked here and decoded one at a time during the run.
Dataset loadDataset(const std::string& dir, const std::string& init_poses_flag, double max_dt) {
  Dataset d;
  d.camera_path = joinPath(dir, "camera.yaml");
  d.rgb_path = joinPath(dir, "rgb.txt");
  d.camera.emplace(readCameraYaml(d.camera_path));
  const std::vector<ImageEntry> images = readImageList(d.rgb_path);
  d.images = static_cast<int>(images.size());
  d.init_poses_path = initPosesPath(dir, init_poses_flag);
  d.frames = matchFrames(images, readTrajectory(d.init_poses_path), max_dt, d);
  const std::string ground_truth = joinPath(dir, "groundtruth.txt");
  if (fs::exists(ground_truth)) {
    d.ground_truth_path = ground_truth;
    d.ground_truth = readTrajectory(ground_truth);
  }
  for (const Frame& frame : d.frames) checkImageFile(frame.image_path);
  return d;
}

cv::Mat loadImage(const Frame& frame, const Camera& camera) {
  cv::Mat image = readColorImage(frame.image_path);
  if (image.cols != camera.width() || image.rows != camera.height()) {
    throw IoError(frame.image_path, "is " + std::to_string(image.cols) + "x" +
                                        std::to_string(image.rows) + " px, camera.yaml says " +
                                        std::to_string(camera.width()) + "x" +
                                        std::to_string(camera.height()));
  }
  return image;
}

// ---------------------------------------------------------------------------------------------
// Run.

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

void printProgress(const KeyframeStats& s, int frames) {
  std::printf(
      "frame %d/%d keyframe %d: curves %d global / %d temporary, registered %d (rejected %d: "
      "%d duplicate, %d edge distance, %d appearance, %d other), new %d, frontend %.0f ms, "
      "local BA %.0f ms\n",
      s.frame_index + 1, frames, s.keyframe_index, s.global_curves, s.temporary_curves,
      s.registered_segments, s.rejectedSegments(), s.rejected_duplicate, s.rejected_edge_distance,
      s.rejected_appearance, s.rejected_depth + s.rejected_viewing_direction, s.new_curves,
      1e3 * s.frontendSeconds(), 1e3 * s.local_ba_seconds);
  std::fflush(stdout);
}

std::vector<KeyframeStats> feedFrames(Pipeline* pipeline, const Dataset& d) {
  std::vector<KeyframeStats> stats;
  const int n = static_cast<int>(d.frames.size());
  for (const Frame& frame : d.frames) {
    const KeyframeStats s = pipeline->addFrame(
        {frame.timestamp, loadImage(frame, *d.camera), frame.initial_cam_from_world});
    if (s.keyframe_index >= 0) printProgress(s, n);
    stats.push_back(s);
  }
  return stats;
}

std::vector<StampedPose> stamped(const std::vector<double>& timestamps,
                                 const std::vector<Pose3>& cam_from_world) {
  std::vector<StampedPose> poses(timestamps.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    poses[k] = {timestamps[k], cam_from_world[k].inverse()};
  }
  return poses;
}

// ATE (Sim(3)) of the initial and refined keyframe trajectories, when there is a ground truth.
struct AteResult {
  std::optional<TrajectoryEvaluation> initial, refined;
  std::string problem;  // Why they are missing, if they are.
};

AteResult evaluateAte(const PipelineResult& r, const Dataset& d) {
  AteResult ate;
  if (d.ground_truth.empty()) return ate;
  try {
    const TrajectoryEvaluationOptions options;  // Sim(3), 0.02 s.
    ate.initial =
        compareTrajectories(stamped(r.keyframe_timestamps, r.keyframe_initial_cam_from_world),
                            d.ground_truth, options, "initial keyframes", d.ground_truth_path);
    ate.refined =
        compareTrajectories(stamped(r.keyframe_timestamps, r.keyframe_cam_from_world),
                            d.ground_truth, options, "refined keyframes", d.ground_truth_path);
  } catch (const TrajectoryEvaluationError& e) {
    ate.problem = e.what();
  }
  return ate;
}

// ---------------------------------------------------------------------------------------------
// Output.

int writeOverlays(const std::string& dir, const Pipeline& pipeline, const PipelineResult& r,
                  const CurveOverlayOptions& options) {
  fs::create_directories(dir);
  for (std::size_t k = 0; k < r.keyframe_cam_from_world.size(); ++k) {
    cv::Mat image = pipeline.keyframeImage(static_cast<int>(k)).clone();
    drawCurves(&image, r.curves, pipeline.undistortedCamera(), r.keyframe_cam_from_world[k],
               options);
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu.png", k);
    writeImage(joinPath(dir, name), image);
  }
  return static_cast<int>(r.keyframe_cam_from_world.size());
}

nlohmann::json frameToJson(const KeyframeStats& s) {
  return {
      {"frame_index", s.frame_index},
      {"keyframe_index", s.keyframe_index},
      {"timestamp", s.timestamp},
      {"seconds",
       {{"undistort", s.undistort_seconds},
        {"edges", s.edges_seconds},
        {"field", s.field_seconds},
        {"depth", s.depth_seconds},
        {"correspondence", s.correspondence_seconds},
        {"initialise", s.initialise_seconds},
        {"frontend", s.frontendSeconds()},
        {"local_ba", s.local_ba_seconds}}},
      {"edge_pixels", s.edge_pixels},
      {"chains", s.chains},
      {"valid_depths", s.valid_depths},
      {"registered_segments", s.registered_segments},
      {"rejected_segments",
       {{"total", s.rejectedSegments()},
        {"duplicate", s.rejected_duplicate},
        {"depth", s.rejected_depth},
        {"edge_distance", s.rejected_edge_distance},
        {"viewing_direction", s.rejected_viewing_direction},
        {"appearance", s.rejected_appearance}}},
      {"new_curves", s.new_curves},
      {"global_curves", s.global_curves},
      {"temporary_curves", s.temporary_curves},
      {"local_ba_cost", {{"initial", s.local_ba_initial_cost}, {"final", s.local_ba_final_cost}}}};
}

// Costs per factor type before the first and after the last solve of global BA.
nlohmann::json globalCostsToJson(const ScheduleReport& report) {
  const ScheduleRound* first = nullptr;
  const ScheduleRound* last = nullptr;
  for (const ScheduleRound& round : report.rounds) {
    if (round.skipped) continue;
    if (!first) first = &round;
    last = &round;
  }
  if (!first) return nlohmann::json::object();
  return {{"initial", costsToJson(first->summary.initial_cost_by_type)},
          {"final", costsToJson(last->summary.final_cost_by_type)}};
}

nlohmann::json ateToJson(const AteResult& ate) {
  const auto stats = [](const std::optional<TrajectoryEvaluation>& e) -> nlohmann::json {
    if (!e) return nullptr;
    const ErrorStatistics& s = e->ate;
    return {{"matched", s.count}, {"rmse", s.rmse},
            {"mean", s.mean},     {"median", s.median},
            {"std", s.std},       {"min", s.min},
            {"max", s.max},       {"scale", e->ground_truth_from_estimate.scale}};
  };
  return {{"alignment", "sim3"},
          {"initial_m", stats(ate.initial)},
          {"refined_m", stats(ate.refined)},
          {"problem", ate.problem}};
}

void writeConfigYaml(const std::string& path, const CLI::App& command) {
  std::ofstream out(path);
  if (!(out << "# curvesfm run: the options in force; rerun with --config " << path << "\n"
            << effectiveOptionsYaml(command))) {
    throw IoError(path, "cannot write");
  }
}

void printAte(const AteResult& ate, const std::string& ground_truth_path) {
  if (ate.initial && ate.refined) {
    std::printf(
        "ATE (sim3) vs %s over %d keyframes: initial rmse %.6f m (max %.6f), refined rmse "
        "%.6f m (max %.6f)\n",
        ground_truth_path.c_str(), ate.refined->ate.count, ate.initial->ate.rmse,
        ate.initial->ate.max, ate.refined->ate.rmse, ate.refined->ate.max);
  } else if (!ate.problem.empty()) {
    std::printf("ATE: not computed: %s\n", ate.problem.c_str());
  }
}

// The frontend budget is per keyframe; local BA is reported apart.
void printFrontendStages(const std::vector<KeyframeStats>& frames) {
  const KeyframeTimes t = keyframeTimes(frames);
  if (t.keyframes == 0) return;
  std::printf(
      "frontend per keyframe (mean ms): undistort %.1f, edges %.1f, field %.1f, depth %.1f, "
      "correspondence %.1f, initialise %.1f; total %.1f, slowest keyframe %.1f\n",
      t.undistort_ms, t.edges_ms, t.field_ms, t.depth_ms, t.correspondence_ms, t.initialise_ms,
      t.frontend_ms, t.slowest_frontend_ms);
}

void printSummary(const Dataset& d, const PipelineResult& r, double seconds) {
  double frontend = 0.0, local_ba = 0.0;
  for (const KeyframeStats& s : r.frames) {
    frontend += s.frontendSeconds();
    local_ba += s.local_ba_seconds;
  }
  const CurveSampleCounts& samples = r.final_samples;
  std::printf(
      "run: %zu frames (%d of %d images without an initial pose skipped), %zu keyframes, "
      "%zu curves (%d segments) in the global map\n",
      d.frames.size(), d.images - static_cast<int>(d.frames.size()), d.images,
      r.keyframe_cam_from_world.size(), r.curves.size(), totalSegments(r.curves));
  if (!r.global_ba.rounds.empty()) {
    std::printf("global BA: cost %.6g -> %.6g, %d iterations, %.2f s (%s)\n",
                r.global_ba.initial_cost, r.global_ba.final_cost, r.global_ba.total_iterations,
                r.global_ba.total_seconds, r.global_ba.stop_reason.c_str());
  }
  for (std::size_t i = 0; i < r.reassociation.size(); ++i) {
    const ScheduleReport& ba = r.reassociation[i].global_ba;
    std::printf("re-association %zu: %d observations added, global BA cost %.6g -> %.6g, %.2f s\n",
                i + 1, r.reassociation[i].added_observations, ba.initial_cost, ba.final_cost,
                ba.total_seconds);
  }
  std::printf(
      "samples: %d on field, %d behind camera, %d outside image, %d beyond reach, %d wrong "
      "orientation\n",
      samples.on_field, samples.behind_camera, samples.outside_image, samples.beyond_reach,
      samples.wrong_orientation);
  std::printf("time: frontend %.2f s, local BA %.2f s, global BA %.2f s, total %.2f s\n", frontend,
              local_ba, r.globalBaSeconds(), seconds);
  printFrontendStages(r.frames);
}

nlohmann::json reassociationToJson(const std::vector<ReassociationRound>& rounds) {
  nlohmann::json json = nlohmann::json::array();
  for (const ReassociationRound& round : rounds) {
    json.push_back({{"added_observations", round.added_observations},
                    {"global_ba", scheduleReportToJson(round.global_ba)}});
  }
  return json;
}

bool globalBaUsable(const ScheduleReport& report) {
  for (const ScheduleRound& round : report.rounds) {
    if (!round.skipped && !round.summary.usable) return false;
  }
  return true;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

RunCommand::RunCommand(CLI::App* app) {
  command_ = app->add_subcommand(
      "run",
      "Curve structure from motion on a TUM RGB-D layout dataset (rgb.txt, camera.yaml, initial "
      "poses): writes trajectory.txt, curves.ply, curves.obj, report.json, config.yaml and, with "
      "--overlays, the curves drawn on each keyframe.");
  addConfigFlag(command_);
  CLI::App* c = command_;
  c->add_option("--dataset", dataset_dir_,
                "Dataset folder: rgb.txt, camera.yaml, optional groundtruth.txt and init_poses.txt")
      ->required();
  c->add_option("--out", out_dir_, "Output folder (created if needed)")->required();
  c->add_option("--init-poses", init_poses_path_,
                "Initial poses, TUM lines 'timestamp tx ty tz qx qy qz qw' (camera-to-world); "
                "default DATASET/init_poses.txt");
  c->add_option("--max-dt", max_dt_,
                "Largest time difference between an image and its initial pose (s)")
      ->capture_default_str();
  c->add_flag("--overlays", overlays_,
              "Write OUT/overlays/NNNNNN.png: the final curves drawn on keyframe NNNNNN");
  c->add_option("--overlay-samples", overlay_.samples_per_segment,
                "Samples per segment of the overlay polylines")
      ->capture_default_str();
  c->add_option("--overlay-thickness", overlay_.thickness_px, "Overlay line thickness (px)")
      ->capture_default_str();
  c->add_option("--overlay-point-radius", overlay_.point_radius_px,
                "Radius of the circles on the curve points Q (px); 0 draws none")
      ->capture_default_str();
  c->add_option("--export-samples", export_samples_per_segment_,
                "Samples per segment of the curves in curves.ply and curves.obj")
      ->capture_default_str();
  for (const OptionField& field : pipelineFields(&options_)) field.add(c);
}

void RunCommand::validate() const {
  options_.validate();
  overlay_.validate();
  if (export_samples_per_segment_ < 1 || export_samples_per_segment_ > 1000) {
    throw InvalidOptions("RunCommand", "export-samples",
                         std::to_string(export_samples_per_segment_), "in [1, 1000]");
  }
  if (!(max_dt_ >= 0.0 && max_dt_ < 1e6)) {
    throw InvalidOptions("RunCommand", "max-dt", std::to_string(max_dt_), "finite and >= 0");
  }
}

int RunCommand::run() const {
  validate();
  const Clock::time_point start = Clock::now();
  const Dataset d = loadDataset(dataset_dir_, init_poses_path_, max_dt_);
  std::error_code error;
  fs::create_directories(out_dir_, error);
  if (error) throw IoError(out_dir_, "cannot create the output folder: " + error.message());
  std::printf("run: %s, %zu of %d images with an initial pose (%s), camera %dx%d\n",
              dataset_dir_.c_str(), d.frames.size(), d.images, d.init_poses_path.c_str(),
              d.camera->width(), d.camera->height());

  Pipeline pipeline(*d.camera, options_);
  feedFrames(&pipeline, d);
  const PipelineResult result = pipeline.finish();
  const AteResult ate = evaluateAte(result, d);

  writeTrajectory(joinPath(out_dir_, "trajectory.txt"),
                  stamped(result.keyframe_timestamps, result.keyframe_cam_from_world));
  writeCurvesPly(joinPath(out_dir_, "curves.ply"), result.curves, export_samples_per_segment_);
  writeCurvesObj(joinPath(out_dir_, "curves.obj"), result.curves, export_samples_per_segment_);
  writeConfigYaml(joinPath(out_dir_, "config.yaml"), *command_);
  const int overlays =
      overlays_ ? writeOverlays(joinPath(out_dir_, "overlays"), pipeline, result, overlay_) : 0;

  nlohmann::json frames = nlohmann::json::array();
  for (const KeyframeStats& s : result.frames) frames.push_back(frameToJson(s));
  const double seconds = secondsSince(start);
  writeJsonFile(joinPath(out_dir_, "report.json"),
                {{"command", "run"},
                 {"config", optionsToJson(*command_)},
                 {"options",
                  {{"pipeline", pipelineOptionsToJson(options_)},
                   {"overlay", overlayOptionsToJson(overlay_)},
                   {"export_samples_per_segment", export_samples_per_segment_}}},
                 {"dataset",
                  {{"dir", dataset_dir_},
                   {"camera", d.camera_path},
                   {"rgb", d.rgb_path},
                   {"init_poses", d.init_poses_path},
                   {"groundtruth", d.ground_truth_path},
                   {"images", d.images},
                   {"frames_with_initial_pose", d.frames.size()}}},
                 {"counts",
                  {{"frames", d.frames.size()},
                   {"keyframes", result.keyframe_cam_from_world.size()},
                   {"curves", result.curves.size()},
                   {"segments", totalSegments(result.curves)},
                   {"overlays", overlays}}},
                 {"frames", frames},
                 {"global_ba", scheduleReportToJson(result.global_ba)},
                 {"global_ba_cost_by_type", globalCostsToJson(result.global_ba)},
                 {"reassociation", reassociationToJson(result.reassociation)},
                 {"final_samples", sampleCountsToJson(result.final_samples)},
                 {"ate", ateToJson(ate)},
                 {"total_seconds", seconds}});

  printSummary(d, result, seconds);
  printAte(ate, d.ground_truth_path);
  std::printf("written: %s (trajectory.txt, curves.ply, curves.obj, report.json, config.yaml%s)\n",
              out_dir_.c_str(), overlays_ ? ", overlays/" : "");
  if (result.curves.empty()) {
    std::fprintf(stderr,
                 "run: no curve reached the global map: nothing was reconstructed (see "
                 "the keyframe lines and report.json)\n");
    return 1;
  }
  std::vector<const ScheduleReport*> global_solves = {&result.global_ba};
  for (const ReassociationRound& round : result.reassociation) {
    global_solves.push_back(&round.global_ba);
  }
  for (const ScheduleReport* report : global_solves) {
    if (!globalBaUsable(*report)) {
      std::fprintf(stderr, "run: global BA failed: %s\n", report->stop_reason.c_str());
      return 1;
    }
  }
  return 0;
}

}  // namespace curvesfm
