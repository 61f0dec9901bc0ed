#include "apps/cli/curve_overlays.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "core/check.h"
#include "core/dataset_io.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

namespace fs = std::filesystem;

// Bright against both the faint curves (green by default) and most photos.
const cv::Scalar kHighlightBgr(255, 0, 255);
// The other curves of a worst-curve image: drawn, then blended back to this share, so the
// highlighted curve stands out among them.
constexpr double kFaintOpacity = 0.35;

// NaN, from a curve without samples, counts as the low end.
double clippedFraction(double value, double low, double high) {
  const double t = (value - low) / (high - low);
  return t >= 0.0 ? std::min(t, 1.0) : 0.0;
}

std::string shortNumber(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

double rankingValue(CurveRanking ranking, const CurveStatistics& s) {
  return ranking == CurveRanking::kResidual ? s.residual_rms_px : s.pose_pull_share;
}

void requireStatisticsOfEveryCurve(const OverlayScene& scene) {
  CURVESFM_CHECK(scene.statistics.empty() || scene.statistics.size() == scene.curves.size())
      << scene.statistics.size() << " curve statistics for " << scene.curves.size() << " curves";
  CURVESFM_CHECK(scene.keyframe_images.size() == scene.keyframe_cam_from_world.size())
      << scene.keyframe_images.size() << " keyframe images for "
      << scene.keyframe_cam_from_world.size() << " poses";
}

std::string keyframeImageName(std::size_t keyframe) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06zu.png", keyframe);
  return name;
}

// ---------------------------------------------------------------------------------------------
// Worst curves.

struct WorstCurveImage {
  CurveRanking ranking;
  std::size_t rank;  // From 1.
  std::size_t curve;
  int keyframe;      // -1: no image.
  std::string file;  // Empty: no image.
};

// Its worst keyframe when known, else its first_keyframe; -1 when neither is in the scene.
int shownKeyframe(const CurveStatistics& s, std::size_t keyframes) {
  for (int k : {s.worst_keyframe, s.first_keyframe}) {
    if (k >= 0 && static_cast<std::size_t>(k) < keyframes) return k;
  }
  return -1;
}

std::string worstCurveImageName(const WorstCurveImage& w) {
  char name[96];
  std::snprintf(name, sizeof(name), "%s_%02zu_curve_%04zu_kf_%04d.png", toString(w.ranking).c_str(),
                w.rank, w.curve, w.keyframe);
  return name;
}

cv::Mat highlightedCurveImage(const OverlayScene& scene, std::size_t curve, int keyframe,
                              const CurveOverlayOptions& drawing) {
  const cv::Mat& image = scene.keyframe_images[keyframe];
  const Pose3& cam_from_world = scene.keyframe_cam_from_world[keyframe];
  cv::Mat others = image.clone();
  CurveOverlayOptions faint = drawing;
  faint.point_radius_px = 0;  // Their segment ends would only clutter the picture.
  drawCurves(&others, scene.curves, scene.camera, cam_from_world, faint);
  cv::Mat result;
  cv::addWeighted(image, 1.0 - kFaintOpacity, others, kFaintOpacity, 0.0, result);
  CurveOverlayOptions highlight = drawing;
  highlight.colour = kHighlightBgr;
  highlight.thickness_px = std::min(50, std::max(3, drawing.thickness_px + 2));
  drawCurves(&result, {scene.curves[curve]}, scene.camera, cam_from_world, highlight);
  return result;
}

void writeWorstCurvesRow(std::ostream& out, const WorstCurveImage& w, const CurveStatistics& s) {
  out << "| " << w.rank << " | " << w.curve << " | " << s.residual_rms_px << " | "
      << 100.0 * s.pose_pull_share << " | " << s.keyframes << " | " << s.first_keyframe << " | "
      << s.last_keyframe << " | " << s.length << " | " << s.triangulation_angle_deg << " | ";
  if (w.file.empty()) {
    out << "none (observed in no keyframe) |\n";
  } else {
    out << "[" << w.file << "](" << w.file << ") (keyframe " << w.keyframe << ") |\n";
  }
}

void writeWorstCurvesIndex(const std::string& path, const std::vector<WorstCurveImage>& images,
                           const std::vector<CurveStatistics>& stats) {
  std::ofstream out(path);
  if (!out) throw IoError(path, "cannot open for writing");
  out << std::setprecision(3)
      << "# The worst curves of the run\n\n"
         "Each curve drawn thick in magenta on the keyframe where its residual is largest, the "
         "other curves faint. `curve` is its index into curves.obj and curves.csv; the rankings "
         "are report.json's `curve_statistics.highest_residual` and `most_pull`. A curve can be "
         "observed before the keyframe that started it: re-association adds observations in "
         "every keyframe. Length in the unit of the poses.\n";
  for (CurveRanking ranking : {CurveRanking::kResidual, CurveRanking::kPull}) {
    out << (ranking == CurveRanking::kResidual ? "\n## Highest residual\n\n"
                                               : "\n## Most pull on the poses\n\n")
        << "| rank | curve | residual rms (px) | pull share (%) | track (keyframes) | started "
           "in keyframe | last keyframe | length | triangulation angle (deg) | image |\n"
           "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n";
    for (const WorstCurveImage& w : images) {
      if (w.ranking == ranking) writeWorstCurvesRow(out, w, stats[w.curve]);
    }
  }
  if (!out) throw IoError(path, "cannot write");
}

}  // namespace

void OverlayColouringOptions::validate() const {
  const OptionCheck require("OverlayColouringOptions");
  require(toString(colour_by) != "unknown", "colour_by", static_cast<int>(colour_by),
          "one of " + enumNameList<CurveColouring>());
}

double colourFraction(CurveColouring colouring, const CurveStatistics& s) {
  switch (colouring) {
    case CurveColouring::kResidual:
      return clippedFraction(s.residual_rms_px, 0.0, kResidualColourMaxPx);
    case CurveColouring::kTrack:
      return clippedFraction(s.keyframes, kTrackColourMin, kTrackColourMax);
    case CurveColouring::kPull:
      if (!(s.pose_pull_share > 0.0)) return 0.0;
      return clippedFraction(std::log10(s.pose_pull_share), std::log10(kPullShareColourMin),
                             std::log10(kPullShareColourMax));
    case CurveColouring::kNone:
      break;
  }
  return 0.0;
}

ColourLegend colourLegend(CurveColouring colouring) {
  switch (colouring) {
    case CurveColouring::kResidual:
      return {"residual rms (px)", "0", ">=" + shortNumber(kResidualColourMaxPx)};
    case CurveColouring::kTrack:
      return {"track length (keyframes)", "<=" + shortNumber(kTrackColourMin),
              ">=" + shortNumber(kTrackColourMax)};
    case CurveColouring::kPull:
      return {"share of the pull on the poses (log)",
              "<=" + shortNumber(100.0 * kPullShareColourMin) + "%",
              ">=" + shortNumber(100.0 * kPullShareColourMax) + "%"};
    case CurveColouring::kNone:
      break;
  }
  CURVESFM_CHECK(false) << "no legend for colouring " << toString(colouring);
  return {};
}

std::vector<cv::Scalar> curveColours(CurveColouring colouring,
                                     const std::vector<CurveStatistics>& stats,
                                     const cv::Scalar& plain) {
  std::vector<cv::Scalar> colours;
  for (const CurveStatistics& s : stats) {
    colours.push_back(
        colouring == CurveColouring::kNone ? plain : colourMapBgr(colourFraction(colouring, s)));
  }
  return colours;
}

std::vector<std::size_t> worstCurves(const std::vector<CurveStatistics>& stats,
                                     CurveRanking ranking, std::size_t count) {
  std::vector<std::size_t> order(stats.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return rankingValue(ranking, stats[a]) > rankingValue(ranking, stats[b]);
  });
  order.resize(std::min(count, order.size()));
  return order;
}

int writeOverlays(const std::string& dir, const OverlayScene& scene,
                  const CurveOverlayOptions& drawing, CurveColouring colouring) {
  requireStatisticsOfEveryCurve(scene);
  // Without statistics (fewer than two keyframes) there is nothing to colour by.
  const bool coloured = colouring != CurveColouring::kNone && !scene.statistics.empty();
  const std::vector<cv::Scalar> colours =
      coloured ? curveColours(colouring, scene.statistics, drawing.colour)
               : std::vector<cv::Scalar>(scene.curves.size(), drawing.colour);
  fs::create_directories(dir);
  for (std::size_t k = 0; k < scene.keyframe_images.size(); ++k) {
    cv::Mat image = scene.keyframe_images[k].clone();
    drawCurves(&image, scene.curves, colours, scene.camera, scene.keyframe_cam_from_world[k],
               drawing);
    if (coloured) drawColourLegend(&image, colourLegend(colouring));
    writeImage((fs::path(dir) / keyframeImageName(k)).string(), image);
  }
  return static_cast<int>(scene.keyframe_images.size());
}

int writeWorstCurves(const std::string& dir, const OverlayScene& scene,
                     const CurveOverlayOptions& drawing) {
  requireStatisticsOfEveryCurve(scene);
  fs::create_directories(dir);
  std::vector<WorstCurveImage> images;
  int written = 0;
  for (CurveRanking ranking : {CurveRanking::kResidual, CurveRanking::kPull}) {
    const std::vector<std::size_t> worst =
        worstCurves(scene.statistics, ranking, kWorstCurvesListed);
    for (std::size_t i = 0; i < worst.size(); ++i) {
      WorstCurveImage w{ranking, i + 1, worst[i],
                        shownKeyframe(scene.statistics[worst[i]], scene.keyframe_images.size()),
                        ""};
      if (w.keyframe >= 0) {
        w.file = worstCurveImageName(w);
        writeImage((fs::path(dir) / w.file).string(),
                   highlightedCurveImage(scene, w.curve, w.keyframe, drawing));
        ++written;
      }
      images.push_back(w);
    }
  }
  writeWorstCurvesIndex((fs::path(dir) / "worst_curves.md").string(), images, scene.statistics);
  return written;
}

}  // namespace curvesfm
