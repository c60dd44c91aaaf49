#include "fit/outputs.h"

#include <cmath>
#include <cstdio>

#include "core/errors.h"
#include "core/file_io.h"
#include "fit/codegen.h"

namespace skybake::fit {

namespace {

const Constituent& Find(const Atmosphere& atmosphere, const std::string& name) {
  for (const Constituent& c : atmosphere.constituents)
    if (c.name == name) return c;
  throw InternalError("constituent '" + name + "' vanished from the atmosphere");
}

// Exact m on a fine zenith grid at the lowest, middle and highest fitted altitude.
SampleGrid PlotSamples(const Atmosphere& atmosphere, const ConstituentFit& fit, const FitOptions& options) {
  std::vector<double> zenith;
  for (int i = 0; i <= 360; ++i) zenith.push_back(0.25 * i);
  double lo = fit.surface.altitude_lo_m, hi = fit.surface.altitude_hi_m;
  std::vector<double> altitudes = hi > lo ? std::vector<double>{lo, 0.5 * (lo + hi), hi} : std::vector<double>{lo};
  return SampleRelativeOpticalPath(atmosphere, Find(atmosphere, fit.name), zenith, altitudes, options.quadrature);
}

double Mu(double zenith_deg) { return zenith_deg >= 90.0 ? 0.0 : std::cos(zenith_deg * 0.017453292519943295); }

std::string AltitudeLabel(double h) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "h = %g m", std::round(h * 10.0) / 10.0);
  return buffer;
}

}  // namespace

LinePlot ComparisonPlot(const Atmosphere& atmosphere, const ConstituentFit& fit, const FitOptions& options,
                        const std::string& caption) {
  SampleGrid grid = PlotSamples(atmosphere, fit, options);
  LinePlot plot;
  plot.title = "Relative optical path of " + fit.name + ": exact, fitted (" + ToString(fit.surface.form) +
               "), Iqbal";
  plot.caption = caption;
  plot.x = {"zenith angle (degrees)", false, 0.0, 90.0};
  plot.y = {"m = slant column / vertical column", true, std::nullopt, std::nullopt};
  for (size_t a = 0; a < grid.altitude_m.size(); ++a) {
    PlotSeries exact{"exact, " + AltitudeLabel(grid.altitude_m[a]), grid.zenith_deg, {}, LineStyle::kSolid,
                     static_cast<int>(a), 2.5};
    PlotSeries fitted{"fitted, " + AltitudeLabel(grid.altitude_m[a]), grid.zenith_deg, {}, LineStyle::kDashed,
                      static_cast<int>(a), 1.5};
    for (size_t z = 0; z < grid.zenith_deg.size(); ++z) {
      exact.y.push_back(grid.At(a, z));
      fitted.y.push_back(fit.surface.RelativeOpticalPath(Mu(grid.zenith_deg[z]), grid.altitude_m[a]));
    }
    plot.series.push_back(std::move(exact));
    plot.series.push_back(std::move(fitted));
  }
  PlotSeries iqbal{"Iqbal (any altitude)", grid.zenith_deg, {}, LineStyle::kDotted, 3, 2.0};
  for (double z : grid.zenith_deg) iqbal.y.push_back(IqbalRelativeOpticalPath(Mu(z)));
  plot.series.push_back(std::move(iqbal));
  return plot;
}

LinePlot ErrorPlot(const Atmosphere& atmosphere, const ConstituentFit& fit, const FitOptions& options,
                   const std::string& caption) {
  SampleGrid grid = PlotSamples(atmosphere, fit, options);
  LinePlot plot;
  plot.title = "Relative error of the fitted (" + std::string(ToString(fit.surface.form)) + ") and Iqbal m, " +
               fit.name;
  plot.caption = caption;
  plot.x = {"zenith angle (degrees)", false, 0.0, 90.0};
  // Below 1e-7 lies quadrature and rounding noise (the fit itself is ~1e-4).
  plot.y = {"|m / m_exact - 1|", true, 1e-7, std::nullopt};
  for (size_t a = 0; a < grid.altitude_m.size(); ++a) {
    PlotSeries fitted{"fitted, " + AltitudeLabel(grid.altitude_m[a]), grid.zenith_deg, {}, LineStyle::kSolid,
                      static_cast<int>(a), 1.5};
    PlotSeries iqbal{"Iqbal, " + AltitudeLabel(grid.altitude_m[a]), grid.zenith_deg, {}, LineStyle::kDotted,
                     static_cast<int>(a), 1.5};
    for (size_t z = 0; z < grid.zenith_deg.size(); ++z) {
      double exact = grid.At(a, z), mu = Mu(grid.zenith_deg[z]);
      // Zero errors (the zenith, where m = 1 exactly) have no place on a log axis and break the line there.
      fitted.y.push_back(std::abs(fit.surface.RelativeOpticalPath(mu, grid.altitude_m[a]) / exact - 1.0));
      iqbal.y.push_back(std::abs(IqbalRelativeOpticalPath(mu) / exact - 1.0));
    }
    plot.series.push_back(std::move(fitted));
    plot.series.push_back(std::move(iqbal));
  }
  return plot;
}

OutputSummary Summarize(const Atmosphere& atmosphere, const FitSet& set, const DomeOptions& dome,
                        const Provenance& provenance, const std::vector<std::string>& files) {
  OutputSummary summary;
  summary.files = files;
  std::string why_not;
  summary.mesh = BuildDomeMesh(atmosphere, set, dome, &why_not);
  if (!summary.mesh) {
    summary.mesh_note = "no sky dome mesh: " + why_not;
  } else if (summary.mesh->haze_name.empty()) {
    summary.mesh_note = set.haze < 0 ? "sky dome without haze ratio: no fitted non-Rayleigh scattering constituent"
                                     : "sky dome without haze ratio: the haze density is zero at the dome altitude";
  }
  ReportContext context{provenance, files, summary.mesh ? &*summary.mesh : nullptr, summary.mesh_note};
  summary.report_json = FitReportJson(set, context);
  return summary;
}

OutputSummary WriteFitOutputs(const Atmosphere& atmosphere, const FitSet& set, const OutputOptions& options) {
  EnsureWritableDirectory(options.directory);
  std::string line = options.provenance.OneLine();
  std::vector<std::string> files;
  // One set (core/file_io.h): an interrupt or a failure leaves the
  // folder's earlier files as they were.
  StagedFiles staged;
  auto write = [&](const std::string& name, const std::string& text) {
    staged.Write(options.directory / name, text);
    files.push_back(name);
  };
  write("sky_dome_fit.glsl", GenerateGlsl(set, line));
  write("sky_dome_fit.h", GenerateCppTwin(set, line));

  std::string why_not;
  std::optional<DomeMesh> mesh = BuildDomeMesh(atmosphere, set, options.dome, &why_not);
  if (mesh) {
    write("sky_dome.obj", ToObj(*mesh, line));
    write("sky_dome.gltf", ToGltf(*mesh, line));
  }
  bool plot_text = true;
  for (const ConstituentFit& fit : set.constituents) {
    if (!fit.fitted) continue;
    for (auto [prefix, plot] : {std::pair{"fit_", ComparisonPlot(atmosphere, fit, set.options, line)},
                                std::pair{"fit_error_", ErrorPlot(atmosphere, fit, set.options, line)}}) {
      std::string base = prefix + fit.identifier;
      WritePlotSvg(staged, options.directory / (base + ".svg"), plot);
      files.push_back(base + ".svg");
      plot_text = WritePlotPng(staged, options.directory / (base + ".png"), plot) && plot_text;
      files.push_back(base + ".png");
    }
  }
  // The report last: it lists the files above, and its presence means they are complete.
  files.push_back("fit.json");
  OutputSummary summary = Summarize(atmosphere, set, options.dome, options.provenance, files);
  staged.Write(options.directory / "fit.json", summary.report_json);
  staged.Commit();
  summary.plot_text = plot_text;
  return summary;
}

}  // namespace skybake::fit
