#pragma once

#include <string>

#include "apps/cli/curve_overlays.h"
#include "apps/cli/options_table.h"
#include "core/camera.h"
#include "core/curve_map_evaluation.h"
#include "core/image_sequence.h"
#include "core/trajectory_evaluation.h"
#include "factors/curve_bundle_adjustment.h"
#include "factors/point_bundle_adjustment.h"
#include "frontend/image/curve_overlay.h"
#include "frontend/image/edge_coverage.h"
#include "frontend/image/feature_matching.h"
#include "frontend/image/point_tracks.h"
#include "frontend/image/two_view_geometry.h"
#include "frontend/mapping/pipeline.h"
#include "frontend/mapping/point_initialiser.h"
#include "frontend/mapping/start_model.h"
#include "graph/optimizer.h"
#include "graph/scheduler.h"
#include "sim/curve_scene.h"
#include "sim/planar_scene.h"
#include "sim/point_scene.h"

namespace curvesfm {

// The table of every options struct: one function per struct adds a row per field (see
// options_table.h). Flags keep the names users know; a struct that appears twice in a command
// (the optimizer of local BA, global BA and tracking) takes a prefix per place.

/// Where a struct's rows go.
struct OptionPlace {
  std::string path;     ///< JSON pointer below report.json's "options", e.g. "/pipeline/local_ba".
  std::string prefix;   ///< Prepended to every flag, e.g. "local-ba-".
  std::string heading;  ///< --help heading, e.g. "Local BA".
  std::string what;     ///< Names the solve in descriptions, e.g. "local BA"; may be empty.

  /// The place of nested struct `field`: its path below this one, the same prefix and heading.
  OptionPlace child(const std::string& field) const;
  /// `text` led by `what` when there is one: "local BA: most rounds".
  std::string describe(const std::string& text) const;
};

void addOptimizerOptions(OptionsTable* table, OptimizerOptions* options, const OptionPlace& place);
/// fix_first_pose is not a flag: the command holds one gauge switch, `*fix_first_pose`, for the
/// graph builder and the scheduler.
void addSchedulerOptions(OptionsTable* table, SchedulerOptions* options, const OptionPlace& place,
                         const bool* fix_first_pose);
void addCurveBundleAdjustmentOptions(OptionsTable* table, CurveBundleAdjustmentOptions* options,
                                     const OptionPlace& place);
void addPointBundleAdjustmentOptions(OptionsTable* table, PointBundleAdjustmentOptions* options,
                                     const OptionPlace& place);
/// Every stage of the pipeline under `path`, flags named by stage (`--edges-*`, `--depth-*`,
/// `--local-ba-*`, ...).
void addPipelineOptions(OptionsTable* table, PipelineOptions* options, const std::string& path);
void addStartModelOptions(OptionsTable* table, StartModelOptions* options, const std::string& path);
/// The sanity checks of the pipeline (`--sanity-*` in run).
void addSanityOptions(OptionsTable* table, SanityOptions* options, const OptionPlace& place);
void addCurveOverlayOptions(OptionsTable* table, CurveOverlayOptions* options,
                            const OptionPlace& place);
/// How run colours the overlays (`--overlay-colour-by`); it shares the drawing's place.
void addOverlayColouringOptions(OptionsTable* table, OverlayColouringOptions* options,
                                const OptionPlace& place);
/// The point-based initialiser (init, and run without initial poses): every flag starts with
/// "points-" (e.g. --points-klt-grid-cols, --points-pnp-min-inliers) so that it never meets the
/// curve pipeline's flags in `run`.
void addPointInitialiserOptions(OptionsTable* table, PointInitialiserOptions* options,
                                const std::string& path);
/// The dataset flags `init` and `run` share: the layout, the camera override and which images to
/// take (report.json "options/sequence").
void addImageSequenceOptions(OptionsTable* table, ImageSequenceOptions* options);
void addFeatureTrackOptions(OptionsTable* table, FeatureTrackOptions* options,
                            const OptionPlace& place);
void addAbsolutePoseOptions(OptionsTable* table, AbsolutePoseOptions* options,
                            const OptionPlace& place);
void addPointTrackerOptions(OptionsTable* table, PointTrackerOptions* options,
                            const OptionPlace& place);
void addFeatureMatchingOptions(OptionsTable* table, FeatureMatchingOptions* options,
                               const OptionPlace& place);
void addCameraIntrinsics(OptionsTable* table, CameraIntrinsics* intrinsics,
                         const OptionPlace& place);
void addCurveSceneOptions(OptionsTable* table, CurveSceneOptions* options,
                          const OptionPlace& place);
void addPointSceneOptions(OptionsTable* table, PointSceneOptions* options,
                          const OptionPlace& place);
/// cx and cy are not flags: `curvesfm synth planar` centres the principal point.
void addPlanarSceneOptions(OptionsTable* table, PlanarSceneOptions* options,
                           const OptionPlace& place);
void addTwoViewOptions(OptionsTable* table, TwoViewOptions* options, const OptionPlace& place);
void addTrajectoryEvaluationOptions(OptionsTable* table, TrajectoryEvaluationOptions* options,
                                    const OptionPlace& place);
/// taus is one comma-separated flag value, e.g. `--tau 0.01,0.02,0.05`.
/// The pipeline's Canny (`--edges-*` in run, under `place.prefix` elsewhere).
void addEdgeDetectorOptions(OptionsTable* table, EdgeDetectorOptions* options,
                            const OptionPlace& place);
/// eval-map's edge coverage of the ground truth (`--edge-coverage-*`).
void addEdgeCoverageOptions(OptionsTable* table, EdgeCoverageOptions* options,
                            const OptionPlace& place);
void addCurveMapEvaluationOptions(OptionsTable* table, CurveMapEvaluationOptions* options,
                                  const OptionPlace& place);

}  // namespace curvesfm
