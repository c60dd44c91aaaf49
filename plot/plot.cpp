#include "plot/plot.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/errors.h"
#include "core/file_io.h"
#include "plot/image_library.h"

namespace skybake {

namespace {

// Layout in pixels; the SVG uses the same numbers so both files agree.
constexpr double kMarginLeft = 80, kMarginRight = 24, kMarginTop = 44, kMarginBottom = 72;
constexpr double kTickLabelSize = 12, kAxisLabelSize = 14, kTitleSize = 16, kCaptionSize = 10;
constexpr double kLegendRow = 18, kLegendSample = 28, kLegendCharWidth = 7, kLegendPad = 8;

// Tableau 10: distinguishable and colour-blind tolerant.
constexpr std::array<unsigned, 10> kPalette = {0x4e79a7, 0xf28e2b, 0xe15759, 0x76b7b2, 0x59a14f,
                                               0xedc948, 0xb07aa1, 0xff9da7, 0x9c755f, 0xbab0ac};

int ColorIndex(const LinePlot& plot, size_t series) {
  int c = plot.series[series].color;
  return c >= 0 ? c : static_cast<int>(series);
}

std::array<float, 3> Rgb(int index) {
  unsigned c = kPalette[static_cast<size_t>(index) % kPalette.size()];
  return {((c >> 16) & 255) / 255.0f, ((c >> 8) & 255) / 255.0f, (c & 255) / 255.0f};
}

bool Usable(double v, bool log) { return std::isfinite(v) && (!log || v > 0.0); }

std::string FormatTick(double v, bool log) {
  char buffer[32];
  if (!log && std::abs(v) < 1e-12) v = 0.0;  // -0 and rounding residue of linear steps
  std::snprintf(buffer, sizeof(buffer), "%g", v);
  return buffer;
}

// Ticks and the widened range for one axis.
void AxisTicks(const PlotAxis& axis, double data_lo, double data_hi, double* lo, double* hi,
               std::vector<double>* ticks) {
  bool have_data = data_lo <= data_hi;
  if (axis.log) {
    double a = axis.min && *axis.min > 0 ? *axis.min : have_data ? data_lo : 1.0;
    double b = axis.max && *axis.max > 0 ? *axis.max : have_data ? data_hi : 10.0;
    if (!(b > a)) {
      a /= std::sqrt(10.0);
      b = a * 10.0;
    }
    double d0 = std::floor(std::log10(a) + 1e-9), d1 = std::ceil(std::log10(b) - 1e-9);
    *lo = axis.min ? a : std::pow(10.0, d0);
    *hi = axis.max ? b : std::pow(10.0, d1);
    bool few = std::log10(*hi / *lo) < 2.0;  // label 2 and 5 too when there are few decades
    double stride = std::max(1.0, std::ceil((d1 - d0) / 8.0));  // at most ~9 labelled decades
    for (double d = d0; d <= d1; d += stride) {
      for (double m : {1.0, 2.0, 5.0}) {
        if (m != 1.0 && !few) continue;
        double v = m * std::pow(10.0, d);
        if (v >= *lo * (1 - 1e-9) && v <= *hi * (1 + 1e-9)) ticks->push_back(v);
      }
    }
    return;
  }
  double a = axis.min ? *axis.min : have_data ? data_lo : 0.0;
  double b = axis.max ? *axis.max : have_data ? data_hi : 1.0;
  if (!(b > a)) {  // one value: centre it
    double half = 0.5 * std::max(1.0, std::abs(a));
    a -= half;
    b += half;
  }
  double raw = (b - a) / 6.0;
  double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double step = magnitude;
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    step = m * magnitude;
    if (step >= raw) break;
  }
  *lo = axis.min ? a : std::floor(a / step + 1e-9) * step;
  *hi = axis.max ? b : std::ceil(b / step - 1e-9) * step;
  for (double v = std::ceil(*lo / step - 1e-9) * step; v <= *hi + 1e-9 * step; v += step) ticks->push_back(v);
}

// Contiguous runs of drawable points of one series, in pixels.
std::vector<std::vector<std::array<double, 2>>> PixelRuns(const PlotFrame& f, const PlotSeries& s) {
  std::vector<std::vector<std::array<double, 2>>> runs(1);
  for (size_t i = 0; i < s.x.size(); ++i) {
    if (Usable(s.x[i], f.x_log) && Usable(s.y[i], f.y_log)) {
      runs.back().push_back({f.PixelX(s.x[i]), f.PixelY(s.y[i])});
    } else if (!runs.back().empty()) {
      runs.emplace_back();
    }
  }
  if (runs.back().empty()) runs.pop_back();
  return runs;
}

std::vector<double> DashPattern(LineStyle style, double width) {
  if (style == LineStyle::kDashed) return {6 * width, 4 * width};
  if (style == LineStyle::kDotted) return {1.2 * width, 2.5 * width};
  return {};
}

struct LegendBox {
  double x, y, width, height;
  std::vector<size_t> entries;  // series indices
};

// The legend goes in the corner of the plot area that hides the fewest points.
LegendBox PlaceLegend(const LinePlot& plot, const PlotFrame& f) {
  LegendBox box{};
  size_t longest = 0;
  for (size_t i = 0; i < plot.series.size(); ++i) {
    if (plot.series[i].name.empty()) continue;
    box.entries.push_back(i);
    longest = std::max(longest, plot.series[i].name.size());
  }
  if (box.entries.empty()) return box;
  box.width = 3 * kLegendPad + kLegendSample + kLegendCharWidth * longest;
  box.height = 2 * kLegendPad + kLegendRow * box.entries.size() - 4;
  size_t best_hidden = SIZE_MAX;
  for (int corner = 0; corner < 4; ++corner) {
    double x = corner % 2 == 0 ? f.left + 10 : f.right - 10 - box.width;
    double y = corner < 2 ? f.top + 10 : f.bottom - 10 - box.height;
    size_t hidden = 0;
    for (const PlotSeries& s : plot.series)
      for (const auto& run : PixelRuns(f, s))
        for (const auto& p : run) hidden += p[0] >= x && p[0] <= x + box.width && p[1] >= y && p[1] <= y + box.height;
    if (hidden < best_hidden) {
      best_hidden = hidden;
      box.x = x;
      box.y = y;
    }
  }
  return box;
}

std::string Caption(const LinePlot& plot) {
  // About 5.5 px per character at 10 px; cut rather than run off the image.
  size_t fits = static_cast<size_t>(std::max(10.0, (plot.width_px - 20) / 5.5));
  if (plot.caption.size() <= fits) return plot.caption;
  return plot.caption.substr(0, fits - 3) + "...";
}

std::string XmlEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default:
        // Control characters are not allowed in XML 1.0.
        if (static_cast<unsigned char>(c) >= 0x20 || c == '\t') out += c;
    }
  }
  return out;
}

std::string Num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.2f", v);
  return buffer;
}

// ---- raster ----

struct Canvas {
  int width, height;
  std::vector<float> rgb;
  Canvas(int w, int h) : width(w), height(h), rgb(static_cast<size_t>(w) * h * 3, 1.0f) {}
  void Blend(int x, int y, const std::array<float, 3>& color, double alpha) {
    if (x < 0 || y < 0 || x >= width || y >= height || alpha <= 0) return;
    float a = static_cast<float>(std::min(1.0, alpha));
    float* p = &rgb[(static_cast<size_t>(y) * width + x) * 3];
    for (int k = 0; k < 3; ++k) p[k] = p[k] * (1 - a) + color[k] * a;
  }
  // Anti-aliased segment of the given width, clipped to `clip` (x0, y0, x1, y1).
  void Segment(double ax, double ay, double bx, double by, double w, const std::array<float, 3>& color,
               const std::array<double, 4>& clip) {
    double r = 0.5 * w;
    int x0 = static_cast<int>(std::floor(std::max(std::min(ax, bx) - r - 1, clip[0])));
    int x1 = static_cast<int>(std::ceil(std::min(std::max(ax, bx) + r + 1, clip[2])));
    int y0 = static_cast<int>(std::floor(std::max(std::min(ay, by) - r - 1, clip[1])));
    int y1 = static_cast<int>(std::ceil(std::min(std::max(ay, by) + r + 1, clip[3])));
    double dx = bx - ax, dy = by - ay, len2 = dx * dx + dy * dy;
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        double px = x + 0.5, py = y + 0.5;
        if (px < clip[0] || px > clip[2] || py < clip[1] || py > clip[3]) continue;
        double t = len2 > 0 ? std::clamp(((px - ax) * dx + (py - ay) * dy) / len2, 0.0, 1.0) : 0.0;
        double ex = px - (ax + t * dx), ey = py - (ay + t * dy);
        double d = std::sqrt(ex * ex + ey * ey);
        Blend(x, y, color, r + 0.5 - d);
      }
    }
  }
  void Polyline(const std::vector<std::array<double, 2>>& pts, double w, LineStyle style,
                const std::array<float, 3>& color, const std::array<double, 4>& clip) {
    std::vector<double> dash = DashPattern(style, w);
    if (pts.size() == 1) {
      Segment(pts[0][0], pts[0][1], pts[0][0], pts[0][1], w, color, clip);
      return;
    }
    size_t phase = 0;
    double left = dash.empty() ? 0 : dash[0];  // length left in the current dash or gap
    for (size_t i = 0; i + 1 < pts.size(); ++i) {
      double ax = pts[i][0], ay = pts[i][1], bx = pts[i + 1][0], by = pts[i + 1][1];
      double len = std::hypot(bx - ax, by - ay);
      if (dash.empty()) {
        Segment(ax, ay, bx, by, w, color, clip);
        continue;
      }
      double s = 0;
      while (s < len) {
        double step = std::min(left, len - s);
        if (phase % 2 == 0) {
          double t0 = s / len, t1 = (s + step) / len;
          Segment(ax + t0 * (bx - ax), ay + t0 * (by - ay), ax + t1 * (bx - ax), ay + t1 * (by - ay), w, color, clip);
        }
        s += step;
        left -= step;
        if (left <= 1e-9) {
          phase = (phase + 1) % dash.size();
          left = dash[phase];
        }
      }
    }
  }
};

Canvas Rasterize(const LinePlot& plot, const PlotFrame& f) {
  Canvas canvas(plot.width_px, plot.height_px);
  std::array<double, 4> everywhere = {0, 0, double(plot.width_px), double(plot.height_px)};
  std::array<double, 4> area = {f.left, f.top, f.right, f.bottom};
  const std::array<float, 3> grid = {0.88f, 0.88f, 0.88f}, axis = {0.2f, 0.2f, 0.2f};
  for (double t : f.x_ticks) {
    double x = f.PixelX(t);
    canvas.Segment(x, f.top, x, f.bottom, 1.0, grid, everywhere);
    canvas.Segment(x, f.bottom, x, f.bottom + 5, 1.0, axis, everywhere);
  }
  for (double t : f.y_ticks) {
    double y = f.PixelY(t);
    canvas.Segment(f.left, y, f.right, y, 1.0, grid, everywhere);
    canvas.Segment(f.left - 5, y, f.left, y, 1.0, axis, everywhere);
  }
  for (size_t i = 0; i < plot.series.size(); ++i) {
    const PlotSeries& s = plot.series[i];
    for (const auto& run : PixelRuns(f, s)) {
      if (s.width_px > 0) canvas.Polyline(run, s.width_px, s.style, Rgb(ColorIndex(plot, i)), area);
      if (s.marker_px > 0)
        for (const auto& p : run) canvas.Segment(p[0], p[1], p[0], p[1], s.marker_px, Rgb(ColorIndex(plot, i)), area);
    }
  }
  // Frame last, so curves along the edges do not hide it.
  canvas.Segment(f.left, f.top, f.right, f.top, 1.0, axis, everywhere);
  canvas.Segment(f.left, f.bottom, f.right, f.bottom, 1.0, axis, everywhere);
  canvas.Segment(f.left, f.top, f.left, f.bottom, 1.0, axis, everywhere);
  canvas.Segment(f.right, f.top, f.right, f.bottom, 1.0, axis, everywhere);
  LegendBox legend = PlaceLegend(plot, f);
  if (!legend.entries.empty()) {
    for (int y = static_cast<int>(legend.y); y < legend.y + legend.height; ++y)
      for (int x = static_cast<int>(legend.x); x < legend.x + legend.width; ++x)
        canvas.Blend(x, y, {1, 1, 1}, 0.9);
    double bx0 = legend.x, by0 = legend.y, bx1 = legend.x + legend.width, by1 = legend.y + legend.height;
    for (auto [ax, ay, cx, cy] : {std::array<double, 4>{bx0, by0, bx1, by0}, {bx1, by0, bx1, by1},
                                  {bx1, by1, bx0, by1}, {bx0, by1, bx0, by0}})
      canvas.Segment(ax, ay, cx, cy, 1.0, {0.7f, 0.7f, 0.7f}, everywhere);
    for (size_t k = 0; k < legend.entries.size(); ++k) {
      const PlotSeries& s = plot.series[legend.entries[k]];
      double y = legend.y + kLegendPad + kLegendRow * (k + 0.5) - 2;
      if (s.width_px > 0)
        canvas.Polyline({{legend.x + kLegendPad, y}, {legend.x + kLegendPad + kLegendSample, y}}, s.width_px,
                        s.style, Rgb(ColorIndex(plot, legend.entries[k])), everywhere);
      if (s.marker_px > 0) {
        double x = legend.x + kLegendPad + 0.5 * kLegendSample;
        canvas.Segment(x, y, x, y, s.marker_px, Rgb(ColorIndex(plot, legend.entries[k])), everywhere);
      }
    }
  }
  return canvas;
}

}  // namespace

double PlotFrame::PixelX(double x) const {
  double u = x_log ? std::log(x / x_min) / std::log(x_max / x_min) : (x - x_min) / (x_max - x_min);
  return left + u * (right - left);
}

double PlotFrame::PixelY(double y) const {
  double u = y_log ? std::log(y / y_min) / std::log(y_max / y_min) : (y - y_min) / (y_max - y_min);
  return bottom - u * (bottom - top);
}

PlotFrame LayoutPlot(const LinePlot& plot) {
  if (plot.width_px < 160 || plot.height_px < 160 || plot.width_px > 16384 || plot.height_px > 16384)
    throw InternalError("plot size " + std::to_string(plot.width_px) + "x" + std::to_string(plot.height_px) +
                        " is outside 160..16384 pixels");
  PlotFrame f;
  f.x_log = plot.x.log;
  f.y_log = plot.y.log;
  double xlo = HUGE_VAL, xhi = -HUGE_VAL, ylo = HUGE_VAL, yhi = -HUGE_VAL;
  for (const PlotSeries& s : plot.series) {
    if (s.x.size() != s.y.size())
      throw InternalError("plot series '" + s.name + "' has " + std::to_string(s.x.size()) + " x and " +
                          std::to_string(s.y.size()) + " y values");
    for (size_t i = 0; i < s.x.size(); ++i) {
      if (!Usable(s.x[i], f.x_log) || !Usable(s.y[i], f.y_log)) continue;
      xlo = std::min(xlo, s.x[i]);
      xhi = std::max(xhi, s.x[i]);
      ylo = std::min(ylo, s.y[i]);
      yhi = std::max(yhi, s.y[i]);
    }
  }
  AxisTicks(plot.x, xlo, xhi, &f.x_min, &f.x_max, &f.x_ticks);
  AxisTicks(plot.y, ylo, yhi, &f.y_min, &f.y_max, &f.y_ticks);
  f.left = kMarginLeft;
  f.right = plot.width_px - kMarginRight;
  f.top = kMarginTop;
  f.bottom = plot.height_px - kMarginBottom;
  return f;
}

std::string PlotColor(int index) {
  char buffer[8];
  std::snprintf(buffer, sizeof(buffer), "#%06x", kPalette[static_cast<size_t>(std::max(0, index)) % kPalette.size()]);
  return buffer;
}

std::string RenderPlotSvg(const LinePlot& plot) {
  PlotFrame f = LayoutPlot(plot);
  std::ostringstream o;
  o << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << plot.width_px << "\" height=\"" << plot.height_px
    << "\" viewBox=\"0 0 " << plot.width_px << " " << plot.height_px
    << "\" font-family=\"DejaVu Sans, Liberation Sans, Arial, sans-serif\">\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << "<defs><clipPath id=\"plot-area\"><rect x=\"" << Num(f.left) << "\" y=\"" << Num(f.top) << "\" width=\""
    << Num(f.right - f.left) << "\" height=\"" << Num(f.bottom - f.top) << "\"/></clipPath></defs>\n";
  o << "<g class=\"grid\" stroke=\"#e0e0e0\" stroke-width=\"1\">\n";
  for (double t : f.x_ticks)
    o << "<line x1=\"" << Num(f.PixelX(t)) << "\" y1=\"" << Num(f.top) << "\" x2=\"" << Num(f.PixelX(t))
      << "\" y2=\"" << Num(f.bottom) << "\"/>\n";
  for (double t : f.y_ticks)
    o << "<line x1=\"" << Num(f.left) << "\" y1=\"" << Num(f.PixelY(t)) << "\" x2=\"" << Num(f.right) << "\" y2=\""
      << Num(f.PixelY(t)) << "\"/>\n";
  o << "</g>\n<g class=\"ticks\" font-size=\"" << kTickLabelSize << "\" fill=\"#333\">\n";
  for (double t : f.x_ticks)
    o << "<text x=\"" << Num(f.PixelX(t)) << "\" y=\"" << Num(f.bottom + 20) << "\" text-anchor=\"middle\">"
      << FormatTick(t, f.x_log) << "</text>\n";
  for (double t : f.y_ticks)
    o << "<text x=\"" << Num(f.left - 8) << "\" y=\"" << Num(f.PixelY(t) + 4) << "\" text-anchor=\"end\">"
      << FormatTick(t, f.y_log) << "</text>\n";
  o << "</g>\n<g class=\"series\" fill=\"none\" clip-path=\"url(#plot-area)\" stroke-linejoin=\"round\">\n";
  for (size_t i = 0; i < plot.series.size(); ++i) {
    const PlotSeries& s = plot.series[i];
    std::string dash;
    for (double d : DashPattern(s.style, s.width_px)) dash += (dash.empty() ? "" : ",") + Num(d);
    for (const auto& run : PixelRuns(f, s)) {
      if (s.marker_px > 0) {
        for (const auto& p : run)
          o << "<circle data-series=\"" << i << "\" cx=\"" << Num(p[0]) << "\" cy=\"" << Num(p[1]) << "\" r=\""
            << Num(0.5 * s.marker_px) << "\" fill=\"" << PlotColor(ColorIndex(plot, i)) << "\" stroke=\"none\"/>\n";
      }
      if (s.width_px <= 0) continue;
      o << "<polyline data-series=\"" << i << "\" stroke=\"" << PlotColor(ColorIndex(plot, i)) << "\" stroke-width=\""
        << Num(s.width_px) << "\"" << (dash.empty() ? "" : " stroke-dasharray=\"" + dash + "\"") << " points=\"";
      for (size_t k = 0; k < run.size(); ++k) o << (k ? " " : "") << Num(run[k][0]) << "," << Num(run[k][1]);
      o << "\"/>\n";
    }
  }
  o << "</g>\n<rect class=\"frame\" x=\"" << Num(f.left) << "\" y=\"" << Num(f.top) << "\" width=\""
    << Num(f.right - f.left) << "\" height=\"" << Num(f.bottom - f.top)
    << "\" fill=\"none\" stroke=\"#333\" stroke-width=\"1\"/>\n";
  LegendBox legend = PlaceLegend(plot, f);
  if (!legend.entries.empty()) {
    o << "<g class=\"legend\" font-size=\"" << kTickLabelSize << "\">\n<rect x=\"" << Num(legend.x) << "\" y=\""
      << Num(legend.y) << "\" width=\"" << Num(legend.width) << "\" height=\"" << Num(legend.height)
      << "\" fill=\"white\" fill-opacity=\"0.9\" stroke=\"#b3b3b3\"/>\n";
    for (size_t k = 0; k < legend.entries.size(); ++k) {
      const PlotSeries& s = plot.series[legend.entries[k]];
      double y = legend.y + kLegendPad + kLegendRow * (k + 0.5) - 2;
      std::string dash;
      for (double d : DashPattern(s.style, s.width_px)) dash += (dash.empty() ? "" : ",") + Num(d);
      if (s.width_px > 0)
        o << "<line x1=\"" << Num(legend.x + kLegendPad) << "\" y1=\"" << Num(y) << "\" x2=\""
          << Num(legend.x + kLegendPad + kLegendSample) << "\" y2=\"" << Num(y) << "\" stroke=\""
          << PlotColor(ColorIndex(plot, legend.entries[k])) << "\" stroke-width=\"" << Num(s.width_px) << "\""
          << (dash.empty() ? "" : " stroke-dasharray=\"" + dash + "\"") << "/>\n";
      if (s.marker_px > 0)
        o << "<circle cx=\"" << Num(legend.x + kLegendPad + 0.5 * kLegendSample) << "\" cy=\"" << Num(y)
          << "\" r=\"" << Num(0.5 * s.marker_px) << "\" fill=\"" << PlotColor(ColorIndex(plot, legend.entries[k]))
          << "\"/>\n";
      o << "<text x=\"" << Num(legend.x + 2 * kLegendPad + kLegendSample) << "\" y=\"" << Num(y + 4) << "\">"
        << XmlEscape(s.name) << "</text>\n";
    }
    o << "</g>\n";
  }
  o << "<text class=\"title\" x=\"" << Num(0.5 * (f.left + f.right)) << "\" y=\"" << Num(f.top - 16)
    << "\" font-size=\"" << kTitleSize << "\" text-anchor=\"middle\">" << XmlEscape(plot.title) << "</text>\n"
    << "<text class=\"x-label\" x=\"" << Num(0.5 * (f.left + f.right)) << "\" y=\"" << Num(f.bottom + 42)
    << "\" font-size=\"" << kAxisLabelSize << "\" text-anchor=\"middle\">" << XmlEscape(plot.x.label) << "</text>\n"
    << "<text class=\"y-label\" transform=\"translate(18," << Num(0.5 * (f.top + f.bottom))
    << ") rotate(-90)\" font-size=\"" << kAxisLabelSize << "\" text-anchor=\"middle\">" << XmlEscape(plot.y.label)
    << "</text>\n"
    << "<text class=\"caption\" x=\"10\" y=\"" << plot.height_px - 8 << "\" font-size=\"" << kCaptionSize
    << "\" fill=\"#666\">" << XmlEscape(Caption(plot)) << "</text>\n"
    << "</svg>\n";
  return o.str();
}

void WritePlotSvg(StagedFiles& files, const std::filesystem::path& path, const LinePlot& plot) {
  files.Write(path, RenderPlotSvg(plot));
}

std::vector<unsigned char> RasterizePlot(const LinePlot& plot) {
  PlotFrame f = LayoutPlot(plot);
  Canvas canvas = Rasterize(plot, f);
  std::vector<unsigned char> pixels(canvas.rgb.size());
  for (size_t i = 0; i < pixels.size(); ++i)
    pixels[i] = static_cast<unsigned char>(std::lround(std::clamp(canvas.rgb[i], 0.0f, 1.0f) * 255.0f));
  return pixels;
}

void WriteSrgbPng(StagedFiles& files, const std::filesystem::path& path, int width, int height,
                  const unsigned char* rgb, const std::vector<std::pair<std::string, std::string>>& text) {
  const image_module::Functions& images = ImageModule();
  files.Write(path, [&](const std::filesystem::path& temp) {
    ThrowIfImageError(path, images.write_srgb_png(temp.string(), width, height, rgb, text));
  });
}

bool WritePlotPng(StagedFiles& files, const std::filesystem::path& path, const LinePlot& plot) {
  using image_module::AlignX;
  const image_module::Functions& images = ImageModule();
  PlotFrame f = LayoutPlot(plot);
  std::vector<unsigned char> pixels = RasterizePlot(plot);
  const image_module::Rgb8Canvas canvas{plot.width_px, plot.height_px, pixels.data()};

  const std::string font = images.find_font();
  if (!font.empty()) {
    const float ink[3] = {0.2f, 0.2f, 0.2f}, grey[3] = {0.4f, 0.4f, 0.4f};
    auto text = [&](double x, double y, const std::string& s, double size, AlignX ax, const float* color = nullptr) {
      if (s.empty()) return;
      images.draw_text(canvas, static_cast<int>(std::lround(x)), static_cast<int>(std::lround(y)), s,
                       static_cast<int>(size), font, color ? color : ink, ax);
    };
    for (double t : f.x_ticks) text(f.PixelX(t), f.bottom + 20, FormatTick(t, f.x_log), kTickLabelSize, AlignX::kCenter);
    for (double t : f.y_ticks) text(f.left - 8, f.PixelY(t) + 4, FormatTick(t, f.y_log), kTickLabelSize, AlignX::kRight);
    text(0.5 * (f.left + f.right), f.top - 16, plot.title, kTitleSize, AlignX::kCenter);
    text(0.5 * (f.left + f.right), f.bottom + 42, plot.x.label, kAxisLabelSize, AlignX::kCenter);
    text(10, plot.height_px - 8, Caption(plot), kCaptionSize, AlignX::kLeft, grey);
    LegendBox legend = PlaceLegend(plot, f);
    for (size_t k = 0; k < legend.entries.size(); ++k) {
      double y = legend.y + kLegendPad + kLegendRow * (k + 0.5) - 2;
      text(legend.x + 2 * kLegendPad + kLegendSample, y + 4, plot.series[legend.entries[k]].name, kTickLabelSize,
           AlignX::kLeft);
    }
    int box[4];
    if (!plot.y.label.empty() && images.text_box(plot.y.label, static_cast<int>(kAxisLabelSize), font, box)) {
      // Drawn horizontally on white, turned a quarter to read bottom to top,
      // and copied into the left margin.
      const int w = box[2] - box[0] + 4, h = box[3] - box[1] + 4;
      std::vector<unsigned char> label(std::size_t(3) * w * h, 255);
      images.draw_text({w, h, label.data()}, 2, 2 - box[1], plot.y.label, static_cast<int>(kAxisLabelSize), font,
                       ink, AlignX::kLeft);
      // Turned: h wide, w high; its pixel (i, j) is the label's (w - 1 - j, i).
      const int x0 = std::max(0, 18 - h / 2);
      const int y0 = std::max(0, static_cast<int>(0.5 * (f.top + f.bottom)) - w / 2);
      for (int j = 0; j < w && y0 + j < plot.height_px; ++j) {
        for (int i = 0; i < h && x0 + i < plot.width_px; ++i) {
          const unsigned char* from = &label[3 * (std::size_t(i) * w + (w - 1 - j))];
          std::copy(from, from + 3, &pixels[3 * (std::size_t(y0 + j) * plot.width_px + (x0 + i))]);
        }
      }
    }
  }

  // The caption (who made the plot) also goes into the PNG's text chunks.
  std::vector<std::pair<std::string, std::string>> text;
  if (!plot.caption.empty()) text.push_back({"ImageDescription", plot.caption});
  if (!plot.title.empty()) text.push_back({"DocumentName", plot.title});
  WriteSrgbPng(files, path, plot.width_px, plot.height_px, pixels.data(), text);
  return !font.empty();
}

}  // namespace skybake
