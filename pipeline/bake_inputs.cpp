#include "pipeline/bake_inputs.h"

#include <nlohmann/json.hpp>

#include "bake/config.h"
#include "core/errors.h"
#include "core/version.h"
#include "formats/sha256.h"
#include "shaders_runtime/snippet.h"

namespace fs = std::filesystem;

namespace skybake::pipeline {

namespace {

using nlohmann::ordered_json;

// Every field of BakeSettings but `threads`. A field added to BakeSettings
// changes its size, and the assertion asks whether the new field changes the
// tables: if it does, it belongs here (then update the size).
static_assert(sizeof(BakeSettings) == 136, "a new BakeSettings field: add it to SettingsInputs if it changes the tables");

ordered_json SettingsInputs(const BakeSettings& s) {
  ordered_json range = nullptr;
  if (const std::optional<ScatteringRange>& r = s.scattering_range) {
    range = {{"altitude_m", {r->altitude_min_m, r->altitude_max_m}},
             {"mu_s", {r->mu_s_min, r->mu_s_max}},
             {"atmosphere_r_mu_mu_s_size", {r->atmosphere_r_size, r->atmosphere_mu_size, r->atmosphere_mu_s_size}},
             {"atmosphere_ray_samples", r->atmosphere_ray_samples}};
  }
  return {{"transmittance_size", {s.transmittance_width, s.transmittance_height}},
          {"irradiance_size", {s.irradiance_width, s.irradiance_height}},
          {"scattering_size", {s.scattering_r_size, s.scattering_mu_size, s.scattering_mu_s_size, s.scattering_nu_size}},
          {"orders", s.orders},
          {"order_tolerance", s.order_tolerance},
          {"max_orders", s.max_orders},
          {"extrapolate_tail", s.extrapolate_tail},
          {"transmittance_samples", s.transmittance_samples},
          {"ray_samples", s.ray_samples},
          {"sphere_samples", s.sphere_samples},
          {"higher_order_divisor", s.higher_order_divisor},
          {"scattering_range", range},
          {"pack_single_mie_in_alpha", s.pack_single_mie_in_alpha},
          {"single_scattering_sky_irradiance", s.single_scattering_sky_irradiance}};
}

}  // namespace

std::string BakeInputsSha256(const Atmosphere& atmosphere, const BakeJob& job, const SpectralBatches* batches,
                             const Scene* scene, const WriteOptions& write_options) {
  ordered_json spectral = nullptr;
  if (batches) {
    ordered_json resolved = ordered_json::array();
    for (const Spectrum& wavelengths : batches->batch_wavelengths_nm) {
      resolved.push_back(ToToml(ParseAtmosphere(job.spectral_source.text, job.spectral_source.name, wavelengths)));
    }
    spectral = {{"wavelengths_nm", batches->wavelengths_nm},
                {"higher_orders", ToString(job.spectral_higher_orders)},
                {"higher_order_wavelengths", batches->HigherOrderWavelengths()},
                {"atmosphere_per_batch", resolved}};
  }
  ordered_json formats = ordered_json::array();
  for (FileFormat format : write_options.formats) formats.push_back(ToString(format));
  ordered_json runtime = ordered_json::array();
  for (ShadingLanguage language : job.runtime_languages) runtime.push_back(ShadingLanguageName(language));
  const ordered_json inputs = {
      {"generator", "skybake " SKYBAKE_VERSION},
      {"atmosphere", ToToml(atmosphere)},
      {"spectral", spectral},
      {"settings", SettingsInputs(job.settings)},
      {"scene", scene ? ordered_json::parse(SceneToJson(*scene)) : ordered_json(nullptr)},
      {"files",
       {{"formats", formats},
        {"half", write_options.half},
        {"half_tables", write_options.half_tables},
        {"ktx2_zstd_level", write_options.ktx2_zstd_level},
        {"runtime", runtime}}},
  };
  return Sha256Hex(inputs.dump());
}

std::optional<Manifest> ReadUpToDateSet(const fs::path& dir, const std::string& inputs_sha256) {
  std::error_code ec;
  if (!fs::is_regular_file(dir / kManifestFileName, ec)) return std::nullopt;
  Manifest manifest;
  try {
    manifest = ReadManifest(dir);
  } catch (const Error&) {
    return std::nullopt;  // baked again, and the manifest written anew
  }
  if (manifest.inputs_sha256 != inputs_sha256) return std::nullopt;
  for (const auto* files : {&manifest.table_files, &manifest.shader_files}) {
    for (const ManifestFile& f : *files) {
      const fs::path path = dir / f.file;
      if (!fs::is_regular_file(path, ec) || fs::file_size(path, ec) != f.bytes || ec) return std::nullopt;
    }
  }
  return manifest;
}

}  // namespace skybake::pipeline
