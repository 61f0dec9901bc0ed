// real_bench: the real image sets of the data folder through the initialiser, the curve pipeline,
// hybrid BA and COLMAP, side by side, evaluated by one code against each set's ground truth.
//
// For every set of kSets found under --data (a missing one is skipped with a note; --sets picks
// some, or none), every photo of --planar-photos rendered by `curvesfm synth planar` as the set
// planar_<name> (the paper's orbit over it, no initial poses), and every folder of --extra-sets
// (any layout `curvesfm run` reads, with ground truth), and every variant of --variants:
//   init    `curvesfm init --dataset SET --out ...` plus the flags of --init-flags: the point
//           initialiser alone;
//   curves  `curvesfm run --dataset SET --out ...`: with no initial poses, run starts with the
//           point initialiser and refines its poses with the curve pipeline;
//   hybrid  as curves plus the flags of --hybrid-flags (default `--ba-points true`: points and
//           curves in one BA);
//   colmap  COLMAP's feature_extractor (the set's intrinsics, one camera, kept fixed unless
//           --colmap-refine-focal), sequential matcher, mapper and model_converter, when `colmap`
//           is on PATH.
// curves and hybrid run once per start of --starts (issue 14's diagnosis): init (no initial
// poses: the point initialiser's), truth (the ground truth at the images), noise (the truth with
// every pose perturbed on its own, once per seed of --noise-seeds: a world-frame shift of
// --noise-spacing-fraction of the median distance between consecutive cameras and a rotation of
// --noise-rotation-deg, both per axis, Gaussian) and colmap (COLMAP's poses, which runs COLMAP
// first). Each such row also holds the start's own ATE at the same keyframes (the run's
// report.json) and refined / start; the summary prints them per set and start, with the spread
// over the noise seeds, beside issue 14's targets. --map-at truth|noise<seed> (truth and noise
// starts only) makes every such run lift and register its curves at that start's poses
// (`run --diagnose-frontend-poses`), so a map and a start of different errors meet;
// --noise-start-prior true gives every noise start's run `--ba-start-prior` at the noise's own
// sigmas (a start known per pose to within them) instead of the motion prior; --start-origin
// first moves every start file's world origin to its first camera (a check that the refined
// poses do not depend on the input's frame); --start-jitter-seed S moves every start camera by
// about 1e-6 camera spacings, which shows how far a single run's figures are from the next one's. A
// set with ground-truth curves (Pavilion) also gets `curvesfm eval-map` on every curve run:
// precision and recall of the curve map at 2 cm. curvesfm runs as a subprocess (--curvesfm, default
// the one built beside this bench); a variant whose flags the executable does not list in its
// --help is skipped with a note, so the table can name flags that a later curvesfm adds. Every
// trajectory (init: every registered frame; curves and hybrid: the keyframes; COLMAP: every
// registered image) is compared with the set's ground truth from loadImageSequence by
// compareTrajectories (Sim(3), core/trajectory_evaluation.h).
//
// --repetitions N runs every set's variants N times, interleaved (each once, then all again), and
// prints each curvesfm run's wall time against COLMAP's per repetition and their median (the
// machines these benches run on change speed over minutes; one pair of runs can be 40 % off).
//
// Writes into --out: real_bench.csv (one row per set, variant and repetition), real_bench.md (the
// table, also printed), SET/groundtruth.txt and SET/VARIANT/aligned_trajectory.txt (the estimate
// carried onto the ground truth), each run's own output and logs in SET/VARIANT/ (a later
// repetition's in SET/VARIANT_runN/), and through `python3 -m curvesfm_plots real-bench OUT`
// (when matplotlib is there) ate_by_set.png and trajectories.png. Exit codes: 0 when every row
// was written (failed and skipped rows included), 1 for bad input (no data folder, no known set
// in it), 2 for usage errors.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "apps/cli/plot_scripts.h"
#include "benchmarks/support/bench_common.h"
#include "benchmarks/support/planar_photos.h"
#include "benchmarks/support/subprocess.h"
#include "core/angles.h"
#include "core/colmap_model.h"
#include "core/dataset_io.h"
#include "core/errors.h"
#include "core/image_sequence.h"
#include "core/median.h"
#include "core/trajectory_evaluation.h"

namespace curvesfm {
namespace {

namespace fs = std::filesystem;

/// --start-jitter-seed's std dev per axis, in median camera spacings: about 1e-7 m on the temples.
constexpr double kStartJitterSpacings = 1e-6;

/// One real image set of the data folder and what it needs to be read as the paper uses it.
struct RealSet {
  std::string name;    ///< The --sets name: the data folder's own name.
  std::string subdir;  ///< The dataset folder below --data.
  std::string camera;  ///< --camera for curvesfm and the intrinsics for COLMAP; empty: the set's.
  int max_frames = 0;  ///< Frame cap of this set (0: all); --max-frames lowers it further.
  int stride = 1;      ///< Every stride-th image.
  std::string why;     ///< Why the entry differs from the defaults, for the table's notes.
  /// Ground-truth curves below --data (curvesfm eval-map's --gt-curves); empty: none.
  std::string gt_curves = "";
  /// A photo `curvesfm synth planar` renders into `subdir` before the set runs (--planar-photos);
  /// empty: the folder is there already.
  std::string rendered_from = "";
};

// The sets of ../shared/data (INDEX.md there). 7-Scenes' camera-intrinsics.txt is the depth
// camera's; its SOURCE.md measured f = 525 for the colour images.
const std::vector<RealSet> kSets = {
    {"7scenes_redkitchen_tsdf300", "7scenes_redkitchen_tsdf300/data", "525,525,320,240", 0, 3,
     "colour camera 525,525,320,240 (SOURCE.md); every 3rd frame (100 over the whole path)"},
    {"kitti_odom06_first51", "kitti_odom06_first51/KITTI_sequence_1", "", 0, 1, ""},
    {"middlebury_templeRing_subset", "middlebury_templeRing_subset", "", 0, 1, ""},
    {"middlebury_templeSparseRing", "middlebury_templeSparseRing", "", 0, 1, ""},
    {"pavilion_chair_midday", "pavilion_chair_midday/chair-sequence", "", 0, 1, "",
     "pavilion_chair_midday/3d/cropped"},
    {"strecha_fountain-P11", "strecha_fountain-P11", "", 0, 1, ""},
};

/// A curvesfm variant: the sub-command and the flags it adds to the common ones.
struct Variant {
  std::string name;
  std::string command;             ///< "init" or "run"; empty for COLMAP.
  std::vector<std::string> flags;  ///< Extra flags, as separate arguments.
};

const std::vector<std::string> kVariantNames = {"init", "curves", "hybrid", "colmap"};
const std::vector<std::string> kStartNames = {"init", "truth", "noise", "colmap"};

struct BenchOptions {
  std::string data = "../shared/data";  ///< Folder holding the sets of kSets (from the repo root).
  std::string out = "bench_out/real";   ///< Output folder (created).
  std::string curvesfm = CURVESFM_EXECUTABLE;         ///< The curvesfm executable.
  std::vector<std::string> sets;                      ///< Names of kSets to run; empty: all.
  bool no_builtin_sets = false;                       ///< --sets none: only the sets below.
  /// Dataset folders run beside kSets (any layout `curvesfm run` reads, with ground truth), each
  /// named by its folder.
  std::vector<std::string> extra_sets;
  /// Photos of --planar-dir rendered by `curvesfm synth planar` (its defaults, no initial poses)
  /// into OUT/planar_sets/STEM and run as the set planar_STEM.
  std::vector<std::string> planar_photos;
  std::string planar_dir = bench::kOpenCvSampleData;  ///< Folder of --planar-photos.
  std::vector<std::string> variants = kVariantNames;  ///< Variants to run, in this order.
  std::string hybrid_flags = "--ba-points true";      ///< Extra flags of the hybrid variant.
  std::string init_flags;                             ///< Extra flags of the init variant.
  int max_frames = 0;  ///< Frame cap for every set (0: each set's own cap).
  int stride = 0;      ///< Every stride-th image of every set (0: each set's own stride).
  int threads = 2;     ///< Threads for every solver flag curvesfm lists and for COLMAP.
  /// Threads of the initialiser's tracking (curvesfm's --points-tracking-threads). 1 keeps the
  /// tracks' time per frame issue 13's one-core figure; an end-to-end comparison with COLMAP,
  /// whose feature extraction runs on `threads`, gives it as many.
  int tracking_threads = 1;
  /// Every set's variants run this many times, interleaved (each variant once, then all again),
  /// so that a machine whose speed drifts over minutes slows curvesfm and COLMAP alike; the
  /// accuracy summaries read the first repetition, the time summary every one.
  int repetitions = 1;
  std::vector<std::string> starts = {"init"};      ///< Starts of the curves and hybrid variants.
  std::vector<int> noise_seeds = {1, 2, 3, 4, 5};  ///< One noise start per seed.
  /// Shift per axis of a noise start, as a fraction of the median camera spacing (unitless).
  double noise_spacing_fraction = 0.01;
  double noise_rotation_deg = 0.1;  ///< Rotation per axis of a noise start (deg).
  /// Tell each noise start's run how its poses were perturbed: `run --ba-start-prior` at the
  /// noise's own sigmas (a start known per pose to within them) and no motion prior, whose model
  /// (accurate consecutive motions) such a start does not follow.
  bool noise_start_prior = false;
  /// Let COLMAP's mapper refine the focal length (`--Mapper.ba_refine_focal_length 1`), the peer
  /// of curvesfm's `--points-ba-refine-focal`; by default both keep the set's calibration.
  bool colmap_refine_focal = false;
  /// Where every start file's world origin lies: "native" (the set's ground-truth frame, or
  /// COLMAP's) or "first" (moved, by a translation, to the first camera's centre).
  std::string start_origin = "native";
  /// > 0: every start file's camera centres get a Gaussian of kStartJitterSpacings median camera
  /// spacings per axis drawn with this seed, to measure the spread a single run hides.
  int start_jitter_seed = 0;
  /// Diagnosis: the start ("truth" or "noiseN") whose poses lift and register every curve of
  /// the truth and noise runs (`run --diagnose-frontend-poses`), so that a map and a start of
  /// different errors meet; empty: each run lifts its map at its own start.
  std::string map_at;
};

/// Where the curve pipeline's poses start: a --starts name and, for noise, its seed.
struct Start {
  std::string kind = "init";
  int seed = 0;
  std::string label() const { return kind == "noise" ? "noise" + std::to_string(seed) : kind; }
};

/// The start a --map-at label names ("truth" or "noise" + seed); nullopt if it names none.
std::optional<Start> startOfLabel(const std::string& label) {
  if (label == "truth") return Start{"truth", 0};
  const std::string prefix = "noise";
  const std::string digits = label.substr(std::min(label.size(), prefix.size()));
  if (label.rfind(prefix, 0) != 0 || digits.empty() || digits.size() > 9) return std::nullopt;
  if (!std::all_of(digits.begin(), digits.end(), [](char c) { return std::isdigit(c) != 0; })) {
    return std::nullopt;
  }
  return Start{"noise", std::stoi(digits)};
}

/// One row of the table: a set through one variant.
struct Row {
  std::string set;
  std::string variant;
  std::string start;          ///< Start label of curves and hybrid rows; empty for the others.
  int repetition = 1;         ///< Which of BenchOptions::repetitions (from 1).
  std::string status = "ok";  ///< ok, failed or skipped.
  std::string note;           ///< Why it failed or was skipped; caps and flags otherwise.
  int frames = 0;             ///< Images of the set after caps.
  int registered = 0;         ///< Frames with a pose (run: those the initialiser registered).
  int evaluated = 0;          ///< Poses matched to the ground truth (run: keyframes).
  ErrorStatistics ate;        ///< Sim(3) ATE (ground-truth unit).
  ErrorStatistics rpe;        ///< RPE translation between consecutive evaluated poses.
  /// The start's ATE rmse at the evaluated keyframes (the run's report.json; NaN without).
  double start_ate = std::nan("");
  /// Curve map against the set's ground-truth curves at 2 cm (curvesfm eval-map); NaN without.
  double map_precision = std::nan("");
  double map_recall = std::nan("");
  /// Curve cost per observation after the run's last BA (report.json final_fit); NaN without.
  double curve_cost_per_observation = std::nan("");
  /// The ATE that the initialiser's points' pixel noise alone would leave (report.json
  /// reprojection.precision.predicted_centre_ate, in the row's own unit until evaluate() scales
  /// it to the ground truth's): how far the points fix the trajectory at all. NaN without.
  double points_ate_floor = std::nan("");
  /// The same from the curves' edge noise after the run's last BA (report.json curve_precision),
  /// samples independent and correlated along each observation; NaN without.
  double curves_ate_floor = std::nan("");
  double curves_ate_floor_correlated = std::nan("");
  // Wall times (s); NaN where the variant has no such stage.
  double tracks_s = std::nan("");
  /// Tracks per frame scaled to 640x480 (ms, wall time on Options::tracking_threads).
  double tracks_ms = std::nan("");
  double init_s = std::nan("");
  double curves_s = std::nan("");
  double local_ba_s = std::nan("");
  double global_ba_s = std::nan("");
  double extraction_s = std::nan("");
  double matching_s = std::nan("");
  double mapping_s = std::nan("");
  double total_s = std::nan("");
};

std::vector<std::string> splitWords(const std::string& text) {
  std::istringstream stream(text);
  std::vector<std::string> words;
  for (std::string word; stream >> word;) words.push_back(word);
  return words;
}

std::string joinWords(const std::vector<std::string>& words, const std::string& separator = " ") {
  std::string text;
  for (const std::string& w : words) text += (text.empty() ? "" : separator) + w;
  return text;
}

// ---------------------------------------------------------------------------------------------
// curvesfm's flags.

/// The long flags `curvesfm COMMAND --help` lists, read once per command.
class FlagCatalogue {
 public:
  FlagCatalogue(std::string executable, std::string scratch)
      : executable_(std::move(executable)), scratch_(std::move(scratch)) {}

  const std::set<std::string>& flags(const std::string& command) {
    auto found = flags_.find(command);
    if (found != flags_.end()) return found->second;
    const std::string log = scratch_ + "/help_" + command + ".txt";
    const bench::ProcessResult r = bench::runProcess({executable_, command, "--help"}, log, log);
    if (r.exit_code != 0) {
      throw Error("real_bench: " + executable_ + " " + command + " --help failed (exit code " +
                  std::to_string(r.exit_code) + "): " + bench::lastLine(log));
    }
    std::set<std::string>& known = flags_[command];
    const std::string text = bench::readTextFile(log);
    const std::regex flag("--[a-z0-9][a-z0-9-]*");
    for (auto it = std::sregex_iterator(text.begin(), text.end(), flag);
         it != std::sregex_iterator(); ++it) {
      known.insert(it->str());
    }
    return known;
  }

  /// The flags of `arguments` (words starting with "--") that `command` does not list.
  std::vector<std::string> unknown(const std::string& command,
                                   const std::vector<std::string>& arguments) {
    std::vector<std::string> missing;
    for (const std::string& a : arguments) {
      if (a.rfind("--", 0) == 0 && flags(command).count(a) == 0) missing.push_back(a);
    }
    return missing;
  }

 private:
  std::string executable_;
  std::string scratch_;
  std::map<std::string, std::set<std::string>> flags_;
};

// ---------------------------------------------------------------------------------------------
// Evaluation.

/// Fills the accuracy columns of `row` from `estimate` vs the set's ground truth and writes the
/// aligned estimate beside the run; a trajectory that cannot be compared fails the row.
void evaluate(const std::vector<StampedPose>& estimate, const ImageSequence& sequence,
              const fs::path& dir, Row* row) {
  try {
    const TrajectoryEvaluation e =
        compareTrajectories(estimate, sequence.ground_truth, TrajectoryEvaluationOptions{},
                            row->variant, sequence.ground_truth_source);
    row->evaluated = e.ate.count;
    row->ate = e.ate;
    row->points_ate_floor *= e.ground_truth_from_estimate.scale;
    row->curves_ate_floor *= e.ground_truth_from_estimate.scale;
    row->curves_ate_floor_correlated *= e.ground_truth_from_estimate.scale;
    row->rpe = e.rpe_translation_stats;
    std::vector<StampedPose> aligned;
    for (const MatchedPose& m : e.matches) {
      aligned.push_back({m.estimate_timestamp, m.aligned_estimate});
    }
    writeTrajectory((dir / "aligned_trajectory.txt").string(), aligned);
  } catch (const Error& e) {
    row->status = "failed";
    row->note = e.what();
  }
}

double number(const nlohmann::json& json, const std::string& key) {
  return json.contains(key) && json[key].is_number() ? json[key].get<double>() : std::nan("");
}

// A predicted ATE of a report: a number, "infinite" where nothing fixes a centre, else NaN.
double predictedAte(const nlohmann::json& ate) {
  return ate.is_number()   ? ate.get<double>()
         : ate.is_string() ? std::numeric_limits<double>::infinity()
                           : std::nan("");
}

// The initialiser's part of a report.json (init: the top level; run: "initialiser"): its times,
// counts and the points' floor.
void readInitialiser(const nlohmann::json& part, Row* row) {
  if (!part.is_object() || !part.contains("seconds")) return;
  const nlohmann::json precision =
      part.value("reprojection", nlohmann::json::object()).value("precision", nlohmann::json());
  if (precision.is_object())
    row->points_ate_floor = predictedAte(precision["predicted_centre_ate"]);
  const nlohmann::json& s = part["seconds"];
  row->tracks_s = number(s, "undistort") + number(s, "klt") + number(s, "matching");
  row->tracks_ms = number(s, "tracks_ms_per_640x480_frame");
  row->init_s = number(s, "total");
  if (part.contains("counts")) row->registered = part["counts"].value("registered", 0);
}

// The curve pipeline's times of a run's report.json: per-frame frontend and local BA summed,
// global BA with its re-association rounds.
void readPipelineTimes(const nlohmann::json& report, Row* row) {
  double frontend = 0.0;
  double local_ba = 0.0;
  for (const nlohmann::json& frame : report.value("frames", nlohmann::json::array())) {
    if (!frame.contains("seconds")) continue;
    frontend += number(frame["seconds"], "frontend");
    local_ba += number(frame["seconds"], "local_ba");
  }
  row->curves_s = frontend;
  row->local_ba_s = local_ba;
  double global_ba = number(report.value("global_ba", nlohmann::json::object()), "total_seconds");
  for (const nlohmann::json& round : report.value("reassociation", nlohmann::json::array())) {
    if (round.contains("global_ba")) global_ba += number(round["global_ba"], "total_seconds");
  }
  row->global_ba_s = global_ba;
}

nlohmann::json readReport(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw IoError(path.string(), "cannot open (the run wrote no report)");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw ParseError(path.string(), 0, "JSON", e.what());
  }
}

// ---------------------------------------------------------------------------------------------
// The variants.

std::vector<std::string> sequenceFlags(const RealSet& set, const ImageSequenceOptions& sequence) {
  std::vector<std::string> flags;
  if (!set.camera.empty()) flags.insert(flags.end(), {"--camera", set.camera});
  if (sequence.max_frames > 0) {
    flags.insert(flags.end(), {"--max-frames", std::to_string(sequence.max_frames)});
  }
  if (sequence.stride > 1) flags.insert(flags.end(), {"--stride", std::to_string(sequence.stride)});
  return flags;
}

/// Fills the curve-map columns from `curvesfm eval-map` on the run in `dir` against the set's
/// ground-truth curves (precision and recall at 2 cm); a failure only adds a note.
void evaluateCurveMap(const BenchOptions& options, const RealSet& set,
                      const ImageSequenceOptions& sequence_options, const fs::path& dir, Row* row) {
  std::vector<std::string> argv = {
      options.curvesfm, "eval-map",
      "--run",          dir.string(),
      "--dataset",      (fs::path(options.data) / set.subdir).string(),
      "--gt-curves",    (fs::path(options.data) / set.gt_curves).string(),
      "--tau",          "0.01,0.02,0.05",
      "--json",         (dir / "eval_map.json").string()};
  const std::vector<std::string> own = sequenceFlags(set, sequence_options);
  argv.insert(argv.end(), own.begin(), own.end());
  const bench::ProcessResult r = bench::runProcess(argv, (dir / "eval_map.stdout.txt").string(),
                                                   (dir / "eval_map.stderr.txt").string());
  if (r.exit_code != 0) {
    row->note += std::string(row->note.empty() ? "" : "; ") +
                 "eval-map failed: " + bench::lastLine(r.stderr_log);
    return;
  }
  for (const nlohmann::json& score :
       readReport(dir / "eval_map.json").value("scores", nlohmann::json::array())) {
    if (std::abs(number(score, "tau") - 0.02) > 1e-12) continue;
    row->map_precision = number(score, "precision");
    row->map_recall = number(score, "recall");
  }
}

/// Runs a curvesfm variant; `init_poses` (a TUM file) is the start of a run, empty for the
/// initialiser's.
void runCurvesfm(const BenchOptions& options, const Variant& variant, const RealSet& set,
                 const ImageSequence& sequence, const ImageSequenceOptions& sequence_options,
                 const std::string& init_poses, FlagCatalogue* catalogue, const fs::path& dir,
                 Row* row) {
  std::vector<std::string> argv = {options.curvesfm, variant.command, "--dataset",
                                   sequence.dir,     "--out",         dir.string()};
  if (!init_poses.empty()) argv.insert(argv.end(), {"--init-poses", init_poses});
  const std::vector<std::string> unknown = catalogue->unknown(variant.command, variant.flags);
  if (!unknown.empty()) {
    row->status = "skipped";
    row->note = "curvesfm " + variant.command + " has no " + joinWords(unknown, ", ");
    return;
  }
  for (const std::string& flag : catalogue->flags(variant.command)) {
    // Every solver's thread count (--threads, --local-ba-threads, ...), whatever curvesfm has;
    // tracking its own (--threads would set it too).
    if (flag == "--points-tracking-threads") {
      argv.insert(argv.end(), {flag, std::to_string(options.tracking_threads)});
      continue;
    }
    if (flag.size() >= 9 && flag.compare(flag.size() - 7, 7, "threads") == 0) {
      argv.insert(argv.end(), {flag, std::to_string(options.threads)});
    }
  }
  const std::vector<std::string> own = sequenceFlags(set, sequence_options);
  argv.insert(argv.end(), own.begin(), own.end());
  argv.insert(argv.end(), variant.flags.begin(), variant.flags.end());
  const bench::ProcessResult r =
      bench::runProcess(argv, (dir / "stdout.txt").string(), (dir / "stderr.txt").string());
  row->total_s = r.seconds;
  if (!fs::exists(dir / "report.json")) {
    row->status = "failed";
    const std::string why = bench::lastLine(r.stderr_log);
    row->note = "exit code " + std::to_string(r.exit_code) + (why.empty() ? "" : ": " + why);
    return;
  }
  const nlohmann::json report = readReport(dir / "report.json");
  if (variant.command == "init") {
    readInitialiser(report, row);
  } else {
    readInitialiser(report.value("initialiser", nlohmann::json()), row);
    readPipelineTimes(report, row);
    const nlohmann::json ate = report.value("ate", nlohmann::json::object());
    if (ate.is_object() && ate.contains("initial_m"))
      row->start_ate = number(ate["initial_m"], "rmse");
    const nlohmann::json curves = report.value("final_fit", nlohmann::json::object())
                                      .value("curve_reprojection", nlohmann::json());
    if (curves.is_object() && number(curves, "count") > 0.0) {
      row->curve_cost_per_observation = number(curves, "cost") / number(curves, "count");
    }
    const nlohmann::json precision = report.value("curve_precision", nlohmann::json());
    if (precision.is_object()) {
      row->curves_ate_floor = predictedAte(precision["predicted_centre_ate"]);
      row->curves_ate_floor_correlated = predictedAte(precision["predicted_centre_ate_correlated"]);
    }
  }
  if (r.exit_code != 0) {
    row->status = "failed";
    row->note = "exit code " + std::to_string(r.exit_code) + ": " + bench::lastLine(r.stderr_log);
    return;
  }
  evaluate(readTrajectory((dir / "trajectory.txt").string()), sequence, dir, row);
  if (variant.command == "run" && !set.gt_curves.empty()) {
    evaluateCurveMap(options, set, sequence_options, dir, row);
  }
}

// ---------------------------------------------------------------------------------------------
// Starts.

/// The ground-truth poses at the sequence's images (by timestamp within 0.02 s).
std::vector<StampedPose> truthAtImages(const ImageSequence& sequence) {
  std::vector<StampedPose> poses;
  for (const SequenceImage& image : sequence.images) {
    const StampedPose* nearest = nullptr;
    for (const StampedPose& p : sequence.ground_truth) {
      if (!nearest || std::abs(p.timestamp - image.timestamp) <
                          std::abs(nearest->timestamp - image.timestamp)) {
        nearest = &p;
      }
    }
    if (nearest && std::abs(nearest->timestamp - image.timestamp) <= 0.02) {
      poses.push_back({image.timestamp, nearest->world_from_cam});
    }
  }
  return poses;
}

/// Median distance between consecutive camera centres.
double medianSpacing(const std::vector<StampedPose>& poses) {
  std::vector<double> spacing;
  for (std::size_t i = 1; i < poses.size(); ++i) {
    spacing.push_back(
        (poses[i].world_from_cam.translation() - poses[i - 1].world_from_cam.translation()).norm());
  }
  return upperMedian(spacing);
}

/// `truth` with every pose perturbed on its own: a world-frame shift of the camera centre and a
/// world-frame rotation about the centre, Gaussian per axis (perturbCamera).
std::vector<StampedPose> noisyStart(const std::vector<StampedPose>& truth,
                                    const BenchOptions& options, int seed) {
  std::mt19937 rng(static_cast<std::uint32_t>(seed));
  std::normal_distribution<double> rotation(0.0, options.noise_rotation_deg * kDegToRad);
  std::normal_distribution<double> shift(0.0,
                                         options.noise_spacing_fraction * medianSpacing(truth));
  std::vector<StampedPose> noisy;
  for (const StampedPose& p : truth) {
    Vector6d delta;
    for (int k = 0; k < 3; ++k) delta(k) = rotation(rng);
    for (int k = 3; k < 6; ++k) delta(k) = shift(rng);
    noisy.push_back({p.timestamp, perturbCamera(p.world_from_cam, delta)});
  }
  return noisy;
}

/// --start-origin and --start-jitter-seed applied to a start's poses.
void reframeStart(const BenchOptions& options, std::vector<StampedPose>* poses) {
  if (poses->empty()) return;
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  if (options.start_origin == "first") shift = -poses->front().world_from_cam.translation();
  // normal_distribution needs a positive std dev: no jitter for a start that does not move.
  const double jitter_sigma =
      options.start_jitter_seed > 0 ? kStartJitterSpacings * medianSpacing(*poses) : 0.0;
  std::mt19937 rng(static_cast<std::uint32_t>(options.start_jitter_seed));
  std::normal_distribution<double> jitter(0.0, jitter_sigma > 0.0 ? jitter_sigma : 1.0);
  for (StampedPose& pose : *poses) {
    Eigen::Vector3d centre = pose.world_from_cam.translation() + shift;
    if (jitter_sigma > 0.0) {
      for (int k = 0; k < 3; ++k) centre[k] += jitter(rng);
    }
    pose.world_from_cam = Pose3(pose.world_from_cam.rotation(), centre);
  }
}

/// The TUM file of `start` for one set (written on first use), or empty for the initialiser's
/// start; throws when COLMAP's start is asked for and COLMAP gave no poses.
std::string startPosesFile(const Start& start, const ImageSequence& sequence,
                           const std::vector<StampedPose>& colmap_poses,
                           const BenchOptions& options, const fs::path& set_dir) {
  if (start.kind == "init") return "";
  const fs::path path = set_dir / ("start_" + start.label() + ".txt");
  std::vector<StampedPose> poses;
  if (start.kind == "truth") poses = truthAtImages(sequence);
  if (start.kind == "noise") poses = noisyStart(truthAtImages(sequence), options, start.seed);
  if (start.kind == "colmap") {
    if (colmap_poses.empty()) throw Error("COLMAP gave no poses to start from");
    poses = colmap_poses;
  }
  reframeStart(options, &poses);
  writeTrajectory(path.string(), poses);
  return path.string();
}

// COLMAP's parameters for our camera: pixel centres at 0.5 there, at 0 here.
std::pair<std::string, std::string> colmapCamera(const Camera& camera) {
  const CameraIntrinsics& k = camera.intrinsics();
  char text[512];
  if (!camera.hasDistortion()) {
    std::snprintf(text, sizeof(text), "%.10g,%.10g,%.10g,%.10g", k.fx, k.fy, k.cx + 0.5,
                  k.cy + 0.5);
    return {"PINHOLE", text};
  }
  if (k.k3 == 0.0) {
    std::snprintf(text, sizeof(text), "%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g", k.fx, k.fy,
                  k.cx + 0.5, k.cy + 0.5, k.k1, k.k2, k.p1, k.p2);
    return {"OPENCV", text};
  }
  std::snprintf(text, sizeof(text), "%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,0,0,0",
                k.fx, k.fy, k.cx + 0.5, k.cy + 0.5, k.k1, k.k2, k.p1, k.p2, k.k3);
  return {"FULL_OPENCV", text};
}

// Runs one COLMAP step; false (and the row failed) on a non-zero exit.
bool colmapStep(const std::string& colmap, const std::string& step,
                const std::vector<std::string>& arguments, const fs::path& dir, double* seconds,
                Row* row) {
  std::vector<std::string> argv = {colmap, step};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  const bench::ProcessResult r = bench::runProcess(argv, (dir / (step + ".stdout.txt")).string(),
                                                   (dir / (step + ".stderr.txt")).string());
  if (seconds) *seconds = r.seconds;
  if (r.exit_code == 0) return true;
  row->status = "failed";
  row->note = "colmap " + step + ": exit code " + std::to_string(r.exit_code) + ": " +
              bench::lastLine(r.stderr_log);
  return false;
}

/// Runs COLMAP; `poses` receives the largest model's poses (empty when it failed).
void runColmap(const BenchOptions& options, const std::string& colmap,
               const ImageSequence& sequence, const fs::path& dir, Row* row,
               std::vector<StampedPose>* poses) {
  const Clock::time_point start = Clock::now();
  const fs::path image_dir = fs::path(sequence.images.front().image_path).parent_path();
  std::ofstream list(dir / "image_list.txt");
  for (const SequenceImage& image : sequence.images) {
    if (fs::path(image.image_path).parent_path() != image_dir) {
      row->status = "skipped";
      row->note = "images in more than one folder";
      return;
    }
    list << fs::path(image.image_path).filename().string() << "\n";
  }
  list.close();
  const std::string database = (dir / "database.db").string();
  fs::remove(database);
  const auto [model, params] = colmapCamera(sequence.camera);
  const std::string threads = std::to_string(options.threads);
  const std::vector<std::string> extract = {"--database_path",
                                            database,
                                            "--image_path",
                                            image_dir.string(),
                                            "--image_list_path",
                                            (dir / "image_list.txt").string(),
                                            "--ImageReader.single_camera",
                                            "1",
                                            "--ImageReader.camera_model",
                                            model,
                                            "--ImageReader.camera_params",
                                            params,
                                            "--SiftExtraction.use_gpu",
                                            "0",
                                            "--SiftExtraction.num_threads",
                                            threads};
  const std::vector<std::string> match = {"--database_path",
                                          database,
                                          "--SequentialMatching.overlap",
                                          "10",
                                          "--SequentialMatching.quadratic_overlap",
                                          "1",
                                          "--SiftMatching.use_gpu",
                                          "0",
                                          "--SiftMatching.num_threads",
                                          threads};
  const fs::path sparse = dir / "sparse";
  fs::remove_all(sparse);
  fs::create_directories(sparse);
  // The intrinsics are the dataset's calibration: COLMAP keeps them fixed, as curvesfm does,
  // unless asked to refine the focal length.
  const std::vector<std::string> map = {"--database_path",
                                        database,
                                        "--image_path",
                                        image_dir.string(),
                                        "--output_path",
                                        sparse.string(),
                                        "--Mapper.num_threads",
                                        threads,
                                        "--Mapper.ba_refine_focal_length",
                                        options.colmap_refine_focal ? "1" : "0",
                                        "--Mapper.ba_refine_principal_point",
                                        "0",
                                        "--Mapper.ba_refine_extra_params",
                                        "0"};
  if (!colmapStep(colmap, "feature_extractor", extract, dir, &row->extraction_s, row) ||
      !colmapStep(colmap, "sequential_matcher", match, dir, &row->matching_s, row) ||
      !colmapStep(colmap, "mapper", map, dir, &row->mapping_s, row)) {
    row->total_s = bench::secondsSince(start);
    return;
  }
  // The mapper writes one numbered folder per model; the one registering most images counts.
  std::vector<StampedPose> best;
  std::vector<fs::path> models;
  for (const fs::directory_entry& entry : fs::directory_iterator(sparse)) {
    if (entry.is_directory()) models.push_back(entry.path());
  }
  std::sort(models.begin(), models.end());
  for (const fs::path& model_dir : models) {
    const fs::path text_dir = dir / "text" / model_dir.filename();
    fs::create_directories(text_dir);
    if (!colmapStep(colmap, "model_converter",
                    {"--input_path", model_dir.string(), "--output_path", text_dir.string(),
                     "--output_type", "TXT"},
                    dir, nullptr, row)) {
      row->total_s = bench::secondsSince(start);
      return;
    }
    try {
      std::vector<StampedPose> poses =
          colmapPosesForSequence(readColmapModel(text_dir.string()), sequence);
      if (poses.size() > best.size()) best = std::move(poses);
    } catch (const Error& e) {
      row->note = e.what();
    }
  }
  row->total_s = bench::secondsSince(start);
  row->registered = static_cast<int>(best.size());
  if (models.size() > 1) row->note = std::to_string(models.size()) + " models, the largest kept";
  if (options.colmap_refine_focal) {
    row->note += std::string(row->note.empty() ? "" : "; ") + "focal length refined";
  }
  if (best.empty()) {
    row->status = "failed";
    if (row->note.empty()) row->note = "the mapper built no model";
    return;
  }
  evaluate(best, sequence, dir, row);
  *poses = std::move(best);
}

// ---------------------------------------------------------------------------------------------
// Output.

std::string formatNumber(double value, const char* format = "%.4g") {
  if (std::isnan(value)) return "";
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

std::string csvQuote(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

bool evaluated(const Row& r) { return r.status == "ok"; }

void writeCsv(const std::vector<Row>& rows, const fs::path& path) {
  std::ofstream out(path);
  if (!out) throw IoError(path.string(), "cannot open for writing");
  out << "set,variant,start,repetition,status,frames,registered,evaluated,start_ate_rmse,ate_rmse,"
         "ate_mean,"
         "ate_median,map_precision_2cm,map_recall_2cm,curve_cost_per_observation,"
         "points_ate_floor,curves_ate_floor,curves_ate_floor_correlated,rpe_translation_rmse,"
         "tracks_s,tracks_ms_per_640x480_frame,init_s,curves_"
         "s,local_ba_s,"
         "global_ba_s,extraction_s,"
         "matching_s,mapping_s,total_s,note\n";
  for (const Row& r : rows) {
    const bool ok = evaluated(r);
    const double nan = std::nan("");
    out << r.set << "," << r.variant << "," << r.start << "," << r.repetition << "," << r.status
        << "," << r.frames << "," << r.registered << "," << r.evaluated << ","
        << formatNumber(r.start_ate, "%.9g") << "," << formatNumber(ok ? r.ate.rmse : nan, "%.9g")
        << "," << formatNumber(ok ? r.ate.mean : nan, "%.9g") << ","
        << formatNumber(ok ? r.ate.median : nan, "%.9g") << ","
        << formatNumber(r.map_precision, "%.4g") << "," << formatNumber(r.map_recall, "%.4g") << ","
        << formatNumber(r.curve_cost_per_observation, "%.6g") << ","
        << formatNumber(ok ? r.points_ate_floor : nan, "%.6g") << ","
        << formatNumber(ok ? r.curves_ate_floor : nan, "%.6g") << ","
        << formatNumber(ok ? r.curves_ate_floor_correlated : nan, "%.6g") << ","
        << formatNumber(ok && r.rpe.count > 0 ? r.rpe.rmse : nan, "%.9g") << ","
        << formatNumber(r.tracks_s, "%.6g") << "," << formatNumber(r.tracks_ms, "%.6g") << ","
        << formatNumber(r.init_s, "%.6g") << "," << formatNumber(r.curves_s, "%.6g") << ","
        << formatNumber(r.local_ba_s, "%.6g") << "," << formatNumber(r.global_ba_s, "%.6g") << ","
        << formatNumber(r.extraction_s, "%.6g") << "," << formatNumber(r.matching_s, "%.6g") << ","
        << formatNumber(r.mapping_s, "%.6g") << "," << formatNumber(r.total_s, "%.6g") << ","
        << csvQuote(r.note) << "\n";
  }
}

std::string markdownRow(const Row& r) {
  const bool ok = evaluated(r);
  const double nan = std::nan("");
  const std::string colmap = std::isnan(r.extraction_s)
                                 ? ""
                                 : formatNumber(r.extraction_s, "%.1f") + " / " +
                                       formatNumber(r.matching_s, "%.1f") + " / " +
                                       formatNumber(r.mapping_s, "%.1f");
  std::string note = r.note;
  std::replace(note.begin(), note.end(), '|', '/');
  std::ostringstream line;
  std::string start = r.start;
  if (r.repetition > 1) {
    start += (start.empty() ? "" : ", ") + std::string("run ") + std::to_string(r.repetition);
  }
  line << "| " << r.set << " | " << r.variant << " | " << start << " | "
       << (r.status == "skipped" ? "skipped"
                                 : std::to_string(r.registered) + " / " + std::to_string(r.frames))
       << " | " << (ok ? std::to_string(r.evaluated) : "") << " | " << formatNumber(r.start_ate)
       << " | " << formatNumber(ok ? r.ate.rmse : nan) << " | "
       << formatNumber(ok && r.start != "truth" ? r.ate.rmse / r.start_ate : nan, "%.3f") << " | "
       << formatNumber(ok ? r.points_ate_floor : nan) << " | "
       << (ok && !std::isnan(r.curves_ate_floor) ? formatNumber(r.curves_ate_floor) + " - " +
                                                       formatNumber(r.curves_ate_floor_correlated)
                                                 : "")
       << " | " << formatNumber(ok ? r.ate.mean : nan) << " | "
       << formatNumber(ok ? r.ate.median : nan) << " | "
       << (std::isnan(r.map_precision)
               ? ""
               : formatNumber(r.map_precision, "%.3f") + " / " + formatNumber(r.map_recall, "%.3f"))
       << " | " << formatNumber(ok && r.rpe.count > 0 ? r.rpe.rmse : nan) << " | "
       << formatNumber(r.tracks_s, "%.1f") << " | " << formatNumber(r.tracks_ms, "%.1f") << " | "
       << formatNumber(r.init_s, "%.1f") << " | " << formatNumber(r.curves_s, "%.1f") << " | "
       << formatNumber(r.local_ba_s, "%.1f") << " | " << formatNumber(r.global_ba_s, "%.1f")
       << " | " << colmap << " | " << formatNumber(r.total_s, "%.1f") << " | "
       << (r.status == "failed" ? "failed: " : "") << note << " |";
  return line.str();
}

std::string markdownTable(const std::vector<Row>& rows, int tracking_threads) {
  std::ostringstream out;
  out << "| set | variant | start | registered | evaluated | start ATE | ATE rmse | ATE / start "
         "| points' ATE floor | curves' ATE floor (independent - correlated) | ATE mean | ATE "
         "median | map P / R at 2 cm | RPE t rmse "
         "| tracks s | tracks ms per 640x480 frame, "
      << (tracking_threads == 1 ? std::string("one core")
                                : std::to_string(tracking_threads) + " threads")
      << " | init s | curves s | local BA s | "
         "global BA s | COLMAP extract / match / "
         "map s | total s | note |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
         "---|\n";
  for (const Row& r : rows) out << markdownRow(r) << "\n";
  return out.str();
}

// " from START, run N" as the progress lines name a run: no start for init and COLMAP, no
// number for the first repetition.
std::string runSuffix(const std::string& start, int repetition) {
  return (start.empty() ? "" : " from " + start) +
         (repetition > 1 ? ", run " + std::to_string(repetition) : "");
}

void printProgress(const Row& r, int done, int total) {
  if (r.status == "ok") {
    std::printf("[%d/%d] %s %s%s: %d/%d registered, %d evaluated, ATE rmse %.4g", done, total,
                r.set.c_str(), r.variant.c_str(), runSuffix(r.start, r.repetition).c_str(),
                r.registered, r.frames, r.evaluated, r.ate.rmse);
    if (!std::isnan(r.start_ate)) std::printf(" (start %.4g)", r.start_ate);
    std::printf(", %.1f s\n", r.total_s);
  } else {
    std::printf("[%d/%d] %s %s: %s: %s\n", done, total, r.set.c_str(), r.variant.c_str(),
                r.status.c_str(), r.note.c_str());
  }
  std::fflush(stdout);
}

// Issue 14's targets for refined / start ATE per start; truth is judged against COLMAP's ATE.
double startTarget(const std::string& kind) {
  if (kind == "noise") return 0.5;
  if (kind == "init" || kind == "colmap") return 0.8;
  return std::nan("");
}

/// Per set, curve variant and start kind: refined / start ATE (noise: median and range over the
/// seeds), and the start exactly at the truth against COLMAP's ATE, beside issue 14's targets.
void printStartSummary(const std::vector<Row>& rows) {
  std::map<std::string, double> colmap_ate;
  for (const Row& r : rows) {
    if (r.variant == "colmap" && r.status == "ok") colmap_ate[r.set] = r.ate.rmse;
  }
  std::map<std::string, std::vector<double>> ratios;  // "set variant kind" -> ratios
  for (const Row& r : rows) {
    if (r.start.empty() || r.status != "ok") continue;
    const std::string kind = r.start.rfind("noise", 0) == 0 ? "noise" : r.start;
    const std::string key = r.set + " " + r.variant + " " + kind;
    if (kind == "truth") {
      const auto colmap = colmap_ate.find(r.set);
      const double reference = colmap == colmap_ate.end() ? std::nan("") : colmap->second;
      if (std::isnan(reference)) {
        std::printf("start %s: drift ATE %.4g (no COLMAP row to compare with)\n", key.c_str(),
                    r.ate.rmse);
      } else {
        std::printf("start %s: drift ATE %.4g, %.2f x COLMAP's %.4g (target <= 0.5)\n", key.c_str(),
                    r.ate.rmse, r.ate.rmse / reference, reference);
      }
      continue;
    }
    if (r.start_ate > 0.0) ratios[key].push_back(r.ate.rmse / r.start_ate);
  }
  for (auto& [key, values] : ratios) {
    std::sort(values.begin(), values.end());
    const std::string kind = key.substr(key.rfind(' ') + 1);
    const double target = startTarget(kind);
    const int met = static_cast<int>(
        std::count_if(values.begin(), values.end(), [&](double v) { return v <= target; }));
    std::printf(
        "start %s: refined / start ATE median %.3f, range %.3f-%.3f over %zu run(s); %d "
        "of %zu <= %.1f\n",
        key.c_str(), values[values.size() / 2], values.front(), values.back(), values.size(), met,
        values.size(), target);
  }
}

/// Per set and curve variant run from the truth and from other starts: each run's curve cost per
/// observation after its last BA, and which start's result the images agree with best. Where a
/// start's result fits better than the truth's, refining towards the images need not approach the
/// ground truth (its own error, or a camera model the images disagree with).
void printFitSummary(const std::vector<Row>& rows) {
  std::map<std::string, std::vector<const Row*>> groups;  // "set variant" -> runs with a cost
  for (const Row& r : rows) {
    if (r.start.empty() || r.status != "ok" || std::isnan(r.curve_cost_per_observation)) continue;
    groups[r.set + " " + r.variant].push_back(&r);
  }
  for (const auto& [key, runs] : groups) {
    const auto truth =
        std::find_if(runs.begin(), runs.end(), [](const Row* r) { return r->start == "truth"; });
    if (truth == runs.end() || runs.size() < 2) continue;
    const double reference = (*truth)->curve_cost_per_observation;
    const Row* best = *truth;
    std::printf("fit %s: curve cost per observation after the last BA:", key.c_str());
    for (const Row* r : runs) {
      std::printf(" %s %.4f", r->start.c_str(), r->curve_cost_per_observation);
      if (r != *truth) std::printf(" (%.3f x truth)", r->curve_cost_per_observation / reference);
      if (r->curve_cost_per_observation < best->curve_cost_per_observation) best = r;
    }
    // One run's map moves the figure by a few per cent (a rendered planar scene, exact truth: a
    // noise run at 0.96 x its truth's), so a smaller lead says nothing.
    constexpr double kSpread = 0.05;
    std::printf("; lowest: %s", best->start.c_str());
    if (best != *truth) {
      if (best->curve_cost_per_observation < (1.0 - kSpread) * reference) {
        std::printf(" (the images agree better with a result off the truth)");
      } else {
        std::printf(" (within %.0f %% of the truth's: one run's spread)", 100.0 * kSpread);
      }
    }
    std::printf("\n");
  }
}

/// Per set and curvesfm run: its wall time against COLMAP's on the same set in the same
/// repetition (issue 15: images to refined trajectory in <= 0.25 x COLMAP's), each repetition's
/// ratio and their median. The runs of one repetition follow each other, so a machine whose
/// speed drifts between them moves a single ratio; the median over interleaved repetitions less.
void printTimeBesideColmap(const std::vector<Row>& rows) {
  std::map<std::pair<std::string, int>, double> colmap_seconds;  // (set, repetition) -> s
  for (const Row& r : rows) {
    if (r.variant == "colmap" && r.status == "ok")
      colmap_seconds[{r.set, r.repetition}] = r.total_s;
  }
  struct Times {
    std::vector<double> ours, colmap, ratios;
  };
  std::map<std::string, Times> runs;  // "set variant[ from start]" -> one entry per repetition
  std::vector<std::string> order;
  for (const Row& r : rows) {
    const auto colmap = colmap_seconds.find({r.set, r.repetition});
    if (r.variant == "colmap" || r.status != "ok" || colmap == colmap_seconds.end()) continue;
    const std::string key = r.set + " " + r.variant + runSuffix(r.start, 1);
    if (runs.count(key) == 0) order.push_back(key);
    Times& times = runs[key];
    times.ours.push_back(r.total_s);
    times.colmap.push_back(colmap->second);
    times.ratios.push_back(r.total_s / colmap->second);
  }
  for (const std::string& key : order) {
    const Times& times = runs[key];
    std::printf(
        "time %s: %.1f s against COLMAP's %.1f s, %.3f x (medians over %zu repetition(s); "
        "each:",
        key.c_str(), upperMedian(times.ours), upperMedian(times.colmap), upperMedian(times.ratios),
        times.ratios.size());
    for (double ratio : times.ratios) std::printf(" %.3f", ratio);
    std::printf(")\n");
  }
}

void printSummary(const std::vector<Row>& rows, const std::vector<std::string>& variants) {
  for (const std::string& v : variants) {
    int ok = 0, failed = 0, skipped = 0;
    std::vector<double> ates;
    double registered = 0.0;
    for (const Row& r : rows) {
      if (r.variant != v) continue;
      ok += r.status == "ok";
      failed += r.status == "failed";
      skipped += r.status == "skipped";
      if (r.status == "ok") {
        ates.push_back(r.ate.rmse);
        registered += r.frames > 0 ? static_cast<double>(r.registered) / r.frames : 0.0;
      }
    }
    std::printf("%s: %d ok, %d failed, %d skipped; over the ok sets: mean registered %.0f %%\n",
                v.c_str(), ok, failed, skipped, ok > 0 ? 100.0 * registered / ok : 0.0);
  }
}

// ---------------------------------------------------------------------------------------------

/// The starts a variant runs from: every --starts entry (noise once per seed) for the curve
/// pipeline's variants, one for the others.
std::vector<Start> startsOf(const Variant& variant, const BenchOptions& options) {
  if (variant.command != "run") return {Start{}};
  std::vector<Start> starts;
  for (const std::string& kind : options.starts) {
    if (kind != "noise") starts.push_back({kind, 0});
    if (kind == "noise") {
      for (int seed : options.noise_seeds) starts.push_back({kind, seed});
    }
  }
  return starts;
}

/// `variant` with --map-at's poses as the poses that lift its map, when --map-at is given.
Variant withMapAt(Variant variant, const ImageSequence& sequence, const BenchOptions& options,
                  const fs::path& set_dir) {
  if (options.map_at.empty() || variant.command != "run") return variant;
  const std::string poses =
      startPosesFile(*startOfLabel(options.map_at), sequence, {}, options, set_dir);
  variant.flags.insert(variant.flags.end(), {"--diagnose-frontend-poses", poses});
  return variant;
}

/// With --noise-start-prior, a noise start's run holds each pose to its start at the noise's
/// sigmas (the rotation per axis, and the shift as a fraction of the camera spacing: the median
/// of all frames here, the mean of the keyframes' in `run`, the same when every frame is a
/// keyframe) and drops the motion prior: independent errors per pose put each consecutive motion
/// 1.4 x the noise off, which the motion prior (0.02 deg by default) would hold.
Variant withStartPrior(Variant variant, const Start& start, const BenchOptions& options) {
  if (!options.noise_start_prior || start.kind != "noise" || variant.command != "run") {
    return variant;
  }
  variant.flags.insert(
      variant.flags.end(),
      {"--ba-start-prior", "true", "--ba-start-prior-rotation",
       formatNumber(options.noise_rotation_deg, "%.10g"), "--ba-start-prior-centre",
       formatNumber(options.noise_spacing_fraction, "%.10g"), "--ba-motion-prior", "false"});
  return variant;
}

bool wantsColmapStart(const BenchOptions& options) {
  return std::find(options.starts.begin(), options.starts.end(), "colmap") != options.starts.end();
}

/// The variants to run, in order; COLMAP first when a curve run starts from its poses (and
/// added when --variants left it out).
std::vector<Variant> selectedVariants(const BenchOptions& options) {
  std::vector<Variant> variants;
  const bool runs_curves =
      std::any_of(options.variants.begin(), options.variants.end(),
                  [](const std::string& name) { return name == "curves" || name == "hybrid"; });
  const bool colmap_first = wantsColmapStart(options) && runs_curves;
  if (colmap_first) variants.push_back({"colmap", "", {}});
  for (const std::string& name : options.variants) {
    if (name == "colmap" && colmap_first) continue;
    if (name == "init") variants.push_back({name, "init", splitWords(options.init_flags)});
    if (name == "curves") variants.push_back({name, "run", {}});
    if (name == "hybrid") variants.push_back({name, "run", splitWords(options.hybrid_flags)});
    if (name == "colmap") variants.push_back({name, "", {}});
  }
  return variants;
}

// --map-at lifts the map in the ground truth's frame: only starts in that frame may use it.
void checkMapAt(const BenchOptions& options) {
  if (options.map_at.empty()) return;
  for (const std::string& kind : options.starts) {
    if (kind != "truth" && kind != "noise") {
      throw InvalidOptions("BenchOptions", "map_at", options.map_at,
                           "needs --starts of truth and noise only (" + kind +
                               " starts are not in the ground truth's frame)")
          .withFlag("map-at");
    }
  }
}

// The sets of kSets that --sets selects and --data holds.
std::vector<RealSet> builtInSets(const BenchOptions& options) {
  std::vector<RealSet> sets;
  if (options.no_builtin_sets) return sets;
  if (!fs::is_directory(options.data)) {
    throw IoError(options.data, "no such folder (--data: the folder of the real sets)");
  }
  for (const RealSet& set : kSets) {
    if (!options.sets.empty() &&
        std::find(options.sets.begin(), options.sets.end(), set.name) == options.sets.end()) {
      continue;
    }
    if (!fs::is_directory(fs::path(options.data) / set.subdir)) {
      std::printf("# skipped %s: no folder %s\n", set.name.c_str(),
                  (fs::path(options.data) / set.subdir).string().c_str());
      continue;
    }
    sets.push_back(set);
  }
  return sets;
}

// Every --planar-photos photo as a set whose folder below `out` is still to be rendered
// (renderPlanarSets), once every set has been checked.
std::vector<RealSet> planarSets(const BenchOptions& options, const fs::path& out) {
  std::vector<RealSet> sets;
  for (const std::string& photo : options.planar_photos) {
    const fs::path image = fs::path(options.planar_dir) / photo;
    if (!fs::is_regular_file(image)) {
      throw IoError(image.string(), "no such photo (--planar-photos)");
    }
    const std::string stem = fs::path(photo).stem().string();
    RealSet set;
    set.name = "planar_" + stem;
    set.subdir = fs::absolute(out / "planar_sets" / stem).string();
    set.why = "rendered from " + photo + " by curvesfm synth planar (its defaults)";
    set.rendered_from = image.string();
    sets.push_back(set);
  }
  return sets;
}

// Renders the sets that come from a photo (curvesfm synth planar: the paper's orbit over it, its
// ground truth, and no initial poses, so that an init start runs the point initialiser).
void renderPlanarSets(const BenchOptions& options, const fs::path& out,
                      const std::vector<RealSet>& sets) {
  for (const RealSet& set : sets) {
    if (set.rendered_from.empty()) continue;
    fs::remove_all(set.subdir);
    const fs::path log = out / (set.name + ".render.log");
    const bench::ProcessResult r =
        bench::runProcess({options.curvesfm, "synth", "planar", "--image", set.rendered_from,
                           "--out", set.subdir, "--init-poses", "false"},
                          log.string(), log.string());
    if (r.exit_code != 0) {
      throw Error("real_bench: curvesfm synth planar --image " + set.rendered_from +
                  " failed (exit code " + std::to_string(r.exit_code) +
                  "): " + bench::lastLine(log.string()));
    }
  }
}

// --extra-sets as sets, each named by its folder.
std::vector<RealSet> extraSets(const BenchOptions& options) {
  std::vector<RealSet> sets;
  for (const std::string& folder : options.extra_sets) {
    const fs::path dir = fs::absolute(folder).lexically_normal();
    if (!fs::is_directory(dir)) throw IoError(folder, "no such folder (--extra-sets)");
    const fs::path name = dir.has_filename() ? dir.filename() : dir.parent_path().filename();
    sets.push_back({name.string(), dir.string(), "", 0, 1, "given by --extra-sets " + folder});
  }
  return sets;
}

// Every set of the run: kSets, then the planar renders, then --extra-sets; names must differ,
// since each names its output folder.
std::vector<RealSet> selectedSets(const BenchOptions& options, const fs::path& out) {
  std::vector<RealSet> sets = builtInSets(options);
  for (const std::vector<RealSet>& more : {planarSets(options, out), extraSets(options)}) {
    sets.insert(sets.end(), more.begin(), more.end());
  }
  std::set<std::string> names;
  for (const RealSet& set : sets) {
    if (!names.insert(set.name).second) {
      const bool planar = !set.rendered_from.empty();
      throw InvalidOptions("BenchOptions", planar ? "planar_photos" : "extra_sets", set.name,
                           "two sets named " + set.name + ": each names its output folder")
          .withFlag(planar ? "planar-photos" : "extra-sets");
    }
  }
  return sets;
}

// The frames a set is read with: its table row's camera, stride and cap, or the command's.
ImageSequenceOptions sequenceOptionsFor(const RealSet& set, const BenchOptions& options) {
  ImageSequenceOptions sequence_options;
  sequence_options.camera = set.camera;
  sequence_options.stride = options.stride > 0 ? options.stride : set.stride;
  sequence_options.max_frames = set.max_frames;
  if (options.max_frames > 0 && (set.max_frames == 0 || options.max_frames < set.max_frames)) {
    sequence_options.max_frames = options.max_frames;
  }
  return sequence_options;
}

// What makes a set's rows differ from its table entry: the table's own note, then the caps.
std::string setNote(const RealSet& set, const BenchOptions& options,
                    const ImageSequenceOptions& sequence_options) {
  std::string note = set.why;
  if (options.stride > 0 && options.stride != set.stride) {
    note += std::string(note.empty() ? "" : "; ") + "--stride " + std::to_string(options.stride) +
            " overrides the table's stride " + std::to_string(set.stride);
  }
  if (sequence_options.max_frames > 0) {
    note += std::string(note.empty() ? "" : "; ") + "first " +
            std::to_string(sequence_options.max_frames) + " frames";
  }
  return note;
}

// One set's images and ground truth (written beside its rows), or nullopt with a `# skipped`
// line when it cannot be read or has no ground truth.
std::optional<ImageSequence> loadSet(const RealSet& set, const BenchOptions& options,
                                     const ImageSequenceOptions& sequence_options,
                                     const fs::path& set_dir) {
  try {
    ImageSequence sequence =
        loadImageSequence((fs::path(options.data) / set.subdir).string(), sequence_options);
    if (sequence.ground_truth.empty()) throw Error("no ground truth");
    writeTrajectory((set_dir / "groundtruth.txt").string(), sequence.ground_truth);
    return sequence;
  } catch (const Error& e) {
    std::printf("# skipped %s: %s\n", set.name.c_str(), e.what());
    return std::nullopt;
  }
}

// Everything one row of the bench needs besides its variant and start.
struct SetRun {
  const BenchOptions& options;
  const RealSet& set;
  const ImageSequence& sequence;
  const ImageSequenceOptions& sequence_options;
  const fs::path& set_dir;
  const std::string& note;
  const std::string& colmap;  // Empty when not on PATH.
  FlagCatalogue* catalogue;
  std::vector<StampedPose>* colmap_poses;  // Filled by the COLMAP row, read by its start.
};

// Runs one variant from one start into its own folder and returns its row.
Row runRow(const SetRun& run, const Variant& variant, const Start& start, int repetition,
           int number, int total) {
  Row row;
  row.set = run.set.name;
  row.variant = variant.name;
  if (variant.command == "run") row.start = start.label();
  row.repetition = repetition;
  row.frames = static_cast<int>(run.sequence.images.size());
  std::string name = start.kind == "init" ? variant.name : variant.name + "_" + start.label();
  if (repetition > 1) name += "_run" + std::to_string(repetition);
  const fs::path dir = run.set_dir / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::printf("[%d/%d] %s %s%s: running\n", number, total, run.set.name.c_str(),
              variant.name.c_str(), runSuffix(row.start, repetition).c_str());
  std::fflush(stdout);
  Variant run_variant = variant;  // with --map-at's flag once its poses file exists
  try {
    if (variant.name == "colmap") {
      if (run.colmap.empty()) {
        row.status = "skipped";
        row.note = "colmap is not on PATH";
      } else {
        runColmap(run.options, run.colmap, run.sequence, dir, &row, run.colmap_poses);
      }
    } else {
      const std::string init_poses =
          startPosesFile(start, run.sequence, *run.colmap_poses, run.options, run.set_dir);
      run_variant = withStartPrior(withMapAt(variant, run.sequence, run.options, run.set_dir),
                                   start, run.options);
      runCurvesfm(run.options, run_variant, run.set, run.sequence, run.sequence_options, init_poses,
                  run.catalogue, dir, &row);
    }
  } catch (const Error& e) {
    row.status = "failed";
    row.note = e.what();
  }
  if (row.status == "ok") {
    // The caps and flags that make this row differ from a plain run, then the run's note.
    std::vector<std::string> parts;
    for (const std::string& part : {run.note, joinWords(run_variant.flags), row.note}) {
      if (!part.empty()) parts.push_back(part);
    }
    row.note = joinWords(parts, "; ");
  }
  return row;
}

// real_bench.md, then the table and the summaries on stdout.
void reportRows(const std::vector<Row>& rows, const BenchOptions& options,
                const std::string& command, const fs::path& out) {
  const std::string table = markdownTable(rows, options.tracking_threads);
  {
    std::ofstream md(out / "real_bench.md");
    md << "# Real sets: initialiser, curves, hybrid BA, COLMAP\n\nCommand: `" << command
       << "`\n\nATE and RPE: Sim(3)-aligned, in the ground truth's unit (m; Blender units for "
          "pavilion); init and COLMAP evaluate every registered frame, curves and hybrid the "
          "keyframes of the curve pipeline. Times are wall times in seconds.\n\n"
       << table;
    if (!md) throw IoError((out / "real_bench.md").string(), "cannot write");
  }
  std::printf("\n%s\n", table.c_str());
  // Every repetition of a run is the same computation: the accuracy is read once.
  std::vector<Row> first;
  std::copy_if(rows.begin(), rows.end(), std::back_inserter(first),
               [](const Row& r) { return r.repetition == 1; });
  printSummary(first, options.variants);
  printStartSummary(first);
  printFitSummary(first);
  printTimeBesideColmap(rows);
}

int run(const BenchOptions& options, const std::string& command) {
  const Clock::time_point start = Clock::now();
  checkMapAt(options);
  const fs::path out(options.out);
  fs::create_directories(out);
  const std::vector<RealSet> sets = selectedSets(options, out);
  if (sets.empty()) {
    throw IoError(options.data,
                  "none of the benchmark's sets is there, and no --planar-photos or "
                  "--extra-sets given");
  }
  renderPlanarSets(options, out, sets);
  // COLMAP's GUI library needs a display unless Qt draws off-screen.
  setenv("QT_QPA_PLATFORM", "offscreen", 0);
  const std::vector<Variant> variants = selectedVariants(options);
  const std::string colmap = bench::findOnPath("colmap");
  FlagCatalogue catalogue(options.curvesfm, out.string());
  std::printf("# real_bench: %zu sets x %zu variants; curvesfm %s; colmap %s\n", sets.size(),
              variants.size(), options.curvesfm.c_str(),
              colmap.empty() ? "not on PATH" : colmap.c_str());

  std::vector<Row> rows;
  int rows_per_set = 0;
  for (const Variant& variant : variants) {
    rows_per_set += static_cast<int>(startsOf(variant, options).size()) * options.repetitions;
  }
  const int total = static_cast<int>(sets.size()) * rows_per_set;
  for (const RealSet& set : sets) {
    const ImageSequenceOptions sequence_options = sequenceOptionsFor(set, options);
    const fs::path set_dir = out / set.name;
    fs::create_directories(set_dir);
    const std::string note = setNote(set, options, sequence_options);
    const std::optional<ImageSequence> sequence = loadSet(set, options, sequence_options, set_dir);
    if (!sequence) continue;
    std::vector<StampedPose> colmap_poses;
    const SetRun set_run{options, set,    *sequence,  sequence_options, set_dir,
                         note,    colmap, &catalogue, &colmap_poses};
    for (int repetition = 1; repetition <= options.repetitions; ++repetition) {
      for (const Variant& variant : variants) {
        for (const Start& start : startsOf(variant, options)) {
          rows.push_back(runRow(set_run, variant, start, repetition,
                                static_cast<int>(rows.size()) + 1, total));
          printProgress(rows.back(), static_cast<int>(rows.size()), total);
          // Rewritten after every row, so that a long bench stopped half-way keeps what it
          // measured.
          writeCsv(rows, out / "real_bench.csv");
        }
      }
    }
  }
  reportRows(rows, options, command, out);
  bench::print("total_seconds", bench::secondsSince(start));
  bench::printText("outputs", (out / "{real_bench.csv,real_bench.md}").string());
  drawFiguresIfPossible({"real-bench", out.string()});
  return 0;
}

std::string setNames() {
  std::string names;
  for (const RealSet& set : kSets) names += (names.empty() ? "" : ", ") + set.name;
  return names;
}

}  // namespace
}  // namespace curvesfm

int main(int argc, char** argv) {
  using curvesfm::BenchOptions;
  BenchOptions options;
  CLI::App app{"Real sets through the initialiser, curves, hybrid BA and COLMAP, side by side"};
  app.name("real_bench");
  app.add_option("--data", options.data, "Folder holding the real sets")->capture_default_str();
  app.add_option("--out", options.out, "Output folder for CSV, table, plots and runs")
      ->capture_default_str();
  app.add_option("--curvesfm", options.curvesfm, "The curvesfm executable")->capture_default_str();
  app.add_option_function<std::string>(
         "--sets",
         [&options](const std::string& list) {
           options.sets = curvesfm::bench::splitAtCommas(list, "--sets");
           options.no_builtin_sets = options.sets == std::vector<std::string>{"none"};
           if (options.no_builtin_sets || options.sets == std::vector<std::string>{"all"}) {
             options.sets.clear();
             return;
           }
           for (const std::string& name : options.sets) {
             const auto known = [&](const curvesfm::RealSet& s) { return s.name == name; };
             if (std::none_of(curvesfm::kSets.begin(), curvesfm::kSets.end(), known)) {
               throw CLI::ValidationError("--sets", "'" + name + "' is not a benchmark set (" +
                                                        curvesfm::setNames() + ")");
             }
           }
         },
         "Comma-separated set names to run, all, or none (only --planar-photos and "
         "--extra-sets)")
      ->default_str("all");
  app.add_option_function<std::string>(
         "--extra-sets",
         [&options](const std::string& list) {
           options.extra_sets = curvesfm::bench::splitAtCommas(list, "--extra-sets");
         },
         "Comma-separated dataset folders to run beside the sets of --data (any layout curvesfm "
         "run reads, with ground truth; each named by its folder, its init start the folder's "
         "init_poses.txt when it has one)")
      ->default_str("");
  app.add_option_function<std::string>(
         "--planar-photos",
         [&options](const std::string& list) {
           options.planar_photos = curvesfm::bench::splitAtCommas(list, "--planar-photos");
           if (options.planar_photos == std::vector<std::string>{"all"}) {
             options.planar_photos.clear();
             for (const auto& photo : curvesfm::bench::planarPhotos()) {
               options.planar_photos.push_back(photo.file);
             }
           }
         },
         "Comma-separated photos of --planar-dir (or all: planar_bench's nine), each rendered "
         "by curvesfm synth planar into OUT/planar_sets and run as the set planar_<name>")
      ->default_str("");
  app.add_option("--planar-dir", options.planar_dir, "Folder of --planar-photos")
      ->capture_default_str();
  app.add_option_function<std::string>(
         "--variants",
         [&options](const std::string& list) {
           options.variants = curvesfm::bench::splitAtCommas(list, "--variants");
           for (const std::string& name : options.variants) {
             if (std::find(curvesfm::kVariantNames.begin(), curvesfm::kVariantNames.end(), name) ==
                 curvesfm::kVariantNames.end()) {
               throw CLI::ValidationError(
                   "--variants", "'" + name + "' is not one of init, curves, hybrid, colmap");
             }
           }
         },
         "Comma-separated variants: init, curves, hybrid, colmap")
      ->default_str("init,curves,hybrid,colmap");
  app.add_option("--hybrid-flags", options.hybrid_flags,
                 "Flags the hybrid variant adds to `curvesfm run` (one string)")
      ->capture_default_str();
  app.add_option("--init-flags", options.init_flags,
                 "Flags the init variant adds to `curvesfm init` (one string), e.g. "
                 "\"--points-ba-refine-focal true\"")
      ->capture_default_str();
  app.add_option("--max-frames", options.max_frames,
                 "At most this many frames of every set (0: each set's own cap)")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  app.add_option("--stride", options.stride,
                 "Every stride-th frame of every set (0: each set's own; 7-Scenes takes every 3rd)")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  app.add_option_function<std::string>(
         "--starts",
         [&options](const std::string& list) {
           options.starts = curvesfm::bench::splitAtCommas(list, "--starts");
           for (const std::string& name : options.starts) {
             if (std::find(curvesfm::kStartNames.begin(), curvesfm::kStartNames.end(), name) ==
                 curvesfm::kStartNames.end()) {
               throw CLI::ValidationError(
                   "--starts", "'" + name + "' is not one of init, truth, noise, colmap");
             }
           }
         },
         "Comma-separated starts of the curves and hybrid runs: init (the point initialiser), "
         "truth, noise (the truth perturbed, per --noise-seeds), colmap (COLMAP's poses)")
      ->default_str("init");
  app.add_option_function<std::string>(
         "--noise-seeds",
         [&options](const std::string& list) {
           options.noise_seeds.clear();
           for (const std::string& word : curvesfm::bench::splitAtCommas(list, "--noise-seeds")) {
             try {
               options.noise_seeds.push_back(std::stoi(word));
             } catch (const std::exception&) {
               throw CLI::ValidationError("--noise-seeds", "'" + word + "' is not an integer");
             }
           }
         },
         "Comma-separated seeds, one noise start each")
      ->default_str("1,2,3,4,5");
  app.add_option("--noise-spacing-fraction", options.noise_spacing_fraction,
                 "Noise start: camera shift per axis as a fraction of the median camera spacing")
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  app.add_option("--noise-rotation-deg", options.noise_rotation_deg,
                 "Noise start: rotation per axis (deg)")
      ->check(CLI::Range(0.0, 90.0))
      ->capture_default_str();
  app.add_option("--noise-start-prior", options.noise_start_prior,
                 "Noise starts: run with --ba-start-prior at the noise's own sigmas (each pose "
                 "known to within them) instead of the motion prior")
      ->capture_default_str();
  app.add_option("--colmap-refine-focal", options.colmap_refine_focal,
                 "COLMAP's mapper refines the focal length (the peer of --init-flags "
                 "\"--points-ba-refine-focal true\"); by default it keeps the set's calibration")
      ->capture_default_str();
  app.add_option("--start-origin", options.start_origin,
                 "Where the start files' world origin lies: native (the set's frame) or first "
                 "(moved by a translation to the first camera's centre); the refined poses must "
                 "not depend on it")
      ->check(CLI::IsMember({"native", "first"}))
      ->capture_default_str();
  app.add_option("--start-jitter-seed", options.start_jitter_seed,
                 "> 0: move every start file's camera centres by a Gaussian of 1e-6 median camera "
                 "spacings per axis drawn with this seed (far below any data's accuracy, yet it "
                 "flips the pipeline's discrete decisions: run several seeds to see the spread a "
                 "single run hides); 0: none")
      ->check(CLI::Range(0, std::numeric_limits<int>::max()))
      ->capture_default_str();
  app.add_option_function<std::string>(
         "--map-at",
         [&options](const std::string& label) {
           if (!curvesfm::startOfLabel(label)) {
             throw CLI::ValidationError("--map-at", "'" + label +
                                                        "' is not truth or noise<seed> (e.g. "
                                                        "noise1)");
           }
           options.map_at = label;
         },
         "Diagnosis: lift and register every curve at these poses (truth, or noise<seed> as "
         "--noise-seeds makes them) while BA starts from each run's own start; needs --starts "
         "of truth and noise only")
      ->default_str("");
  app.add_option("--threads", options.threads, "Threads of every solver and of COLMAP")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  app.add_option("--tracking-threads", options.tracking_threads,
                 "Threads of curvesfm's tracking (--points-tracking-threads; 1: the tracks ms per "
                 "frame are per core; --threads for the time beside COLMAP, whose feature "
                 "extraction runs on --threads)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  app.add_option("--repetitions", options.repetitions,
                 "Runs every set's variants this many times, interleaved (each once, then all "
                 "again), and prints each curvesfm run's wall time against COLMAP's per "
                 "repetition and their median: a shared machine's speed drifts over minutes")
      ->check(CLI::Range(1, 20))
      ->capture_default_str();
  const std::string command = curvesfm::bench::commandLine(argc, argv);
  return curvesfm::bench::parseAndRun(app, argc, argv,
                                      [&] { return curvesfm::run(options, command); });
}
