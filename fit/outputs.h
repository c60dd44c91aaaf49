// Writes the fit's files into the output directory, each atomically:
//   fit.json             the report (report.h)
//   sky_dome_fit.glsl    one GLSL function per fitted constituent (codegen.h)
//   sky_dome_fit.h       its C++ twin
//   sky_dome.obj / .gltf the dome mesh (dome_mesh.h), when there is an air constituent
//   fit_<id>.svg / .png  exact vs fitted vs Iqbal at three altitudes, per constituent
//   fit_error_<id>.svg / .png  their relative errors
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bake/atmosphere.h"
#include "fit/dome_mesh.h"
#include "fit/report.h"
#include "fit/sky_dome_fit.h"
#include "plot/plot.h"

namespace skybake::fit {

struct OutputOptions {
  std::filesystem::path directory;
  DomeOptions dome;
  Provenance provenance;
};

struct OutputSummary {
  std::vector<std::string> files;  // names inside the directory, in writing order
  std::optional<DomeMesh> mesh;
  std::string mesh_note;           // why there is no mesh, or why it has no haze ratio
  bool plot_text = true;           // false: no font was found for the PNG labels
  std::string report_json;         // the fit.json text
};

// The plots of one fitted constituent: relative optical path, and relative error.
LinePlot ComparisonPlot(const Atmosphere& atmosphere, const ConstituentFit& fit, const FitOptions& options,
                        const std::string& caption);
LinePlot ErrorPlot(const Atmosphere& atmosphere, const ConstituentFit& fit, const FitOptions& options,
                   const std::string& caption);

// The mesh and the report without writing anything (for --json alone).
OutputSummary Summarize(const Atmosphere& atmosphere, const FitSet& set, const DomeOptions& dome,
                        const Provenance& provenance, const std::vector<std::string>& files);

OutputSummary WriteFitOutputs(const Atmosphere& atmosphere, const FitSet& set, const OutputOptions& options);

}  // namespace skybake::fit
