// `skybake convert IN OUT`: one table file between OpenEXR and KTX2 and
// between float32 and half, keeping its skybake metadata. Rounding to half
// is the only lossy step; its error is measured and reported.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "core/constants.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "formats/bruneton2017.h"
#include "formats/lut_files.h"
#include "formats/manifest.h"
#include "formats/table_file.h"
#include "formats/table_stats.h"

namespace skybake::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct ConvertOptions {
  std::string input;
  std::string output;
  bool half = false;
  std::string ktx2_supercompression = "none";
  bool to_float = false;
  double floor = kDefaultHalfErrorFloor;
  bool json = false;
  std::string layout;
  std::optional<double> lowest_sun_zenith_deg;
};

// `convert SET_DIR OUT_DIR --layout bruneton2017`: the whole set resampled
// into Bruneton's 2017 layout (formats/bruneton2017.h).
void RunConvertLayout(const ConvertOptions& o) {
  if (o.layout != "bruneton2017") throw UsageError("--layout: unknown layout '" + o.layout + "' (bruneton2017)");
  if (o.ktx2_supercompression != "none") throw UsageError("--layout bruneton2017 writes OpenEXR files only");
  if (!fs::is_directory(o.input)) throw UsageError(o.input + ": --layout takes a baked set's directory");
  if (fs::exists(fs::path(o.output) / kManifestFileName)) {
    throw UsageError(o.output + ": holds a skybake set; write the export into a directory of its own");
  }
  CheckOutputDirectory(o.output);
  const LutSet luts = LoadLutSet(o.input);
  Bruneton2017Layout layout;
  layout.mu_s_min = luts.parameters.mu_s_min;
  if (o.lowest_sun_zenith_deg) {
    const double zenith = *o.lowest_sun_zenith_deg;
    if (!(zenith > 90.0 && zenith < 180.0)) throw UsageError("--lowest-sun-zenith-deg must lie in (90, 180)");
    layout.mu_s_min = std::cos(zenith * kPi / 180.0);
  }
  WriteBruneton2017Set(luts, layout, o.to_float ? PixelType::kFloat : PixelType::kHalf, o.output);
  std::fprintf(stderr, "%s -> %s: Bruneton 2017 layout (%s), lowest sun mu_s %.6g (the set's %.6g)\n",
               o.input.c_str(), o.output.c_str(), o.to_float ? "float" : "half", layout.mu_s_min,
               luts.parameters.mu_s_min);
}

void RunConvert(const ConvertOptions& o) {
  if (!o.layout.empty()) return RunConvertLayout(o);
  if (o.lowest_sun_zenith_deg) throw UsageError("--lowest-sun-zenith-deg needs --layout");
  const std::optional<FileFormat> target = FileFormatOfPath(o.output);
  if (!target) throw UsageError(o.output + ": the output name must end in .exr or .ktx2");
  if (o.half && o.to_float) throw UsageError("--half and --float exclude each other");
  const int zstd_level = ParseKtx2Supercompression(o.ktx2_supercompression);
  if (zstd_level > 0 && *target != FileFormat::kKtx2) {
    throw UsageError("--ktx2-supercompression: only KTX2 files are supercompressed, and " + o.output +
                     " is not one; give one or the other");
  }
  if (!(o.floor > 0.0)) throw UsageError("--floor must be positive");

  // Writing over a file a manifest lists would leave the set failing its
  // checksums; converted files belong beside the set, not in it.
  if (const std::optional<ManifestFile> listed = FindListing(o.output)) {
    throw UsageError(o.output + ": is listed in " + (fs::path(o.output).parent_path() / kManifestFileName).string() +
                     "; write the converted file elsewhere (or re-bake with --format/--half)");
  }
  const fs::path input = o.input;
  const std::vector<std::uint8_t> bytes = ReadFileBytes(input);
  const std::optional<ManifestFile> listing = FindListing(input);
  if (listing) VerifyListedFile(*listing, bytes, input.string());
  const TableImage in = DecodeTableImage(bytes, input.string());

  TableImage out;
  out.format = *target;
  out.pixel_type = o.half ? PixelType::kHalf : o.to_float ? PixelType::kFloat : in.pixel_type;
  out.width = in.width, out.height = in.height, out.depth = in.depth, out.is_3d = in.is_3d;
  out.metadata = in.metadata;
  // The encoders write these themselves, for the new file.
  for (const char* key : {"KTXwriter", "KTXorientation", kExrGeneratorKey, kSizeKey}) out.metadata.erase(key);
  const std::vector<std::string> channels = MeaningfulChannels(in, input.string());
  out.channel_names = channels;
  out.values.resize(in.TexelCount() * channels.size());
  const std::size_t in_stride = in.channel_names.size();
  for (std::size_t c = 0; c < channels.size(); ++c) {
    const std::size_t from = std::find(in.channel_names.begin(), in.channel_names.end(), channels[c]) -
                             in.channel_names.begin();
    for (std::size_t i = 0; i < in.TexelCount(); ++i) out.values[i * channels.size() + c] = in.values[i * in_stride + from];
  }
  ChooseFileStorage(&out, zstd_level);
  WriteTableImage(o.output, out);
  const std::uint64_t written = fs::file_size(o.output);

  // Half error only where this conversion rounds: float in, half out.
  const bool rounds = in.pixel_type == PixelType::kFloat && out.pixel_type == PixelType::kHalf;
  const HalfError error = rounds ? MeasureHalfError(out.values.data(), out.values.size(), o.floor) : HalfError{};
  if (o.json) {
    json report = {{"input", o.input},
                   {"output", o.output},
                   {"from", {{"format", ToString(in.format)}, {"pixel_type", ToString(in.pixel_type)}}},
                   {"to", {{"format", ToString(out.format)}, {"pixel_type", ToString(out.pixel_type)}}},
                   {"channels", channels},
                   {"bytes", written},
                   {"half_error", rounds ? ToJson(error) : json(nullptr)}};
    std::printf("%s\n", report.dump(2, ' ', false, json::error_handler_t::replace).c_str());
    return;
  }
  // The summary goes to stderr, as every command's; stdout carries only --json.
  std::fprintf(stderr, "%s (%s %s) -> %s (%s %s), %llu bytes\n", o.input.c_str(), ToString(in.format),
               ToString(in.pixel_type), o.output.c_str(), ToString(out.format), ToString(out.pixel_type),
               static_cast<unsigned long long>(written));
  if (!rounds) {
    std::fprintf(stderr, "lossless: every value is stored exactly\n");
    return;
  }
  std::fprintf(stderr, "half: max relative error %.4g (at %.6g) over %zu values with |v| >= %g\n",
               error.max_relative_error, error.worst_value, error.measured, error.floor);
  std::fprintf(stderr,
               "half: %zu non-zero values below the floor, max absolute error there %.3g; %zu flushed to zero; "
               "%zu overflowed to infinity\n",
               error.below_floor, error.max_absolute_error_below_floor, error.flushed_to_zero, error.overflowed);
}

}  // namespace

void AddConvertCommand(CLI::App& app) {
  auto o = std::make_shared<ConvertOptions>();
  CLI::App* cmd = app.add_subcommand(
      "convert",
      "Convert a table file between EXR and KTX2 (by OUT's extension) and between float and half, keeping its "
      "metadata; reports the error half introduces: max |half(v) - v| / |v| over values with |v| >= --floor");
  cmd->add_option("input", o->input, "Table file (.exr or .ktx2)")->required();
  cmd->add_option("output", o->output, "Output file (.exr or .ktx2), written atomically")->required();
  cmd->add_flag("--half", o->half, "Store half floats");
  cmd->add_flag("--float", o->to_float, "Store float32");
  cmd->add_option("--ktx2-supercompression", o->ktx2_supercompression, kKtx2SupercompressionHelp)
      ->capture_default_str();
  cmd->add_option("--floor", o->floor,
                  "Smallest |value| the half relative error is measured over (default 2^-14, the smallest normal half)");
  cmd->add_flag("--json", o->json, "Print a machine-readable report on stdout");
  cmd->add_option("--layout", o->layout,
                  "bruneton2017: resample the baked set in directory INPUT into Bruneton's 2017 tables "
                  "(transmittance, scattering, single_mie_scattering, irradiance .exr, half unless --float) and "
                  "parameters.json in directory OUTPUT, as three-atmosphere and other ports of his runtime load them");
  cmd->add_option("--lowest-sun-zenith-deg", o->lowest_sun_zenith_deg,
                  "With --layout: the lowest sun of the exported mu_s axis (default: the set's own; "
                  "three-atmosphere's default textures use 120)");
  cmd->callback([o] { RunConvert(*o); });
}

}  // namespace skybake::cli
