// Tests of the line-plot writer: layout and ticks, the SVG's geometry and
// escaping, and the PNG read back through OpenImageIO.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <sstream>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include <OpenImageIO/imagebuf.h>
#include <gtest/gtest.h>

#include "core/errors.h"
#include "plot/plot.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;

LinePlot SamplePlot() {
  LinePlot plot;
  plot.title = "m & friends <test>";
  plot.caption = "skybake test caption";
  plot.x = {"zenith angle (degrees)", false, 0.0, 90.0};
  plot.y = {"m", true, std::nullopt, std::nullopt};
  PlotSeries flat{"flat at 10", {0.0, 45.0, 90.0}, {10.0, 10.0, 10.0}, LineStyle::kSolid, 0, 6.0};
  PlotSeries rising{"rising", {0.0, 30.0, 60.0, 90.0}, {1.0, 2.0, 5.0, 90.0}, LineStyle::kDashed, 1, 2.0};
  plot.series = {flat, rising};
  return plot;
}

std::vector<std::string> Polylines(const std::string& svg) {
  std::vector<std::string> points;
  std::regex polyline("<polyline[^>]* points=\"([^\"]*)\"");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), polyline); it != std::sregex_iterator(); ++it)
    points.push_back((*it)[1]);
  return points;
}

TEST(Plot, LayoutMapsRangesToThePlotArea) {
  LinePlot plot = SamplePlot();
  PlotFrame f = LayoutPlot(plot);
  EXPECT_EQ(f.x_min, 0.0);
  EXPECT_EQ(f.x_max, 90.0);
  // Log axis widened to whole decades around the data (1 .. 90).
  EXPECT_DOUBLE_EQ(f.y_min, 1.0);
  EXPECT_DOUBLE_EQ(f.y_max, 100.0);
  EXPECT_DOUBLE_EQ(f.PixelX(0.0), f.left);
  EXPECT_DOUBLE_EQ(f.PixelX(90.0), f.right);
  EXPECT_DOUBLE_EQ(f.PixelY(1.0), f.bottom);
  EXPECT_DOUBLE_EQ(f.PixelY(100.0), f.top);
  EXPECT_NEAR(f.PixelY(10.0), 0.5 * (f.top + f.bottom), 1e-9);  // log: 10 halfway between 1 and 100
  for (double decade : {1.0, 10.0, 100.0})
    EXPECT_NE(std::find(f.y_ticks.begin(), f.y_ticks.end(), decade), f.y_ticks.end()) << decade;
  // Linear ticks: evenly spaced round numbers covering the range.
  // Linear ticks: evenly spaced round numbers spanning the (given) range.
  ASSERT_GE(f.x_ticks.size(), 4u);
  EXPECT_EQ(f.x_ticks.front(), 0.0);
  double step = f.x_ticks[1] - f.x_ticks[0];
  for (size_t i = 1; i < f.x_ticks.size(); ++i) EXPECT_NEAR(f.x_ticks[i] - f.x_ticks[i - 1], step, 1e-9);
  EXPECT_LE(f.x_ticks.back(), 90.0);
  EXPECT_GT(f.x_ticks.back() + step, 90.0);
  double mantissa = step / std::pow(10.0, std::floor(std::log10(step)));
  EXPECT_TRUE(mantissa == 1.0 || mantissa == 2.0 || mantissa == 2.5 || mantissa == 5.0) << step;
}

TEST(Plot, AutomaticLinearRangeCoversTheData) {
  LinePlot plot;
  plot.series = {{"s", {-3.2, 7.9}, {0.013, 0.027}}};
  PlotFrame f = LayoutPlot(plot);
  EXPECT_LE(f.x_min, -3.2);
  EXPECT_GE(f.x_max, 7.9);
  EXPECT_LE(f.y_min, 0.013);
  EXPECT_GE(f.y_max, 0.027);
  EXPECT_LT(f.y_max - f.y_min, 0.05);  // widened to ticks, not blown up
}

TEST(Plot, SvgPolylinesFollowTheDataAndBreakAtGaps) {
  LinePlot plot = SamplePlot();
  // A NaN and a non-positive value (on the log axis) break the line.
  plot.series.push_back({"gappy", {0.0, 10.0, 20.0, 30.0, 40.0, 50.0}, {2.0, 3.0, std::nan(""), 4.0, -1.0, 6.0}});
  std::string svg = RenderPlotSvg(plot);
  PlotFrame f = LayoutPlot(plot);
  std::vector<std::string> lines = Polylines(svg);
  ASSERT_EQ(lines.size(), 1u + 1u + 3u);
  // The points of the second series, parsed back, are the mapped data.
  std::istringstream points(lines[1]);
  const PlotSeries& rising = plot.series[1];
  for (size_t i = 0; i < rising.x.size(); ++i) {
    double px, py;
    char comma;
    ASSERT_TRUE(points >> px >> comma >> py);
    EXPECT_NEAR(px, f.PixelX(rising.x[i]), 0.006);
    EXPECT_NEAR(py, f.PixelY(rising.y[i]), 0.006);
  }
  // Runs of the gappy series: (0, 2)-(10, 3), then (30, 4), then (50, 6).
  auto count = [](const std::string& pts) { return std::count(pts.begin(), pts.end(), ',') ; };
  EXPECT_EQ(count(lines[2]), 2);
  EXPECT_EQ(count(lines[3]), 1);
  EXPECT_EQ(count(lines[4]), 1);
  EXPECT_NEAR(std::stod(lines[4]), f.PixelX(50.0), 0.006);
  EXPECT_NE(svg.find("stroke-dasharray"), std::string::npos);
  EXPECT_NE(svg.find(PlotColor(1)), std::string::npos);
}

TEST(Plot, MarkersSitOnThePointsAndLinesCanBeLeftOut) {
  LinePlot plot = SamplePlot();
  PlotSeries dots{"dots", {10.0, 50.0}, {3.0, 30.0}, LineStyle::kSolid, 2, 0.0, 8.0};
  plot.series.push_back(dots);
  std::string svg = RenderPlotSvg(plot);
  PlotFrame f = LayoutPlot(plot);
  EXPECT_EQ(Polylines(svg).size(), 2u);  // the markers-only series draws no line
  std::regex circle("<circle data-series=\"2\" cx=\"([^\"]*)\" cy=\"([^\"]*)\" r=\"([^\"]*)\"");
  std::vector<std::array<double, 2>> centres;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), circle); it != std::sregex_iterator(); ++it) {
    centres.push_back({std::stod((*it)[1]), std::stod((*it)[2])});
    EXPECT_DOUBLE_EQ(std::stod((*it)[3]), 4.0);  // radius: half the marker's diameter
  }
  ASSERT_EQ(centres.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_NEAR(centres[i][0], f.PixelX(dots.x[i]), 0.006);
    EXPECT_NEAR(centres[i][1], f.PixelY(dots.y[i]), 0.006);
  }
  // The raster has the marker's colour at its centre.
  std::vector<unsigned char> pixels = RasterizePlot(plot);
  int x = static_cast<int>(centres[0][0]), y = static_cast<int>(centres[0][1]);
  const unsigned char* p = &pixels[(static_cast<size_t>(y) * plot.width_px + x) * 3];
  unsigned colour = std::stoul(PlotColor(2).substr(1), nullptr, 16);
  EXPECT_NEAR(p[0], (colour >> 16) & 255, 2);
  EXPECT_NEAR(p[1], (colour >> 8) & 255, 2);
  EXPECT_NEAR(p[2], colour & 255, 2);
}

TEST(Plot, SvgEscapesText) {
  std::string svg = RenderPlotSvg(SamplePlot());
  EXPECT_NE(svg.find("m &amp; friends &lt;test&gt;"), std::string::npos);
  EXPECT_EQ(svg.find("<test>"), std::string::npos);
  EXPECT_NE(svg.find("flat at 10"), std::string::npos);
  EXPECT_NE(svg.find("zenith angle (degrees)"), std::string::npos);
  EXPECT_NE(svg.find("skybake test caption"), std::string::npos);
}

TEST(Plot, RejectsMismatchedSeries) {
  LinePlot plot;
  plot.series = {{"bad", {1.0, 2.0}, {1.0}}};
  EXPECT_THROW(LayoutPlot(plot), InternalError);
  plot.series.clear();
  plot.width_px = 10;
  EXPECT_THROW(RenderPlotSvg(plot), InternalError);
}

TEST(Plot, EmptyAndDegeneratePlotsStillRender) {
  LinePlot empty;
  empty.y.log = true;
  EXPECT_NO_THROW(RenderPlotSvg(empty));
  LinePlot constant;
  constant.series = {{"c", {5.0, 5.0}, {3.0, 3.0}}};
  PlotFrame f = LayoutPlot(constant);
  EXPECT_LT(f.x_min, 5.0);
  EXPECT_GT(f.x_max, 5.0);
  EXPECT_TRUE(std::isfinite(f.PixelY(3.0)));
}

class PlotFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("skybake_plot_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  fs::path dir_;
};

TEST_F(PlotFiles, PngShowsTheSeriesWhereTheLayoutPutsThem) {
  LinePlot plot = SamplePlot();
  fs::path png = dir_ / "plot.png";
  StagedFiles staged;
  bool text = WritePlotPng(staged, png, plot);
  staged.Commit();
  OIIO::ImageBuf image(png.string());
  ASSERT_TRUE(image.read()) << image.geterror();
  ASSERT_EQ(image.spec().width, plot.width_px);
  ASSERT_EQ(image.spec().height, plot.height_px);
  PlotFrame f = LayoutPlot(plot);
  auto pixel = [&](double x, double y) {
    float rgb[3];
    image.getpixel(static_cast<int>(x), static_cast<int>(y), rgb, 3);
    return std::array<float, 3>{rgb[0], rgb[1], rgb[2]};
  };
  // The 6-px flat series at y = 10 in palette colour 0 (#4e79a7), away from the legend.
  std::array<float, 3> on_line = pixel(f.PixelX(70.0), f.PixelY(10.0));
  EXPECT_NEAR(on_line[0], 0x4e / 255.0, 0.02);
  EXPECT_NEAR(on_line[1], 0x79 / 255.0, 0.02);
  EXPECT_NEAR(on_line[2], 0xa7 / 255.0, 0.02);
  // Far from every line and grid line: white background.
  std::array<float, 3> empty = pixel(f.PixelX(75.0) + 7, f.PixelY(3.0) + 7);
  EXPECT_GT(empty[0] + empty[1] + empty[2], 2.9);
  // Outside the plot area nothing is drawn except text.
  if (text) {
    // The title is dark text centred above the plot area.
    int dark = 0;
    for (int x = static_cast<int>(f.left); x < f.right; ++x)
      for (int y = 10; y < f.top - 4; ++y) dark += pixel(x, y)[0] < 0.5f;
    EXPECT_GT(dark, 50);
  } else {
    std::cout << "no TrueType font found: PNG text not checked\n";
  }
  // The same frame drawn by RasterizePlot (no text) agrees pixel for pixel on the line.
  std::vector<unsigned char> raster = RasterizePlot(plot);
  size_t at = (static_cast<size_t>(f.PixelY(10.0)) * plot.width_px + static_cast<size_t>(f.PixelX(70.0))) * 3;
  EXPECT_EQ(raster[at], 0x4e);
}

TEST_F(PlotFiles, WritesAreAtomic) {
  fs::path missing = dir_ / "no" / "such" / "dir" / "plot.svg";
  {
    StagedFiles staged;
    EXPECT_THROW(WritePlotSvg(staged, missing, SamplePlot()), IoError);
    EXPECT_THROW(WritePlotPng(staged, dir_ / "no" / "plot.png", SamplePlot()), IoError);
  }
  StagedFiles staged;
  WritePlotSvg(staged, dir_ / "plot.svg", SamplePlot());
  staged.Commit();
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) {
    ++files;
    EXPECT_EQ(entry.path().filename(), "plot.svg");  // no temporary left behind
  }
  EXPECT_EQ(files, 1u);
}

}  // namespace
}  // namespace skybake
