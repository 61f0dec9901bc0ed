#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

namespace curvesfm {

/// PNG charts for the benchmark harnesses and `curvesfm eval --plot`, drawn with OpenCV alone
/// (the machines that run the experiments have no Python). Two chart kinds share one look:
/// white background, light grey grid, "nice" 1-2-5 ticks (decades on log axes), a title, axis
/// labels (the y label rotated), a legend with colour swatches and markers, and a small grey
/// note under the x axis that counts the values that could not be shown. Colours come from the
/// Okabe-Ito colour-blind-friendly palette and markers from a list of distinct shapes, both by
/// series index.
///
/// Rendering is deterministic, single-threaded and takes about 1 ms at 900 x 600; nothing is
/// cached, so a chart may be changed (add()) and rendered again.

/// Shape drawn at each data point of a PlotSeries.
enum class MarkerShape {
  kCircle,
  kSquare,
  kTriangleUp,
  kDiamond,
  kTriangleDown,
  kCross,
  kPlus,
  kStar,
};

/// Where the legend goes. kAuto tries the four corners inside the plot area (top right, top
/// left, bottom right, bottom left, in that order of preference) and takes the first that hides
/// no data; when every corner would hide data it puts the legend right of the plot area. The
/// legend is left out when no series has a label.
enum class LegendPosition {
  kAuto,
  kTopRight,
  kTopLeft,
  kBottomRight,
  kBottomLeft,
  kOutsideRight,
  kNone,
};

/// A closed interval of data values shown along an axis.
struct AxisRange {
  double min = 0.0;  ///< Value at the left (x) or bottom (y) edge; finite, < max.
  double max = 1.0;  ///< Value at the right (x) or top (y) edge; finite, > min.
};

/// The i-th colour of the palette (BGR, 0..255): Okabe-Ito without its black, yellow last;
/// wraps around after 7 colours.
cv::Scalar paletteColor(int index);

/// The i-th marker shape: the MarkerShape enumerators in order, wrapping around after 8.
MarkerShape paletteMarker(int index);

/// One curve of a Plot: points (x[k], y[k]) joined in the given order.
struct PlotSeries {
  enum class Style { kLine, kMarkers, kLineMarkers };

  std::string label;      ///< Legend text; an empty label keeps the series out of the legend.
  std::vector<double> x;  ///< Abscissae, as many as y. A non-finite x or y skips the point and
                          ///< breaks the line there; so does x <= 0 on a log x axis.
  std::vector<double> y;  ///< Ordinates; y <= 0 is skipped on a log y axis.
  Style style = Style::kLineMarkers;  ///< Line, markers, or both.
  std::optional<cv::Scalar> color;    ///< BGR 0..255; unset: paletteColor(series index).
  std::optional<MarkerShape> marker;  ///< Unset: paletteMarker(series index).
  double line_width = 2.0;            ///< Line thickness (px); [0.5, 20].
  double marker_size = 8.0;           ///< Marker diameter (px); [2, 50].

  /// Throws InvalidOptions naming the field, its value and the constraint (x and y of different
  /// sizes included).
  void validate() const;
};

/// Looks and axes of a Plot.
struct PlotOptions {
  std::string title;    ///< Centred above the plot area; empty: no title and no room for one.
  std::string x_label;  ///< Centred under the x tick labels; empty: none.
  std::string y_label;  ///< Rotated, left of the y tick labels; empty: none.
  bool log_x = false;   ///< Base-10 logarithmic x axis (non-positive x skipped and counted).
  bool log_y = false;   ///< Base-10 logarithmic y axis (non-positive y skipped and counted).
  int width = 900;      ///< Image width (px); [240, 8000].
  int height = 600;     ///< Image height (px); [180, 8000].
  /// Shown x interval; unset: the data's extent plus a 5% margin on each side (in log10 units on
  /// a log axis). On a log axis both ends must be > 0.
  std::optional<AxisRange> x_range;
  std::optional<AxisRange> y_range;               ///< As x_range, for y.
  LegendPosition legend = LegendPosition::kAuto;  ///< See LegendPosition.
  double font_scale = 1.0;  ///< Multiplies every text size and spacing; [0.5, 4].

  /// Throws InvalidOptions naming the field, its value and the constraint.
  void validate() const;
};

/// A line / scatter chart:
///   PlotOptions options;
///   options.title = "RMSE vs noise";
///   options.x_label = "pixel noise (px)";
///   options.log_x = true;
///   PlotSeries alternating;
///   alternating.label = "alternating";
///   alternating.x = noise;
///   alternating.y = rmse;
///   Plot(options).add(alternating).save("/tmp/rmse.png");
class Plot {
 public:
  /// Throws InvalidOptions if `options` is invalid.
  explicit Plot(PlotOptions options = {});

  /// Appends a series, drawn over the earlier ones. Throws InvalidOptions if it is invalid.
  Plot& add(PlotSeries series);

  /// The chart as an options.height x options.width CV_8UC3 (BGR) image. With no drawable point
  /// it still shows the axes (range 0..1, or 1..10 on a log axis, unless set) and "no data".
  cv::Mat render() const;

  /// The pixel rectangle of render()'s image that holds the data: AxisRange::min of x at its
  /// left column, max at its right column (x + width - 1); y's min at its bottom row and max at
  /// its top row; linear in log10 of the value on a log axis.
  cv::Rect plotArea() const;

  /// Writes render() as a PNG file at `png_path` (any extension; the content is PNG). Throws
  /// IoError naming the path when the file cannot be written.
  void save(const std::string& png_path) const;

  const PlotOptions& options() const { return options_; }
  const std::vector<PlotSeries>& series() const { return series_; }

 private:
  PlotOptions options_;
  std::vector<PlotSeries> series_;
};

/// One bar per category of a BarChart.
struct BarSeries {
  std::string label;           ///< Legend text; empty: not in the legend.
  std::vector<double> values;  ///< One per category; a non-finite value (or <= 0 on a log axis)
                               ///< draws no bar and is counted in the note.
  std::optional<cv::Scalar> color;  ///< BGR 0..255; unset: paletteColor(series index).
};

/// Looks and value axis of a BarChart.
struct BarChartOptions {
  std::string title;    ///< Centred above the plot area; empty: none.
  std::string x_label;  ///< Under the category names; empty: none.
  std::string y_label;  ///< Rotated, left of the y tick labels; empty: none.
  bool log_y = false;   ///< Base-10 logarithmic value axis; bars rise from its bottom edge.
  int width = 900;      ///< Image width (px); [240, 8000].
  int height = 600;     ///< Image height (px); [180, 8000].
  /// Shown value interval; unset: from 0 (or the smallest value, if negative) to the largest
  /// value plus a margin; on a log axis from below the smallest to above the largest value.
  std::optional<AxisRange> y_range;
  LegendPosition legend = LegendPosition::kAuto;  ///< See LegendPosition.
  bool value_labels = false;  ///< Prints each bar's value (3 significant digits) above it.
  double font_scale = 1.0;    ///< Multiplies every text size and spacing; [0.5, 4].

  /// Throws InvalidOptions naming the field, its value and the constraint.
  void validate() const;
};

/// A grouped bar chart: categories along x (e.g. strategies), one bar per series (e.g. metric or
/// dataset) in each category's group, series in the order added.
class BarChart {
 public:
  /// Throws InvalidOptions if `options` is invalid or `categories` is empty.
  explicit BarChart(std::vector<std::string> categories, BarChartOptions options = {});

  /// Appends a series; throws InvalidOptions unless it has one value per category.
  BarChart& add(BarSeries series);

  /// As Plot::render(); "no data" when no bar can be drawn.
  cv::Mat render() const;

  /// The pixel rectangle holding the bars; category i is centred at column
  /// x + (i + 0.5) * (width - 1) / categories; the value axis maps as in Plot::plotArea().
  cv::Rect plotArea() const;

  /// As Plot::save().
  void save(const std::string& png_path) const;

 private:
  std::vector<std::string> categories_;
  BarChartOptions options_;
  std::vector<BarSeries> series_;
};

/// Writes `image` (8-bit, 1 or 3 channels) as a PNG file at `png_path` (any extension). Throws
/// IoError naming the path when it cannot be encoded or written.
void savePng(const cv::Mat& image, const std::string& png_path);

/// Tick and label helpers, exposed for tests.
namespace plot_detail {

/// The 1-2-5 step (1, 2 or 5 times a power of ten) that splits [lo, hi] into about
/// `target_count` intervals. Requires finite lo < hi and target_count >= 1 (CheckError).
double niceStep(double lo, double hi, int target_count);

/// The multiples of niceStep(lo, hi, target_count) inside [lo, hi] (both ends included up to
/// rounding), ascending; values within 1e-9 steps of zero are exactly 0.
std::vector<double> niceTicks(double lo, double hi, int target_count);

/// Labelled ticks of a log axis showing [lo, hi] (0 < lo < hi, max_count >= 1; CheckError
/// otherwise), ascending, the first rule that applies:
/// - 1, 2 and 5 times the powers of ten, if 2..max_count of them fall inside;
/// - the powers of ten inside, if there are 2 or more: those whose exponent is divisible by the
///   smallest stride that keeps at most `max_count` of them (so 1 stays on the axis);
/// - otherwise niceTicks(lo, hi, max_count): the range is about a decade or less.
std::vector<double> logTicks(double lo, double hi, int max_count);

/// Unlabelled grid values of a log axis for [lo, hi]: 2..9 times each power of ten when at most
/// 6 decades are shown, otherwise the powers of ten; values in `major` left out.
std::vector<double> logMinorTicks(double lo, double hi, const std::vector<double>& major);

/// Label for `value` on an axis whose ticks are `step` (> 0) apart, with the decimals that
/// `step` needs: fixed ("0.0", "0.5", "1500", "0.001") or, if `scientific`, a short mantissa and
/// exponent ("1e-4", "2.5e5", "-3e-6", and "0" for zero). A value within 1e-9 steps of zero is
/// zero (no "-0.0").
std::string formatTick(double value, double step, bool scientific);

/// Labels for the ticks `values` of a linear axis, `step` apart: all fixed, or all scientific
/// when the largest |value| is < 1e-3 or >= 1e5 (zero aside).
std::vector<std::string> formatTicks(const std::vector<double>& values, double step);

/// Labels for the ticks `values` (> 0) of a log axis, each with the digits it needs itself
/// ("0.002", "20", "2.5"); all scientific ("1e-4", "2e6", "1e0") when any value is < 1e-3 or
/// >= 1e5, so that a column of decades reads alike.
std::vector<std::string> formatLogTicks(const std::vector<double>& values);

}  // namespace plot_detail

}  // namespace curvesfm
