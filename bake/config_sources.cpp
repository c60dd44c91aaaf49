// Where atmospheres come from and how they are written out: the built-in
// presets, the rule that resolves a command-line word to a preset or a file,
// and the canonical TOML and JSON forms of a resolved Atmosphere. Reading and
// validating the files is bake/config.cpp.
#include "bake/config.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <nlohmann/json.hpp>

#include "bake/spectral_form.h"
#include "bake/toml_input.h"
#include "core/constants.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "core/version.h"
#include "shaders_runtime/embedded_text.h"

namespace skybake {

namespace {

using namespace toml_input;

// A TOML float literal: FormatNumber plus ".0" where it would read as an integer.
std::string TomlFloat(double value) {
  std::string text = FormatNumber(value);
  if (text.find_first_of(".eni") == std::string::npos) text += ".0";
  return text;
}

const EmbeddedText* FindPreset(const std::string& name) {
  for (const EmbeddedText& file : kPresetFiles) {
    if (file.name == name + ".toml") return &file;
  }
  return nullptr;
}

std::string PresetName(std::string_view file_name) {
  return std::string(file_name.substr(0, file_name.rfind(".toml")));
}

std::string Array3(const Spectrum& value) {
  return "[" + TomlFloat(value[0]) + ", " + TomlFloat(value[1]) + ", " + TomlFloat(value[2]) + "]";
}

std::string List(const std::vector<double>& values) {
  std::string text = "[";
  for (size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + TomlFloat(values[i]);
  return text + "]";
}

// A per-wavelength value in the form the file gave it, where that form
// still gives `values` at `wavelengths_nm` bit for bit (an Atmosphere
// changed after reading keeps a form that no longer does), otherwise the
// three values. `table_key` names a table's values ("per_m", "albedo").
std::string FormToml(const SpectralForm& form, const Spectrum& values, const Spectrum& wavelengths_nm,
                     std::string_view table_key) {
  using Kind = SpectralForm::Kind;
  const Spectrum evaluated = Evaluate(form, wavelengths_nm);
  bool holds = form.kind != Kind::kValues;
  for (int i = 0; i < kWavelengthCount; ++i) holds = holds && evaluated[i] == values[i];
  if (!holds) return Array3(values);
  const std::vector<double>& p = form.parameters;
  switch (form.kind) {
    case Kind::kValues:
      break;
    case Kind::kConstant:
      return TomlFloat(p[0]);
    case Kind::kRayleighLaw:
      return "{ rayleigh_at_1um = " + TomlFloat(p[0]) + " }";
    case Kind::kAngstrom:
      return "{ angstrom_reference = " + TomlFloat(p[0]) + ", reference_nm = " + TomlFloat(p[1]) +
             ", exponent = " + TomlFloat(p[2]) + " }";
    case Kind::kRefractiveIndex:
      return "{ refractive_index = " + TomlFloat(p[0]) + ", number_density_per_m3 = " + TomlFloat(p[1]) +
             ", depolarization = " + TomlFloat(p[2]) + " }";
    case Kind::kTabulated: {
      std::string text = "{ wavelength_nm = " + List(form.wavelength_nm) + ", " + std::string(table_key) + " = " +
                         List(form.values);
      if (form.interpolation != SpectralForm::Interpolation::kLinear)
        text += ", interpolation = " + TomlString(ToString(form.interpolation));
      return text + " }";
    }
    case Kind::kCrossSection:
      return "{ cross_section = " + TomlString(form.name) + ", molecules_per_m3 = " + TomlFloat(p[0]) + " }";
    case Kind::kSolarSpectrum:
      if (p[0] == 1.0) return TomlString(form.name);
      return "{ spectrum = " + TomlString(form.name) + ", distance_au = " + TomlFloat(p[0]) + " }";
  }
  return Array3(values);
}

constexpr std::string_view kPresetPrefix = "preset:";

// Whether `file_or_preset` is spelled as a path: standard input, a '/' or a
// ".toml" suffix. Other words are preset names first.
bool SpelledAsPath(const std::string& file_or_preset) {
  return file_or_preset == kStandardStream || file_or_preset.find('/') != std::string::npos ||
         std::filesystem::path(file_or_preset).extension() == ".toml";
}

// The preset `file_or_preset` names under LoadAtmosphere's rule, or nullopt
// where it names a file.
std::optional<std::string> NamedPreset(const std::string& file_or_preset) {
  const std::string_view text(file_or_preset);
  if (text.substr(0, kPresetPrefix.size()) == kPresetPrefix) return std::string(text.substr(kPresetPrefix.size()));
  if (!SpelledAsPath(file_or_preset) && FindPreset(file_or_preset)) return file_or_preset;
  return std::nullopt;
}

}  // namespace

AtmosphereSource ReadAtmosphereSource(const std::string& file_or_preset) {
  if (std::optional<std::string> preset = NamedPreset(file_or_preset)) {
    const EmbeddedText* file = FindPreset(*preset);
    if (!file) throw InputError(*preset + ": no such preset (see skybake presets)");
    return {std::string(file->text), std::string(file->name)};
  }
  const std::filesystem::path path(file_or_preset);
  std::error_code error;
  if (!SpelledAsPath(file_or_preset) && !std::filesystem::exists(path, error)) {
    throw IoError(file_or_preset + ": no such file or preset (see skybake presets)", ErrorLocation(file_or_preset));
  }
  return {ReadFileText(path, "an atmosphere file"), InputName(file_or_preset),
          file_or_preset == kStandardStream ? std::string() : file_or_preset};
}

Atmosphere LoadAtmosphere(const std::string& file_or_preset) {
  const AtmosphereSource source = ReadAtmosphereSource(file_or_preset);
  return ParseAtmosphere(source.text, source.name);
}

std::string InputName(const std::string& path) { return path == kStandardStream ? "standard input" : path; }

std::string AtmosphereSourceName(const std::string& file_or_preset) {
  if (std::optional<std::string> preset = NamedPreset(file_or_preset)) return *preset;
  if (file_or_preset == kStandardStream) return "stdin";
  return std::filesystem::path(file_or_preset).stem().string();
}

std::vector<PresetInfo> ListPresets() {
  std::vector<PresetInfo> presets;
  for (const EmbeddedText& file : kPresetFiles) {
    std::string name = PresetName(file.name);
    presets.push_back({name, LoadPreset(name).description});
  }
  return presets;
}

Atmosphere LoadPreset(const std::string& name) {
  const EmbeddedText* file = FindPreset(name);
  if (!file) throw InputError(name + ": no such preset (see skybake presets)");
  return ParseAtmosphere(file->text, std::string(file->name));
}

std::string ToToml(const Atmosphere& a) {
  std::ostringstream out;
  out << "# Resolved to SI units by skybake " SKYBAKE_VERSION "; a valid atmosphere file.\n"
      << "name = " << TomlString(a.name) << "\n"
      << "description = " << TomlString(a.description) << "\n"
      << "\n[planet]\n"
      << "ground_radius_m = " << TomlFloat(a.bottom_radius_m) << "\n"
      << "top_radius_m = " << TomlFloat(a.top_radius_m) << "\n"
      << "ground_albedo = " << FormToml(a.ground_albedo_form, a.ground_albedo, a.wavelengths_nm, "albedo") << "\n"
      << "\n[spectrum]\n"
      << "wavelengths_nm = " << Array3(a.wavelengths_nm) << "\n"
      << "\n[sun]\n"
      << "irradiance_w_m2_nm = " << FormToml(a.solar_irradiance_form, a.solar_irradiance, a.wavelengths_nm, "")
      << "\n"
      << "angular_radius_rad = " << TomlFloat(a.sun_angular_radius_rad) << "\n"
      << "mu_s_min = " << TomlFloat(a.mu_s_min);
  char zenith[64];
  std::snprintf(zenith, sizeof zenith, "  # lowest sun zenith %.6g deg\n",
                std::acos(std::clamp(a.mu_s_min, -1.0, 1.0)) * 180.0 / kPi);
  out << zenith;

  for (const Constituent& c : a.constituents) {
    std::string section = "constituents." + TomlKey(c.name);
    out << "\n[" << section << "]\n"
        << "phase = { function = " << TomlString(ToString(c.phase.kind));
    if (c.phase.kind == PhaseKind::kHenyeyGreenstein || c.phase.kind == PhaseKind::kCornetteShanks)
      out << ", g = " << TomlFloat(c.phase.g);
    out << " }\n"
        << "scattering_per_m = " << FormToml(c.scattering_form, c.scattering_per_m, a.wavelengths_nm, "per_m") << "\n"
        << "absorption_per_m = " << FormToml(c.absorption_form, c.absorption_per_m, a.wavelengths_nm, "per_m")
        << "\n";
    const DensityProfile& d = c.density;
    if (d.kind == DensityProfile::Kind::kLayers) {
      out << "\n[" << section << ".density]\nlayers = [\n";
      for (const DensityLayer& l : d.layers) {
        out << "  { width_m = " << TomlFloat(l.width_m) << ", exp_term = " << TomlFloat(l.exp_term)
            << ", exp_scale_per_m = " << TomlFloat(l.exp_scale_per_m)
            << ", linear_term_per_m = " << TomlFloat(l.linear_term_per_m)
            << ", constant_term = " << TomlFloat(l.constant_term) << " },\n";
      }
      out << "]\n";
    } else {
      out << "\n[" << section << ".density.tabulated]\n"
          << "altitude_m = " << List(d.altitudes_m) << "\n"
          << "density = " << List(d.densities) << "\n";
    }
  }
  return out.str();
}

std::string ToJson(const Atmosphere& a) {
  using Json = nlohmann::ordered_json;
  auto array3 = [](const Spectrum& s) { return Json::array({s[0], s[1], s[2]}); };
  Json constituents = Json::object();
  for (const Constituent& c : a.constituents) {
    Json phase = {{"function", ToString(c.phase.kind)}};
    if (c.phase.kind == PhaseKind::kHenyeyGreenstein || c.phase.kind == PhaseKind::kCornetteShanks)
      phase["g"] = c.phase.g;
    Json density;
    if (c.density.kind == DensityProfile::Kind::kLayers) {
      Json layers = Json::array();
      for (const DensityLayer& l : c.density.layers) {
        layers.push_back({{"width_m", l.width_m},
                          {"exp_term", l.exp_term},
                          {"exp_scale_per_m", l.exp_scale_per_m},
                          {"linear_term_per_m", l.linear_term_per_m},
                          {"constant_term", l.constant_term}});
      }
      density["layers"] = layers;
    } else {
      density["tabulated"] = {{"altitude_m", c.density.altitudes_m},
                              {"density", c.density.densities}};
    }
    constituents[c.name] = {{"phase", phase},
                            {"scattering_per_m", array3(c.scattering_per_m)},
                            {"absorption_per_m", array3(c.absorption_per_m)},
                            {"density", density}};
  }
  Json json = {
      {"name", a.name},
      {"description", a.description},
      {"planet",
       {{"ground_radius_m", a.bottom_radius_m},
        {"top_radius_m", a.top_radius_m},
        {"ground_albedo", array3(a.ground_albedo)}}},
      {"spectrum", {{"wavelengths_nm", array3(a.wavelengths_nm)}}},
      {"sun",
       {{"irradiance_w_m2_nm", array3(a.solar_irradiance)},
        {"angular_radius_rad", a.sun_angular_radius_rad},
        {"mu_s_min", a.mu_s_min}}},
      {"constituents", constituents},
  };
  return json.dump(2) + "\n";
}

}  // namespace skybake
