#include "core/plot.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "core/check.h"
#include "core/errors.h"

namespace curvesfm {

// ---------------------------------------------------------------------------------------------
// Ticks and labels
// ---------------------------------------------------------------------------------------------
namespace plot_detail {
namespace {

// Relative tolerance for "this value is on that tick": ticks are computed as k * step, so
// their rounding error is a few ulps; 1e-9 is far above that and far below any visible step.
constexpr double kTickTolerance = 1e-9;

double powerOfTen(int exponent) { return std::pow(10.0, exponent); }

// Smallest number of decimals d with `value` * 10^d an integer (to 1e-6 relative), at most 15.
int decimalsFor(double value) {
  value = std::abs(value);
  int decimals = 0;
  while (decimals < 15) {
    const double scaled = value * powerOfTen(decimals);
    if (std::abs(scaled - std::round(scaled)) <= 1e-6 * std::max(scaled, 1.0)) break;
    ++decimals;
  }
  return decimals;
}

// "1.50000e+05" with `digits` mantissa decimals, shortened to "1.5e5".
std::string scientific(double value, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*e", digits, value);
  std::string text(buffer);
  const std::size_t e = text.find('e');
  std::string mantissa = text.substr(0, e);
  if (mantissa.find('.') != std::string::npos) {
    mantissa.erase(mantissa.find_last_not_of('0') + 1);
    if (mantissa.back() == '.') mantissa.pop_back();
  }
  return mantissa + "e" + std::to_string(std::stoi(text.substr(e + 1)));
}

// Exponent of `value` as %e prints it (immune to log10 rounding at exact powers of ten).
int decimalExponent(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.14e", value);
  return std::stoi(std::strchr(buffer, 'e') + 1);
}

bool needsScientific(double magnitude) {
  return magnitude != 0.0 && (magnitude < 1e-3 || magnitude >= 1e5);
}

// Powers of ten 10^k, first <= k <= last, with k - anchor divisible by stride.
std::vector<double> decades(int first, int last, int stride, int anchor) {
  std::vector<double> ticks;
  for (int k = first; k <= last; ++k) {
    if ((k - anchor) % stride == 0) ticks.push_back(powerOfTen(k));
  }
  return ticks;
}

bool insideRange(double value, double lo, double hi) {
  return value >= lo * (1.0 - kTickTolerance) && value <= hi * (1.0 + kTickTolerance);
}

}  // namespace

double niceStep(double lo, double hi, int target_count) {
  CURVESFM_CHECK(std::isfinite(lo) && std::isfinite(hi) && lo < hi)
      << "need finite lo < hi, got [" << lo << ", " << hi << "]";
  CURVESFM_CHECK(target_count >= 1) << "target_count = " << target_count;
  const double raw = (hi - lo) / target_count;
  const double magnitude = powerOfTen(static_cast<int>(std::floor(std::log10(raw))));
  const double normalised = raw / magnitude;
  if (normalised < 1.5) return magnitude;
  if (normalised < 3.0) return 2.0 * magnitude;
  if (normalised < 7.0) return 5.0 * magnitude;
  return 10.0 * magnitude;
}

std::vector<double> niceTicks(double lo, double hi, int target_count) {
  const double step = niceStep(lo, hi, target_count);
  const double first = std::ceil(lo / step - kTickTolerance);
  const double last = std::floor(hi / step + kTickTolerance);
  std::vector<double> ticks;
  // k * step rather than a running sum, so that errors do not accumulate along the axis.
  for (double k = first; k <= last && ticks.size() < 10000; k += 1.0) {
    const double value = k * step;
    ticks.push_back(std::abs(value) < kTickTolerance * step ? 0.0 : value);
  }
  return ticks;
}

std::vector<double> logTicks(double lo, double hi, int max_count) {
  CURVESFM_CHECK(std::isfinite(lo) && std::isfinite(hi) && 0.0 < lo && lo < hi)
      << "need finite 0 < lo < hi, got [" << lo << ", " << hi << "]";
  CURVESFM_CHECK(max_count >= 1) << "max_count = " << max_count;
  const int first = static_cast<int>(std::ceil(std::log10(lo) - kTickTolerance));
  const int last = static_cast<int>(std::floor(std::log10(hi) + kTickTolerance));
  const int count = last - first + 1;
  std::vector<double> one_two_five;
  for (int k = first - 1; k <= last && count <= max_count; ++k) {
    for (double m : {1.0, 2.0, 5.0}) {
      const double value = m * powerOfTen(k);
      if (insideRange(value, lo, hi)) one_two_five.push_back(value);
    }
  }
  const int n = static_cast<int>(one_two_five.size());
  if (n >= 2 && n <= max_count) return one_two_five;
  if (count >= 2) {
    // Exponents divisible by the stride put 1 on the axis whenever it is shown and give the
    // same ticks for neighbouring ranges; counting from the first decade is the fallback.
    const int stride = (count + max_count - 1) / max_count;
    std::vector<double> ticks = decades(first, last, stride, 0);
    if (ticks.size() < 2) ticks = decades(first, last, stride, first);
    return ticks;
  }
  return niceTicks(lo, hi, max_count);
}

std::vector<double> logMinorTicks(double lo, double hi, const std::vector<double>& major) {
  CURVESFM_CHECK(0.0 < lo && lo < hi) << "need 0 < lo < hi, got [" << lo << ", " << hi << "]";
  const int first = static_cast<int>(std::floor(std::log10(lo)));
  const int last = static_cast<int>(std::ceil(std::log10(hi)));
  const int max_multiple = last - first <= 6 ? 9 : 1;
  std::vector<double> minor;
  for (int k = first; k <= last; ++k) {
    for (int m = 1; m <= max_multiple; ++m) {
      const double value = m * powerOfTen(k);
      const bool is_major = std::any_of(major.begin(), major.end(), [&](double tick) {
        return std::abs(tick - value) <= kTickTolerance * value;
      });
      if (!is_major && insideRange(value, lo, hi)) minor.push_back(value);
    }
  }
  return minor;
}

std::string formatTick(double value, double step, bool scientific_notation) {
  CURVESFM_CHECK(step > 0.0) << "step = " << step;
  if (std::abs(value) < kTickTolerance * step) {
    if (scientific_notation) return "0";
    value = 0.0;  // Not -0.0, nor a rounding residue like 5.5e-17.
  }
  if (scientific_notation) {
    const int digits = decimalExponent(value) - decimalExponent(step);
    return scientific(value, std::max(digits, 0));
  }
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimalsFor(step), value);
  return buffer;
}

std::vector<std::string> formatTicks(const std::vector<double>& values, double step) {
  double largest = 0.0;
  for (double value : values) largest = std::max(largest, std::abs(value));
  const bool use_scientific = needsScientific(largest);
  std::vector<std::string> labels;
  for (double value : values) labels.push_back(formatTick(value, step, use_scientific));
  return labels;
}

std::vector<std::string> formatLogTicks(const std::vector<double>& values) {
  const bool use_scientific = std::any_of(values.begin(), values.end(), needsScientific);
  std::vector<std::string> labels;
  for (double value : values) {
    CURVESFM_CHECK(value > 0.0) << "log tick " << value;
    if (use_scientific) {
      const double mantissa = value / powerOfTen(decimalExponent(value));
      labels.push_back(scientific(value, std::min(decimalsFor(mantissa), 6)));
    } else {
      labels.push_back(formatTick(value, powerOfTen(-decimalsFor(value)), false));
    }
  }
  return labels;
}

}  // namespace plot_detail

// ---------------------------------------------------------------------------------------------
// Drawing primitives
// ---------------------------------------------------------------------------------------------
namespace {

const cv::Scalar kWhite(255, 255, 255);
const cv::Scalar kTextColor(34, 34, 34);
const cv::Scalar kFrameColor(90, 90, 90);
const cv::Scalar kGridColor(226, 226, 226);
const cv::Scalar kMinorGridColor(243, 243, 243);
const cv::Scalar kNoteColor(115, 115, 115);
const cv::Scalar kLegendBorder(200, 200, 200);

// OpenCV draws with integer coordinates carrying kShift fractional bits: 1/16 px.
constexpr int kShift = 4;
constexpr double kShiftScale = 1 << kShift;

cv::Point fixedPoint(cv::Point2d p) {
  return {cvRound(p.x * kShiftScale), cvRound(p.y * kShiftScale)};
}

struct Font {
  double scale = 0.5;
  int thickness = 1;
  int face = cv::FONT_HERSHEY_SIMPLEX;
  cv::Scalar color = kTextColor;
};

// Every size and gap of a chart, scaled by font_scale.
struct Style {
  double scale = 1.0;  // PlotOptions::font_scale.
  Font title, label, tick, legend, note;
  int pad = 10;         // Gap between blocks (title, labels, image edge).
  int tick_length = 5;  // Outward tick marks.
  int tick_gap = 4;     // Between a tick mark and its label.
};

Style makeStyle(double s) {
  const int thickness = std::max(1, static_cast<int>(std::lround(s)));
  Style style;
  style.scale = s;
  style.title = {0.62 * s, thickness, cv::FONT_HERSHEY_DUPLEX, kTextColor};
  style.label = {0.52 * s, thickness, cv::FONT_HERSHEY_SIMPLEX, kTextColor};
  style.tick = {0.45 * s, thickness, cv::FONT_HERSHEY_SIMPLEX, kTextColor};
  style.legend = {0.45 * s, thickness, cv::FONT_HERSHEY_SIMPLEX, kTextColor};
  style.note = {0.4 * s, thickness, cv::FONT_HERSHEY_SIMPLEX | cv::FONT_ITALIC, kNoteColor};
  style.pad = static_cast<int>(std::lround(10 * s));
  style.tick_length = static_cast<int>(std::lround(5 * s));
  style.tick_gap = static_cast<int>(std::lround(4 * s));
  return style;
}

struct TextBox {
  int width = 0;
  int ascent = 0;   // Baseline to the top of the capitals.
  int descent = 0;  // Baseline to the lowest descender.
  int height() const { return ascent + descent; }
};

TextBox measure(const std::string& text, const Font& font) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, font.face, font.scale, font.thickness, &baseline);
  return {size.width, size.height, baseline};
}

enum class Align { kStart, kCenter, kEnd };

// Places the text relative to `anchor`: horizontally kStart puts its left edge there, kEnd its
// right edge; vertically kStart puts the top of the capitals there, kEnd the lowest descender,
// and kCenter centres the capitals (so that numbers sit level with a tick).
void drawText(cv::Mat& image, const std::string& text, cv::Point anchor, const Font& font,
              Align horizontal, Align vertical) {
  const TextBox box = measure(text, font);
  const int left = horizontal == Align::kStart    ? anchor.x
                   : horizontal == Align::kCenter ? anchor.x - box.width / 2
                                                  : anchor.x - box.width;
  const int baseline_y = vertical == Align::kStart    ? anchor.y + box.ascent
                         : vertical == Align::kCenter ? anchor.y + box.ascent / 2
                                                      : anchor.y - box.descent;
  cv::putText(image, text, {left, baseline_y}, font.face, font.scale, font.color, font.thickness,
              cv::LINE_AA);
}

// Text turned 90 degrees counter-clockwise (reading upwards), centred on `centre`. Drawn on its
// own tile, rotated, and merged with a per-pixel minimum: dark text over a light background.
void drawTextUpwards(cv::Mat& image, const std::string& text, cv::Point centre, const Font& font) {
  const TextBox box = measure(text, font);
  const int margin = 2 + font.thickness;
  cv::Mat tile(box.height() + 2 * margin, box.width + 2 * margin, CV_8UC3, kWhite);
  drawText(tile, text, {margin, margin}, font, Align::kStart, Align::kStart);
  cv::rotate(tile, tile, cv::ROTATE_90_COUNTERCLOCKWISE);
  const cv::Rect target(centre.x - tile.cols / 2, centre.y - tile.rows / 2, tile.cols, tile.rows);
  const cv::Rect visible = target & cv::Rect(0, 0, image.cols, image.rows);
  if (visible.empty()) return;
  cv::Mat destination = image(visible);
  cv::min(destination, tile(visible - target.tl()), destination);
}

// Liang-Barsky: clips the segment a-b to `box`; false when nothing is left. Keeps far-away
// points (1e300 after a log axis, say) from overflowing OpenCV's integer coordinates.
bool clipSegment(cv::Point2d& a, cv::Point2d& b, const cv::Rect2d& box) {
  const cv::Point2d d = b - a;
  double t0 = 0.0, t1 = 1.0;
  const std::array<double, 4> p = {-d.x, d.x, -d.y, d.y};
  const std::array<double, 4> q = {a.x - box.x, box.x + box.width - a.x, a.y - box.y,
                                   box.y + box.height - a.y};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0.0) {
      if (q[i] < 0.0) return false;
      continue;
    }
    const double t = q[i] / p[i];
    if (p[i] < 0.0) {
      t0 = std::max(t0, t);
    } else {
      t1 = std::min(t1, t);
    }
    if (t0 > t1) return false;
  }
  const cv::Point2d start = a;
  a = start + t0 * d;
  b = start + t1 * d;
  return true;
}

// Vertices of a polygonal marker of diameter `size` around `centre`.
std::vector<cv::Point2d> markerPolygon(MarkerShape shape, cv::Point2d centre, double size) {
  const double r = 0.5 * size;
  std::vector<cv::Point2d> unit;
  switch (shape) {
    case MarkerShape::kSquare:
      unit = {{-0.85, -0.85}, {0.85, -0.85}, {0.85, 0.85}, {-0.85, 0.85}};
      break;
    case MarkerShape::kTriangleUp:
      unit = {{0.0, -1.15}, {1.0, 0.75}, {-1.0, 0.75}};
      break;
    case MarkerShape::kTriangleDown:
      unit = {{0.0, 1.15}, {1.0, -0.75}, {-1.0, -0.75}};
      break;
    case MarkerShape::kDiamond:
      unit = {{0.0, -1.2}, {0.85, 0.0}, {0.0, 1.2}, {-0.85, 0.0}};
      break;
    case MarkerShape::kStar:
      for (int i = 0; i < 10; ++i) {
        const double angle = -M_PI / 2 + i * M_PI / 5;
        const double radius = i % 2 == 0 ? 1.25 : 0.5;
        unit.emplace_back(radius * std::cos(angle), radius * std::sin(angle));
      }
      break;
    default:
      break;
  }
  std::vector<cv::Point2d> polygon;
  for (const cv::Point2d& u : unit) polygon.push_back(centre + r * u);
  return polygon;
}

void drawMarkerShape(cv::Mat& image, MarkerShape shape, cv::Point2d centre, double size,
                     const cv::Scalar& color, double stroke) {
  const double r = 0.5 * size;
  if (shape == MarkerShape::kCircle) {
    cv::circle(image, fixedPoint(centre), cvRound(r * kShiftScale), color, cv::FILLED, cv::LINE_AA,
               kShift);
    return;
  }
  if (shape == MarkerShape::kCross || shape == MarkerShape::kPlus) {
    const double arm = shape == MarkerShape::kCross ? 0.85 * r : 1.1 * r;
    const int thickness = std::max(1, cvRound(stroke));
    const cv::Point2d u =
        shape == MarkerShape::kCross ? cv::Point2d(arm, arm) : cv::Point2d(arm, 0);
    const cv::Point2d v =
        shape == MarkerShape::kCross ? cv::Point2d(arm, -arm) : cv::Point2d(0, arm);
    cv::line(image, fixedPoint(centre - u), fixedPoint(centre + u), color, thickness, cv::LINE_AA,
             kShift);
    cv::line(image, fixedPoint(centre - v), fixedPoint(centre + v), color, thickness, cv::LINE_AA,
             kShift);
    return;
  }
  std::vector<cv::Point> polygon;
  for (const cv::Point2d& p : markerPolygon(shape, centre, size)) polygon.push_back(fixedPoint(p));
  cv::fillPoly(image, std::vector<std::vector<cv::Point>>{polygon}, color, cv::LINE_AA, kShift);
}

// A thin white halo first, so that markers stay distinct where curves cross or overlap.
void drawMarker(cv::Mat& image, MarkerShape shape, cv::Point2d centre, double size,
                const cv::Scalar& color) {
  const double stroke = std::max(2.0, 0.25 * size);
  drawMarkerShape(image, shape, centre, size + 3.0, kWhite, stroke + 3.0);
  drawMarkerShape(image, shape, centre, size, color, stroke);
}

void drawSegment(cv::Mat& image, cv::Point2d a, cv::Point2d b, const cv::Scalar& color,
                 double width) {
  const double margin = 10.0 + width;
  const cv::Rect2d box(-margin, -margin, image.cols + 2 * margin, image.rows + 2 * margin);
  if (!clipSegment(a, b, box)) return;
  cv::line(image, fixedPoint(a), fixedPoint(b), color, std::max(1, cvRound(width)), cv::LINE_AA,
           kShift);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Chart frame: axes, layout, legend; shared by Plot and BarChart
// ---------------------------------------------------------------------------------------------
namespace {

// What is shown along one axis.
struct AxisSpec {
  double lo = 0.0;
  double hi = 1.0;
  bool log = false;
  std::vector<std::string> categories;  // Non-empty: a category axis with lo = 0, hi = count.
};

// An axis with its ticks chosen for a given length in pixels.
struct Axis {
  AxisSpec spec;
  std::vector<double> ticks;  // Labelled, with a grid line (value axes).
  std::vector<std::string> labels;
  std::vector<double> minor;    // Grid line only.
  bool upright_labels = false;  // Category names turned to read upwards: too wide side by side.
  std::vector<std::vector<std::string>> label_lines;  // Category names wrapped to their slot.

  bool categorical() const { return !spec.categories.empty(); }

  // 0 at lo, 1 at hi; linear in log10 on a log axis.
  double fraction(double value) const {
    if (!spec.log) return (value - spec.lo) / (spec.hi - spec.lo);
    return std::log10(value / spec.lo) / std::log10(spec.hi / spec.lo);
  }
};

// Data values to pixels of the plot area (origin at its top-left pixel).
struct Mapping {
  cv::Size size;
  const Axis& x;
  const Axis& y;

  double column(double value) const { return x.fraction(value) * (size.width - 1); }
  double row(double value) const { return (1.0 - y.fraction(value)) * (size.height - 1); }
  cv::Point2d toPixel(double x_value, double y_value) const {
    return {column(x_value), row(y_value)};
  }
};

using DataPainter = std::function<void(cv::Mat& area, const Mapping& mapping)>;

struct LegendEntry {
  std::string label;
  cv::Scalar color;
  bool line = false;                  // A line sample.
  std::optional<MarkerShape> marker;  // A marker in the middle of the sample.
  bool swatch = false;                // A filled square (bars).
  double line_width = 2.0;
  double marker_size = 8.0;
};

// Everything a chart kind hands to the frame code.
struct ChartSpec {
  std::string title, x_label, y_label;
  cv::Size size;
  double font_scale = 1.0;
  LegendPosition legend_position = LegendPosition::kAuto;
  AxisSpec x, y;
  std::vector<LegendEntry> legend;
  std::string note;    // Grey line at the bottom left, e.g. counts of points not shown.
  bool empty = false;  // Nothing to draw: "no data" in the plot area.
};

struct Layout {
  cv::Rect area;
  Axis x, y;
  cv::Rect legend;  // Image coordinates; empty: no legend.
};

int scaled(const Style& style, double pixels) {
  return static_cast<int>(std::lround(pixels * style.scale));
}

Axis valueAxisWithTarget(const AxisSpec& spec, int target) {
  Axis axis;
  axis.spec = spec;
  if (spec.log) {
    axis.ticks = plot_detail::logTicks(spec.lo, spec.hi, target);
    axis.labels = plot_detail::formatLogTicks(axis.ticks);
    axis.minor = plot_detail::logMinorTicks(spec.lo, spec.hi, axis.ticks);
  } else {
    axis.ticks = plot_detail::niceTicks(spec.lo, spec.hi, target);
    axis.labels =
        plot_detail::formatTicks(axis.ticks, plot_detail::niceStep(spec.lo, spec.hi, target));
  }
  return axis;
}

// True when neighbouring tick labels keep a clear gap along an axis `length` pixels long.
bool labelsFit(const Axis& axis, int length, bool horizontal, const Style& style) {
  const int gap = horizontal ? scaled(style, 14) : measure("0", style.tick).ascent;
  for (std::size_t i = 1; i < axis.ticks.size(); ++i) {
    const double distance =
        (axis.fraction(axis.ticks[i]) - axis.fraction(axis.ticks[i - 1])) * (length - 1);
    const double extent = horizontal ? 0.5 * (measure(axis.labels[i], style.tick).width +
                                              measure(axis.labels[i - 1], style.tick).width)
                                     : measure("0", style.tick).ascent;
    if (distance < extent + gap) return false;
  }
  return true;
}

// Value axis: the most ticks, up to one per ~100 px (x) or ~60 px (y), whose labels fit.
Axis valueAxis(const AxisSpec& spec, int length, bool horizontal, const Style& style) {
  const double spacing = (horizontal ? 100.0 : 60.0) * style.scale;
  int target = std::clamp(static_cast<int>(length / spacing), 2, 12);
  Axis axis = valueAxisWithTarget(spec, target);
  while (target > 1 && !labelsFit(axis, length, horizontal, style)) {
    axis = valueAxisWithTarget(spec, --target);
  }
  return axis;
}

// Greedy word wrap into lines at most `width` px wide; empty when a word alone is wider.
std::vector<std::string> wrapWords(const std::string& text, int width, const Font& font) {
  std::istringstream words(text);
  std::vector<std::string> lines;
  std::string word;
  while (words >> word) {
    if (measure(word, font).width > width) return {};
    if (!lines.empty() && measure(lines.back() + " " + word, font).width <= width) {
      lines.back() += " " + word;
    } else {
      lines.push_back(word);
    }
  }
  if (lines.empty()) lines.emplace_back();
  return lines;
}

// Category names centred under their slots, wrapped onto up to 3 lines; when one does not fit
// that way, all of them turn upright.
Axis categoryAxis(const AxisSpec& spec, int length, const Style& style) {
  constexpr std::size_t kMaxLines = 3;
  Axis axis;
  axis.spec = spec;
  axis.labels = spec.categories;
  const int slot = length / static_cast<int>(spec.categories.size()) - scaled(style, 8);
  for (std::size_t i = 0; i < spec.categories.size(); ++i) {
    axis.ticks.push_back(i + 0.5);
    axis.label_lines.push_back(wrapWords(spec.categories[i], slot, style.tick));
    const std::size_t lines = axis.label_lines.back().size();
    if (lines == 0 || lines > kMaxLines) axis.upright_labels = true;
  }
  return axis;
}

Axis makeAxis(const AxisSpec& spec, int length, bool horizontal, const Style& style) {
  if (!spec.categories.empty()) return categoryAxis(spec, length, style);
  return valueAxis(spec, length, horizontal, style);
}

int widestLabel(const Axis& axis, const Style& style) {
  int widest = 0;
  for (const std::string& label : axis.labels) {
    widest = std::max(widest, measure(label, style.tick).width);
  }
  return widest;
}

int lineHeight(const Font& font) { return measure("Ag", font).height() + 2; }

// Height of the band of x tick labels under the plot area.
int xLabelBand(const Axis& axis, const Style& style) {
  if (axis.upright_labels) return widestLabel(axis, style);
  std::size_t lines = 1;
  for (const std::vector<std::string>& label : axis.label_lines) {
    lines = std::max(lines, label.size());
  }
  return static_cast<int>(lines) * lineHeight(style.tick) - 2;
}

// The plot area left once titles, labels, the note and an outside legend have their room.
cv::Rect areaFor(const ChartSpec& spec, const Style& style, const Axis& x, const Axis& y,
                 int outside_legend_width) {
  const int pad = style.pad;
  const int top = pad + (spec.title.empty() ? pad / 2 + measure("0", style.tick).ascent / 2
                                            : measure(spec.title, style.title).height() + pad);
  const int left = pad +
                   (spec.y_label.empty() ? 0 : measure(spec.y_label, style.label).height() + pad) +
                   widestLabel(y, style) + style.tick_gap + style.tick_length;
  const int bottom =
      style.tick_length + style.tick_gap + xLabelBand(x, style) +
      (spec.x_label.empty() ? 0 : pad + measure(spec.x_label, style.label).height()) +
      (spec.note.empty() ? 0 : pad + measure(spec.note, style.note).height()) + pad;
  // The last x label is centred on the right edge and may stick out by half its width.
  const int overhang =
      x.labels.empty() || x.categorical() ? 0 : measure(x.labels.back(), style.tick).width / 2 + 2;
  int right = std::max(2 * pad, overhang);
  if (outside_legend_width > 0) right = std::max(right, outside_legend_width + 2 * pad);
  const int minimum = 16;
  return {left, top, std::max(minimum, spec.size.width - left - right),
          std::max(minimum, spec.size.height - top - bottom)};
}

// Margins depend on the tick labels and the ticks on the area's size: a few rounds settle it.
Layout layoutChart(const ChartSpec& spec, const Style& style, int outside_legend_width) {
  Layout layout;
  layout.area = cv::Rect(spec.size.width / 10, spec.size.height / 10, spec.size.width * 8 / 10,
                         spec.size.height * 3 / 4);
  for (int round = 0; round < 3; ++round) {
    layout.y = makeAxis(spec.y, layout.area.height, false, style);
    layout.x = makeAxis(spec.x, layout.area.width, true, style);
    layout.area = areaFor(spec, style, layout.x, layout.y, outside_legend_width);
  }
  return layout;
}

// --- legend ----------------------------------------------------------------------------------

int legendRowHeight(const std::vector<LegendEntry>& entries, const Style& style) {
  int row = measure("Ag", style.legend).height();
  for (const LegendEntry& entry : entries) {
    if (entry.marker) row = std::max(row, cvRound(entry.marker_size) + 2);
  }
  return row + scaled(style, 6);
}

int legendSampleWidth(const Style& style) { return scaled(style, 30); }

cv::Size legendSize(const std::vector<LegendEntry>& entries, const Style& style) {
  int widest = 0;
  for (const LegendEntry& entry : entries) {
    widest = std::max(widest, measure(entry.label, style.legend).width);
  }
  const int inner = scaled(style, 8);
  return {inner + legendSampleWidth(style) + inner + widest + inner,
          inner + static_cast<int>(entries.size()) * legendRowHeight(entries, style) +
              scaled(style, 2)};
}

cv::Rect legendRect(LegendPosition position, const cv::Rect& area, cv::Size size,
                    const Style& style) {
  const int margin = scaled(style, 8);
  const int left = area.x + margin;
  const int right = area.x + area.width - margin - size.width;
  const int top = area.y + margin;
  const int bottom = area.y + area.height - margin - size.height;
  switch (position) {
    case LegendPosition::kTopLeft:
      return {{left, top}, size};
    case LegendPosition::kBottomRight:
      return {{right, bottom}, size};
    case LegendPosition::kBottomLeft:
      return {{left, bottom}, size};
    case LegendPosition::kOutsideRight:
      return {{area.x + area.width + style.pad, area.y}, size};
    default:
      return {{right, top}, size};
  }
}

void drawLegendSample(cv::Mat& image, const LegendEntry& entry, cv::Rect sample) {
  const cv::Point2d centre(sample.x + 0.5 * sample.width, sample.y + 0.5 * sample.height);
  if (entry.swatch) {
    const int side = std::min(sample.height, sample.width) - 2;
    cv::rectangle(image,
                  cv::Rect(cvRound(centre.x) - side / 2, cvRound(centre.y) - side / 2, side, side),
                  entry.color, cv::FILLED);
  }
  if (entry.line) {
    drawSegment(image, {static_cast<double>(sample.x), centre.y},
                {static_cast<double>(sample.x + sample.width), centre.y}, entry.color,
                entry.line_width);
  }
  if (entry.marker) drawMarker(image, *entry.marker, centre, entry.marker_size, entry.color);
}

void drawLegend(cv::Mat& image, const cv::Rect& box, const std::vector<LegendEntry>& entries,
                const Style& style) {
  const cv::Rect visible = box & cv::Rect(0, 0, image.cols, image.rows);
  cv::Mat background = image(visible);
  // Mostly opaque, so that grid lines (and any data underneath) stay faintly visible.
  cv::addWeighted(background, 0.12, cv::Mat(background.size(), background.type(), kWhite), 0.88,
                  0.0, background);
  cv::rectangle(image, visible, kLegendBorder, 1);
  const int inner = scaled(style, 8);
  const int row_height = legendRowHeight(entries, style);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const int row_top = box.y + inner + static_cast<int>(i) * row_height - scaled(style, 2);
    const cv::Rect sample(box.x + inner, row_top, legendSampleWidth(style), row_height);
    drawLegendSample(image, entries[i], sample);
    drawText(image, entries[i].label, {sample.x + sample.width + inner, row_top + row_height / 2},
             style.legend, Align::kStart, Align::kCenter);
  }
}

// Non-white pixels of the data drawn alone: what a legend must not hide.
cv::Mat dataMask(const Layout& layout, const DataPainter& painter) {
  cv::Mat canvas(layout.area.size(), CV_8UC3, kWhite);
  painter(canvas, Mapping{canvas.size(), layout.x, layout.y});
  cv::Mat gray, mask;
  cv::cvtColor(canvas, gray, cv::COLOR_BGR2GRAY);
  cv::threshold(gray, mask, 250, 255, cv::THRESH_BINARY_INV);
  return mask;
}

bool hidesNoData(const cv::Rect& legend, const Layout& layout, const cv::Mat& mask) {
  const cv::Rect local = legend - layout.area.tl();
  if ((local & cv::Rect(0, 0, mask.cols, mask.rows)) != local) return false;
  return cv::countNonZero(mask(local)) == 0;
}

// Resolves LegendPosition::kAuto: the first free inside corner, else outside on the right.
Layout layoutWithLegend(const ChartSpec& spec, const Style& style, const DataPainter& painter) {
  if (spec.legend.empty() || spec.legend_position == LegendPosition::kNone) {
    return layoutChart(spec, style, 0);
  }
  const cv::Size size = legendSize(spec.legend, style);
  if (spec.legend_position == LegendPosition::kOutsideRight) {
    Layout layout = layoutChart(spec, style, size.width);
    layout.legend = legendRect(LegendPosition::kOutsideRight, layout.area, size, style);
    return layout;
  }
  Layout layout = layoutChart(spec, style, 0);
  if (spec.legend_position != LegendPosition::kAuto) {
    layout.legend = legendRect(spec.legend_position, layout.area, size, style);
    return layout;
  }
  const cv::Mat mask = dataMask(layout, painter);
  for (LegendPosition corner : {LegendPosition::kTopRight, LegendPosition::kTopLeft,
                                LegendPosition::kBottomRight, LegendPosition::kBottomLeft}) {
    const cv::Rect candidate = legendRect(corner, layout.area, size, style);
    if (hidesNoData(candidate, layout, mask)) {
      layout.legend = candidate;
      return layout;
    }
  }
  layout = layoutChart(spec, style, size.width);
  layout.legend = legendRect(LegendPosition::kOutsideRight, layout.area, size, style);
  return layout;
}

// --- frame -----------------------------------------------------------------------------------

void drawGrid(cv::Mat& image, const Layout& layout) {
  const Mapping mapping{layout.area.size(), layout.x, layout.y};
  const cv::Rect& a = layout.area;
  auto vertical = [&](double value, const cv::Scalar& color) {
    const int column = a.x + cvRound(mapping.column(value));
    cv::line(image, {column, a.y}, {column, a.y + a.height - 1}, color, 1);
  };
  auto horizontal = [&](double value, const cv::Scalar& color) {
    const int row = a.y + cvRound(mapping.row(value));
    cv::line(image, {a.x, row}, {a.x + a.width - 1, row}, color, 1);
  };
  if (!layout.x.categorical()) {
    for (double value : layout.x.minor) vertical(value, kMinorGridColor);
    for (double value : layout.x.ticks) vertical(value, kGridColor);
  }
  for (double value : layout.y.minor) horizontal(value, kMinorGridColor);
  for (double value : layout.y.ticks) horizontal(value, kGridColor);
}

void drawXAxis(cv::Mat& image, const Layout& layout, const Style& style) {
  const Mapping mapping{layout.area.size(), layout.x, layout.y};
  const int axis_row = layout.area.y + layout.area.height;  // The frame's bottom line.
  const int label_top = axis_row + style.tick_length + style.tick_gap;
  for (std::size_t i = 0; i < layout.x.ticks.size(); ++i) {
    const int column = layout.area.x + cvRound(mapping.column(layout.x.ticks[i]));
    if (!layout.x.categorical()) {
      cv::line(image, {column, axis_row}, {column, axis_row + style.tick_length}, kFrameColor, 1);
    }
    if (layout.x.upright_labels) {
      const int width = measure(layout.x.labels[i], style.tick).width;
      drawTextUpwards(image, layout.x.labels[i], {column, label_top + width / 2}, style.tick);
    } else if (layout.x.categorical()) {
      const std::vector<std::string>& lines = layout.x.label_lines[i];
      for (std::size_t k = 0; k < lines.size(); ++k) {
        drawText(image, lines[k],
                 {column, label_top + static_cast<int>(k) * lineHeight(style.tick)}, style.tick,
                 Align::kCenter, Align::kStart);
      }
    } else {
      drawText(image, layout.x.labels[i], {column, label_top}, style.tick, Align::kCenter,
               Align::kStart);
    }
  }
}

void drawYAxis(cv::Mat& image, const Layout& layout, const Style& style) {
  const Mapping mapping{layout.area.size(), layout.x, layout.y};
  const int axis_column = layout.area.x - 1;  // The frame's left line.
  for (std::size_t i = 0; i < layout.y.ticks.size(); ++i) {
    const int row = layout.area.y + cvRound(mapping.row(layout.y.ticks[i]));
    cv::line(image, {axis_column - style.tick_length, row}, {axis_column, row}, kFrameColor, 1);
    drawText(image, layout.y.labels[i], {axis_column - style.tick_length - style.tick_gap, row},
             style.tick, Align::kEnd, Align::kCenter);
  }
}

void drawTitles(cv::Mat& image, const ChartSpec& spec, const Layout& layout, const Style& style) {
  const cv::Rect& a = layout.area;
  const int centre_x = a.x + a.width / 2;
  if (!spec.title.empty()) {
    drawText(image, spec.title, {centre_x, style.pad}, style.title, Align::kCenter, Align::kStart);
  }
  if (!spec.x_label.empty()) {
    const int top = a.y + a.height + style.tick_length + style.tick_gap +
                    xLabelBand(layout.x, style) + style.pad;
    drawText(image, spec.x_label, {centre_x, top}, style.label, Align::kCenter, Align::kStart);
  }
  if (!spec.y_label.empty()) {
    const int centre_x_of_label = style.pad + measure(spec.y_label, style.label).height() / 2;
    drawTextUpwards(image, spec.y_label, {centre_x_of_label, a.y + a.height / 2}, style.label);
  }
}

// "no data" on a white patch, so that no grid line runs through it.
void drawNoData(cv::Mat& image, const cv::Rect& area, const Style& style) {
  Font font = style.label;
  font.color = kNoteColor;
  const std::string text = "no data";
  const TextBox box = measure(text, font);
  const cv::Point centre(area.x + area.width / 2, area.y + area.height / 2);
  const int margin = scaled(style, 6);
  cv::rectangle(image,
                cv::Rect(centre.x - box.width / 2 - margin, centre.y - box.ascent / 2 - margin,
                         box.width + 2 * margin, box.height() + 2 * margin),
                kWhite, cv::FILLED);
  drawText(image, text, centre, font, Align::kCenter, Align::kCenter);
}

cv::Mat drawChart(const ChartSpec& spec, const DataPainter& painter, cv::Rect* area_out) {
  const Style style = makeStyle(spec.font_scale);
  const Layout layout = layoutWithLegend(spec, style, painter);
  if (area_out != nullptr) *area_out = layout.area;
  cv::Mat image(spec.size, CV_8UC3, kWhite);
  drawGrid(image, layout);
  cv::Mat area = image(layout.area);
  painter(area, Mapping{layout.area.size(), layout.x, layout.y});
  cv::rectangle(image, {layout.area.x - 1, layout.area.y - 1},
                {layout.area.x + layout.area.width, layout.area.y + layout.area.height},
                kFrameColor, 1);
  drawXAxis(image, layout, style);
  drawYAxis(image, layout, style);
  drawTitles(image, spec, layout, style);
  if (!layout.legend.empty()) drawLegend(image, layout.legend, spec.legend, style);
  if (!spec.note.empty()) {
    drawText(image, spec.note, {style.pad, spec.size.height - style.pad}, style.note, Align::kStart,
             Align::kEnd);
  }
  if (spec.empty) drawNoData(image, layout.area, style);
  return image;
}

// --- shared helpers of both chart kinds ------------------------------------------------------

bool usable(double value, bool log) { return std::isfinite(value) && (!log || value > 0.0); }

// The data's extent plus 5% on each side (in log10 units on a log axis); a single value gets
// +-10% of itself (+-0.5 for zero, +-half a decade on a log axis).
AxisSpec autoRange(const std::vector<double>& values, bool log) {
  AxisSpec spec;
  spec.log = log;
  if (values.empty()) {
    spec.lo = log ? 1.0 : 0.0;
    spec.hi = log ? 10.0 : 1.0;
    return spec;
  }
  auto [lo_it, hi_it] = std::minmax_element(values.begin(), values.end());
  double lo = log ? std::log10(*lo_it) : *lo_it;
  double hi = log ? std::log10(*hi_it) : *hi_it;
  const double span = hi - lo;
  const double margin = span > 1e-12 * std::max(std::abs(lo), std::abs(hi))
                            ? 0.05 * span
                            : (log ? 0.5 : (lo != 0.0 ? 0.1 * std::abs(lo) : 0.5));
  lo -= margin;
  hi += margin;
  spec.lo = log ? std::pow(10.0, lo) : lo;
  spec.hi = log ? std::pow(10.0, hi) : hi;
  return spec;
}

AxisSpec rangeSpec(const std::optional<AxisRange>& range, bool log) {
  AxisSpec spec;
  spec.lo = range->min;
  spec.hi = range->max;
  spec.log = log;
  return spec;
}

std::string countPhrase(int count, const std::string& singular, const std::string& plural,
                        const std::string& rest) {
  return std::to_string(count) + " " + (count == 1 ? singular : plural) + " " + rest;
}

std::string joinNotes(const std::vector<std::string>& parts) {
  std::string note;
  for (const std::string& part : parts) note += (note.empty() ? "" : "; ") + part;
  return note;
}

std::string formatValue(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.3g", value);
  return buffer;
}

void require(bool ok, const char* struct_name, const std::string& field, double value,
             const std::string& constraint) {
  const OptionCheck check(struct_name);
  check(ok, field, value, constraint);
}

void validateSize(const char* struct_name, int width, int height, double font_scale) {
  require(width >= 240 && width <= 8000, struct_name, "width", width, "must be in [240, 8000]");
  require(height >= 180 && height <= 8000, struct_name, "height", height, "must be in [180, 8000]");
  require(font_scale >= 0.5 && font_scale <= 4.0, struct_name, "font_scale", font_scale,
          "must be in [0.5, 4]");
}

void validateRange(const char* struct_name, const std::string& field,
                   const std::optional<AxisRange>& range, bool log) {
  if (!range) return;
  require(std::isfinite(range->min), struct_name, field + ".min", range->min, "must be finite");
  require(std::isfinite(range->max), struct_name, field + ".max", range->max, "must be finite");
  require(range->max > range->min, struct_name, field + ".max", range->max,
          "must be > " + field + ".min (" + formatValue(range->min) + ")");
  require(!log || range->min > 0.0, struct_name, field + ".min", range->min,
          "must be > 0 on a log axis");
}

}  // namespace

void savePng(const cv::Mat& image, const std::string& path) {
  std::vector<unsigned char> bytes;
  if (!cv::imencode(".png", image, bytes)) throw IoError(path, "cannot encode the image as PNG");
  std::ofstream file(path, std::ios::binary);
  if (!file) throw IoError(path, std::string("cannot open for writing: ") + std::strerror(errno));
  file.write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
  file.close();
  if (!file) throw IoError(path, "write failed");
}

cv::Scalar paletteColor(int index) {
  // Okabe & Ito (2008), "Color Universal Design", as BGR: blue, vermillion, bluish green,
  // reddish purple, orange, sky blue, yellow. Black is left for the axes; yellow, pale on
  // white, comes last.
  static const std::array<cv::Scalar, 7> kPalette = {
      cv::Scalar(178, 114, 0),   cv::Scalar(0, 94, 213),  cv::Scalar(115, 158, 0),
      cv::Scalar(167, 121, 204), cv::Scalar(0, 159, 230), cv::Scalar(233, 180, 86),
      cv::Scalar(66, 228, 240)};
  const int n = static_cast<int>(kPalette.size());
  return kPalette[((index % n) + n) % n];
}

MarkerShape paletteMarker(int index) {
  constexpr int kShapes = 8;
  return static_cast<MarkerShape>(((index % kShapes) + kShapes) % kShapes);
}

// ---------------------------------------------------------------------------------------------
// Plot
// ---------------------------------------------------------------------------------------------

void PlotSeries::validate() const {
  require(line_width >= 0.5 && line_width <= 20.0, "PlotSeries", "line_width", line_width,
          "must be in [0.5, 20]");
  require(marker_size >= 2.0 && marker_size <= 50.0, "PlotSeries", "marker_size", marker_size,
          "must be in [2, 50]");
  if (x.size() != y.size()) {
    throw InvalidOptions("PlotSeries", "y", std::to_string(y.size()) + " values",
                         "must have as many values as x (" + std::to_string(x.size()) + ")");
  }
}

void PlotOptions::validate() const {
  validateSize("PlotOptions", width, height, font_scale);
  validateRange("PlotOptions", "x_range", x_range, log_x);
  validateRange("PlotOptions", "y_range", y_range, log_y);
}

namespace {

struct PointCounts {
  int drawable = 0;
  int non_finite = 0;
  int x_not_positive = 0;  // Finite, but x <= 0 on a log x axis.
  int y_not_positive = 0;  // Finite, x fine, but y <= 0 on a log y axis.
};

PointCounts countPoints(const std::vector<PlotSeries>& series, const PlotOptions& options) {
  PointCounts counts;
  for (const PlotSeries& s : series) {
    for (std::size_t k = 0; k < s.x.size(); ++k) {
      if (!std::isfinite(s.x[k]) || !std::isfinite(s.y[k])) {
        ++counts.non_finite;
      } else if (options.log_x && s.x[k] <= 0.0) {
        ++counts.x_not_positive;
      } else if (options.log_y && s.y[k] <= 0.0) {
        ++counts.y_not_positive;
      } else {
        ++counts.drawable;
      }
    }
  }
  return counts;
}

std::string plotNote(const PointCounts& counts) {
  std::vector<std::string> parts;
  if (counts.x_not_positive > 0) {
    parts.push_back(countPhrase(counts.x_not_positive, "point", "points",
                                "with x <= 0 not shown on the log x axis"));
  }
  if (counts.y_not_positive > 0) {
    parts.push_back(countPhrase(counts.y_not_positive, "point", "points",
                                "with y <= 0 not shown on the log y axis"));
  }
  if (counts.non_finite > 0) {
    parts.push_back(
        countPhrase(counts.non_finite, "non-finite point", "non-finite points", "skipped"));
  }
  return joinNotes(parts);
}

bool drawablePoint(const PlotSeries& s, std::size_t k, const PlotOptions& options) {
  return usable(s.x[k], options.log_x) && usable(s.y[k], options.log_y);
}

// Coordinates of the drawable points along one axis, for its automatic range.
std::vector<double> drawableValues(const std::vector<PlotSeries>& series,
                                   const PlotOptions& options, bool along_x) {
  std::vector<double> values;
  for (const PlotSeries& s : series) {
    for (std::size_t k = 0; k < s.x.size(); ++k) {
      if (drawablePoint(s, k, options)) values.push_back(along_x ? s.x[k] : s.y[k]);
    }
  }
  return values;
}

void paintSeries(cv::Mat& area, const Mapping& mapping, const PlotSeries& s, int index,
                 const PlotOptions& options) {
  const cv::Scalar color = s.color.value_or(paletteColor(index));
  if (s.style != PlotSeries::Style::kMarkers) {
    for (std::size_t k = 1; k < s.x.size(); ++k) {
      if (!drawablePoint(s, k - 1, options) || !drawablePoint(s, k, options)) continue;
      drawSegment(area, mapping.toPixel(s.x[k - 1], s.y[k - 1]), mapping.toPixel(s.x[k], s.y[k]),
                  color, s.line_width);
    }
  }
  if (s.style == PlotSeries::Style::kLine) return;
  const MarkerShape shape = s.marker.value_or(paletteMarker(index));
  const cv::Rect2d reach(-s.marker_size, -s.marker_size, area.cols + 2 * s.marker_size,
                         area.rows + 2 * s.marker_size);
  for (std::size_t k = 0; k < s.x.size(); ++k) {
    if (!drawablePoint(s, k, options)) continue;
    const cv::Point2d centre = mapping.toPixel(s.x[k], s.y[k]);
    if (reach.contains(centre)) drawMarker(area, shape, centre, s.marker_size, color);
  }
}

LegendEntry legendEntry(const PlotSeries& s, int index) {
  LegendEntry entry;
  entry.label = s.label;
  entry.color = s.color.value_or(paletteColor(index));
  entry.line = s.style != PlotSeries::Style::kMarkers;
  if (s.style != PlotSeries::Style::kLine) entry.marker = s.marker.value_or(paletteMarker(index));
  entry.line_width = s.line_width;
  entry.marker_size = s.marker_size;
  return entry;
}

// The title, labels, size, font and legend placement every chart kind takes from its options.
template <class Options>
ChartSpec labelledSpec(const Options& options) {
  ChartSpec spec;
  spec.title = options.title;
  spec.x_label = options.x_label;
  spec.y_label = options.y_label;
  spec.size = {options.width, options.height};
  spec.font_scale = options.font_scale;
  spec.legend_position = options.legend;
  return spec;
}

ChartSpec plotSpec(const PlotOptions& options, const std::vector<PlotSeries>& series) {
  ChartSpec spec = labelledSpec(options);
  spec.x = options.x_range ? rangeSpec(options.x_range, options.log_x)
                           : autoRange(drawableValues(series, options, true), options.log_x);
  spec.y = options.y_range ? rangeSpec(options.y_range, options.log_y)
                           : autoRange(drawableValues(series, options, false), options.log_y);
  for (std::size_t i = 0; i < series.size(); ++i) {
    if (!series[i].label.empty())
      spec.legend.push_back(legendEntry(series[i], static_cast<int>(i)));
  }
  const PointCounts counts = countPoints(series, options);
  spec.note = plotNote(counts);
  spec.empty = counts.drawable == 0;
  return spec;
}

cv::Mat renderPlot(const PlotOptions& options, const std::vector<PlotSeries>& series,
                   cv::Rect* area) {
  const DataPainter painter = [&](cv::Mat& canvas, const Mapping& mapping) {
    for (std::size_t i = 0; i < series.size(); ++i) {
      paintSeries(canvas, mapping, series[i], static_cast<int>(i), options);
    }
  };
  return drawChart(plotSpec(options, series), painter, area);
}

}  // namespace

Plot::Plot(PlotOptions options) : options_(std::move(options)) { options_.validate(); }

Plot& Plot::add(PlotSeries series) {
  series.validate();
  series_.push_back(std::move(series));
  return *this;
}

cv::Mat Plot::render() const { return renderPlot(options_, series_, nullptr); }

cv::Rect Plot::plotArea() const {
  cv::Rect area;
  renderPlot(options_, series_, &area);
  return area;
}

void Plot::save(const std::string& png_path) const { savePng(render(), png_path); }

// ---------------------------------------------------------------------------------------------
// BarChart
// ---------------------------------------------------------------------------------------------

void BarChartOptions::validate() const {
  validateSize("BarChartOptions", width, height, font_scale);
  validateRange("BarChartOptions", "y_range", y_range, log_y);
}

namespace {

// From zero (or the lowest negative value) to the highest value, with head room for the
// value labels; on a log axis from the decade below the smallest value, so it shows a bar.
AxisSpec barRange(const std::vector<double>& values, bool log, bool value_labels) {
  AxisSpec spec;
  spec.log = log;
  const double head_room = value_labels ? 0.12 : 0.05;
  if (values.empty()) return autoRange(values, log);
  auto [lo_it, hi_it] = std::minmax_element(values.begin(), values.end());
  if (log) {
    const double lo = std::log10(*lo_it);
    const double hi = std::log10(*hi_it);
    const double span = std::max(hi - lo, 1.0);
    spec.lo = std::pow(10.0, std::floor(lo - 0.05 * span));
    spec.hi = std::pow(10.0, hi + head_room * span);
    return spec;
  }
  const double lo = std::min(0.0, *lo_it);
  const double hi = std::max(0.0, *hi_it);
  const double span = hi > lo ? hi - lo : 1.0;
  spec.lo = lo < 0.0 ? lo - head_room * span : 0.0;
  spec.hi = hi > 0.0 || lo == 0.0 ? hi + head_room * span : 0.0;
  return spec;
}

void drawValueLabel(cv::Mat& area, double value, double centre_x, double bar_end_row,
                    bool downwards, int bar_width, const Style& style) {
  const std::string text = formatValue(value);
  Font font = style.tick;
  font.scale *= 0.9;
  while (measure(text, font).width > bar_width + 4 && font.scale > 0.3 * style.scale) {
    font.scale *= 0.9;
  }
  if (measure(text, font).width > bar_width + 4) return;
  const int gap = scaled(style, 3);
  const cv::Point anchor(cvRound(centre_x), cvRound(bar_end_row) + (downwards ? gap : -gap));
  drawText(area, text, anchor, font, Align::kCenter, downwards ? Align::kStart : Align::kEnd);
}

struct BarGeometry {
  double slot = 0.0;        // Width of one category (px).
  double bar = 0.0;         // Width of one bar (px).
  double group_left = 0.0;  // Offset of a category's first bar from the slot's left edge.
};

BarGeometry barGeometry(int width, int categories, int series) {
  BarGeometry geometry;
  geometry.slot = static_cast<double>(width - 1) / categories;
  const double group = 0.8 * geometry.slot;
  geometry.bar = group / std::max(series, 1);
  geometry.group_left = 0.5 * (geometry.slot - group);
  return geometry;
}

void paintBars(cv::Mat& area, const Mapping& mapping, const std::vector<BarSeries>& series,
               int categories, const BarChartOptions& options) {
  const Style style = makeStyle(options.font_scale);
  const BarGeometry g = barGeometry(area.cols, categories, static_cast<int>(series.size()));
  const double base_value =
      options.log_y ? mapping.y.spec.lo : std::clamp(0.0, mapping.y.spec.lo, mapping.y.spec.hi);
  const double base_row = mapping.row(base_value);
  // A white gap between neighbouring bars once they are wide enough to spare it.
  const int gap = g.bar >= 8.0 ? 1 : 0;
  for (std::size_t j = 0; j < series.size(); ++j) {
    const cv::Scalar color = series[j].color.value_or(paletteColor(static_cast<int>(j)));
    for (int i = 0; i < categories; ++i) {
      const double value = series[j].values[i];
      if (!usable(value, options.log_y)) continue;
      const double left = i * g.slot + g.group_left + j * g.bar;
      const int x0 = cvRound(left) + gap;
      const int x1 = std::max(x0, cvRound(left + g.bar) - 1 - gap);
      const double end_row = std::clamp(mapping.row(value), -1.0, static_cast<double>(area.rows));
      cv::rectangle(area, {x0, cvRound(std::min(end_row, base_row))},
                    {x1, cvRound(std::max(end_row, base_row))}, color, cv::FILLED);
      if (options.value_labels) {
        drawValueLabel(area, value, left + 0.5 * g.bar, end_row, end_row > base_row, x1 - x0 + 1,
                       style);
      }
    }
  }
}

std::string barNote(const std::vector<BarSeries>& series, bool log) {
  int non_finite = 0;
  int not_positive = 0;
  for (const BarSeries& s : series) {
    for (double value : s.values) {
      if (!std::isfinite(value)) {
        ++non_finite;
      } else if (log && value <= 0.0) {
        ++not_positive;
      }
    }
  }
  std::vector<std::string> parts;
  if (not_positive > 0) {
    parts.push_back(countPhrase(not_positive, "value", "values", "<= 0 not shown on the log axis"));
  }
  if (non_finite > 0) {
    parts.push_back(countPhrase(non_finite, "non-finite value", "non-finite values", "not shown"));
  }
  return joinNotes(parts);
}

ChartSpec barSpec(const std::vector<std::string>& categories, const BarChartOptions& options,
                  const std::vector<BarSeries>& series) {
  ChartSpec spec = labelledSpec(options);
  spec.x.hi = static_cast<double>(categories.size());
  spec.x.categories = categories;
  std::vector<double> values;
  for (std::size_t j = 0; j < series.size(); ++j) {
    for (double value : series[j].values) {
      if (usable(value, options.log_y)) values.push_back(value);
    }
    if (series[j].label.empty()) continue;
    LegendEntry entry;
    entry.label = series[j].label;
    entry.color = series[j].color.value_or(paletteColor(static_cast<int>(j)));
    entry.swatch = true;
    spec.legend.push_back(entry);
  }
  spec.y = options.y_range ? rangeSpec(options.y_range, options.log_y)
                           : barRange(values, options.log_y, options.value_labels);
  spec.note = barNote(series, options.log_y);
  spec.empty = values.empty();
  return spec;
}

cv::Mat renderBars(const std::vector<std::string>& categories, const BarChartOptions& options,
                   const std::vector<BarSeries>& series, cv::Rect* area) {
  const DataPainter painter = [&](cv::Mat& canvas, const Mapping& mapping) {
    paintBars(canvas, mapping, series, static_cast<int>(categories.size()), options);
  };
  return drawChart(barSpec(categories, options, series), painter, area);
}

}  // namespace

BarChart::BarChart(std::vector<std::string> categories, BarChartOptions options)
    : categories_(std::move(categories)), options_(std::move(options)) {
  options_.validate();
  if (categories_.empty()) {
    throw InvalidOptions("BarChart", "categories", "{}", "must name at least one category");
  }
}

BarChart& BarChart::add(BarSeries series) {
  if (series.values.size() != categories_.size()) {
    throw InvalidOptions(
        "BarSeries", "values", std::to_string(series.values.size()) + " values",
        "must have one value per category (" + std::to_string(categories_.size()) + ")");
  }
  series_.push_back(std::move(series));
  return *this;
}

cv::Mat BarChart::render() const { return renderBars(categories_, options_, series_, nullptr); }

cv::Rect BarChart::plotArea() const {
  cv::Rect area;
  renderBars(categories_, options_, series_, &area);
  return area;
}

void BarChart::save(const std::string& png_path) const { savePng(render(), png_path); }

}  // namespace curvesfm
