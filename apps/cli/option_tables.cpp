#include "apps/cli/option_tables.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <locale>
#include <sstream>
#include <vector>

#include "core/errors.h"

namespace curvesfm {
namespace {

// "x,y,z" for a vector flag; InvalidOptions naming `struct_name`.`field` for anything else.
Eigen::Vector3d parseVector3(const std::string& text, const std::string& struct_name,
                             const std::string& field) {
  std::istringstream in(text);
  in.imbue(std::locale::classic());
  Eigen::Vector3d v;
  char comma1 = 0, comma2 = 0;
  in >> v.x() >> comma1 >> v.y() >> comma2 >> v.z();
  const bool whole = in && (in >> std::ws).eof();
  if (!whole || comma1 != ',' || comma2 != ',' || !v.allFinite()) {
    throw InvalidOptions(struct_name, field, "\"" + text + "\"",
                         "expected three numbers \"x,y,z\"");
  }
  return v;
}

// "a,b,c" (one or more numbers) for a list flag; InvalidOptions naming `struct_name`.`field`.
std::vector<double> parseNumberList(const std::string& text, const std::string& struct_name,
                                    const std::string& field) {
  std::vector<double> values;
  std::istringstream in(text);
  in.imbue(std::locale::classic());
  for (;;) {
    double value = 0.0;
    if (!(in >> value) || !std::isfinite(value)) {
      throw InvalidOptions(struct_name, field, "\"" + text + "\"",
                           "expected comma-separated numbers \"a,b,...\"");
    }
    values.push_back(value);
    char comma = 0;
    if (!(in >> comma)) break;
    if (comma != ',') {
      throw InvalidOptions(struct_name, field, "\"" + text + "\"",
                           "expected comma-separated numbers \"a,b,...\"");
    }
  }
  return values;
}

std::string printNumberList(const std::vector<double>& values) {
  std::string text;
  for (const double value : values) text += (text.empty() ? "" : ",") + formatOptionValue(value);
  return text;
}

std::string printVector3(const Eigen::Vector3d& v) {
  return formatOptionValue(v.x()) + "," + formatOptionValue(v.y()) + "," + formatOptionValue(v.z());
}

OptionPlace stage(const std::string& path, const std::string& field, const std::string& prefix,
                  const std::string& heading) {
  return {path + "/" + field, prefix, heading, ""};
}

void addImageStages(OptionsTable* table, PipelineOptions* o, const std::string& path) {
  OptionPlace u = stage(path, "undistort", "undistort-", "Undistortion");
  table->group(&o->undistort, "ImageUndistorterOptions", u.path, u.prefix, u.heading)
      .number("valid_margin_px", "valid-margin", &o->undistort.valid_margin_px,
              "Band along the border of the undistorted data ignored by edge detection (px)");
  addEdgeDetectorOptions(table, &o->edges, stage(path, "edges", "edges-", "Edges"));
  OptionPlace c = stage(path, "chains", "chains-", "Chains");
  table->group(&o->chains, "EdgeChainOptions", c.path, c.prefix, c.heading)
      .number("min_length_px", "min-length", &o->chains.min_length_px,
              "Chains with fewer pixels are dropped (px)")
      .number("max_turn_deg", "max-turn", &o->chains.max_turn_deg,
              "Split a chain where it turns by more than this over the turn window (deg)")
      .number("turn_window_px", "turn-window", &o->chains.turn_window_px,
              "Window of the turn measure (chain pixels)");
  OptionPlace f = stage(path, "field", "field-", "Nearest-edge field");
  table->group(&o->field, "NearestEdgeFieldOptions", f.path, f.prefix, f.heading)
      .number("max_distance_px", "max-distance", &o->field.max_distance_px,
              "Reach of the nearest-edge field (px)");
}

}  // namespace

void addEdgeDetectorOptions(OptionsTable* table, EdgeDetectorOptions* e, const OptionPlace& place) {
  table->group(e, "EdgeDetectorOptions", place.path, place.prefix, place.heading)
      .number("blur_sigma_px", "blur-sigma", &e->blur_sigma_px,
              "Gaussian blur before differentiation (px); 0 disables it")
      .number("sobel_aperture", "sobel-aperture", &e->sobel_aperture, "Sobel aperture: 3 or 5")
      .number("canny_low_threshold", "canny-low", &e->canny_low_threshold,
              "Canny low threshold (grey levels/px); 0 = auto-low-ratio x high")
      .number("canny_high_threshold", "canny-high", &e->canny_high_threshold,
              "Canny high threshold (grey levels/px); 0 = automatic")
      .number("auto_noise_factor", "auto-noise-factor", &e->auto_noise_factor,
              "Automatic high threshold in gradient noise std devs")
      .number("auto_max_seed_fraction", "auto-max-seed-fraction", &e->auto_max_seed_fraction,
              "Largest fraction of pixels above the automatic high threshold")
      .number("auto_min_high_threshold", "auto-min-high", &e->auto_min_high_threshold,
              "Floor of the automatic high threshold (grey levels/px)")
      .number("auto_low_ratio", "auto-low-ratio", &e->auto_low_ratio,
              "Automatic low threshold as a fraction of the high one");
}

void addEdgeCoverageOptions(OptionsTable* table, EdgeCoverageOptions* o, const OptionPlace& place) {
  table->group(o, "EdgeCoverageOptions", place.path, place.prefix, place.heading)
      .number("max_edge_distance_px", "distance", &o->max_edge_distance_px,
              "A ground-truth point is on an edge in an image when an edge pixel's centre lies "
              "within this distance of the pixel its projection falls in (px) ...")
      .number("max_normal_angle_deg", "normal-angle", &o->max_normal_angle_deg,
              "... and that pixel's edge normal within this angle of the projected curve's "
              "normal (deg)")
      .nested("edges");
  OptionPlace edges = place.child("edges");
  edges.prefix += "edges-";
  addEdgeDetectorOptions(table, &o->edges, edges);
}

namespace {

void addDepth(OptionsTable* table, EpipolarDepthOptions* d, const std::string& path) {
  const OptionPlace p = stage(path, "depth", "depth-", "Depth");
  table->group(d, "EpipolarDepthOptions", p.path, p.prefix, p.heading)
      .number("min_depth", "min", &d->min_depth, "Nearest depth searched (scene scales)")
      .number("max_depth", "max", &d->max_depth,
              "Farthest depth searched (scene scales); inf searches to the vanishing point")
      .number("min_parallax_deg", "min-parallax", &d->min_parallax_deg,
              "Least parallax of a reference frame at the mid-range depth (deg)")
      .number("max_optical_axis_angle_deg", "max-axis-angle", &d->max_optical_axis_angle_deg,
              "Largest angle between the optical axes of keyframe and reference (deg)")
      .number("max_gradient_epipolar_angle_deg", "max-gradient-epipolar-angle",
              &d->max_gradient_epipolar_angle_deg,
              "Largest angle between a pixel's gradient and its epipolar line (deg)")
      .number("patch_half_size_1d", "patch-1d", &d->patch_half_size_1d,
              "Half size of the 1D patch along the epipolar line (samples)")
      .number("patch_half_size_2d", "patch-2d", &d->patch_half_size_2d,
              "Half size of the square 2D check patch (px)")
      .number("max_candidates", "max-candidates", &d->max_candidates,
              "Best 1D minima kept for the 2D check")
      .boolean("subtract_patch_mean", "subtract-patch-mean", &d->subtract_patch_mean,
               "Compare patches after subtracting their means")
      .number("max_patch_rms_grey", "max-patch-rms", &d->max_patch_rms_grey,
              "Largest RMS patch difference of a match (grey levels)")
      .number("max_ambiguity_ratio", "max-ambiguity-ratio", &d->max_ambiguity_ratio,
              "Best 2D cost at most this fraction of the next best")
      .number("image_noise_sigma_grey", "image-noise", &d->image_noise_sigma_grey,
              "Image noise std dev (grey levels)")
      .number("epipolar_sigma_px", "epipolar-sigma", &d->epipolar_sigma_px,
              "Std dev of the epipolar line position from pose error (px)")
      .number("max_relative_inverse_depth_sigma", "max-relative-sigma",
              &d->max_relative_inverse_depth_sigma,
              "Largest inverse-depth std dev as a fraction of the inverse depth")
      .number("pixel_step", "pixel-step", &d->pixel_step, "Search every k-th chain pixel (px)")
      .number("smoothing_half_window", "smoothing-half-window", &d->smoothing_half_window,
              "Half window of the robust average along a chain (pixels); 0 turns it off")
      .number("min_window_support", "min-window-support", &d->min_window_support,
              "Least consistent depths in a pixel's window")
      .number("outlier_sigmas", "outlier-sigmas", &d->outlier_sigmas,
              "Outlier distance from the window median (std devs)")
      .threads("num_threads", "threads", &d->num_threads,
               "Threads the chains are split over (the depths do not depend on it)");
}

void addCurveStages(OptionsTable* table, PipelineOptions* o, const std::string& path) {
  CurveInitialiserOptions* i = &o->initialiser;
  const OptionPlace p = stage(path, "initialiser", "init-", "Curve initialisation");
  table->group(i, "CurveInitialiserOptions", p.path, p.prefix, p.heading)
      .number("pixels_per_segment", "pixels-per-segment", &i->pixels_per_segment,
              "Target lifted pixels per Bezier segment")
      .number("min_segments", "min-segments", &i->min_segments,
              "Curves with fewer segments are dropped")
      .number("max_gap_px", "max-gap", &i->max_gap_px,
              "Longest bridged run of pixels without depth (chain pixels)")
      .number("max_relative_depth_jump", "max-depth-jump", &i->max_relative_depth_jump,
              "A run ends at a relative depth jump above this")
      .number("max_rms_residual_rel_chord", "max-rms-residual", &i->max_rms_residual_rel_chord,
              "Reject a segment whose RMS fit residual exceeds this fraction of its chord")
      .number("min_chord", "min-chord", &i->min_chord,
              "Reject segments with a shorter chord (scene scales)")
      .number("max_arm_to_chord", "max-arm-to-chord", &i->max_arm_to_chord,
              "Reject a segment whose arm exceeds this multiple of its chord");
  CurveExtensionOptions* x = &o->extension;
  const OptionPlace e = stage(path, "extension", "extend-", "Curve extension");
  table->group(x, "CurveExtensionOptions", e.path, e.prefix, e.heading)
      .boolean("enabled", "curves", &x->enabled,
               "Append a new curve that continues an existing curve's end to that curve")
      .number("max_gap_px", "max-gap", &x->max_gap_px,
              "Largest gap between the projected end points (px)")
      .number("max_lateral_px", "max-lateral", &x->max_lateral_px,
              "Largest offset across the existing end's image tangent, and overlap behind it (px)")
      .number("max_angle_deg", "max-angle", &x->max_angle_deg,
              "Largest angle between the two curves' image directions at the join (deg)")
      .number("max_relative_depth_gap", "max-depth-gap", &x->max_relative_depth_gap,
              "Largest 3D gap between the end points, as a fraction of the existing end's depth");
  CorrespondenceOptions* c = &o->correspondence;
  const OptionPlace m = stage(path, "correspondence", "match-", "Correspondence checks");
  table->group(c, "CorrespondenceOptions", m.path, m.prefix, m.heading)
      .number("samples_per_segment", "samples-per-segment", &c->samples_per_segment,
              "Samples per segment of the checks")
      .number("min_depth", "min-depth", &c->min_depth,
              "Least depth of every sample in the new camera (scene scales)")
      .number("max_mean_edge_distance_px", "max-edge-distance", &c->max_mean_edge_distance_px,
              "Largest mean distance to the nearest edge (px)")
      .number("appearance_half_width_px", "appearance-half-width", &c->appearance_half_width_px,
              "Half width of the appearance band (px)")
      .number("hue_weight", "hue-weight", &c->hue_weight,
              "Weight lambda of the hue term of the appearance error")
      .number("max_appearance_error", "max-appearance-error", &c->max_appearance_error,
              "Largest HSV appearance error")
      .number("max_viewing_angle_deg", "max-viewing-angle", &c->max_viewing_angle_deg,
              "Largest angle to the mean earlier viewing direction (deg)");
  CurveMapOptions* map = &o->map;
  const OptionPlace k = stage(path, "map", "map-", "Maps and keyframes");
  table->group(map, "CurveMapOptions", k.path, k.prefix, k.heading)
      .number("promotion_observations", "promotion-observations", &map->promotion_observations,
              "Keyframes that move a temporary curve to the global map")
      .number("disable_window_keyframes", "disable-window", &map->disable_window_keyframes,
              "Recent keyframes over which a curve must stay visible")
      .number("disable_unseen_fraction", "disable-unseen-fraction", &map->disable_unseen_fraction,
              "Disable a curve when more of its segments than this went unseen in the window")
      .number("min_keyframe_translation", "keyframe-translation", &map->min_keyframe_translation,
              "New keyframe when the initial camera centre moved more than this (scene scales)")
      .number("min_keyframe_rotation_deg", "keyframe-rotation", &map->min_keyframe_rotation_deg,
              "... or turned more than this (deg)");
}

}  // namespace

OptionPlace OptionPlace::child(const std::string& field) const {
  return {path + "/" + field, prefix, heading, what};
}

std::string OptionPlace::describe(const std::string& text) const {
  if (!what.empty()) return what + ": " + text;
  std::string sentence = text;
  if (!sentence.empty()) sentence[0] = static_cast<char>(std::toupper(sentence[0]));
  return sentence;
}

void addOptimizerOptions(OptionsTable* table, OptimizerOptions* o, const OptionPlace& place) {
  table->group(o, "OptimizerOptions", place.path, place.prefix, place.heading)
      .enumeration("linear_solver", "linear-solver", &o->linear_solver,
                   place.describe("linear solver of each step"))
      .enumeration("trust_region", "trust-region", &o->trust_region,
                   place.describe("trust-region strategy"))
      .number("max_iterations", "max-iterations", &o->max_iterations,
              place.describe("most solver iterations per solve"))
      .number("initial_trust_region_radius", "initial-trust-region",
              &o->initial_trust_region_radius,
              place.describe("first step's trust region (Levenberg-Marquardt: 1 / damping)"))
      .threads("num_threads", "threads", &o->num_threads, place.describe("solver threads"))
      .number("function_tolerance", "function-tolerance", &o->function_tolerance,
              place.describe("stop when the relative cost change falls below this"))
      .number("gradient_tolerance", "gradient-tolerance", &o->gradient_tolerance,
              place.describe("stop when the max gradient falls below this"))
      .number("parameter_tolerance", "parameter-tolerance", &o->parameter_tolerance,
              place.describe("stop when the relative step falls below this"))
      .number("stall_iterations", "stall-iterations", &o->stall_iterations,
              place.describe("stop when the lowest cost fell by less than the stall tolerance "
                             "over this many iterations, from the first kept step (0: off)"))
      .number("stall_tolerance", "stall-tolerance", &o->stall_tolerance,
              place.describe("relative fall of the lowest cost over the stall iterations"))
      .boolean("structure_first_ordering", "structure-first", &o->structure_first_ordering,
               place.describe("Schur order structure first (false: Ceres chooses)"))
      .boolean("curve_blocks", "curve-blocks", &o->curve_blocks,
               place.describe("one solver block per curve, eliminated in the Schur complement "
                              "(false: one per variable)"))
      .number("max_curve_block_size", "max-curve-block", &o->max_curve_block_size,
              place.describe("a curve with more free dimensions (7 per segment + 5) keeps a "
                             "block per variable"))
      .boolean("solve_components_apart", "components-apart", &o->solve_components_apart,
               place.describe("with every pose held, solve each curve and point alone (own "
                              "Levenberg-Marquardt; false: one Ceres solve)"))
      .boolean("use_inner_iterations", "inner-iterations", &o->use_inner_iterations,
               place.describe("Ceres inner iterations"))
      .boolean("verbose", "verbose", &o->verbose, place.describe("print Ceres' iteration log"))
      .derived(
          "on_iteration", [] { return nlohmann::json("a progress hook, set by the program"); },
          "a progress hook the program sets (run: --progress-interval), not a tunable");
}

void addSchedulerOptions(OptionsTable* table, SchedulerOptions* s, const OptionPlace& place,
                         const bool* fix_first_pose) {
  table->group(s, "SchedulerOptions", place.path, place.prefix, place.heading)
      .enumeration("strategy", "strategy", &s->strategy,
                   place.describe("how the free variables are split into solves"))
      .enumeration("scope", "scope", &s->scope,
                   place.describe("free variables: all (global) or the last keyframes' (local)"))
      .number("local_window", "local-window", &s->local_window,
              place.describe("free keyframes in local scope"))
      .number("max_rounds", "max-rounds", &s->max_rounds,
              place.describe("alternating: most rounds"))
      .number("round_tolerance", "round-tolerance", &s->round_tolerance,
              place.describe("alternating: stop when a round gains less than this fraction"))
      .derived(
          "fix_first_pose", [fix_first_pose] { return nlohmann::json(*fix_first_pose); },
          "the gauge switch of the bundle adjustment options (fix-first-pose)")
      .nested("optimizer");
  addOptimizerOptions(table, &s->optimizer, place.child("optimizer"));
}

void addCurveBundleAdjustmentOptions(OptionsTable* table, CurveBundleAdjustmentOptions* b,
                                     const OptionPlace& place) {
  table->group(b, "CurveBundleAdjustmentOptions", place.path, place.prefix, place.heading)
      .number("samples_per_segment", "samples-per-segment", &b->samples_per_segment,
              "s: residuals per (segment, keyframe) pair are s + 1")
      .boolean("use_subpixel_edges", "subpixel-edges", &b->use_subpixel_edges,
               "Measure against the sub-pixel edge position (false: the edge pixel centre)")
      .number("max_normal_angle_deg", "max-normal-angle", &b->max_normal_angle_deg,
              "Match only edges whose normal is within this angle of the curve's (deg); 90 "
              "accepts every match")
      .boolean("interpolate_edges", "interpolate-edges", &b->interpolate_edges,
               "Blend the residuals to the nearest edges of the four pixel centres around a "
               "sample, so that it does not jump between pixels")
      .number("interpolate_max_line_offset_px", "interpolate-max-line-offset",
              &b->interpolate_max_line_offset_px,
              "Blend: two edge pixels are one edge if each lies within this distance of the "
              "other's line (px)")
      .number("interpolate_max_normal_angle_deg", "interpolate-max-normal-angle",
              &b->interpolate_max_normal_angle_deg,
              "Blend: ...and their normals are within this angle (deg)")
      .number("border_margin_px", "border-margin", &b->border_margin_px,
              "Measure samples up to this far outside the image against the edge line at the "
              "border instead of capping them (px; 0: capped)")
      .number("pixel_sigma", "pixel-sigma", &b->pixel_sigma, "Std dev of an edge residual (px)")
      .enumeration("kernel", "kernel", &b->kernel, "Robust kernel on edge residuals")
      .number("kernel_width", "kernel-width", &b->kernel_width, "Kernel width (sigmas)")
      .number("lambda1", "lambda1", &b->lambda1,
              "Weight of the segment-length term (px^2 per squared length unit: scene scale in "
              "run, scene unit in curve-ba); 0 drops it")
      .boolean("length_from_creation", "length-from-creation", &b->length_from_creation,
               "Segment-length term against each segment's length at creation (else its chord "
               "when each BA starts)")
      .number("length_sigma_rel", "length-sigma-rel", &b->length_sigma_rel,
              "Segment-length term relative to each segment instead: std dev of its chord as a "
              "fraction of its reference length (0: lambda1)")
      .number("lambda2", "lambda2", &b->lambda2,
              "Weight of the tangent term (px^2/rad^2); 0 drops it")
      .boolean("fix_first_pose", "fix-first-pose", &b->fix_first_pose,
               "Hold keyframe 0 constant (rotation and translation gauge)")
      .boolean("fix_scale", "fix-scale", &b->fix_scale,
               "Hold the distance between keyframes 0 and 1 (scale gauge)")
      .number("scale_sigma", "scale-sigma", &b->scale_sigma,
              "Std dev of that distance constraint (length unit: scene scales in run)")
      .boolean("motion_prior", "motion-prior", &b->motion_prior,
               "Tie the motion between consecutive keyframes to the initial poses'")
      .number("motion_prior_rotation_sigma_deg", "motion-prior-rotation",
              &b->motion_prior_rotation_sigma_deg,
              "Std dev per axis of that motion's rotation (deg)")
      .number("motion_prior_translation_sigma_rel", "motion-prior-translation",
              &b->motion_prior_translation_sigma_rel,
              "Std dev per axis of that motion's translation, as a fraction of the mean distance "
              "between consecutive keyframes")
      .boolean("start_prior", "start-prior", &b->start_prior,
               "Tie each keyframe's orientation and centre to its initial pose (a start known "
               "per pose to within the two sigmas below; then set --ba-motion-prior false)")
      .number("start_prior_rotation_sigma_deg", "start-prior-rotation",
              &b->start_prior_rotation_sigma_deg,
              "Std dev per axis of each keyframe's initial orientation (deg)")
      .number("start_prior_centre_sigma_rel", "start-prior-centre",
              &b->start_prior_centre_sigma_rel,
              "Std dev per axis of each keyframe's initial centre, as a fraction of the mean "
              "distance between consecutive keyframes")
      .boolean("points", "points", &b->points,
               "Hybrid graph: keep the initialiser's points beside the curves")
      .number("point_pixel_sigma", "point-sigma", &b->point_pixel_sigma,
              "Std dev of a point's reprojection residual (px)")
      .number("keypoint_pixel_sigma", "keypoint-sigma", &b->keypoint_pixel_sigma,
              "Std dev of the residual of a point seen as a descriptor keypoint, detected in its "
              "image alone (px; 0: --ba-point-sigma)")
      .number("keypoint_reference_size", "keypoint-reference-size", &b->keypoint_reference_size,
              "Keypoints larger than this diameter get the keypoint sigma x their size / it, "
              "as their scale localises them less precisely (px, SIFT's diameters; ORB's are "
              "its 31 px patch per level; 0: size ignored)")
      .enumeration("point_kernel", "point-kernel", &b->point_kernel,
                   "Robust kernel on point residuals")
      .number("point_kernel_width", "point-kernel-width", &b->point_kernel_width,
              "Point kernel width (point sigmas)");
}

void addPointBundleAdjustmentOptions(OptionsTable* table, PointBundleAdjustmentOptions* b,
                                     const OptionPlace& place) {
  table->group(b, "PointBundleAdjustmentOptions", place.path, place.prefix, place.heading)
      .number("pixel_sigma", "pixel-sigma", &b->pixel_sigma, "Std dev of an image residual (px)")
      .enumeration("kernel", "kernel", &b->kernel, "Robust kernel on image residuals")
      .number("kernel_width", "kernel-width", &b->kernel_width, "Kernel width (sigmas)")
      .boolean("fix_first_pose", "fix-first-pose", &b->fix_first_pose,
               "Hold the first camera constant (rotation and translation gauge)")
      .boolean("fix_scale", "fix-scale", &b->fix_scale,
               "Hold the distance between the first two cameras (scale gauge)")
      .number("scale_sigma", "scale-sigma", &b->scale_sigma,
              "Std dev of that distance constraint (scene units)")
      .boolean("refine_focal", "refine-focal", &b->refine_focal,
               "Refine the focal lengths, one factor for every image (the initialiser: in "
               "global BA)");
}

void addSanityOptions(OptionsTable* table, SanityOptions* o, const OptionPlace& place) {
  table->group(o, "SanityOptions", place.path, place.prefix, place.heading)
      .boolean("drop_implausible_curves", "drop-curves", &o->drop_implausible_curves,
               "Drop curves outside the scene's extent or longer than its diagonal (else only "
               "list them)")
      .number("extent_percentile", "extent-percentile", &o->extent_percentile,
              "The extent spans the points between this percentile and 100 minus it per axis, "
              "and every camera (%)")
      .number("extent_margin", "extent-margin", &o->extent_margin,
              "Enlarge the extent on every side by this fraction of its diagonal")
      .number("samples_per_segment", "samples-per-segment", &o->samples_per_segment,
              "Samples per segment checked against the extent")
      .number("max_curve_residual_px", "max-curve-residual", &o->max_curve_residual_px,
              "After each global BA, a curve whose residual RMS exceeds this is implausible too "
              "(px; 0: off)")
      .number("min_chord_ratio", "min-chord-ratio", &o->min_chord_ratio,
              "After each global BA, a curve whose chords shrank below this fraction of their "
              "lengths at creation is implausible too (0: off)")
      .number("min_epipolar_angle_deg", "min-epipolar-angle", &o->min_epipolar_angle_deg,
              "Before the first global BA and after each, a curve whose median sample runs within "
              "this angle of its views' epipolar planes is implausible too: its depth along "
              "itself is unobserved (deg; 0: off)")
      .number("max_implausible_fraction", "max-implausible-fraction", &o->max_implausible_fraction,
              "Verdict when more than this fraction of the global map's curves is implausible")
      .number("max_pose_move_spacings", "max-pose-move", &o->max_pose_move_spacings,
              "Verdict when a refined keyframe moved more than this many keyframe spacings "
              "(after Sim(3) alignment onto the initial poses)")
      .number("min_keyframes", "min-keyframes", &o->min_keyframes,
              "Verdict when the run has fewer keyframes")
      .number("min_curves", "min-curves", &o->min_curves,
              "Verdict when the final map has fewer curves");
}

void addStartModelOptions(OptionsTable* table, StartModelOptions* o, const std::string& path) {
  table->group(o, "StartModelOptions", path, "start-model-", "Start model")
      .boolean("from_images", "from-images", &o->from_images,
               "With given initial poses, register each frame again on the points triangulated "
               "at them; when the frames move against the points (per pose, or drifting with "
               "tie-drifting-per-pose), tie each keyframe to its start (start prior, at the "
               "sigma scales times the measured sigmas) instead of each motion to the start's")
      .number("min_points", "min-points", &o->min_points, "Points a measured frame sees at least")
      .number("min_frames", "min-frames", &o->min_frames, "Measured frames a verdict needs")
      .number("min_rotation_deg", "min-rotation", &o->min_rotation_deg,
              "Frames that move less than this (RMS per axis) agree with the images (deg)")
      .number("min_rotation_to_measurement", "min-rotation-to-measurement",
              &o->min_rotation_to_measurement,
              "... as do frames that move less than this many times the PnP rotation's own noise")
      .number("max_variogram_lag", "max-variogram-lag", &o->max_variogram_lag,
              "The moves' variogram is read at lags 1 and min(this, measured frames / 3)")
      .number("max_variogram_growth", "max-variogram-growth", &o->max_variogram_growth,
              "Above min-rotation, the start is off per pose when the variogram grows at most "
              "this much from lag 1 to that lag (else it drifts)")
      .number("prior_sigma_scale", "prior-sigma-scale", &o->prior_sigma_scale,
              "A start off per pose is tied to its centres at this times the measured noise")
      .number("rotation_prior_sigma_scale", "rotation-prior-sigma-scale",
              &o->rotation_prior_sigma_scale,
              "... and to its orientations at this times the measured rotation noise")
      .number("relift_passes", "relift-passes", &o->relift_passes,
              "A start tied per pose is lifted again at the refined poses this many times (at "
              "least: --relift-passes may ask more)")
      .boolean("tie_drifting_per_pose", "tie-drifting-per-pose", &o->tie_drifting_per_pose,
               "A start read as drifting is tied to each pose and lifted again as a per-pose one "
               "(false: it keeps the motion prior)")
      .number("reassociation_rounds", "reassociation-rounds", &o->reassociation_rounds,
              "A start tied per pose runs at most this many re-association rounds per pass "
              "(-1: --reassociation-rounds)")
      .boolean("two_view_points", "two-view-points", &o->two_view_points,
               "Read the start against two-view points where the BA's points are refined "
               "(--points-refine-at-given-poses), as the scales were set")
      .number("max_reprojection_error_px", "max-reprojection-error", &o->max_reprojection_error_px,
              "PnP's inlier threshold (px)");
}

void addPipelineOptions(OptionsTable* table, PipelineOptions* o, const std::string& path) {
  table->group(o, "PipelineOptions", path, "", "Pipeline")
      .number("scene_scale", "scene-scale", &o->scene_scale,
              "Unit of every length option (pose units); 0 = the distance between the first two "
              "distinct initial camera centres")
      .nested("undistort")
      .nested("edges")
      .nested("chains")
      .nested("field")
      .nested("depth")
      .nested("initialiser")
      .nested("extension")
      .nested("correspondence")
      .nested("map")
      .nested("ba")
      .nested("local_ba")
      .boolean("local_ba_refines_poses", "local-ba-refine-poses", &o->local_ba_refines_poses,
               "local BA: move the window's poses too (else curves alone)")
      .number("local_ba_max_curve_keyframes", "local-ba-max-curve-keyframes",
              &o->local_ba_max_curve_keyframes,
              "local BA: keyframes per curve segment at most, the window's and the rest spread "
              "over its track (0: all)")
      .nested("global_ba")
      .boolean("run_global_ba", "run-global-ba", &o->run_global_ba,
               "Run global BA after the last frame")
      .number("reassociation_rounds", "reassociation-rounds", &o->reassociation_rounds,
              "After global BA: rounds of re-registering every curve in every keyframe, each "
              "followed by global BA (0: none)")
      .number("reassociation_interim_iterations", "reassociation-interim-iterations",
              &o->reassociation_interim_iterations,
              "Most iterations of a global BA that a re-association round follows (0: "
              "--global-ba-max-iterations; the last global BA always runs to it)")
      .number("last_global_ba_kernel_width", "last-global-ba-kernel-width",
              &o->last_global_ba_kernel_width,
              "Kernel width of the last global BA (sigmas; 0: --ba-kernel-width)")
      .number("curve_precision_max_keyframes", "curve-precision-max-keyframes",
              &o->curve_precision_max_keyframes,
              "The centres' precision from the curves' edge noise after the last global BA, for "
              "runs of at most this many keyframes (0: never)")
      .boolean("reassociation_skip_explained", "reassociation-skip-explained",
               &o->reassociation_skip_explained,
               "Re-association leaves edges that curves observed in a keyframe already explain")
      .boolean("reassociation_skip_occluded", "reassociation-skip-occluded",
               &o->reassociation_skip_occluded,
               "Re-association leaves segments hidden behind a nearer curve observed in a keyframe")
      .number("reassociation_occluder_depth_ratio", "reassociation-occluder-depth-ratio",
              &o->reassociation_occluder_depth_ratio,
              "A curve hides a sample where its depth is below this fraction of the sample's")
      .number("reassociation_max_edge_distance_px", "reassociation-max-edge-distance",
              &o->reassociation_max_edge_distance_px,
              "Largest mean edge distance of a re-associated segment (px; 0: "
              "--match-max-edge-distance)")
      .number("reassociation_max_viewing_angle_deg", "reassociation-max-viewing-angle",
              &o->reassociation_max_viewing_angle_deg,
              "Largest viewing angle of a re-associated segment to its earlier views (deg; 0: "
              "--match-max-viewing-angle)")
      .number("depth_reference_candidates", "depth-reference-candidates",
              &o->depth_reference_candidates, "Recent keyframes considered as depth references")
      .boolean("track_keyframe_pose", "track-keyframe-pose", &o->track_keyframe_pose,
               "Refine a new keyframe's starting pose against the map before registration")
      .nested("tracking")
      .threads("registration_threads", "registration-threads", &o->registration_threads,
               "Threads trying the map's segments in a keyframe (the result does not depend on "
               "it)")
      .number("explained_radius_px", "explained-radius", &o->explained_radius_px,
              "Chain pixels this close to a registered segment seed no new curve (px)")
      .boolean("point_depth_range", "point-depth-range", &o->point_depth_range,
               "Take each keyframe's depth range from the initialiser's points it sees")
      .number("point_depth_margin", "point-depth-margin", &o->point_depth_margin,
              "Widen the points' depth range by this factor on both sides")
      .nested("sanity");
  addImageStages(table, o, path);
  addDepth(table, &o->depth, path);
  addCurveStages(table, o, path);
  addCurveBundleAdjustmentOptions(table, &o->ba, stage(path, "ba", "ba-", "BA objective"));
  addSchedulerOptions(table, &o->local_ba,
                      {path + "/local_ba", "local-ba-", "Local BA", "local BA"},
                      &o->ba.fix_first_pose);
  addSchedulerOptions(table, &o->global_ba,
                      {path + "/global_ba", "global-ba-", "Global BA", "global BA"},
                      &o->ba.fix_first_pose);
  addOptimizerOptions(table, &o->tracking,
                      {path + "/tracking", "track-", "Pose tracking", "pose tracking"});
  addSanityOptions(table, &o->sanity, stage(path, "sanity", "sanity-", "Sanity checks"));
}

void addCurveOverlayOptions(OptionsTable* table, CurveOverlayOptions* o, const OptionPlace& place) {
  table->group(o, "CurveOverlayOptions", place.path, place.prefix, place.heading)
      .number("samples_per_segment", "samples", &o->samples_per_segment,
              "Samples per segment of the drawn curves")
      .text(
          "colour", "colour", "B,G,R",
          [o] {
            return formatOptionValue(o->colour[0]) + "," + formatOptionValue(o->colour[1]) + "," +
                   formatOptionValue(o->colour[2]);
          },
          [o](const std::string& text) {
            const Eigen::Vector3d bgr = parseVector3(text, "CurveOverlayOptions", "colour");
            o->colour = cv::Scalar(bgr.x(), bgr.y(), bgr.z());
          },
          "Colour of the curves with --overlay-colour-by none, and of the faint curves in "
          "worst_curves/: blue, green, red in [0, 255]")
      .number("thickness_px", "thickness", &o->thickness_px, "Line thickness (px)")
      .number("point_radius_px", "point-radius", &o->point_radius_px,
              "Radius of the dots at segment ends (px); 0 draws none");
}

void addOverlayColouringOptions(OptionsTable* table, OverlayColouringOptions* o,
                                const OptionPlace& place) {
  table->group(o, "OverlayColouringOptions", place.path, place.prefix, place.heading)
      .enumeration("colour_by", "colour-by", &o->colour_by,
                   "Statistic colouring each curve of the overlays over a fixed range, with a "
                   "legend (residual rms 0-3 px; track length 2-20 keyframes; share of the pull "
                   "on the poses 0.01-10 %, log scale; none: every curve in --overlay-colour)");
}

void addPointTrackerOptions(OptionsTable* table, PointTrackerOptions* o, const OptionPlace& place) {
  table->group(o, "PointTrackerOptions", place.path, place.prefix, place.heading)
      .number("grid_cols", "grid-cols", &o->grid_cols, "Columns of the corner bucketing grid")
      .number("grid_rows", "grid-rows", &o->grid_rows, "Rows of the corner bucketing grid")
      .number("corners_per_cell", "corners-per-cell", &o->corners_per_cell,
              "Live tracks each grid cell is topped up to")
      .number("quality_level", "quality-level", &o->quality_level,
              "Shi-Tomasi quality level within a cell (fraction of its strongest corner)")
      .number("image_quality_level", "image-quality-level", &o->image_quality_level,
              "Weakest corner as a fraction of the image's strongest")
      .number("min_distance_px", "min-distance", &o->min_distance_px,
              "Shortest distance between a new corner and any track (px)")
      .number("corner_block_size", "corner-block-size", &o->corner_block_size,
              "Corner response window (px, odd)")
      .number("window_size_px", "window", &o->window_size_px, "KLT window side (px, odd)")
      .number("pyramid_levels", "pyramid-levels", &o->pyramid_levels,
              "KLT pyramid levels above the image")
      .number("max_iterations", "max-iterations", &o->max_iterations,
              "Most KLT iterations per pyramid level")
      .number("epsilon_px", "epsilon", &o->epsilon_px, "KLT stops below this step (px)")
      .number("min_eigen_threshold", "min-eigen", &o->min_eigen_threshold,
              "KLT gives up on flatter windows (OpenCV's minEigThreshold)")
      .number("max_forward_backward_px", "max-forward-backward", &o->max_forward_backward_px,
              "Largest forward-backward tracking error (px)")
      .number("border_px", "border", &o->border_px, "Tracks this close to the border end (px)")
      .number("min_live_tracks", "min-live-tracks", &o->min_live_tracks,
              "Detect new corners only while fewer tracks are live");
}

void addFeatureMatchingOptions(OptionsTable* table, FeatureMatchingOptions* o,
                               const OptionPlace& place) {
  table->group(o, "FeatureMatchingOptions", place.path, place.prefix, place.heading)
      .enumeration("kind", "kind", &o->kind, "Descriptor detected and matched")
      .number("max_features", "max-features", &o->max_features,
              "Most features kept per image, the strongest first")
      .number("detection_scale", "detection-scale", &o->detection_scale,
              "Features are detected on the image resized by this factor (1: full size)")
      .number("ratio", "ratio", &o->ratio,
              "Lowe's ratio: nearest over second-nearest descriptor distance below this")
      .boolean("mutual_check", "mutual-check", &o->mutual_check,
               "Keep only matches that are each other's nearest both ways");
}

void addCameraIntrinsics(OptionsTable* table, CameraIntrinsics* k, const OptionPlace& place) {
  table->group(k, "CameraIntrinsics", place.path, place.prefix, place.heading)
      .number("fx", "fx", &k->fx, "Focal length along x (px)")
      .number("fy", "fy", &k->fy, "Focal length along y (px)")
      .number("cx", "cx", &k->cx, "Principal point x (px)")
      .number("cy", "cy", &k->cy, "Principal point y (px)")
      .number("k1", "k1", &k->k1, "Radial distortion k1")
      .number("k2", "k2", &k->k2, "Radial distortion k2")
      .number("p1", "p1", &k->p1, "Tangential distortion p1")
      .number("p2", "p2", &k->p2, "Tangential distortion p2")
      .number("k3", "k3", &k->k3, "Radial distortion k3")
      .number("width", "width", &k->width, "Image width (px)")
      .number("height", "height", &k->height, "Image height (px)");
}

void addCurveSceneOptions(OptionsTable* table, CurveSceneOptions* o, const OptionPlace& place) {
  table->group(o, "CurveSceneOptions", place.path, place.prefix, place.heading)
      .number("num_keyframes", "keyframes", &o->num_keyframes, "Keyframes (rendered images)")
      .enumeration("camera_path", "camera-path", &o->camera_path, "Where the keyframes are")
      .number("camera_distance", "camera-distance", &o->camera_distance,
              "Distance of the cameras from the room centre (m)")
      .number("arc_degrees", "arc", &o->arc_degrees, "orbit: angle spanned by the keyframes (deg)")
      .number("walk_length", "walk-length", &o->walk_length,
              "forward_walk, sideways_walk: distance from the first to the last keyframe (m)")
      .nested("intrinsics")
      .number("num_curves", "curves", &o->num_curves, "3D curves in the room")
      .enumeration("curve_kind", "curve-kind", &o->curve_kind, "Shape of the curves")
      .number("segments_per_curve", "segments-per-curve", &o->segments_per_curve,
              "Cubic segments per curve")
      .number("min_curve_length", "min-curve-length", &o->min_curve_length, "Shortest curve (m)")
      .number("max_curve_length", "max-curve-length", &o->max_curve_length, "Longest curve (m)")
      .text(
          "volume_half_extents", "volume-half-extents", "X,Y,Z",
          [o] { return printVector3(o->volume_half_extents); },
          [o](const std::string& text) {
            o->volume_half_extents = parseVector3(text, "CurveSceneOptions", "volume_half_extents");
          },
          "Half extents of the box around the room centre that holds the curves (m)")
      .number("min_camera_distance", "min-camera-distance", &o->min_camera_distance,
              "Least distance of a curve point from every camera centre (m)")
      .number("edge_blur_sigma_px", "edge-blur-sigma", &o->edge_blur_sigma_px,
              "Blur of the rendered step edges (px)")
      .number("edge_return_length_px", "edge-return-length", &o->edge_return_length_px,
              "Length of the linear return to the background beside a rendered edge (px); 0: "
              "max(8 sigma, 8 px)")
      .number("step_contrast", "step-contrast", &o->step_contrast,
              "Intensity step across a rendered edge (8-bit units)")
      .number("pixel_noise", "image-noise", &o->pixel_noise,
              "Std dev of the image intensity noise (8-bit units)")
      .number("canny_low_threshold", "canny-low", &o->canny_low_threshold,
              "Canny low threshold of the scene's edge images")
      .number("canny_high_threshold", "canny-high", &o->canny_high_threshold,
              "Canny high threshold of the scene's edge images")
      .number("num_clutter_edges", "clutter", &o->num_clutter_edges,
              "Edges per image that belong to no 3D curve")
      .number("occlusion_fraction", "occlusion", &o->occlusion_fraction,
              "Probability that 30-50% of a curve is hidden in a keyframe")
      .number("min_visible_fraction", "min-visible-fraction", &o->min_visible_fraction,
              "A segment is observed in a keyframe when this fraction of it is in the image")
      .number("visibility_margin_px", "visibility-margin", &o->visibility_margin_px,
              "Margin inside the image border of a visible sample (px)")
      .number("min_projected_length_px", "min-projected-length", &o->min_projected_length_px,
              "Shortest projected segment that counts as observed (px)")
      .number("pose_noise_translation", "pose-noise-trans", &o->pose_noise_translation,
              "Start-guess camera centre noise (m)")
      .number("pose_noise_rotation_deg", "pose-noise-rot", &o->pose_noise_rotation_deg,
              "Start-guess rotation noise (deg)")
      .number("curve_point_noise", "curve-point-noise", &o->curve_point_noise,
              "Start-guess noise of the curve points Q (m)")
      .number("curve_tangent_noise_deg", "curve-tangent-noise", &o->curve_tangent_noise_deg,
              "Start-guess noise of the tangents v per component (deg)")
      .number("curve_length_noise", "curve-length-noise", &o->curve_length_noise,
              "Start-guess relative noise of the tangent lengths d1, d2")
      .number("seed", "seed", &o->seed, "Random seed");
  addCameraIntrinsics(table, &o->intrinsics,
                      {place.path + "/intrinsics", place.prefix + "camera-", place.heading, ""});
}

void addPointSceneOptions(OptionsTable* table, PointSceneOptions* o, const OptionPlace& place) {
  table->group(o, "PointSceneOptions", place.path, place.prefix, place.heading)
      .number("num_cameras", "cameras", &o->num_cameras, "Cameras on the arc")
      .number("num_points", "points", &o->num_points, "Points in the cube")
      .number("track_length", "track-length", &o->track_length,
              "Consecutive cameras seeing each point")
      .number("orbit_radius", "orbit-radius", &o->orbit_radius,
              "Distance of the cameras from the cube centre (m)")
      .number("arc_degrees", "arc", &o->arc_degrees, "Angle spanned by the camera arc (deg)")
      .number("cube_half_size", "cube-half-size", &o->cube_half_size,
              "Half edge of the point cube (m)")
      .number("pixel_noise", "pixel-noise", &o->pixel_noise, "Pixel noise std dev (px)")
      .number("pose_noise_translation", "pose-noise-trans", &o->pose_noise_translation,
              "Start-guess camera centre noise (m)")
      .number("pose_noise_rotation_deg", "pose-noise-rot", &o->pose_noise_rotation_deg,
              "Start-guess rotation noise (deg)")
      .number("point_noise", "point-noise", &o->point_noise, "Start-guess point noise (m)")
      .number("seed", "seed", &o->seed, "Random seed")
      .nested("intrinsics");
  addCameraIntrinsics(table, &o->intrinsics,
                      {place.path + "/intrinsics", place.prefix + "camera-", place.heading, ""});
}

void addPlanarSceneOptions(OptionsTable* table, PlanarSceneOptions* o, const OptionPlace& place) {
  table->group(o, "PlanarSceneOptions", place.path, place.prefix, place.heading)
      .number("num_frames", "frames", &o->num_frames, "Views along the orbit arc")
      .number("intensity_noise", "noise", &o->intensity_noise,
              "P: std dev of the per-pixel, per-channel intensity noise as a fraction of 255 "
              "(0.05 = 5%)")
      .number("seed", "seed", &o->seed, "Random seed of the noise and the initial poses")
      .enumeration("init_noise_model", "init-noise-model", &o->init_noise_model,
                   "Initial poses: every pose perturbed on its own (independent) or every motion "
                   "between consecutive frames, errors accumulating as in visual odometry (drift)")
      .number("init_noise_translation", "init-noise-trans", &o->init_noise_translation,
              "Initial poses: std dev per axis of the camera-centre error (m), per pose or, "
              "with drift, per step")
      .number("init_noise_rotation_deg", "init-noise-rot", &o->init_noise_rotation_deg,
              "Initial poses: std dev per axis of the rotation error (deg), per pose or, with "
              "drift, per step")
      .number("width", "width", &o->width, "Image width (px); the principal point is centred")
      .number("height", "height", &o->height, "Image height (px)")
      .number("fx", "fx", &o->fx, "Focal length along x (px)")
      .number("fy", "fy", &o->fy, "Focal length along y (px)")
      .derived(
          "cx", [o] { return nlohmann::json(0.5 * (o->width - 1)); }, "centred: (width - 1) / 2")
      .derived(
          "cy", [o] { return nlohmann::json(0.5 * (o->height - 1)); }, "centred: (height - 1) / 2")
      .number("plane_width", "plane-width", &o->plane_width,
              "Extent of the photo's longer side on the plane (m)")
      .number("orbit_radius", "orbit-radius", &o->orbit_radius,
              "Horizontal distance of the cameras from the plane centre (m)")
      .number("camera_height", "camera-height", &o->camera_height, "Height of the orbit (m)")
      .number("arc_degrees", "arc", &o->arc_degrees, "Orbit arc spanned by the views (deg)");
}

void addTwoViewOptions(OptionsTable* table, TwoViewOptions* o, const OptionPlace& place) {
  table->group(o, "TwoViewOptions", place.path, place.prefix, place.heading)
      .number("min_matches", "min-matches", &o->min_matches, "Fewest matches worth fitting")
      .enumeration("robust_score", "robust-score", &o->robust_score,
                   "USAC score of the E and H fits")
      .number("ransac_threshold_px", "ransac-threshold", &o->ransac_threshold_px,
              "USAC inlier threshold of the E and H fits (px)")
      .number("confidence", "confidence", &o->confidence, "USAC confidence")
      .number("max_iterations", "max-iterations", &o->max_iterations, "Most USAC iterations")
      .number("seed", "seed", &o->seed, "USAC random seed")
      .number("score_sigma_px", "score-sigma", &o->score_sigma_px,
              "Pixel noise of the ORB-SLAM scores and inliers (px)")
      .number("homography_score_ratio", "homography-score-ratio", &o->homography_score_ratio,
              "Select H when S_H / (S_H + S_E) exceeds this (ORB-SLAM)")
      .number("homography_inlier_ratio", "homography-inlier-ratio", &o->homography_inlier_ratio,
              "Select H when its inliers exceed this times E's (COLMAP)")
      .number("pure_rotation_fraction", "pure-rotation-fraction", &o->pure_rotation_fraction,
              "Pure rotation when a rotation alone explains this fraction of the inliers")
      .number("clear_winner_ratio", "clear-winner-ratio", &o->clear_winner_ratio,
              "Ambiguous when a second decomposition keeps more than this fraction of the "
              "winner's points")
      .number("min_triangulated_points", "min-points", &o->min_triangulated_points,
              "Fewest triangulated points")
      .number("min_triangulated_fraction", "min-triangulated-fraction",
              &o->min_triangulated_fraction, "Fewest triangulated points as a fraction of inliers")
      .number("max_reprojection_error_px", "max-reprojection-error", &o->max_reprojection_error_px,
              "Largest reprojection error of a triangulated point (px)")
      .number("parallax_rank", "parallax-rank", &o->parallax_rank,
              "Which largest triangulation angle the parallax gate reads (ORB-SLAM: 51)")
      .number("min_parallax_deg", "min-parallax", &o->min_parallax_deg,
              "Smallest accepted parallax-rank-th largest triangulation angle (deg)")
      .number("min_median_parallax_deg", "min-median-parallax", &o->min_median_parallax_deg,
              "Smallest accepted median triangulation angle (deg); 0 is off");
}

void addTrajectoryEvaluationOptions(OptionsTable* table, TrajectoryEvaluationOptions* o,
                                    const OptionPlace& place) {
  table->group(o, "TrajectoryEvaluationOptions", place.path, place.prefix, place.heading)
      .enumeration("alignment", "align", &o->alignment,
                   "Alignment of the estimate onto the ground truth (sim3 for monocular)")
      .number("max_dt", "max-dt", &o->max_dt, "Largest time difference of a matched pose pair (s)")
      .number("rpe_delta", "rpe-delta", &o->rpe_delta, "RPE over this many matched poses (frames)");
}

void addCurveMapEvaluationOptions(OptionsTable* table, CurveMapEvaluationOptions* o,
                                  const OptionPlace& place) {
  table->group(o, "CurveMapEvaluationOptions", place.path, place.prefix, place.heading)
      .text(
          "taus", "tau", "TAU[,TAU...]", [o] { return printNumberList(o->taus); },
          [o](const std::string& text) {
            o->taus = parseNumberList(text, "CurveMapEvaluationOptions", "taus");
          },
          "Distance thresholds, increasing (ground-truth units, e.g. m)")
      .number("sample_spacing", "sample-spacing", &o->sample_spacing,
              "Longest arc one sample of either map stands for (ground-truth units; 0: a tenth of "
              "the smallest tau)")
      .boolean("crop", "crop", &o->crop,
               "Precision counts only the estimate inside the ground truth's bounding box grown "
               "by --crop-margin")
      .number("crop_margin", "crop-margin", &o->crop_margin,
              "Growth of that box on every side (ground-truth units)");
}

}  // namespace curvesfm

namespace curvesfm {

void addAbsolutePoseOptions(OptionsTable* table, AbsolutePoseOptions* o, const OptionPlace& place) {
  table->group(o, "AbsolutePoseOptions", place.path, place.prefix, place.heading)
      .number("max_reprojection_error_px", "max-reprojection-error", &o->max_reprojection_error_px,
              "RANSAC inlier threshold on the reprojection error (px)")
      .number("confidence", "confidence", &o->confidence, "RANSAC confidence")
      .number("max_iterations", "max-iterations", &o->max_iterations, "Most RANSAC iterations")
      .number("min_inliers", "min-inliers", &o->min_inliers, "Fewest inliers to register a frame")
      .number("min_inlier_ratio", "min-inlier-ratio", &o->min_inlier_ratio,
              "Fewest inliers as a fraction of the 2D-3D correspondences");
}

void addFeatureTrackOptions(OptionsTable* table, FeatureTrackOptions* o, const OptionPlace& place) {
  table->group(o, "FeatureTrackOptions", place.path, place.prefix, place.heading)
      .number("match_interval", "match-interval", &o->match_interval,
              "Every this many frames descriptors are matched (1: every frame)")
      .number("match_overlap", "match-overlap", &o->match_overlap,
              "Earlier matching frames each matching frame is matched with (0: KLT only)")
      .number("exhaustive_max_frames", "exhaustive-max-frames", &o->exhaustive_max_frames,
              "A sequence of at most this many frames has every pair of matching frames matched")
      .number("min_tracked_fraction", "min-tracked-fraction", &o->min_tracked_fraction,
              "Below this fraction of KLT tracks kept, a frame is a matching frame")
      .boolean("match_frame_before_break", "match-frame-before-break", &o->match_frame_before_break,
               "The frame before such a break is a matching frame too")
      .number("merge_radius_px", "merge-radius", &o->merge_radius_px,
              "A keypoint joins the KLT track this close in its frame (px)")
      .number("verify_threshold_px", "verify-threshold", &o->verify_threshold_px,
              "Descriptor matches must fit a RANSAC F or H this closely (px)")
      .number("min_verified_matches", "min-verified-matches", &o->min_verified_matches,
              "A pair with fewer verified matches keeps none");
}

void addLoopMatchOptions(OptionsTable* table, LoopMatchOptions* o, const OptionPlace& place) {
  table->group(o, "LoopMatchOptions", place.path, place.prefix, place.heading)
      .boolean("enabled", "enabled", &o->enabled,
               "Match frames that see the same scene without shared tracks, and merge tracks")
      .number(
          "min_covisible_fraction", "min-covisible-fraction", &o->min_covisible_fraction,
          "A loop candidate: at least this fraction of one frame's points project into the other")
      .number("max_view_angle_deg", "max-view-angle", &o->max_view_angle_deg,
              "... counting only points whose two rays differ by at most this (deg)")
      .number("max_shared_fraction", "max-shared-fraction", &o->max_shared_fraction,
              "... and at most this fraction of those are tracked there already")
      .number("max_merge_error_px", "max-merge-error", &o->max_merge_error_px,
              "A merged point reprojects within this into every registered frame of both (px)")
      .number("max_rounds", "max-rounds", &o->max_rounds,
              "Most rounds of merges, each followed by global BA");
}

void addPointInitialiserOptions(OptionsTable* table, PointInitialiserOptions* o,
                                const std::string& path) {
  const std::string heading = "Point initialiser";
  table->group(o, "PointInitialiserOptions", path, "points-", heading)
      .nested("undistort")
      .nested("klt")
      .nested("features")
      .nested("tracks")
      .nested("two_view")
      .nested("registration")
      .nested("ba")
      .nested("local_ba")
      .nested("global_ba")
      .nested("loops")
      .number("pair_search_frames", "pair-search-frames", &o->pair_search_frames,
              "The initial pair's first frame is searched among this many frames")
      .number("max_pair_gap", "max-pair-gap", &o->max_pair_gap,
              "Most frames between the initial pair's two frames")
      .number("min_pair_flow_px", "min-pair-flow", &o->min_pair_flow_px,
              "Pairs whose shared tracks move less (median, px) are not tried")
      .number("pair_flow_step", "pair-flow-step", &o->pair_flow_step,
              "A second frame is tried when its median flow exceeds the last tried one's by this")
      .number("min_pair_median_parallax_deg", "min-pair-parallax", &o->min_pair_median_parallax_deg,
              "Smallest median triangulation angle of the initial pair (deg)")
      .number("pair_parallax_cap_deg", "pair-parallax-cap", &o->pair_parallax_cap_deg,
              "The pair score counts the median angle up to this (deg)")
      .number("max_reprojection_error_px", "max-reprojection-error", &o->max_reprojection_error_px,
              "Largest reprojection error of an observation kept in the map (px)")
      .boolean("refine_at_given_poses", "refine-at-given-poses", &o->refine_at_given_poses,
               "At given poses, refine each point over its views within the gate (poses held)")
      .number("given_poses_gate_scale", "given-poses-gate-scale", &o->given_poses_gate_scale,
              "At given poses, with refine-at-given-poses, gate at this times the points' median "
              "reprojection error (0: fixed)")
      .number("given_poses_max_gate_px", "given-poses-max-gate", &o->given_poses_max_gate_px,
              "At given poses, the widest gate (px)")
      .number("min_triangulation_angle_deg", "min-triangulation-angle",
              &o->min_triangulation_angle_deg, "Smallest ray angle of a triangulated point (deg)")
      .number("local_ba_frames", "local-ba-frames", &o->local_ba_frames,
              "Frames refined by local BA: the new one and those registered just before")
      .number("global_ba_growth", "global-ba-growth", &o->global_ba_growth,
              "Global BA when the registered frames grew by this factor")
      .number("max_registration_trials", "max-registration-trials", &o->max_registration_trials,
              "Candidates tried per registration step before a model is stuck")
      .number("fallback_min_inliers", "fallback-min-inliers", &o->fallback_min_inliers,
              "When no frame registers, PnP is retried accepting this many inliers")
      .number("max_models", "max-models", &o->max_models,
              "Most sub-models started after registration failures")
      .number("min_merge_points", "min-merge-points", &o->min_merge_points,
              "Fewest shared points to merge two sub-models by Sim(3)")
      .threads("tracking_threads", "tracking-threads", &o->tracking_threads,
               "OpenCV threads while building the tracks (0: every core)")
      .number("precision_max_frames", "precision-max-frames", &o->precision_max_frames,
              "The centres' predicted precision for at most this many posed frames (0: never)");
  table
      ->group(&o->undistort, "ImageUndistorterOptions", path + "/undistort", "points-undistort-",
              heading)
      .number("valid_margin_px", "valid-margin", &o->undistort.valid_margin_px,
              "Band along the border of the undistorted data (px)");
  addPointTrackerOptions(table, &o->klt, {path + "/klt", "points-klt-", heading, ""});
  addFeatureMatchingOptions(table, &o->features,
                            {path + "/features", "points-features-", heading, ""});
  addFeatureTrackOptions(table, &o->tracks, {path + "/tracks", "points-tracks-", heading, ""});
  addLoopMatchOptions(table, &o->loops, {path + "/loops", "points-loops-", heading, ""});
  addTwoViewOptions(table, &o->two_view, {path + "/two_view", "points-two-view-", heading, ""});
  addAbsolutePoseOptions(table, &o->registration,
                         {path + "/registration", "points-pnp-", heading, ""});
  addPointBundleAdjustmentOptions(table, &o->ba, {path + "/ba", "points-ba-", heading, ""});
  addOptimizerOptions(table, &o->local_ba,
                      {path + "/local_ba", "points-local-ba-", heading, "point local BA"});
  addOptimizerOptions(table, &o->global_ba,
                      {path + "/global_ba", "points-global-ba-", heading, "point global BA"});
}

void addImageSequenceOptions(OptionsTable* table, ImageSequenceOptions* o) {
  table->group(o, "ImageSequenceOptions", "/sequence", "", "Dataset")
      .enumeration("layout", "layout", &o->layout,
                   "The dataset folder's layout (README \"Dataset layouts\"); auto detects it")
      .text(
          "camera", "camera", "FX,FY,CX,CY[,K1,K2,P1,P2[,K3]]", [o] { return o->camera; },
          [o](const std::string& text) { o->camera = text; },
          "Intrinsics (px) instead of the dataset's own")
      .number("max_frames", "max-frames", &o->max_frames, "At most this many images (0: all)")
      .number("stride", "stride", &o->stride, "Every stride-th image");
}

}  // namespace curvesfm
