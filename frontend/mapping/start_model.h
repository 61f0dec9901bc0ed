#pragma once

#include <array>
#include <utility>

#include "core/camera.h"
#include "core/enum_names.h"
#include "frontend/mapping/point_initialiser.h"

namespace curvesfm {

// How the initial poses a run is given are off, read from the images (issue 14). The BA's prior
// on the start has to match it: a start that drifts (odometry, the point initialiser, COLMAP) is
// locally accurate, and the motion prior ties each consecutive motion to its own; a start whose
// poses are each off on their own (GNSS/INS, the benches' truth + noise) has consecutive motions
// off by 1.4 times that noise, and the motion prior holds those errors (planar protocol with 0.1
// deg per pose: refined / start 3.15 x with it, 0.65 x with a prior on each pose alone;
// docs/benchmarks.md). The images tell the two apart: the points triangulated at the given poses
// average each frame's error over their tracks, so registering each frame again against them
// (PnP) moves it by its error less the local mean of its neighbours'. Errors independent per pose
// give moves that differ as much between frames one apart as between frames k apart (a flat
// variogram); a drift, a random walk, gives moves that differ more the further apart the frames
// are (a variogram that grows with the lag, up to the tracks' length); a start that agrees with
// the images (the truth, or a start refined on these points) hardly moves at all.
// Measured since (session 36), the variogram does not separate the two kinds on 30 frames, and
// a start that drifts does better tied per pose and lifted again than under the motion prior, so
// by default every start that moves is tied per pose (tiesEachPose); the motion prior stays for
// starts that agree with the images, those not measured and the initialiser's own.

/// What the images say about the given start.
enum class StartModel {
  kNotMeasured,  ///< Too few frames saw enough points, or none are 1 and k apart (see below).
  kConsistent,   ///< The frames move too little (below min_rotation_deg, or within
                 ///< min_rotation_to_measurement times the PnP's own noise): the start agrees
                 ///< with the images as far as they tell.
  kDrifting,     ///< They move more, farther apart more unlike: a drift.
  kPerPose,      ///< They move more, as unlike at any lag: an error independent per pose.
};

template <>
struct EnumNames<StartModel> {
  static constexpr std::array<std::pair<StartModel, const char*>, 4> kNames = {{
      {StartModel::kNotMeasured, "not_measured"},
      {StartModel::kConsistent, "consistent"},
      {StartModel::kDrifting, "drifting"},
      {StartModel::kPerPose, "per_pose"},
  }};
};

/// What estimateStartModel() calls a start, and which verdicts make the run tie each keyframe to
/// its start (CurveBundleAdjustmentOptions::start_prior) instead of using the motion prior.
struct StartModelOptions {
  /// Measure the start and, when it moves against the images (tiesEachPose), switch the BA from
  /// the motion prior to the start prior at rotation_prior_sigma_scale and prior_sigma_scale times
  /// the measured sigmas (run only, with given initial poses; an explicit --ba-start-prior keeps
  /// its own sigmas).
  bool from_images = true;
  /// A frame is measured only if it sees at least this many of the points (count). >= 6.
  int min_points = 30;
  /// A verdict needs at least this many measured frames (count): the variogram at lag k then
  /// averages at least 14 pairs of frames. The still sets (11-19 frames, some not in view order)
  /// gave verdicts that flipped between noise seeds of one kind (docs/benchmarks.md). >= 3.
  int min_frames = 20;
  /// A start whose frames move by less than this, RMS per axis, agrees with the images (deg).
  /// Above the measurement's own noise: a true start moves 0.005-0.037 deg on fountain-P11,
  /// Pavilion, KITTI 06 and templeRing (7-Scenes' ground truth, good to 1-2 cm, 0.15 deg;
  /// docs/benchmarks.md). Finite, > 0.
  double min_rotation_deg = 0.04;
  /// ... nor when they move less than this many times the PnP rotation's own standard deviation
  /// (from its inliers' reprojection scatter; unitless, RMS over the frames): 1 is a start whose
  /// moves are the measurement's noise alone. True starts measure 1.0-1.7 x on the planar scenes
  /// and 1.4 x on Pavilion, noise of 0.1 deg per pose 1.2-5.5 x (the logos, whose few corners
  /// measure poorly, 1.2-3.3 x): the images cannot tell the two apart there, and the errors cost
  /// unequally. A start off per pose read as consistent keeps the motion prior and ends 3-5 x
  /// farther off than it started (LinuxLogo 3.7 x, tied per pose 0.53 x), a true start tied per
  /// pose drifts 0.01-0.07 mm instead of 0.01-0.04 on the planar scenes (docs/benchmarks.md,
  /// sessions 34 and 36). Finite, > 0.
  double min_rotation_to_measurement = 1.0;
  /// The variogram is read at lags 1 and k = min(this, measured frames / 3) (frames). In [2, 100].
  int max_variogram_lag = 8;
  /// Above min_rotation_deg, the start is off per pose when the rotation moves' mean squared
  /// difference at lag k is at most this many times that at lag 1 (unitless; 1 for errors
  /// independent per pose, about min(k, track length) for a random walk). Measured at lag 8:
  /// 0.85-1.46 for noise applied per pose (Pavilion, KITTI 06, planar scenes), 1.7-5.6 for the
  /// planar drift starts and 7-Scenes' ground truth (docs/benchmarks.md). Finite, > 0.
  double max_variogram_growth = 1.6;
  /// A start off per pose is tied to each of its centres with std devs of this times the measured
  /// centre noise (unitless): the edge term counts each segment's shared error once per sample,
  /// so a prior at the true noise loses to it, as the motion prior's sigmas are the drift's over
  /// 2.5 (CurveBundleAdjustmentOptions). Pavilion noise seed 1, refined / start at 1 / 0.4 of the
  /// measured sigmas: 0.99 / 0.65 x (docs/benchmarks.md). In (0, 10].
  double prior_sigma_scale = 0.4;
  /// ... and to each of its orientations with std devs of this times the measured rotation noise
  /// (unitless). The curves measure a view's rotation far better than its centre: a prior that
  /// holds the rotations near their noisy start makes the BA fit the images by moving the centres
  /// instead (a planar start off by 0.1 deg and exact in its centres ended 0.14 mm off at 0.4 x).
  /// At 1.5 rather than 0.4: the planar per-pose starts 0.26-0.53 x against 0.41-1.74,
  /// KITTI 06's five noise starts median 0.57 against 0.59, Pavilion's median 0.43 against 0.42
  /// (docs/benchmarks.md, "The rotation prior of a per-pose start"). In (0, 100].
  double rotation_prior_sigma_scale = 1.5;
  /// A start tied per pose runs the pipeline this many more times (at least; --relift-passes may
  /// ask more), each lifting and registering the map again at the previous pass's refined poses
  /// under the same start prior: the map lifted at the noisy start holds its noise, one lifted at
  /// better poses gives better poses. Refined / start, one pass against none, noise seeds 1-3:
  /// Pavilion 0.50-0.53 against 0.66-0.71 x, KITTI 06 0.50-0.63 against 0.74-0.91 x, planar
  /// per-pose starts 0.46-1.10 against 0.64-1.08 x (docs/benchmarks.md, session 34); it doubles
  /// the run's time. In [0, 100].
  int relift_passes = 1;
  /// A start read as drifting is tied to each of its poses too, as a per-pose one (start prior
  /// at the measured sigmas, relift_passes), instead of keeping the motion prior. On 30 frames
  /// the variogram does not tell the two kinds apart (planar starts: growth 0.7-2.0 for noise
  /// per pose, 0.9-4.2 for a drift), and a drift tied per pose ends closer than under the motion
  /// prior: 19 of 26 planar drift starts (median 0.72 x its ATE), the 7-Scenes kitchen's truth
  /// (its ground truth's own drift) 15.4 mm off instead of 19.8 (docs/benchmarks.md, "A start
  /// that moves is tied per pose"). False keeps the motion prior for drifting starts.
  bool tie_drifting_per_pose = true;
  /// A start tied per pose runs at most this many re-association rounds in each pass
  /// (PipelineOptions::reassociation_rounds, 3; count, -1: the pipeline's own). Its relift pass
  /// already registers the map again at better poses, and each further round adds matches that
  /// pull a close start away. Two rather than three, side by side in one build (session 37):
  /// Pavilion's noise starts median 0.41 against 0.43 x, KITTI 06's 0.55 against 0.59 x, the
  /// planar per-pose starts 37 against 35 of 45 at or below 0.5 x, the 7-Scenes kitchen's truth
  /// 12.7 against 14.3 mm. One round gains more on the kitchen (9.6 mm) but loses on Pavilion
  /// (median 0.48 x) and KITTI (0.62 x) (docs/benchmarks.md, "Two re-association rounds for a
  /// start tied per pose"). -1 or in [0, 100].
  int reassociation_rounds = 2;
  /// Read the start against the points triangulated from two views each
  /// (PointInitialisation::two_view_points) where the BA's points were refined over all their
  /// views (PointInitialiserOptions::refine_at_given_poses), rather than against those. The
  /// scales above were set on two-view points; refined points share more of each frame's error,
  /// so on the planar scenes they read a per-pose start as off by less (box_in_scene noise seed
  /// 1: 0.033 against 0.050 spacings) and the prior ties it tighter. Planar noise starts with
  /// refined points, 45 runs: 34 at or below 0.5 x read this way, 30 read on the refined points,
  /// 36 with two-view points throughout (docs/benchmarks.md, session 53); Pavilion and KITTI 06
  /// read the same within 5 % either way.
  bool two_view_points = true;
  /// PnP's inlier threshold on the reprojection error (px). Finite, > 0.
  double max_reprojection_error_px = 4.0;

  /// Throws InvalidOptions naming the first field outside its range.
  void validate() const;
};

/// The measurement and the verdict.
struct StartModelEstimate {
  StartModel model = StartModel::kNotMeasured;
  int frames_measured = 0;  ///< Frames with a pose registered again by PnP.
  /// RMS per axis over the measured frames of the rotation that takes each given pose to its PnP
  /// pose (deg), and of the centre's move (pose units, and in mean spacings between consecutive
  /// given camera centres): about the start's noise per pose when it is off per pose (a little
  /// less, as the points share it).
  double rotation_rms_deg = 0.0;
  double centre_rms = 0.0;
  double centre_rms_spacings = 0.0;
  /// The rotation moves over the PnP rotation's own standard deviation (RMS over the frames).
  double rotation_to_measurement = 0.0;
  /// The lag k (frames) and the variogram's growth from lag 1 to it (StartModelOptions).
  int variogram_lag = 0;
  double variogram_growth = 0.0;
};

/// Whether a run ties each keyframe to its start (the start prior at the measured sigmas, and
/// relift_passes) rather than each motion to the start's: for a start read as per pose, and for a
/// drifting one unless options.tie_drifting_per_pose is false.
bool tiesEachPose(const StartModelEstimate& estimate, const StartModelOptions& options);

/// Registers every posed frame of `points` (InitialisedFrame::cam_from_world, the given start;
/// PointInitialiser::finishAtPoses) again by PnP against the points triangulated at those poses
/// and reads the start's model from how the frames move. `camera`: the undistorted pinhole camera
/// the observations' pixels refer to. Deterministic. Throws InvalidOptions on bad options.
StartModelEstimate estimateStartModel(const Camera& camera, const PointInitialisation& points,
                                      const StartModelOptions& options = {});

}  // namespace curvesfm
