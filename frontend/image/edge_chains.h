#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "frontend/image/edge_detector.h"

namespace curvesfm {

/// How extractEdgeChains() groups edge pixels into chains (paper §2.3: "grouping them into
/// curves based on simple connectivity and thresholding of local curvature").
struct EdgeChainOptions {
  /// Chains with fewer pixels are dropped (px; a chain of n pixels spans between n - 1 and
  /// 1.42 (n - 1) px of arc). In [2, 1e6].
  int min_length_px = 10;
  /// A chain is split where its direction turns by more than this over the turn window (deg):
  /// the angle between the chords p[i - w] -> p[i] and p[i] -> p[i + w]. A circle of radius
  /// r turns by about w / r rad, so the defaults split corners and arcs of radius below about
  /// 7.6 px, while the +-0.5 px staircase of a digital line (at most 2 atan(1 / w) = 19 deg)
  /// never splits. In (0, 180].
  double max_turn_deg = 45.0;
  /// The window w of the turn measure (px, counted in chain pixels). Longer windows average out
  /// pixel noise but round corners off. In [1, 1000].
  int turn_window_px = 6;

  /// Throws InvalidOptions naming the first field outside its range.
  void validate() const;
};

/// An ordered chain of 8-connected edge pixels.
struct EdgeChain {
  /// Pixel (column, row) of each chain pixel, in chain order; consecutive pixels are
  /// 8-neighbours (as are the last and the first of a closed chain).
  std::vector<Eigen::Vector2i> pixels;
  /// Unit image gradient (dark to bright) at each pixel, the same order; (1, 0) where the gradient
  /// is zero, as NearestEdgeField does.
  std::vector<Eigen::Vector2f> normals;
  /// True for a closed loop (no end point, no junction and no split on it).
  bool closed = false;

  /// Polyline length through the pixel centres (px), including the closing step of a loop.
  double arcLength() const;
};

/// Traces the edge pixels of `edge_image` into ordered chains (paper §2.3).
///
/// 1. Thinning: an edge pixel is removed (in row-major order, until nothing changes) if it has at
///    least two edge neighbours and removing it changes neither the 8-connectivity of its edge
///    neighbours nor the 4-connectivity of the background around it (a simple point). This
///    removes the redundant corner pixels of 4-connected staircases that Canny leaves, which
///    would otherwise look like junctions, and keeps end points, curves and holes. The apex of a
///    right-angled corner is such a pixel too (its two neighbours touch diagonally) and goes.
/// 2. Junctions: a remaining pixel with three or more edge neighbours is a junction; junction
///    pixels belong to no chain, so the branches meeting there become separate chains.
/// 3. Tracing: chains start at end points (in row-major order), then what is left are closed
///    loops, each started at its first pixel in row-major order.
/// 4. Splitting at high curvature: where the turn (see EdgeChainOptions) exceeds max_turn_deg,
///    the chain is cut at the pixel of largest turn in each such run; that pixel ends the first
///    piece. Near the ends of an open chain the arms shrink to what is there, down to half a
///    window (a corner closer to an end is not cut). A split loop becomes open pieces.
/// 5. Orientation: each chain runs so that the brighter side lies on its right in the image
///    (sum of cross(p[i+1] - p[i], normal[i]) >= 0, y down), which makes the output independent
///    of the scan order and tells matching which side is which.
/// 6. Chains with fewer than min_length_px pixels are dropped.
/// Every edge pixel is in at most one chain; the order of the chains is that of tracing, which
/// depends only on the edge image.
///
/// `edge_image.edges` CV_8UC1 (non-zero = edge), grad_x / grad_y CV_16SC1 of the same size.
/// Throws InvalidOptions on bad options, CheckError on bad images.
std::vector<EdgeChain> extractEdgeChains(const EdgeImage& edge_image,
                                         const EdgeChainOptions& options = {});

/// CV_8UC1 image of `size`, 255 at the pixels of `chains` and 0 elsewhere: an edge map for
/// NearestEdgeField::build that holds exactly the pixels the curves are initialised from.
cv::Mat chainEdgeMap(const std::vector<EdgeChain>& chains, const cv::Size& size);

}  // namespace curvesfm
