#include "core/plot.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/errors.h"

namespace curvesfm {
namespace {

using plot_detail::formatLogTicks;
using plot_detail::formatTick;
using plot_detail::formatTicks;
using plot_detail::logMinorTicks;
using plot_detail::logTicks;
using plot_detail::niceStep;
using plot_detail::niceTicks;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

const cv::Scalar kRed(0, 0, 255);  // BGR; not in the palette, the grid or the text.

bool isRed(const cv::Vec3b& pixel) { return pixel[2] > 180 && pixel[1] < 90 && pixel[0] < 90; }

// Pixels of `image` that are clearly red, inside `region` (the whole image by default).
int countRed(const cv::Mat& image, cv::Rect region = {}) {
  if (region.empty()) region = cv::Rect(0, 0, image.cols, image.rows);
  int count = 0;
  for (int r = region.y; r < region.y + region.height; ++r) {
    for (int c = region.x; c < region.x + region.width; ++c)
      count += isRed(image.at<cv::Vec3b>(r, c));
  }
  return count;
}

// Centre of mass of the red pixels in the columns [first, last).
cv::Point2d redCentroid(const cv::Mat& image, int first_column, int last_column) {
  first_column = std::max(first_column, 0);
  last_column = std::min(last_column, image.cols);
  cv::Point2d sum(0, 0);
  int count = 0;
  for (int r = 0; r < image.rows; ++r) {
    for (int c = first_column; c < last_column; ++c) {
      if (!isRed(image.at<cv::Vec3b>(r, c))) continue;
      sum += cv::Point2d(c, r);
      ++count;
    }
  }
  return count > 0 ? sum / count : cv::Point2d(-1, -1);
}

PlotSeries redMarkers(std::vector<double> x, std::vector<double> y) {
  PlotSeries series;
  series.x = std::move(x);
  series.y = std::move(y);
  series.style = PlotSeries::Style::kMarkers;
  series.color = kRed;
  series.marker = MarkerShape::kSquare;
  return series;
}

PlotOptions unitSquareOptions() {
  PlotOptions options;
  options.x_range = AxisRange{0.0, 10.0};
  options.y_range = AxisRange{0.0, 10.0};
  options.legend = LegendPosition::kNone;
  return options;
}

bool isStep125(double step) {
  const double mantissa = step / std::pow(10.0, std::floor(std::log10(step) + 1e-12));
  return std::abs(mantissa - 1) < 1e-9 || std::abs(mantissa - 2) < 1e-9 ||
         std::abs(mantissa - 5) < 1e-9;
}

// --- ticks -------------------------------------------------------------------------------------

TEST(PlotTicks, NiceStepsAreOneTwoFiveTimesAPowerOfTen) {
  EXPECT_DOUBLE_EQ(niceStep(0.0, 10.0, 5), 2.0);
  EXPECT_DOUBLE_EQ(niceStep(0.0, 1.0, 10), 0.1);
  EXPECT_DOUBLE_EQ(niceStep(0.0, 100.0, 3), 50.0);
  EXPECT_DOUBLE_EQ(niceStep(-3e-5, 7e-5, 5), 2e-5);
  for (double hi : {0.37, 1.0, 4.2, 17.0, 123.0, 9999.0}) {
    for (int target : {2, 5, 8}) EXPECT_TRUE(isStep125(niceStep(0.0, hi, target))) << hi;
  }
}

TEST(PlotTicks, NiceTicksCoverTheRangeWithMultiplesOfTheStep) {
  const double lo = -0.37, hi = 2.81;
  const double step = niceStep(lo, hi, 6);
  const std::vector<double> ticks = niceTicks(lo, hi, 6);
  ASSERT_GE(ticks.size(), 4u);
  EXPECT_GE(ticks.front(), lo);
  EXPECT_LT(ticks.front() - lo, step);
  EXPECT_LE(ticks.back(), hi);
  EXPECT_LT(hi - ticks.back(), step);
  for (std::size_t i = 0; i < ticks.size(); ++i) {
    EXPECT_NEAR(ticks[i] / step, std::round(ticks[i] / step), 1e-9);
    if (i > 0) {
      EXPECT_NEAR(ticks[i] - ticks[i - 1], step, 1e-12);
    }
  }
  EXPECT_THAT(niceTicks(0.0, 1.0, 5),
              testing::ElementsAre(0.0, 0.2, 0.4, 0.6000000000000001, 0.8, 1.0));
  EXPECT_THROW(niceTicks(1.0, 1.0, 5), CheckError);
  EXPECT_THROW(niceTicks(0.0, kNaN, 5), CheckError);
}

TEST(PlotTicks, ZeroIsExactlyZero) {
  const std::vector<double> ticks = niceTicks(-0.3, 0.3, 6);
  EXPECT_THAT(ticks, testing::Contains(0.0));
  for (double tick : ticks) EXPECT_FALSE(tick != 0.0 && std::abs(tick) < 1e-12);
}

TEST(PlotTicks, LogTicksAreDecadesWithAStrideWhenTooMany) {
  EXPECT_THAT(logTicks(0.5, 2000.0, 6), testing::ElementsAre(1.0, 10.0, 100.0, 1000.0));
  const std::vector<double> sparse = logTicks(1e-12, 1e3, 6);
  EXPECT_THAT(sparse, testing::ElementsAre(1e-12, 1e-9, 1e-6, 1e-3, 1.0, 1e3));
  // 16 decades, at most 3 ticks: every 6th, anchored at 1.
  EXPECT_THAT(logTicks(1e-12, 1e3, 3), testing::ElementsAre(1e-12, 1e-6, 1.0));
}

TEST(PlotTicks, FewDecadesGetOneTwoFiveOrLinearTicks) {
  EXPECT_THAT(logTicks(0.8, 60.0, 10), testing::ElementsAre(1.0, 2.0, 5.0, 10.0, 20.0, 50.0));
  EXPECT_THAT(logTicks(0.8, 60.0, 3), testing::ElementsAre(1.0, 10.0));
  EXPECT_THAT(logTicks(0.5, 2000.0, 12), testing::ElementsAre(0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0,
                                                              100.0, 200.0, 500.0, 1000.0, 2000.0));
  const std::vector<double> narrow = logTicks(2.1, 7.9, 5);
  ASSERT_GE(narrow.size(), 3u);
  EXPECT_GE(narrow.front(), 2.1);
  EXPECT_LE(narrow.back(), 7.9);
  EXPECT_THROW(logTicks(0.0, 10.0, 5), CheckError);
}

TEST(PlotTicks, LogMinorTicksFillTheDecadesButSkipMajors) {
  const std::vector<double> minor = logMinorTicks(1.0, 100.0, {1.0, 10.0, 100.0});
  ASSERT_EQ(minor.size(), 16u);  // 2..9 and 20..90.
  EXPECT_DOUBLE_EQ(minor.front(), 2.0);
  EXPECT_DOUBLE_EQ(minor.back(), 90.0);
  EXPECT_THAT(logMinorTicks(1e-12, 1e3, {1e-12, 1e-6, 1.0}), testing::SizeIs(13));
}

TEST(PlotTicks, LabelsHaveTheDigitsTheStepNeeds) {
  EXPECT_THAT(formatTicks({0.0, 0.5, 1.0, 1.5}, 0.5),
              testing::ElementsAre("0.0", "0.5", "1.0", "1.5"));
  EXPECT_THAT(formatTicks({-5.5e-20, 0.001, 0.002}, 0.001),
              testing::ElementsAre("0.000", "0.001", "0.002"));
  EXPECT_THAT(formatTicks({-20.0, 0.0, 20.0}, 20.0), testing::ElementsAre("-20", "0", "20"));
  EXPECT_THAT(formatTicks({0.0, 1e-4, 2e-4}, 1e-4), testing::ElementsAre("0", "1e-4", "2e-4"));
  EXPECT_THAT(formatTicks({0.0, 5e4, 1e5, 1.5e5}, 5e4),
              testing::ElementsAre("0", "5e4", "1e5", "1.5e5"));
  EXPECT_EQ(formatTick(-2.5e-6, 5e-7, true), "-2.5e-6");
  EXPECT_EQ(formatTick(0.6000000000000001, 0.2, false), "0.6");
}

TEST(PlotTicks, LogLabelsUseTheValuesOwnDigits) {
  EXPECT_THAT(formatLogTicks({0.001, 0.002, 0.005, 0.01}),
              testing::ElementsAre("0.001", "0.002", "0.005", "0.01"));
  EXPECT_THAT(formatLogTicks({1.0, 2.0, 2.5, 20.0, 1e4}),
              testing::ElementsAre("1", "2", "2.5", "20", "10000"));
  // One value out of [1e-3, 1e5) turns the whole axis scientific.
  EXPECT_THAT(formatLogTicks({2e-5, 1e-4, 1.0, 1e4}),
              testing::ElementsAre("2e-5", "1e-4", "1e0", "1e4"));
  EXPECT_THAT(formatLogTicks({1e4, 1e6}), testing::ElementsAre("1e4", "1e6"));
  EXPECT_THROW(formatLogTicks({0.0}), CheckError);
}

// --- Plot ----------------------------------------------------------------------------------------

TEST(Plot, RendersAnImageOfTheRequestedSize) {
  PlotOptions options;
  options.width = 640;
  options.height = 300;
  options.title = "title";
  PlotSeries series;
  series.label = "a";
  series.x = {1, 2, 3};
  series.y = {3, 1, 2};
  const cv::Mat image = Plot(options).add(series).render();
  EXPECT_EQ(image.cols, 640);
  EXPECT_EQ(image.rows, 300);
  EXPECT_EQ(image.type(), CV_8UC3);
  EXPECT_EQ(image.at<cv::Vec3b>(0, 0), cv::Vec3b(255, 255, 255));
}

TEST(Plot, MarkersLandWhereTheAxesPutThem) {
  Plot plot(unitSquareOptions());
  plot.add(redMarkers({2.0, 8.0}, {8.0, 2.0}));
  const cv::Mat image = plot.render();
  const cv::Rect area = plot.plotArea();
  ASSERT_GT(area.width, 400);
  ASSERT_GT(area.height, 300);
  const double sx = (area.width - 1) / 10.0, sy = (area.height - 1) / 10.0;
  const cv::Point2d upper_left(area.x + 2 * sx, area.y + area.height - 1 - 8 * sy);
  const cv::Point2d lower_right(area.x + 8 * sx, area.y + area.height - 1 - 2 * sy);
  const int middle = area.x + area.width / 2;
  const cv::Point2d left = redCentroid(image, 0, middle);
  const cv::Point2d right = redCentroid(image, middle, image.cols);
  EXPECT_NEAR(left.x, upper_left.x, 1.0);
  EXPECT_NEAR(left.y, upper_left.y, 1.0);
  EXPECT_NEAR(right.x, lower_right.x, 1.0);
  EXPECT_NEAR(right.y, lower_right.y, 1.0);
  // Nothing red outside the two markers (8 px squares: within 8 px of their centres).
  const int total = countRed(image);
  EXPECT_GT(total, 40);
  EXPECT_EQ(
      countRed(image, cv::Rect(cvRound(upper_left.x) - 8, cvRound(upper_left.y) - 8, 17, 17)) +
          countRed(image, cv::Rect(cvRound(lower_right.x) - 8, cvRound(lower_right.y) - 8, 17, 17)),
      total);
}

TEST(Plot, LinesJoinPointsAndStayInsideThePlotArea) {
  PlotOptions options = unitSquareOptions();
  PlotSeries line = redMarkers({-5.0, 15.0}, {5.0, 5.0});  // Crosses the whole area.
  line.style = PlotSeries::Style::kLine;
  Plot plot(options);
  plot.add(line);
  const cv::Mat image = plot.render();
  const cv::Rect area = plot.plotArea();
  const int row = area.y + area.height / 2;
  EXPECT_GT(countRed(image, cv::Rect(area.x, row - 3, area.width, 7)), area.width);
  EXPECT_EQ(countRed(image, cv::Rect(0, row - 3, area.x - 1, 7)), 0);
  EXPECT_EQ(countRed(image, cv::Rect(area.x + area.width + 1, row - 3,
                                     image.cols - area.x - area.width - 1, 7)),
            0);
}

TEST(Plot, LogAxisPutsDecadesAtEqualSpacing) {
  PlotOptions options;
  options.log_x = true;
  options.legend = LegendPosition::kNone;
  Plot plot(options);
  plot.add(redMarkers({1.0, 10.0, 100.0, 1000.0}, {1.0, 1.0, 1.0, 1.0}));
  const cv::Mat image = plot.render();
  const cv::Rect area = plot.plotArea();
  std::vector<double> columns;
  const double decade = area.width / 3.3;  // 3 decades plus 5% margins each side.
  for (int k = 0; k < 4; ++k) {
    const double expected = area.x + (0.15 + k) * decade;
    const int first = cvRound(expected - decade / 2), last = cvRound(expected + decade / 2);
    columns.push_back(redCentroid(image, first, last).x);
  }
  for (int k = 1; k < 4; ++k)
    EXPECT_NEAR(columns[k] - columns[k - 1], columns[1] - columns[0], 1.0);
  EXPECT_NEAR(columns[1] - columns[0], (area.width - 1) / 3.3, 1.5);
}

TEST(Plot, NonFiniteAndNonPositiveLogValuesAreSkipped) {
  PlotOptions options;
  options.log_y = true;
  PlotSeries series;
  series.label = "mixed";
  series.x = {0, 1, 2, 3, 4, 5, kNaN};
  series.y = {1, kInf, -kInf, 0.0, -2.0, 100.0, 3.0};
  series.color = kRed;
  Plot plot(options);
  plot.add(series);
  const cv::Mat image = plot.render();
  EXPECT_GT(countRed(plot.render(), plot.plotArea()), 20);  // Points 0 and 5 are drawn.
  EXPECT_EQ(image.size(), cv::Size(900, 600));
}

TEST(Plot, AllNonFiniteOrEmptyStillRendersAxes) {
  PlotOptions options;
  options.log_x = true;
  PlotSeries series = redMarkers({kNaN, kInf}, {1.0, 2.0});  // No label: no red legend marker.
  for (const Plot& plot : {Plot(options), Plot(options).add(series)}) {
    const cv::Mat image = plot.render();
    ASSERT_EQ(image.size(), cv::Size(900, 600));
    EXPECT_EQ(countRed(image, plot.plotArea()), 0);
    // The frame and tick labels are dark.
    cv::Mat gray;
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
    EXPECT_GT(cv::countNonZero(gray < 128), 200);
  }
}

TEST(Plot, FarAwayPointsDoNotBreakDrawing) {
  PlotOptions options = unitSquareOptions();
  PlotSeries series = redMarkers({1.0, 1e300, -1e300, 5.0}, {1.0, 5.0, 1e300, 5.0});
  series.style = PlotSeries::Style::kLineMarkers;
  Plot plot(options);
  plot.add(series);
  EXPECT_GT(countRed(plot.render()), 50);
}

TEST(Plot, AutoLegendAvoidsTheData) {
  PlotOptions options = unitSquareOptions();
  options.legend = LegendPosition::kAuto;
  PlotSeries series = redMarkers({9.8, 9.0, 9.5}, {9.8, 9.0, 9.5});  // Top-right corner.
  series.label = "a series with a long name";
  Plot plot(options);
  plot.add(series);
  const cv::Mat image = plot.render();
  const cv::Rect area = plot.plotArea();
  // The legend, and with it a red sample marker, moves to the top left, the first free corner.
  const cv::Rect top_left(area.x, area.y, area.width / 2, area.height / 4);
  const cv::Rect bottom_half(area.x, area.y + area.height / 2, area.width, area.height / 2);
  EXPECT_GT(countRed(image, top_left), 20);
  EXPECT_EQ(countRed(image, bottom_half), 0);
}

TEST(Plot, AutoLegendGoesOutsideWhenEveryCornerHasData) {
  PlotOptions options = unitSquareOptions();
  PlotSeries series = redMarkers({0.2, 9.8, 0.2, 9.8}, {0.2, 0.2, 9.8, 9.8});
  series.label = "corners";
  options.legend = LegendPosition::kNone;
  Plot without_legend(options);
  without_legend.add(series);
  options.legend = LegendPosition::kAuto;
  Plot plot(options);
  plot.add(series);
  const cv::Rect area = plot.plotArea();
  EXPECT_LT(area.width, without_legend.plotArea().width - 50);
  const cv::Mat image = plot.render();
  const cv::Rect right_margin(area.x + area.width + 2, area.y, image.cols - area.x - area.width - 2,
                              area.height);
  EXPECT_GT(countRed(image, right_margin), 20);  // The legend's sample marker.
}

TEST(Plot, SaveWritesALoadablePng) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("plot_test_" + std::to_string(::getpid()) + ".png");
  Plot plot(unitSquareOptions());
  plot.add(redMarkers({5.0}, {5.0}));
  plot.save(path.string());
  const cv::Mat loaded = cv::imread(path.string(), cv::IMREAD_COLOR);
  std::filesystem::remove(path);
  ASSERT_FALSE(loaded.empty());
  EXPECT_EQ(cv::norm(loaded, plot.render(), cv::NORM_INF), 0.0);
}

TEST(Plot, SaveToAnUnwritablePathThrowsIoErrorNamingIt) {
  const std::string path = "/nonexistent_plot_dir/sub/plot.png";
  try {
    Plot().save(path);
    FAIL() << "expected IoError";
  } catch (const IoError& error) {
    EXPECT_THAT(error.what(), testing::HasSubstr("IoError: " + path + ": "));
  }
}

TEST(Plot, InvalidOptionsAndSeriesAreRejected) {
  PlotOptions options;
  options.width = 10;
  EXPECT_THROW(Plot{options}, InvalidOptions);
  options = PlotOptions();
  options.log_y = true;
  options.y_range = AxisRange{0.0, 1.0};
  try {
    Plot{options};
    FAIL() << "expected InvalidOptions";
  } catch (const InvalidOptions& error) {
    EXPECT_STREQ(error.what(),
                 "InvalidOptions: PlotOptions.y_range.min = 0: must be > 0 on a log axis");
  }
  PlotSeries series;
  series.x = {1, 2};
  series.y = {1};
  EXPECT_THROW(Plot().add(series), InvalidOptions);
}

TEST(Plot, PaletteColoursAndMarkersDiffer) {
  for (int i = 0; i < 7; ++i) {
    for (int j = i + 1; j < 7; ++j) EXPECT_NE(paletteColor(i), paletteColor(j));
  }
  EXPECT_EQ(paletteColor(7), paletteColor(0));
  EXPECT_NE(paletteMarker(0), paletteMarker(1));
  EXPECT_EQ(paletteMarker(8), paletteMarker(0));
}

// --- BarChart ------------------------------------------------------------------------------------

TEST(BarChart, BarsRiseFromZeroToTheirValue) {
  BarChartOptions options;
  options.y_range = AxisRange{0.0, 10.0};
  options.legend = LegendPosition::kNone;
  BarChart chart({"a", "b"}, options);
  BarSeries series;
  series.values = {2.0, 8.0};
  series.color = kRed;
  chart.add(series);
  const cv::Mat image = chart.render();
  const cv::Rect area = chart.plotArea();
  const double slot = (area.width - 1) / 2.0;
  const double sy = (area.height - 1) / 10.0;
  const int bottom = area.y + area.height - 1;
  for (int i = 0; i < 2; ++i) {
    const int column = cvRound(area.x + (i + 0.5) * slot);
    int top = bottom;
    while (top > 0 && isRed(image.at<cv::Vec3b>(top - 1, column))) --top;
    EXPECT_NEAR(bottom - top, series.values[i] * sy, 2.0) << "category " << i;
  }
  // No bar between the groups.
  EXPECT_EQ(countRed(image, cv::Rect(cvRound(area.x + slot) - 3, area.y, 7, area.height)), 0);
}

TEST(BarChart, RejectsMismatchedSeriesAndRendersWithoutData) {
  BarChart chart({"a", "b", "c"});
  BarSeries series;
  series.values = {1.0, 2.0};
  EXPECT_THROW(chart.add(series), InvalidOptions);
  EXPECT_THROW(BarChart({}), InvalidOptions);
  series.values = {kNaN, kInf, 1.0};
  series.color = kRed;
  chart.add(series);
  EXPECT_EQ(chart.render().size(), cv::Size(900, 600));
  BarChartOptions log_options;
  log_options.log_y = true;
  BarChart log_chart({"a"}, log_options);
  series.values = {-1.0};
  log_chart.add(series);
  EXPECT_EQ(countRed(log_chart.render()), 0);
}

}  // namespace
}  // namespace curvesfm
