#include "apps/cli/pipeline_flags.h"

#include <functional>
#include <string>
#include <vector>

#include "apps/cli/cli_options.h"

namespace curvesfm {
namespace {

// One table row per PipelineOptions field gives its flag (and so its --config key) and its
// report.json entry.
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
                        Enum* target, const std::string& description) {
  return {group, field, [=](CLI::App* c) { addEnumFlag(c, flag, target, description); },
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
      enumeration(g, "kernel", "ba-kernel", &b->kernel,
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
      boolean(g, "motion_prior", "ba-motion-prior", &b->motion_prior,
              "Tie the motion between consecutive keyframes to the initial poses'"),
      number(g, "motion_prior_rotation_sigma_deg", "ba-motion-prior-rotation",
             &b->motion_prior_rotation_sigma_deg,
             "Std dev per axis of that motion's rotation (deg)"),
      number(g, "motion_prior_translation_sigma_rel", "ba-motion-prior-translation",
             &b->motion_prior_translation_sigma_rel,
             "Std dev per axis of that motion's translation, as a fraction of the mean distance "
             "between consecutive keyframes"),
  };
}

// `what` names the solve in the descriptions, e.g. "local BA".
OptionFields optimizerFields(const std::string& group, const std::string& prefix,
                             const std::string& what, OptimizerOptions* o) {
  const std::string g = group + "/optimizer", p = prefix;
  return {
      enumeration(g, "linear_solver", p + "linear-solver", &o->linear_solver,
                  what + ": linear solver (sparse_schur, dense_schur, iterative_schur, "
                         "sparse_normal_cholesky)"),
      enumeration(g, "trust_region", p + "trust-region", &o->trust_region,
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
      enumeration(group, "strategy", prefix + "strategy", &s->strategy,
                  what + ": joint, alternating or inner_iterations"),
      enumeration(group, "scope", prefix + "scope", &s->scope,
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

OptionFields extensionFields(CurveExtensionOptions* o) {
  const std::string g = "extension";
  return {
      boolean(g, "enabled", "extend-curves", &o->enabled,
              "Append a new curve that continues an existing curve's end to that curve"),
      number(g, "max_gap_px", "extend-max-gap", &o->max_gap_px,
             "Largest gap between the projected end points (px)"),
      number(g, "max_lateral_px", "extend-max-lateral", &o->max_lateral_px,
             "Largest offset across the existing end's image tangent, and overlap behind it (px)"),
      number(g, "max_angle_deg", "extend-max-angle", &o->max_angle_deg,
             "Largest angle between the two curves' image directions at the join (deg)"),
      number(g, "max_relative_depth_gap", "extend-max-depth-gap", &o->max_relative_depth_gap,
             "Largest 3D gap between the end points, as a fraction of the existing end's depth"),
  };
}

OptionFields pipelineFields(PipelineOptions* o) {
  const std::string g = "pipeline";
  OptionFields fields = imageFields(o);
  append(&fields, depthFields(&o->depth));
  append(&fields, initialiserFields(&o->initialiser));
  append(&fields, extensionFields(&o->extension));
  append(&fields, matchAndMapFields(&o->correspondence, &o->map));
  append(&fields, objectiveFields(&o->ba));
  append(&fields, schedulerFields("local_ba", "local-ba-", "local BA", &o->local_ba));
  fields.push_back(boolean("local_ba", "refine_poses", "local-ba-refine-poses",
                           &o->local_ba_refines_poses,
                           "local BA: move the window's poses too (else curves alone)"));
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

}  // namespace

void addPipelineFlags(CLI::App* command, PipelineOptions* options) {
  for (const OptionField& field : pipelineFields(options)) field.add(command);
}

nlohmann::json pipelineOptionsToJson(PipelineOptions options) {
  nlohmann::json json = nlohmann::json::object();
  for (const OptionField& f : pipelineFields(&options)) {
    json[nlohmann::json::json_pointer("/" + f.group + "/" + f.field)] = f.value();
  }
  return json;
}

}  // namespace curvesfm
