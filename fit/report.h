// The fit report: fit.json (machine-readable, also printed by --json) and the
// human-readable error table printed on stderr.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "fit/dome_mesh.h"
#include "fit/sky_dome_fit.h"

namespace skybake::fit {

// What made an output: recorded in every file the fit writes.
struct Provenance {
  std::string command_line;
  std::string version;  // skybake version
  std::string OneLine() const;  // "skybake VERSION: COMMAND LINE"
};

struct ReportContext {
  Provenance provenance;
  std::vector<std::string> outputs;  // file names written in the output directory
  const DomeMesh* mesh = nullptr;    // null: no mesh, see mesh_note
  std::string mesh_note;
};

// fit.json; `context.outputs` lists the files written beside it.
std::string FitReportJson(const FitSet& set, const ReportContext& context);
std::string ErrorTable(const FitSet& set);

}  // namespace skybake::fit
