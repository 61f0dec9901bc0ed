#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "core/camera.h"
#include "core/curve_map_io.h"
#include "core/pose3.h"
#include "frontend/image/edge_detector.h"

namespace curvesfm {

// How much of a set of 3D curves the images show as edges. For each point of the curves (with the
// curve's direction there), the views whose image it projects into and those where the image has
// an edge at its projection: an edge pixel (the pipeline's Canny) within a pixel or two whose
// normal is nearly normal to the projected curve. On ground-truth curves this bounds what an
// edge-based reconstruction can lift: a point that no two views show on an edge cannot be
// triangulated from edges. Occlusion is not modelled (a hidden point whose projection falls on
// another edge of the same direction counts), so the figures are upper bounds; in a textured
// image a point falls near some edge by chance, which the direction test and a share of the
// views (EdgeCoverage's callers) keep apart from an edge the image really shows.

/// Options of EdgeCoverageCounter.
struct EdgeCoverageOptions {
  /// The nearest edge pixel's centre lies within this distance of the pixel centre the point
  /// projects into (px). In (0, 100].
  double max_edge_distance_px = 1.5;
  /// ... and its normal within this angle of the projected curve's normal (deg). In (0, 90].
  double max_normal_angle_deg = 30.0;
  EdgeDetectorOptions edges;  ///< The edge detector (run's --edges-* defaults).
  /// Throws InvalidOptions naming the first field outside its range.
  void validate() const;
};

/// Per point, how many views it projects into and how many show it on an edge.
struct PointViews {
  int in_image = 0;  ///< In front of the camera and inside the image.
  int on_edge = 0;   ///< Of those, the views with an edge of the curve's direction there.
  /// Of those, the views where one of the nearby curves (setNearbyCurves) projects within
  /// max_edge_distance_px of it.
  int near_curve = 0;
};

/// Counts the views of fixed points, one view at a time (a long sequence need not be in memory).
class EdgeCoverageCounter {
 public:
  /// `points` and the unit `directions` of their curves there, in the world frame of the poses
  /// given to addView(). Throws InvalidOptions, and CheckError when the sizes differ.
  EdgeCoverageCounter(std::vector<Eigen::Vector3d> points,
                      std::vector<Eigen::Vector3d> directions, const EdgeCoverageOptions& options);

  /// One view: its 8-bit image (grey or BGR), undistorted for the pinhole `camera` of its size,
  /// and its pose. Throws CheckError when the image does not have the camera's size.
  void addView(const cv::Mat& image, const Pose3& cam_from_world, const Camera& camera);

  /// Curves (polylines in the points' world frame, e.g. an estimated map aligned onto the ground
  /// truth) whose projection the views after this call also look for near each point: where an
  /// image shows a ground-truth curve as an edge, whether the map has a curve there in the image,
  /// whatever its depth. Segments with an end behind the camera are left out.
  void setNearbyCurves(Polylines3 curves) { nearby_curves_ = std::move(curves); }

  int numViews() const { return num_views_; }
  const std::vector<PointViews>& views() const { return views_; }

 private:
  std::vector<Eigen::Vector3d> points_;
  std::vector<Eigen::Vector3d> directions_;
  EdgeCoverageOptions options_;
  std::vector<PointViews> views_;
  Polylines3 nearby_curves_;
  int num_views_ = 0;
};

}  // namespace curvesfm
