// Line plots of named (x, y) series as SVG and PNG, for error tables, fit
// comparisons and convergence studies. Both renderers share one layout
// (LayoutPlot), so a point lands on the same pixel in either file.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/file_io.h"

namespace skybake {

enum class LineStyle { kSolid, kDashed, kDotted };

struct PlotSeries {
  std::string name;          // legend entry; empty: left out of the legend
  std::vector<double> x, y;  // equal lengths; a non-finite point, or one <= 0 on a log axis, breaks the line
  LineStyle style = LineStyle::kSolid;
  int color = -1;            // palette index; -1: the series' position in the plot
  double width_px = 2.0;     // line width; 0: no line (markers only)
  double marker_px = 0.0;    // diameter of a dot drawn at every point; 0: none
};

struct PlotAxis {
  std::string label;
  bool log = false;
  std::optional<double> min, max;  // default: the data range, widened to whole ticks
};

struct LinePlot {
  std::string title;
  std::string caption;  // small print under the plot, e.g. the command line that made it
  PlotAxis x, y;
  std::vector<PlotSeries> series;
  int width_px = 900;
  int height_px = 600;
};

// Data-to-pixel mapping; pixel y grows downward.
struct PlotFrame {
  double left = 0, top = 0, right = 0, bottom = 0;  // plot area, pixels
  double x_min = 0, x_max = 1, y_min = 0, y_max = 1;
  bool x_log = false, y_log = false;
  std::vector<double> x_ticks, y_ticks;  // labelled ticks, data units
  double PixelX(double x) const;
  double PixelY(double y) const;
};

// Throws InternalError for series with x and y of different lengths or a
// size outside 160..16384 pixels; the caller built the plot.
PlotFrame LayoutPlot(const LinePlot& plot);

// Palette colour `index` (wraps) as "#rrggbb".
std::string PlotColor(int index);

std::string RenderPlotSvg(const LinePlot& plot);
// Staged into `files` (core/file_io.h), which the caller commits.
void WritePlotSvg(StagedFiles& files, const std::filesystem::path& path, const LinePlot& plot);

// Every PNG skybake writes (plots, render previews) goes through here: 8-bit
// RGB pixels, row-major from the top, already encoded with the sRGB transfer
// function, staged into `files` (core/file_io.h) with an sRGB chunk (and the gAMA and cHRM
// chunks the PNG specification pairs with it), so viewers need not guess
// the colour space, and `text` as text chunks. The pixels are stored as
// given. IoError on failure.
void WriteSrgbPng(StagedFiles& files, const std::filesystem::path& path, int width, int height,
                  const unsigned char* rgb, const std::vector<std::pair<std::string, std::string>>& text);

// RGB pixels, row-major from the top, 8 bits per channel, without text.
std::vector<unsigned char> RasterizePlot(const LinePlot& plot);
// PNG through OpenImageIO, with text in the first TrueType font found of
// DejaVu Sans, Liberation Sans, FreeSans. Returns false if none was found:
// the PNG is then written without text (the SVG always has it).
bool WritePlotPng(StagedFiles& files, const std::filesystem::path& path, const LinePlot& plot);

}  // namespace skybake
