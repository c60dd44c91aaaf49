#include "report/colour_errors.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "bake/colour.h"
#include "bake/config.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "report/reference_files.h"
#include "report/run_time_models.h"

namespace skybake::report {

namespace {

// The colour group of a case's radiance: its case group, twilight split by
// the sun's zenith angle.
std::string RadianceGroup(const ReferenceCase& c) {
  if (c.group != "twilight") return c.group;
  const double sun = c.query.sun_zenith_deg;
  return sun <= 90.0 ? "twilight to 90" : sun <= 96.0 ? "twilight 91-96" : "twilight 97-100";
}

// Relative luminance errors and Delta u'v' of one group.
struct GroupSamples {
  std::vector<double> luminance, delta_uv;
};

double Rms(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x * x;
  return v.empty() ? 0.0 : std::sqrt(sum / double(v.size()));
}

double LargestMagnitude(const std::vector<double>& v) {
  double largest = 0.0;
  for (double x : v) largest = std::max(largest, std::abs(x));
  return largest;
}

ColourStats Summarise(const GroupSamples& s) {
  return {static_cast<int>(s.luminance.size()), Rms(s.luminance), LargestMagnitude(s.luminance), Rms(s.delta_uv),
          LargestMagnitude(s.delta_uv)};
}

// Per case, what a set answers in XYZ: radiance, or for an irradiance case
// the sky irradiance; `to_xyz` turns its channels into XYZ.
std::vector<glm::dvec3> AnswerInXyz(const ReferenceSet& reference, const LutSet& luts, const glm::dmat3& to_xyz) {
  const Twin twin(MakeTwinTables(luts));
  std::vector<glm::dvec3> answers;
  for (const ReferenceCase& c : reference.cases) {
    const ModelAnswer a = EvaluateTwin(twin, c);
    answers.push_back(to_xyz * (c.query.has_normal ? a.sky_irradiance : a.radiance));
  }
  return answers;
}

glm::dvec3 ReferenceXyz(const ReferenceCase& c) { return c.query.has_normal ? c.sky_irradiance : c.radiance; }

std::map<std::string, GroupSamples> Samples(const ReferenceSet& reference, const std::vector<glm::dvec3>& answers,
                                            double scale) {
  std::map<std::string, GroupSamples> groups;
  for (std::size_t i = 0; i < reference.cases.size(); ++i) {
    const ReferenceCase& c = reference.cases[i];
    const glm::dvec3 truth = ReferenceXyz(c), value = answers[i];
    if (!(truth.y > 0.0)) continue;  // no light to compare (a view from space past the planet)
    GroupSamples& g = groups[c.query.has_normal ? "sky_irradiance" : RadianceGroup(c)];
    g.luminance.push_back(scale * value.y / truth.y - 1.0);
    g.delta_uv.push_back(glm::length(UcsChromaticity(value) - UcsChromaticity(truth)));
  }
  return groups;
}

std::string Percent(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f %%", 100.0 * x);
  return text;
}

std::string Fixed4(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4f", x);
  return text;
}

nlohmann::json StatsJson(const ColourStats& s) {
  return {{"cases", s.cases},
          {"luminance_rms", s.luminance_rms},
          {"luminance_max", s.luminance_max},
          {"delta_uv_rms", s.delta_uv_rms},
          {"delta_uv_max", s.delta_uv_max}};
}

}  // namespace

const ColourGroup& ColourErrors::Group(const std::string& name) const {
  for (const ColourGroup& g : groups) {
    if (g.name == name) return g;
  }
  throw InternalError("colour errors: no group " + name);
}

std::optional<ReferenceSet> LoadSpectralReference(const std::string& file, const std::string& atmosphere_name) {
  const std::string expected = "a spectral reference (columns X, Y, Z; skybake reference --wavelengths N)";
  if (!file.empty()) {
    return ParseReference(ReadFileText(file), InputName(file), XyzChannels(), expected);
  }
  const EmbeddedText* committed = CommittedReference(atmosphere_name + "_spectral");
  if (!committed) return std::nullopt;
  return ParseReference(std::string(committed->text), std::string(committed->name), XyzChannels(), expected);
}

ColourErrors MeasureColourErrors(const ReferenceSet& reference, const LutSet& spectral,
                                 const LutSet& three_wavelength) {
  if (!spectral.colour) throw InputError("colour errors: the spectral set's tables are not in XYZ");
  if (three_wavelength.colour) throw InputError("colour errors: the three-wavelength set's tables are in XYZ");
  ColourErrors errors;
  errors.wavelengths = static_cast<int>(spectral.colour->wavelengths_nm.size());
  errors.higher_order_wavelengths = static_cast<int>(spectral.colour->higher_order_wavelengths_nm.size());
  const std::vector<glm::dvec3> colour = AnswerInXyz(reference, spectral, glm::dmat3(1.0));
  const std::vector<glm::dvec3> as_srgb = AnswerInXyz(reference, three_wavelength, LinearSrgbToXyzMatrix());

  // Least squares over the daylight radiances: scale minimises
  // sum (scale * Y - Y_reference)^2.
  double product = 0.0, square = 0.0;
  for (std::size_t i = 0; i < reference.cases.size(); ++i) {
    const ReferenceCase& c = reference.cases[i];
    if (c.group != "daylight" || c.query.has_normal) continue;
    product += as_srgb[i].y * c.radiance.y;
    square += as_srgb[i].y * as_srgb[i].y;
  }
  errors.as_srgb_luminance_scale = square > 0.0 ? product / square : 1.0;

  std::map<std::string, GroupSamples> spectral_samples = Samples(reference, colour, 1.0);
  std::map<std::string, GroupSamples> srgb_samples = Samples(reference, as_srgb, errors.as_srgb_luminance_scale);
  for (const char* name : kColourGroups) {
    if (!spectral_samples.count(name)) continue;
    errors.groups.push_back({name, Summarise(spectral_samples[name]), Summarise(srgb_samples[name])});
  }
  return errors;
}

std::string ColourMarkdown(const ColourErrors& e) {
  std::string s = "| case group | cases | " + std::to_string(e.wavelengths) +
                  " wavelengths: luminance RMS / max | Δu′v′ RMS / max | 680/550/440 nm as sRGB: luminance RMS / "
                  "max | as sRGB: Δu′v′ RMS / max |\n| --- | ---: | ---: | ---: | ---: | ---: |\n";
  for (const ColourGroup& g : e.groups) {
    s += "| " + g.name + " | " + std::to_string(g.spectral.cases) + " | " + Percent(g.spectral.luminance_rms) +
         " / " + Percent(g.spectral.luminance_max) + " | " + Fixed4(g.spectral.delta_uv_rms) + " / " +
         Fixed4(g.spectral.delta_uv_max) + " | " + Percent(g.as_srgb.luminance_rms) + " / " +
         Percent(g.as_srgb.luminance_max) + " | " + Fixed4(g.as_srgb.delta_uv_rms) + " / " +
         Fixed4(g.as_srgb.delta_uv_max) + " |\n";
  }
  const std::string interpolated =
      e.higher_order_wavelengths < e.wavelengths
          ? " (its higher orders computed at " + std::to_string(e.higher_order_wavelengths) + " of the " +
                std::to_string(e.wavelengths) + " wavelengths and interpolated at the others)"
          : "";
  char scale[32], seconds[32];
  std::snprintf(scale, sizeof scale, "%.4g", e.as_srgb_luminance_scale);
  std::snprintf(seconds, sizeof seconds, "%.1f", e.spectral_bake_seconds);
  return s + "\nThe three-wavelength set's luminance is scaled by " + scale +
         " (fitted on daylight); the spectral bake" + interpolated + " took " + seconds + " s.\n";
}

nlohmann::json ColourJson(const ColourErrors& e) {
  nlohmann::json groups = nlohmann::json::array();
  for (const ColourGroup& g : e.groups) {
    groups.push_back({{"group", g.name}, {"spectral", StatsJson(g.spectral)}, {"as_srgb", StatsJson(g.as_srgb)}});
  }
  return {{"wavelengths", e.wavelengths},
          {"higher_order_wavelengths", e.higher_order_wavelengths},
          {"spectral_bake_seconds", e.spectral_bake_seconds},
          {"as_srgb_luminance_scale", e.as_srgb_luminance_scale},
          {"groups", groups}};
}

}  // namespace skybake::report
