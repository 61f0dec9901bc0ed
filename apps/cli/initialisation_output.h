#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/dataset_io.h"
#include "core/image_sequence.h"
#include "core/tum_dataset.h"
#include "frontend/mapping/pipeline.h"
#include "frontend/mapping/point_initialiser.h"

namespace curvesfm {

// What `init` and `run` (without initial poses) share: running the point initialiser over a
// sequence with progress lines, its summary, and its files (trajectory, points, report part).

/// Runs the initialiser over every image of `sequence`, printing a line every tenth of the
/// frames while tracking and after every tenth registered frame. IoError for an image that does
/// not load or has another size than the camera.
PointInitialisation initialiseSequence(const ImageSequence& sequence,
                                       const PointInitialiserOptions& options);

/// The initialiser's tracks of every image of `sequence`, triangulated at the poses of `frames`
/// (PointInitialiser::finishAtPoses; an image is matched to its frame by path, and one without a
/// frame keeps no pose). Prints progress as initialiseSequence.
PointInitialisation triangulateAtPoses(const ImageSequence& sequence,
                                       const std::vector<DatasetFrame>& frames,
                                       const PointInitialiserOptions& options);

/// Per frame of `frames` (in their order, matched to the images by path), the points of
/// `result` it sees: the hybrid graph's input for frames that did not come from the initialiser.
std::vector<std::vector<PointSighting>> sightingsOfFrames(const ImageSequence& sequence,
                                                          const std::vector<DatasetFrame>& frames,
                                                          const PointInitialisation& result);

/// The registered frames with their images and poses, in sequence order: the frames `run` feeds
/// to the curve pipeline.
std::vector<DatasetFrame> initialisedFrames(const ImageSequence& sequence,
                                            const PointInitialisation& result);

/// Per frame of initialisedFrames(), the map points it sees (the hybrid graph's input).
std::vector<std::vector<PointSighting>> initialisedSightings(const PointInitialisation& result);

/// The registered frames as a TUM trajectory (camera-to-world, the images' timestamps).
std::vector<StampedPose> initialisedTrajectory(const ImageSequence& sequence,
                                               const PointInitialisation& result);

/// Writes the map as points.ply (colour and track length per point) at `path`; with
/// `refined_positions` (one per point, e.g. after the hybrid graph's BA) at those positions.
void writeInitialisedPoints(const std::string& path, const PointInitialisation& result,
                            const std::vector<Eigen::Vector3d>* refined_positions = nullptr);

/// A camera's intrinsics and image size as report.json gives them.
nlohmann::json cameraToJson(const Camera& camera);

/// "N observations reproject with rms R px, mean residual (x, y) px": the summary line of a
/// ReprojectionSummary, followed by its centre precision when it has one (the noise per
/// coordinate and the ATE it alone would leave, or that the points do not fix every centre).
std::string reprojectionLine(const ReprojectionSummary& reprojection);

/// The report.json part of the initialiser: counts, the points' reprojection, the scale
/// convention, the initial pair, per frame its registration (status, reason, correspondences,
/// inliers), every BA's summary and the per-stage times.
nlohmann::json initialisationToJson(const ImageSequence& sequence,
                                    const PointInitialisation& result);

/// Prints the summary: frames registered, the unregistered frames by reason, models, points,
/// times; with ground truth, the Sim(3) ATE of the registered frames. Returns that ATE's JSON
/// (null without ground truth).
nlohmann::json printInitialisationSummary(const ImageSequence& sequence,
                                          const PointInitialisation& result);

}  // namespace curvesfm
