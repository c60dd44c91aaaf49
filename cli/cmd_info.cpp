// `skybake info FILE|DIR`: what a table file holds (format, size, per-channel
// range and NaN/Inf counts, metadata), checked against the manifest when one
// lists it; for a directory, every file its manifest lists. `--plot OUT` also
// draws the set's table slices through the CPU twin (render/lut_plots.h).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "formats/lut_files.h"
#include "formats/manifest.h"
#include "formats/sha256.h"
#include "formats/table_file.h"
#include "formats/table_stats.h"
#include "render/lut_plots.h"

namespace skybake::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct InfoOptions {
  std::string path;
  std::string plot_dir;  // empty: no plots
  bool json = false;
};

// Long or multi-line metadata (the parameters JSON, the atmosphere TOML) is
// shortened in text output; --json has it whole.
std::string Shortened(const std::string& value) {
  constexpr std::size_t kMax = 96;
  std::string first = value.substr(0, value.find('\n'));
  if (first.size() > kMax) first = first.substr(0, kMax);
  if (first.size() == value.size()) return value;
  return first + " ... (" + std::to_string(value.size()) + " bytes)";
}

// Describes a table file's bytes (already checked against `listing`, the
// manifest entry, when there is one).
json DescribeTableFile(const fs::path& path, const std::vector<std::uint8_t>& bytes,
                       const std::optional<ManifestFile>& listing) {
  const TableImage image = DecodeTableImage(bytes, path.string());
  if (listing && (image.format != listing->format || image.pixel_type != listing->pixel_type)) {
    throw IoError(path.string() + ": is " + ToString(image.format) + " " + ToString(image.pixel_type) +
                  ", the manifest says " + ToString(listing->format) + " " + ToString(listing->pixel_type));
  }
  const std::vector<std::string> meaningful = MeaningfulChannels(image, path.string());
  json channels = json::array();
  for (const ChannelStats& s : ComputeChannelStats(image)) {
    json c = ToJson(s);
    // KTX2 pads RGB tables with an alpha channel that carries no data.
    c["padding"] = std::find(meaningful.begin(), meaningful.end(), s.name) == meaningful.end();
    channels.push_back(c);
  }
  json size = image.is_3d ? json::array({image.width, image.height, image.depth})
                          : json::array({image.width, image.height});
  return json{{"file", path.string()},
              {"format", ToString(image.format)},
              {"pixel_type", ToString(image.pixel_type)},
              {"storage", image.StorageName()},
              {"size", size},
              {"dimensions", image.is_3d ? 3 : 2},
              {"bytes", bytes.size()},
              {"sha256", Sha256Hex(bytes.data(), bytes.size())},
              {"manifest", listing ? "checksum matches skybake.json" : "not listed in a manifest"},
              {"channels", channels},
              {"metadata", image.metadata}};
}

void PrintTableFile(const json& d) {
  std::string size;
  for (const json& n : d["size"]) size += (size.empty() ? "" : "x") + std::to_string(n.get<int>());
  std::printf("%s\n", d["file"].get<std::string>().c_str());
  std::printf("  %s, %s, %dD %s, %zu bytes\n", d["format"].get<std::string>().c_str(),
              d["storage"].get<std::string>().c_str(), d["dimensions"].get<int>(), size.c_str(),
              d["bytes"].get<std::size_t>());
  std::printf("  sha256 %s (%s)\n", d["sha256"].get<std::string>().c_str(), d["manifest"].get<std::string>().c_str());
  std::printf("  %-8s %14s %14s %10s %6s %6s\n", "channel", "min", "max", "finite", "NaN", "Inf");
  for (const json& c : d["channels"]) {
    const std::string name = c["name"].get<std::string>() + (c["padding"].get<bool>() ? " (pad)" : "");
    std::printf("  %-8s %14.6g %14.6g %10zu %6zu %6zu\n", name.c_str(), c["min"].get<double>(),
                c["max"].get<double>(), c["finite"].get<std::size_t>(), c["nan"].get<std::size_t>(),
                c["inf"].get<std::size_t>());
  }
  if (!d["metadata"].empty()) std::printf("  metadata\n");
  for (const auto& [key, value] : d["metadata"].items()) {
    std::printf("    %s = %s\n", key.c_str(), Shortened(value.get<std::string>()).c_str());
  }
}

// Plots of the set's table slices into o.plot_dir: those the set's tables
// can draw, each one left out named on stderr. Adds "plots" and
// "plots_left_out" to `report`.
void WritePlots(const InfoOptions& o, json* report) {
  const LutSet luts = LoadLutSet(o.path);
  EnsureWritableDirectory(o.plot_dir);
  StagedFiles staged;  // the plots appear together or not at all
  const render::PlotFiles plots = render::WriteLutPlots(staged, luts, o.plot_dir, CommandLine());
  staged.Commit();
  if (!plots.png_text) std::fputs("info: no TrueType font found; the PNG plots have no text\n", stderr);
  json files = json::array();
  for (const fs::path& f : plots.files) files.push_back(f.string());
  for (const std::string& line : plots.left_out) std::fprintf(stderr, "info: plot left out: %s\n", line.c_str());
  (*report)["plots"] = files;
  (*report)["plots_left_out"] = plots.left_out;
}

void RunInfo(const InfoOptions& o) {
  const fs::path path = o.path;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw IoError(o.path + ": no such file or directory");
  if (!o.plot_dir.empty() && !fs::is_directory(path)) {
    throw UsageError("info: --plot needs a baked directory, not a single file");
  }
  if (!fs::is_directory(path)) {
    const std::optional<ManifestFile> listing = FindListing(path);
    const std::vector<std::uint8_t> bytes = ReadFileBytes(path);
    if (listing) VerifyListedFile(*listing, bytes, path.string());
    const json d = DescribeTableFile(path, bytes, listing);
    if (o.json) {
      std::printf("%s\n", d.dump(2, ' ', false, json::error_handler_t::replace).c_str());
    } else {
      PrintTableFile(d);
    }
    return;
  }

  const Manifest manifest = ReadManifest(path);
  json files = json::array(), shaders = json::array();
  for (const ManifestFile& f : manifest.table_files) {
    json d = DescribeTableFile(path / f.file, ReadListedFile(manifest, f), f);
    d["table"] = f.table;
    files.push_back(d);
  }
  for (const ManifestFile& f : manifest.shader_files) {
    const std::vector<std::uint8_t> bytes = ReadListedFile(manifest, f);
    shaders.push_back({{"file", (path / f.file).string()}, {"bytes", bytes.size()}, {"sha256", f.sha256}});
  }
  const std::vector<std::string> unlisted = EntriesNotIn(manifest.Directory(), ListedFileNames(manifest.Directory()));
  const json& doc = manifest.document;
  json plot_report = json::object();
  if (!o.plot_dir.empty()) WritePlots(o, &plot_report);
  if (o.json) {
    json report = {{"manifest", manifest.path.string()},
                   {"schema_version", doc["schema_version"]},
                   {"generator", doc.value("generator", "")},
                   {"command", doc.value("command", "")},
                   {"atmosphere", manifest.luts.atmosphere.name},
                   {"wavelengths_nm", doc["wavelengths_nm"]},
                   {"files", files},
                   {"shaders", shaders},
                   {"unlisted_files", unlisted}};
    report.update(plot_report);
    std::printf("%s\n", report.dump(2, ' ', false, json::error_handler_t::replace).c_str());
    return;
  }
  std::printf("%s: schema %s version %d, %s\n", manifest.path.string().c_str(), kManifestSchema,
              doc["schema_version"].get<int>(), doc.value("generator", "").c_str());
  std::printf("  atmosphere %s, wavelengths %s nm, %d scattering orders%s\n", manifest.luts.atmosphere.name.c_str(),
              doc["wavelengths_nm"].dump().c_str(), manifest.luts.orders_used,
              manifest.luts.settings.orders == 0 ? " (auto)" : "");
  std::printf("  command: %s\n", doc.value("command", "").c_str());
  std::printf("  %zu table files, %zu shader files; every checksum matches\n", files.size(), shaders.size());
  if (!unlisted.empty()) {
    std::string names;
    for (const std::string& name : unlisted) names += (names.empty() ? "" : ", ") + name;
    std::printf("  warning: %zu files here are not listed in the manifest (not part of this set): %s\n",
                unlisted.size(), names.c_str());
  }
  std::printf("\n");
  for (const json& d : files) {
    PrintTableFile(d);
    std::printf("\n");
  }
  for (const json& s : shaders) {
    std::printf("%s\n  %zu bytes, sha256 %s (matches)\n", s["file"].get<std::string>().c_str(),
                s["bytes"].get<std::size_t>(), s["sha256"].get<std::string>().c_str());
  }
  for (const json& f : plot_report.value("plots", json::array())) {
    std::printf("plot %s\n", f.get<std::string>().c_str());
  }
}

}  // namespace

void AddInfoCommand(CLI::App& app) {
  auto o = std::make_shared<InfoOptions>();
  CLI::App* cmd = app.add_subcommand(
      "info", "Describe a table file (EXR or KTX2) or a baked directory: size, format, per-channel min/max and "
              "NaN/Inf counts, metadata; files a manifest lists are checked against its SHA-256. Files in a "
              "directory that its manifest does not list (e.g. tables of an earlier bake) are named in one "
              "warning line (--json: \"unlisted_files\"); they are a warning, not an error: exit 0");
  cmd->add_option("path", o->path, "Table file (.exr, .ktx2) or directory written by skybake bake")->required();
  cmd->add_flag("--json", o->json, "Print the description as JSON on stdout");
  cmd->add_option("--plot", o->plot_dir,
                  "Also plot table slices of a baked directory (transmittance, sky radiance, irradiance; "
                  "lut_*.svg and .png) into this directory; a plot whose table the set leaves out (a scene's "
                  "bake) is not drawn and is named on stderr")
      ->check(OutputPath());
  cmd->callback([o] { RunInfo(*o); });
}

}  // namespace skybake::cli
