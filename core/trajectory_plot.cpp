#include "core/trajectory_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "core/plot.h"

namespace curvesfm {
namespace {

constexpr char kAxisNames[] = "xyz";
// Smallest extent shown in the top view (m), so that a trajectory standing still still gets a
// valid axis.
constexpr double kMinTopViewSpan = 1e-3;
// Pixels kept free of data at the top of the top view for the legend (two rows and a margin).
constexpr double kLegendBand = 70.0;
// The ground truth is drawn wide and grey under the estimate, so that both stay visible where
// they coincide.
const cv::Scalar kGroundTruthColor(150, 150, 150);

struct Extent {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();

  void add(double value) {
    lo = std::min(lo, value);
    hi = std::max(hi, value);
  }
  double span() const { return hi >= lo ? hi - lo : 0.0; }
  double centre() const { return hi >= lo ? 0.5 * (lo + hi) : 0.0; }
};

PlotSeries lineSeries(const std::string& label, std::vector<double> x, std::vector<double> y) {
  PlotSeries series;
  series.label = label;
  series.x = std::move(x);
  series.y = std::move(y);
  // Markers would bury the line of a long trajectory; a short one shows its poses.
  const bool long_series = series.x.size() > 60;
  series.style = long_series ? PlotSeries::Style::kLine : PlotSeries::Style::kLineMarkers;
  series.line_width = long_series ? 1.5 : 2.0;
  series.marker_size = 5.0;
  return series;
}

std::string formatMetres(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.4g m", value);
  return buffer;
}

// Ranges with the same metres per pixel on both axes for a plot area of `area` pixels: the data
// centred horizontally and kept out of a band at the top where the legend goes.
void setEqualScaleRanges(const Extent& h, const Extent& v, cv::Size area, PlotOptions* options) {
  const double width = std::max(area.width - 1, 1);
  const double height = std::max(area.height - 1, 1);
  const double data_height = std::max(height - kLegendBand, 0.5 * height);
  // 5% head room on the tighter axis, as Plot's automatic ranges have.
  const double metres_per_pixel =
      1.1 * std::max({h.span() / width, v.span() / data_height, kMinTopViewSpan / width});
  const double bottom = v.centre() - 0.5 * metres_per_pixel * data_height;
  options->x_range = AxisRange{h.centre() - 0.5 * metres_per_pixel * width,
                               h.centre() + 0.5 * metres_per_pixel * width};
  options->y_range = AxisRange{bottom, bottom + metres_per_pixel * height};
}

cv::Mat renderTopView(const TrajectoryEvaluation& evaluation, cv::Size size) {
  std::vector<Eigen::Vector3d> truth, estimate;
  for (const MatchedPose& m : evaluation.matches) {
    truth.push_back(m.ground_truth.translation());
    estimate.push_back(m.aligned_estimate.translation());
  }
  const TopViewAxes axes = chooseTopViewAxes(truth);
  std::vector<double> truth_h, truth_v, estimate_h, estimate_v;
  Extent h, v;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    truth_h.push_back(truth[k][axes.horizontal]);
    truth_v.push_back(truth[k][axes.vertical]);
    estimate_h.push_back(estimate[k][axes.horizontal]);
    estimate_v.push_back(estimate[k][axes.vertical]);
    for (const Eigen::Vector3d* p : {&truth[k], &estimate[k]}) {
      h.add((*p)[axes.horizontal]);
      v.add((*p)[axes.vertical]);
    }
  }
  const std::string plane = {kAxisNames[axes.horizontal], '-', kAxisNames[axes.vertical]};
  PlotOptions options;
  options.width = size.width;
  options.height = size.height;
  options.title = "Top view: " + plane + " plane (largest spread)";
  options.x_label = std::string(1, kAxisNames[axes.horizontal]) + " (m)";
  options.y_label = std::string(1, kAxisNames[axes.vertical]) + " (m)";
  const std::string estimate_label =
      "estimate (" + toString(evaluation.options.alignment) + "-aligned)";
  const auto makePlot = [&] {
    Plot plot(options);
    PlotSeries ground_truth = lineSeries("ground truth", truth_h, truth_v);
    ground_truth.color = kGroundTruthColor;
    ground_truth.line_width = 4.0;
    plot.add(ground_truth);
    plot.add(lineSeries(estimate_label, estimate_h, estimate_v));
    return plot;
  };
  // The plot area depends on the tick labels, which depend on the ranges: two rounds settle it.
  for (int round = 0; round < 2; ++round) {
    setEqualScaleRanges(h, v, makePlot().plotArea().size(), &options);
  }
  return makePlot().render();
}

cv::Mat renderErrorOverTime(const TrajectoryEvaluation& evaluation, cv::Size size) {
  std::vector<double> time, error;
  const double start =
      evaluation.matches.empty() ? 0.0 : evaluation.matches.front().ground_truth_timestamp;
  for (const MatchedPose& m : evaluation.matches) {
    time.push_back(m.ground_truth_timestamp - start);
    error.push_back(m.position_error);
  }
  PlotOptions options;
  options.width = size.width;
  options.height = size.height;
  options.title = "ATE per matched pose (" + toString(evaluation.options.alignment) + " alignment)";
  options.x_label = "time since the first match (s)";
  options.y_label = "position error (m)";
  const double top = std::max(evaluation.ate.max, evaluation.ate.rmse);
  options.y_range = AxisRange{0.0, top > 0.0 ? 1.08 * top : 1.0};
  Plot plot(options);
  plot.add(lineSeries("ATE", time, error));
  if (!time.empty()) {
    PlotSeries rmse =
        lineSeries("rmse " + formatMetres(evaluation.ate.rmse), {time.front(), time.back()},
                   {evaluation.ate.rmse, evaluation.ate.rmse});
    rmse.style = PlotSeries::Style::kLine;
    rmse.line_width = 2.0;
    plot.add(rmse);
  }
  return plot.render();
}

void requireInRange(int value, int lo, int hi, const char* field) {
  if (value < lo || value > hi) {
    throw InvalidOptions("TrajectoryPlotOptions", field, std::to_string(value),
                         "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
}

}  // namespace

TopViewAxes chooseTopViewAxes(const std::vector<Eigen::Vector3d>& positions) {
  Extent extent[3];
  for (const Eigen::Vector3d& p : positions) {
    for (int a = 0; a < 3; ++a) extent[a].add(p[a]);
  }
  int dropped = 1;
  for (int a : {0, 2}) {
    if (extent[a].span() < extent[dropped].span()) dropped = a;
  }
  TopViewAxes axes;
  axes.horizontal = dropped == 0 ? 1 : 0;
  axes.vertical = dropped == 2 ? 1 : 2;
  return axes;
}

void TrajectoryPlotOptions::validate() const {
  requireInRange(panel_width, 240, 8000, "panel_width");
  requireInRange(panel_height, 180, 8000, "panel_height");
}

cv::Mat renderTrajectoryEvaluation(const TrajectoryEvaluation& evaluation,
                                   const TrajectoryPlotOptions& options) {
  options.validate();
  const cv::Size panel(options.panel_width, options.panel_height);
  cv::Mat figure;
  cv::hconcat(renderTopView(evaluation, panel), renderErrorOverTime(evaluation, panel), figure);
  return figure;
}

void saveTrajectoryEvaluationPlot(const std::string& png_path,
                                  const TrajectoryEvaluation& evaluation,
                                  const TrajectoryPlotOptions& options) {
  savePng(renderTrajectoryEvaluation(evaluation, options), png_path);
}

}  // namespace curvesfm
