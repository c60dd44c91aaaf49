// `skybake eval`: answers queries from baked tables through the CPU twin.
// The query format is documented in docs/eval.md.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "bake/config.h"
#include "bake/scene.h"
#include "cli/command_line.h"
#include "cli/commands.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "formats/lut_files.h"
#include "formats/query_csv.h"
#include "report/twin_query.h"
#include "shaders_runtime/query.h"
#include "shaders_runtime/twin.h"

namespace skybake::cli {

namespace {

struct EvalOptions {
  std::string lut_dir;
  std::string input;
  std::string output;
  bool clamp = false;
};

void RunEval(const EvalOptions& o) {
  // Queries are checked before the tables are loaded: a malformed file fails fast.
  QueryTable table = ParseQueryCsv(ReadFileText(o.input), InputName(o.input));
  LutSet luts = LoadLutSet(o.lut_dir);
  if (luts.scene) {
    // A scene's tables cover only its ranges (and may lack whole tables):
    // a query outside them would read clamped or missing texels.
    for (size_t row = 0; row < table.queries.size(); ++row) {
      std::vector<std::string> clamped;
      const std::string problem =
          SceneQueryProblem(*luts.scene, luts.parameters.bottom_radius, o.clamp, &table.queries[row], &clamped);
      const int line = table.line_numbers[row];
      const std::string where = LocationPrefix(table.source_name, line);
      if (!problem.empty()) {
        throw InputError(where + problem + " (scene '" + luts.scene->name + "' of " + o.lut_dir +
                             (o.clamp ? ")" : "; --clamp moves altitudes, sun angles and distances into range)"),
                         {table.source_name, line});
      }
      for (const std::string& c : clamped) std::fprintf(stderr, "warning: %s%s\n", where.c_str(), c.c_str());
    }
  }
  // Past the tables' lowest sun there is no light to read (`render` refuses
  // such suns alike).
  for (size_t row = 0; row < table.queries.size(); ++row) {
    const double sun_zenith_deg = table.queries[row].sun_zenith_deg;
    const std::string problem = report::SunZenithOutsideTables(luts.parameters, sun_zenith_deg);
    if (!problem.empty()) {
      const int line = table.line_numbers[row];
      char value[32];
      std::snprintf(value, sizeof(value), "%g", sun_zenith_deg);
      throw InputError(LocationPrefix(table.source_name, line) + "sun_zenith_deg = " + value + " " + problem,
                       {table.source_name, line, "sun_zenith_deg"});
    }
  }
  Twin twin(MakeTwinTables(luts));

  std::string out;
  for (size_t i = 0; i < table.header.size(); ++i) out += (i ? "," : "") + table.header[i];
  const ChannelNames wavelengths = TableChannels(luts);
  for (const char* quantity : {"radiance_", "transmittance_"}) {
    for (const std::string& w : wavelengths) out += "," + std::string(quantity) + w;
  }
  if (table.has_normal) {
    for (const char* quantity : {"sun_irradiance_", "sky_irradiance_"}) {
      for (const std::string& w : wavelengths) out += "," + std::string(quantity) + w;
    }
  }
  out += "\n";

  char buffer[64];
  for (size_t row = 0; row < table.queries.size(); ++row) {
    const Query& q = table.queries[row];
    QueryGeometry g = MakeQueryGeometry(q, luts.parameters.bottom_radius);
    glsl::vec3 transmittance;
    glsl::vec3 radiance = report::QuerySkyRadiance(twin, q, g, &transmittance);
    std::string line = CsvInputColumns(table, row);
    auto append = [&](const glsl::vec3& v) {
      for (int c = 0; c < 3; ++c) {
        std::snprintf(buffer, sizeof(buffer), ",%.9g", v[c]);
        line += buffer;
      }
    };
    append(radiance);
    append(transmittance);
    if (table.has_normal) {
      if (q.has_normal) {
        glsl::vec3 sky;
        glsl::vec3 sun = twin.SunAndSkyIrradiance(g.camera, g.normal, g.sun, &sky);
        append(sun);
        append(sky);
      } else {
        line += ",,,,,,";
      }
    }
    out += line + "\n";
  }

  if (o.output.empty() || o.output == "-") {
    std::fputs(out.c_str(), stdout);
  } else {
    WriteFileAtomically(o.output, out);
  }
}

}  // namespace

void AddEvalCommand(CLI::App& app) {
  auto o = std::make_shared<EvalOptions>();
  CLI::App* cmd = app.add_subcommand(
      "eval", "Evaluate sky radiance, transmittance and irradiance queries (CSV) against baked tables");
  cmd->add_option("lut_dir", o->lut_dir, "Directory written by skybake bake")->required();
  cmd->add_option("--in", o->input, "Query CSV: altitude_m, view_zenith_deg, sun_zenith_deg, "
                                    "view_sun_azimuth_deg [, distance_m] [, normal_zenith_deg]")
      ->required();
  cmd->add_option("--out", o->output, "Result CSV (default: stdout)")
      ->check(OutputPath());
  cmd->add_flag("--clamp", o->clamp,
                "On a scene's bake: clamp altitudes, sun angles and distances outside the scene's ranges into them "
                "(with a warning) instead of rejecting the query");
  cmd->callback([o] { RunEval(*o); });
}

}  // namespace skybake::cli
