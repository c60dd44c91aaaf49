// Atmosphere files: TOML text -> validated Atmosphere (SI units). The presets,
// the resolution of a command-line word to a preset or a file, and the
// canonical TOML and JSON writers are in bake/config_sources.cpp.
//
// Checks happen in two places on purpose. While reading, each value is checked
// against the key the user wrote, in the unit the user wrote it in, so that
// "planet.top_radius_km = 6300 must exceed planet.ground_radius_km = 6360"
// quotes the file rather than its SI translation. Validate() then checks the
// resolved model with the same rules under the canonical SI keys; it is the
// only check a hand-built Atmosphere gets. Both use the intervals below, so a
// rule is written once.
#include "bake/config.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <set>
#include <tuple>
#include <utility>

#include <toml++/toml.h>

#include "bake/spectral_data.h"
#include "bake/spectral_form.h"
#include "bake/toml_input.h"
#include "core/constants.h"
#include "core/errors.h"
#include "core/file_io.h"

namespace skybake {

namespace {

using namespace toml_input;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr Spectrum kDefaultWavelengthsNm{680.0, 550.0, 440.0};

constexpr Interval kFinite{-kInf, kInf, false, false};
constexpr Interval kPositive{0.0, kInf, false, false};
constexpr Interval kNonNegative{0.0, kInf, true, false};
constexpr Interval kUnit{0.0, 1.0, true, true};
constexpr Interval kAsymmetry{-1.0, 1.0, false, false};
// The sun's angular radius from 1e-6 rad, the Sun seen from 4,650 AU (from
// Sedna's aphelion, 937 AU, it is 5e-6 rad). Smaller discs lose the digits
// of their arithmetic: the drawn disc's solid angle 2 pi (1 - cos a)
// (render/views.cpp) has a relative error of 1e-4 at 1e-6 rad and is 0
// below 1e-8 rad, the runtime's disc radiance E / (pi a^2) overflows float
// below 1e-19 rad (1e-17 for a spectral set's sun in lux), and once a
// underflows float (below 1e-45 rad) the bake's visible fraction of the disc
// at the horizon, a smoothstep over +-0, divides 0 by 0: the NaN texels
// fuzzing found at 1e-300.
constexpr double kSunRadiusMinRad = 1e-6;
constexpr Interval kSunRadiusRad{kSunRadiusMinRad, kPi / 2, true, false, "[1e-6, pi/2)"};
constexpr Interval kSunRadiusDeg{0.0, 90.0, false, false};
constexpr Interval kLowestZenithDeg{0.0, 180.0, false, true};
constexpr Interval kMuSMin{-1.0, 1.0, true, false};
// Ranges outside which the tables' arithmetic overflows or loses every digit
// (squared radii, optical depths along the longest chord, radiance times the
// sharpest phase function, in float), found by fuzzing: a top radius of
// 1e200 m, a scattering coefficient of 1e308 m^-1 or an irradiance of 1e308
// baked to NaN and inf. Nothing physical comes near them: planets are
// 1e3 m to 1e8 m in radius (Jupiter 7e7 m), the densest fog extinguishes
// ~0.1 m^-1 (1000 m^-1 is a mean free path of 1 mm), the sun at Mercury's
// orbit gives ~15 W m^-2 nm^-1.
constexpr Interval kRadiusRange{1.0, 1e11, true, true, "[1 m, 1e11 m]"};
constexpr Interval kCoefficientRange{0.0, 1e3, true, true, "[0, 1000] m^-1"};
constexpr Interval kIrradianceRange{0.0, 1e25, true, true, "[0, 1e25]"};
// Depolarization ratio of natural light by anisotropic molecules is at most
// 1/2; beyond 6/7 the King factor changes sign.
constexpr Interval kDepolarization{0.0, 0.5, true, true};

void CheckSpectrum(const Reporter& report, const std::string& path, const Spectrum& value,
                   const Interval& interval) {
  for (int i = 0; i < kWavelengthCount; ++i) CheckNumber(report, Index(path, i), value[i], interval);
}

// Evaluates one layer's unclamped expression.
double LayerExpression(const DensityLayer& layer, double altitude_m) {
  return layer.exp_term * std::exp(layer.exp_scale_per_m * altitude_m) +
         layer.linear_term_per_m * altitude_m + layer.constant_term;
}

// Layered profiles are clamped to [0, 1] by definition (that is how the ozone
// tent is written: negative parts clamp to 0). The clamp at 1, though, would
// silently cut a profile the user meant to exceed 1, so that is an error, as
// is an expression that overflows inside the atmosphere. Inside one layer the
// expression a e^(b h) + c h + d is convex or concave, so its extremes lie at
// the layer's ends or at the one stationary point.
void CheckLayer(const Reporter& report, const std::string& path, const DensityLayer& layer,
                double base_m, double end_m) {
  std::vector<double> probes = {base_m, end_m};
  double ab = layer.exp_term * layer.exp_scale_per_m;
  if (ab != 0.0 && -layer.linear_term_per_m / ab > 0.0) {
    double h = std::log(-layer.linear_term_per_m / ab) / layer.exp_scale_per_m;
    if (h > base_m && h < end_m) probes.push_back(h);
  }
  for (double h : probes) {
    double d = LayerExpression(layer, h);
    if (!std::isfinite(d))
      report.Fail(path, "density is not finite at altitude " + FormatNumber(h) + " m");
    if (d > 1.0 + 1e-9)
      report.Fail(path, "density reaches " + FormatNumber(d) + " at altitude " + FormatNumber(h) +
                            " m, but layer densities are clamped to [0, 1]; scale the "
                            "constituent's coefficients instead");
  }
}

void CheckDensityProfile(const Reporter& report, const std::string& path,
                         const DensityProfile& profile, double thickness_m) {
  if (profile.kind == DensityProfile::Kind::kLayers) {
    std::string layers_path = path + ".layers";
    if (profile.layers.empty()) report.Fail(layers_path, "needs at least one layer");
    double base = 0.0;
    for (size_t i = 0; i < profile.layers.size(); ++i) {
      const DensityLayer& layer = profile.layers[i];
      std::string layer_path = Index(layers_path, i);
      CheckNumber(report, layer_path + ".width_m", layer.width_m, kNonNegative);
      CheckNumber(report, layer_path + ".exp_term", layer.exp_term, kFinite);
      CheckNumber(report, layer_path + ".exp_scale_per_m", layer.exp_scale_per_m, kFinite);
      CheckNumber(report, layer_path + ".linear_term_per_m", layer.linear_term_per_m, kFinite);
      CheckNumber(report, layer_path + ".constant_term", layer.constant_term, kFinite);
      bool last = i + 1 == profile.layers.size();
      double end = last ? thickness_m : std::min(base + layer.width_m, thickness_m);
      if (base < thickness_m) CheckLayer(report, layer_path, layer, base, end);
      base += layer.width_m;
    }
    return;
  }
  std::string table_path = path + ".tabulated";
  const std::vector<double>& h = profile.altitudes_m;
  const std::vector<double>& d = profile.densities;
  if (h.size() != d.size())
    report.Fail(table_path, "altitude_m has " + std::to_string(h.size()) +
                                " values but density has " + std::to_string(d.size()));
  if (h.size() < 2)
    report.Fail(table_path + ".altitude_m",
                "needs at least 2 samples, got " + std::to_string(h.size()));
  for (size_t i = 0; i < h.size(); ++i) {
    std::string altitude_path = Index(table_path + ".altitude_m", i);
    CheckNumber(report, altitude_path, h[i], kFinite);
    if (i > 0 && !(h[i] > h[i - 1]))
      report.FailValue(altitude_path, h[i],
                       "must exceed altitude_m[" + std::to_string(i - 1) + "] = " +
                           FormatNumber(h[i - 1]) + " (altitudes must strictly increase)");
    CheckNumber(report, Index(table_path + ".density", i), d[i], kNonNegative);
  }
}

void CheckPhase(const Reporter& report, const std::string& path, const PhaseFunction& phase) {
  bool takes_g = phase.kind == PhaseKind::kHenyeyGreenstein ||
                 phase.kind == PhaseKind::kCornetteShanks;
  if (takes_g) {
    CheckNumber(report, path + ".g", phase.g, kAsymmetry);
  } else if (phase.g != 0.0) {
    report.FailValue(path + ".g", phase.g,
                     std::string("is not used by the ") + ToString(phase.kind) +
                         " phase function (only henyey-greenstein and cornette-shanks take g)");
  }
}

// ---------------------------------------------------------------------------
// Reading the TOML tree.

struct PhaseName {
  std::string_view name;
  PhaseKind kind;
};
constexpr PhaseName kPhaseNames[] = {
    {"rayleigh", PhaseKind::kRayleigh},
    {"isotropic", PhaseKind::kIsotropic},
    {"henyey-greenstein", PhaseKind::kHenyeyGreenstein},
    {"cornette-shanks", PhaseKind::kCornetteShanks},
};

// The table forms of a coefficient (see examples/atmospheres/README.md).
enum class CoefficientForm { kRayleighLaw, kAngstrom, kRefractiveIndex, kTabulated, kCrossSection };
struct CoefficientFormKeys {
  CoefficientForm form;
  std::vector<std::string_view> keys;
};
const CoefficientFormKeys kCoefficientForms[] = {
    {CoefficientForm::kRayleighLaw, {"rayleigh_at_1um"}},
    {CoefficientForm::kAngstrom, {"angstrom_reference", "reference_nm", "exponent"}},
    {CoefficientForm::kRefractiveIndex,
     {"refractive_index", "number_density_per_m3", "depolarization"}},
    {CoefficientForm::kTabulated, {"wavelength_nm", "per_m", "interpolation"}},
    {CoefficientForm::kCrossSection, {"cross_section", "molecules_per_m3"}},
};
constexpr const char* kCoefficientFormsText =
    "{ rayleigh_at_1um }, { angstrom_reference, reference_nm, exponent }, "
    "{ refractive_index, number_density_per_m3, depolarization }, { wavelength_nm, per_m[, interpolation] } or "
    "{ cross_section, molecules_per_m3 }";

// A per-wavelength value at the wavelengths the file is read at, and the
// form the file gave it in.
struct SpectralValue {
  Spectrum values{0.0};
  SpectralForm form;
};

// A length given as <base>_km or <base>_m, as written and in metres.
struct Length {
  std::string path;
  double written;
  double metres;
};

class FileReader : public TomlReader {
 public:
  // With `wavelengths_nm`, the atmosphere is read at those wavelengths
  // instead of the file's [spectrum] (a spectral bake's batches); values
  // given once per file wavelength then have no meaning and are errors,
  // but for the ground's albedo, read as the smooth reflectance through them.
  FileReader(const std::string& source, std::optional<Spectrum> wavelengths_nm)
      : TomlReader(source), wavelengths_override_(wavelengths_nm) {}

  Atmosphere Read(const toml::table& root) {
    CheckKeys(root, "", {"name", "description", "planet", "spectrum", "sun", "constituents"});
    Atmosphere atmosphere;
    atmosphere.name = RequireString(root, "", "name");
    if (atmosphere.name.empty()) report_.Fail("name", "must not be empty");
    if (const toml::node* node = root.get("description"))
      atmosphere.description = ReadString(*node, "description");

    // The wavelengths first: the planet's albedo given at the file's three
    // is read through them at other wavelengths.
    file_wavelengths_nm_ = kDefaultWavelengthsNm;
    if (const toml::table* spectrum = OptionalTable(root, "", "spectrum")) {
      CheckKeys(*spectrum, "spectrum", {"wavelengths_nm"});
      if (const toml::node* node = spectrum->get("wavelengths_nm"))
        file_wavelengths_nm_ = ReadArray3(*node, "spectrum.wavelengths_nm", kPositive);
    }
    atmosphere.wavelengths_nm = wavelengths_override_ ? *wavelengths_override_ : file_wavelengths_nm_;

    ReadPlanet(RequireTable(root, "", "planet"), atmosphere);

    ReadSun(RequireTable(root, "", "sun"), atmosphere);

    if (const toml::table* constituents = OptionalTable(root, "", "constituents")) {
      // toml++ keeps keys sorted; keep the file's order instead, so that a file
      // and its ToToml() output list constituents alike.
      std::vector<std::tuple<uint32_t, uint32_t, std::string, const toml::node*>> entries;
      for (auto&& [key, node] : *constituents) {
        entries.emplace_back(key.source().begin.line, key.source().begin.column,
                             std::string(key.str()), &node);
      }
      std::sort(entries.begin(), entries.end());
      for (const auto& [line, column, name, node] : entries) {
        std::string path = Join("constituents", name);
        const toml::table* table = node->as_table();
        if (!table) report_.Fail(path, "expected a table, got " + TypeName(*node));
        atmosphere.constituents.push_back(ReadConstituent(*table, path, name, atmosphere));
      }
    }
    return atmosphere;
  }

 private:
  Spectrum ReadArray3(const toml::node& node, const std::string& path,
                      const Interval& interval) const {
    const toml::array* array = node.as_array();
    if (!array || array->size() != kWavelengthCount)
      report_.Fail(path, "expected an array of 3 numbers (one per wavelength), got " +
                             TypeName(node));
    Spectrum value;
    for (int i = 0; i < kWavelengthCount; ++i)
      value[i] = ReadNumber(*array->get(i), Index(path, i), interval);
    return value;
  }

  // A per-wavelength value given as one number for all wavelengths, or as an
  // array of 3 at the file's wavelengths, which read at other wavelengths
  // (a spectral bake's) has no meaning: `elsewhere` lists what would.
  SpectralValue ReadNumberOrArray(const toml::node& node, const std::string& path, const Interval& interval,
                                  const std::string& elsewhere) const {
    SpectralValue value;
    if (node.is_number()) {
      const double number = ReadNumber(node, path, interval);
      value.form.kind = SpectralForm::Kind::kConstant;
      value.form.parameters = {number};
      value.values = Spectrum(number);
      return value;
    }
    if (!node.is_array())
      report_.Fail(path, "expected a number or an array of 3 numbers, got " + TypeName(node));
    if (wavelengths_override_) {
      report_.Fail(path, "gives a value at each of spectrum.wavelengths_nm only; a spectral bake needs it at "
                         "any wavelength: " + elsewhere);
    }
    value.values = ReadArray3(node, path, interval);
    return value;
  }

  // A tabulated spectrum { wavelength_nm = [...], <value_key> = [...] }: at
  // least 2 samples, wavelengths increasing, values in `interval`; with
  // `interpolation` allowed, that key may choose "angstrom" over "linear".
  SpectralForm ReadTable(const toml::table& table, const std::string& path, std::string_view value_key,
                         const Interval& interval, bool interpolation) const {
    const std::string wavelengths_path = path + ".wavelength_nm", values_path = Join(path, value_key);
    auto read_array = [&](std::string_view key, const std::string& key_path, const Interval& range) {
      const toml::array* array = Require(table, path, key).as_array();
      if (!array) report_.Fail(key_path, "expected an array of numbers");
      std::vector<double> values;
      for (std::size_t i = 0; i < array->size(); ++i) {
        values.push_back(ReadNumber(*array->get(i), Index(key_path, i), range));
      }
      return values;
    };
    SpectralForm form;
    form.kind = SpectralForm::Kind::kTabulated;
    form.wavelength_nm = read_array("wavelength_nm", wavelengths_path, kPositive);
    form.values = read_array(value_key, values_path, interval);
    const std::vector<double>& nm = form.wavelength_nm;
    if (nm.size() < 2) report_.Fail(wavelengths_path, "needs at least 2 wavelengths");
    if (form.values.size() != nm.size()) {
      report_.Fail(values_path, "has " + std::to_string(form.values.size()) + " values for " +
                                    std::to_string(nm.size()) + " wavelengths");
    }
    for (std::size_t i = 1; i < nm.size(); ++i) {
      if (!(nm[i] > nm[i - 1])) report_.Fail(Index(wavelengths_path, i), "must exceed the wavelength before it");
    }
    if (const toml::node* node = interpolation ? table.get("interpolation") : nullptr) {
      const std::string interpolation_path = path + ".interpolation";
      const std::string name = ReadString(*node, interpolation_path);
      if (name == ToString(SpectralForm::Interpolation::kAngstrom)) {
        form.interpolation = SpectralForm::Interpolation::kAngstrom;
      } else if (name != ToString(SpectralForm::Interpolation::kLinear)) {
        report_.Fail(interpolation_path, TomlString(name) + " is not an interpolation (expected \"linear\" or "
                                                            "\"angstrom\")");
      }
    }
    if (form.interpolation == SpectralForm::Interpolation::kAngstrom) {
      for (std::size_t i = 0; i < form.values.size(); ++i) {
        if (!(form.values[i] > 0.0))
          report_.FailValue(Index(values_path, i), form.values[i],
                            "must be > 0 with interpolation = \"angstrom\" (a power law through the samples)");
      }
    }
    return form;
  }

  // A table's values at the wavelengths; a linear table must cover them.
  Spectrum TableValues(const SpectralForm& form, const std::string& path, const Spectrum& wavelengths_nm) const {
    const std::vector<double>& nm = form.wavelength_nm;
    for (int c = 0; c < kWavelengthCount; ++c) {
      const double w = wavelengths_nm[c];
      if (form.interpolation == SpectralForm::Interpolation::kLinear && !(w >= nm.front() && w <= nm.back())) {
        report_.Fail(path + ".wavelength_nm", "covers " + FormatNumber(nm.front()) + " to " +
                                                  FormatNumber(nm.back()) + " nm, not the wavelength " +
                                                  FormatNumber(w) + " nm");
      }
    }
    return Evaluate(form, wavelengths_nm);
  }

  Length ReadLength(const toml::table& table, const std::string& path,
                    const std::string& base) const {
    auto [which, node] = ExactlyOne(table, path, {base + "_km", base + "_m"});
    Length length;
    length.path = Join(path, which == 0 ? base + "_km" : base + "_m");
    length.written = ReadNumber(*node, length.path, kPositive);
    length.metres = which == 0 ? length.written * 1000.0 : length.written;
    return length;
  }

  // --- sections ---

  void ReadPlanet(const toml::table& planet, Atmosphere& atmosphere) const {
    CheckKeys(planet, "planet", {"ground_radius_km", "ground_radius_m", "top_radius_km",
                                 "top_radius_m", "ground_albedo"});
    Length ground = ReadLength(planet, "planet", "ground_radius");
    Length top = ReadLength(planet, "planet", "top_radius");
    if (!(top.metres > ground.metres))
      report_.FailValue(top.path, top.written,
                        "must exceed " + ground.path + " = " + FormatNumber(ground.written));
    atmosphere.bottom_radius_m = ground.metres;
    atmosphere.top_radius_m = top.metres;
    const SpectralValue albedo = ReadAlbedo(Require(planet, "planet", "ground_albedo"), atmosphere.wavelengths_nm);
    atmosphere.ground_albedo = albedo.values;
    atmosphere.ground_albedo_form = albedo.form;
  }

  // The ground's albedo: a number, 3 numbers at the file's wavelengths (read
  // at others as the smooth reflectance through them, SmoothReflectance), or
  // a tabulated spectrum { wavelength_nm, albedo }, linear between samples.
  SpectralValue ReadAlbedo(const toml::node& node, const Spectrum& wavelengths_nm) const {
    const std::string path = "planet.ground_albedo";
    SpectralValue albedo;
    if (const toml::table* table = node.as_table()) {
      CheckKeys(*table, path, {"wavelength_nm", "albedo"});
      albedo.form = ReadTable(*table, path, "albedo", kUnit, false);
      albedo.values = TableValues(albedo.form, path, wavelengths_nm);
      return albedo;
    }
    if (!node.is_number() && !node.is_array())
      report_.Fail(path, "expected a number, an array of 3 numbers or a table { wavelength_nm, albedo }, got " +
                             TypeName(node));
    if (node.is_number()) return ReadNumberOrArray(node, path, kUnit, "");
    const Spectrum samples = ReadArray3(node, path, kUnit);
    albedo.values = samples;
    if (!wavelengths_override_) return albedo;
    for (int i = 0; i < kWavelengthCount; ++i) {
      for (int j = 0; j < i; ++j) {
        if (file_wavelengths_nm_[i] == file_wavelengths_nm_[j] && samples[i] != samples[j]) {
          report_.Fail(path, "gives " + FormatNumber(samples[j]) + " and " + FormatNumber(samples[i]) +
                                 " at the same wavelength " + FormatNumber(file_wavelengths_nm_[i]) +
                                 " nm; a spectral bake reads no spectrum through them (give a table "
                                 "{ wavelength_nm, albedo })");
        }
      }
    }
    for (int c = 0; c < kWavelengthCount; ++c)
      albedo.values[c] = SmoothReflectance(file_wavelengths_nm_, samples, wavelengths_nm[c]);
    return albedo;
  }

  // The sun's irradiance at the wavelengths: a number, 3 numbers,
  // "astm-g173", the 10 nm bin means of the ASTM G173-03 extraterrestrial
  // spectrum from each wavelength up (bake/spectral_data.h), or that
  // spectrum at another distance from the sun, { spectrum = "astm-g173",
  // distance_au = d }, scaled by the inverse-square law 1 / d^2.
  SpectralValue ReadSolarIrradiance(const toml::node& node, const Spectrum& wavelengths_nm) const {
    const std::string path = "sun.irradiance_w_m2_nm";
    const std::string spectrum_forms =
        "a spectrum (\"" + std::string(kAstmG173) + "\", { spectrum = \"" + std::string(kAstmG173) + "\", distance_au })";
    if (node.is_number() || node.is_array()) {
      return ReadNumberOrArray(node, path, kNonNegative, "one number or " + spectrum_forms);
    }
    SpectralValue irradiance;
    irradiance.form.kind = SpectralForm::Kind::kSolarSpectrum;
    irradiance.form.parameters = {1.0};
    std::string name_path = path;
    if (const toml::table* table = node.as_table()) {
      CheckKeys(*table, path, {"spectrum", "distance_au"});
      name_path = path + ".spectrum";
      irradiance.form.name = RequireString(*table, path, "spectrum");
      irradiance.form.parameters = {ReadNumber(Require(*table, path, "distance_au"), path + ".distance_au", kPositive)};
    } else if (node.is_string()) {
      irradiance.form.name = **node.as_string();
    } else {
      report_.Fail(path, "expected a number, an array of 3 numbers or " + spectrum_forms + ", got " + TypeName(node));
    }
    const std::string& name = irradiance.form.name;
    if (name != kAstmG173) {
      report_.Fail(name_path, "unknown spectrum \"" + name + "\" (expected \"" + std::string(kAstmG173) + "\")");
    }
    for (int i = 0; i < kWavelengthCount; ++i) {
      if (!AstmG173BinCovers(wavelengths_nm[i])) {
        report_.Fail(name_path, "\"" + std::string(kAstmG173) + "\" covers 280 to 4000 nm; a 10 nm bin from " +
                                    FormatNumber(wavelengths_nm[i]) + " nm is outside it");
      }
    }
    irradiance.values = Evaluate(irradiance.form, wavelengths_nm);
    for (int i = 0; i < kWavelengthCount; ++i) {
      if (!std::isfinite(irradiance.values[i]))
        report_.Fail(path, "evaluates to " + FormatNumber(irradiance.values[i]) + " at " +
                               FormatNumber(wavelengths_nm[i]) + " nm");
    }
    return irradiance;
  }

  void ReadSun(const toml::table& sun, Atmosphere& atmosphere) const {
    CheckKeys(sun, "sun", {"irradiance_w_m2_nm", "angular_radius_rad", "angular_radius_deg",
                           "lowest_zenith_deg", "mu_s_min"});
    const SpectralValue irradiance =
        ReadSolarIrradiance(Require(sun, "sun", "irradiance_w_m2_nm"), atmosphere.wavelengths_nm);
    atmosphere.solar_irradiance = irradiance.values;
    atmosphere.solar_irradiance_form = irradiance.form;
    auto [radius_key, radius] = ExactlyOne(sun, "sun", {"angular_radius_rad", "angular_radius_deg"});
    if (radius_key == 0) {
      atmosphere.sun_angular_radius_rad = ReadNumber(*radius, "sun.angular_radius_rad", kSunRadiusRad);
    } else {
      const double degrees = ReadNumber(*radius, "sun.angular_radius_deg", kSunRadiusDeg);
      atmosphere.sun_angular_radius_rad = degrees * kPi / 180.0;
      if (!kSunRadiusRad.Contains(atmosphere.sun_angular_radius_rad))
        report_.FailValue("sun.angular_radius_deg", degrees, "is outside [5.73e-5, 90) (1e-6 rad to 90 deg)");
    }
    // mu_s_min is what the tables use; lowest_zenith_deg is what people think
    // in. The writer emits mu_s_min because cos(acos(x)) need not return x.
    auto [lowest_key, lowest] = ExactlyOne(sun, "sun", {"lowest_zenith_deg", "mu_s_min"});
    atmosphere.mu_s_min =
        lowest_key == 0
            ? std::cos(ReadNumber(*lowest, "sun.lowest_zenith_deg", kLowestZenithDeg) * kPi / 180.0)
            : ReadNumber(*lowest, "sun.mu_s_min", kMuSMin);
  }

  Constituent ReadConstituent(const toml::table& table, const std::string& path,
                              const std::string& name, const Atmosphere& atmosphere) const {
    CheckKeys(table, path, {"phase", "scattering_per_m", "absorption_per_m", "density"});
    Constituent constituent;
    constituent.name = name;
    const SpectralValue scattering = ReadCoefficient(Require(table, path, "scattering_per_m"),
                                                     path + ".scattering_per_m", atmosphere.wavelengths_nm);
    constituent.scattering_per_m = scattering.values;
    constituent.scattering_form = scattering.form;
    if (const toml::node* node = table.get("absorption_per_m")) {
      const SpectralValue absorption = ReadCoefficient(*node, path + ".absorption_per_m", atmosphere.wavelengths_nm);
      constituent.absorption_per_m = absorption.values;
      constituent.absorption_form = absorption.form;
    } else {
      constituent.absorption_form.kind = SpectralForm::Kind::kConstant;
      constituent.absorption_form.parameters = {0.0};
    }

    // A pure absorber (ozone) never scatters, so its phase function would be
    // noise in the file; anything that scatters must say how.
    const toml::node* phase = table.get("phase");
    if (phase) {
      constituent.phase = ReadPhase(*phase, path + ".phase");
    } else if (constituent.scattering_per_m != Spectrum(0.0)) {
      report_.Fail(path + ".phase", "missing (required for a constituent that scatters)");
    }

    constituent.density = ReadDensity(Require(table, path, "density"), path + ".density");
    CheckDensityProfile(report_, path + ".density", constituent.density,
                        atmosphere.top_radius_m - atmosphere.bottom_radius_m);
    return constituent;
  }

  PhaseFunction ReadPhase(const toml::node& node, const std::string& path) const {
    const toml::table* table = node.as_table();
    if (!table) report_.Fail(path, "expected a table such as { function = \"rayleigh\" }, got " +
                                       TypeName(node));
    CheckKeys(*table, path, {"function", "g"});
    std::string name = RequireString(*table, path, "function");
    const PhaseName* match = std::find_if(std::begin(kPhaseNames), std::end(kPhaseNames),
                                          [&](const PhaseName& p) { return p.name == name; });
    if (match == std::end(kPhaseNames))
      report_.Fail(path + ".function",
                   TomlString(name) +
                       " is not a phase function (expected rayleigh, isotropic, "
                       "henyey-greenstein or cornette-shanks)");
    PhaseFunction phase;
    phase.kind = match->kind;
    bool takes_g = phase.kind == PhaseKind::kHenyeyGreenstein ||
                   phase.kind == PhaseKind::kCornetteShanks;
    const toml::node* g = table->get("g");
    if (takes_g) {
      if (!g) report_.Fail(path + ".g", "missing (required by the " + name + " phase function)");
      phase.g = ReadNumber(*g, path + ".g", kAsymmetry);
    } else if (g) {
      report_.Fail(path + ".g", "not allowed for the " + name +
                                    " phase function (only henyey-greenstein and "
                                    "cornette-shanks take g)");
    }
    return phase;
  }

  SpectralValue ReadCoefficient(const toml::node& node, const std::string& path,
                                const Spectrum& wavelengths_nm) const {
    if (node.is_number() || node.is_array()) {
      return ReadNumberOrArray(node, path, kNonNegative,
                               "one number, a law, a tabulated spectrum or a cross-section");
    }
    const toml::table* table = node.as_table();
    if (!table)
      report_.Fail(path, "expected a number, an array of 3 numbers or a table " +
                             std::string(kCoefficientFormsText) + ", got " + TypeName(node));
    if (table->empty())
      report_.Fail(path, "empty table (expected " + std::string(kCoefficientFormsText) + ")");

    // The first key picks the form; every other key must belong to it.
    const CoefficientFormKeys* form = nullptr;
    std::string_view form_key;
    for (auto&& [key, value] : *table) {
      const CoefficientFormKeys* owner = nullptr;
      for (const CoefficientFormKeys& candidate : kCoefficientForms) {
        const auto& keys = candidate.keys;
        if (std::find(keys.begin(), keys.end(), key.str()) != keys.end()) owner = &candidate;
      }
      if (!owner)
        report_.Fail(Join(path, key.str()),
                     "unknown key (expected " + std::string(kCoefficientFormsText) + ")");
      if (form && owner != form)
        report_.Fail(Join(path, key.str()), "cannot be combined with " + Join(path, form_key) +
                                                " (they belong to different forms)");
      if (!form) form_key = key.str();
      form = owner;
    }

    SpectralForm result;
    std::string coverage_path = path;
    switch (form->form) {
      case CoefficientForm::kRayleighLaw:
        result.kind = SpectralForm::Kind::kRayleighLaw;
        result.parameters = {
            ReadNumber(Require(*table, path, "rayleigh_at_1um"), path + ".rayleigh_at_1um", kNonNegative)};
        break;
      case CoefficientForm::kAngstrom:
        result.kind = SpectralForm::Kind::kAngstrom;
        result.parameters = {
            ReadNumber(Require(*table, path, "angstrom_reference"), path + ".angstrom_reference", kNonNegative),
            ReadNumber(Require(*table, path, "reference_nm"), path + ".reference_nm", kPositive),
            ReadNumber(Require(*table, path, "exponent"), path + ".exponent", kFinite)};
        break;
      case CoefficientForm::kRefractiveIndex:
        result.kind = SpectralForm::Kind::kRefractiveIndex;
        result.parameters = {
            ReadNumber(Require(*table, path, "refractive_index"), path + ".refractive_index", kPositive),
            ReadNumber(Require(*table, path, "number_density_per_m3"), path + ".number_density_per_m3", kPositive),
            ReadNumber(Require(*table, path, "depolarization"), path + ".depolarization", kDepolarization)};
        break;
      case CoefficientForm::kTabulated:
        result = ReadTable(*table, path, "per_m", kNonNegative, true);
        break;
      case CoefficientForm::kCrossSection: {
        // beta = sigma(lambda) N, sigma linear between the published samples.
        result.kind = SpectralForm::Kind::kCrossSection;
        result.name = RequireString(*table, path, "cross_section");
        coverage_path = path + ".cross_section";
        if (result.name != kOzone233K) {
          report_.Fail(coverage_path, "unknown cross-section \"" + result.name + "\" (expected \"" +
                                          std::string(kOzone233K) + "\")");
        }
        result.parameters = {
            ReadNumber(Require(*table, path, "molecules_per_m3"), path + ".molecules_per_m3", kNonNegative)};
        const SpectralData& sigma = OzoneCrossSection233K();
        for (int i = 0; i < kWavelengthCount; ++i) {
          if (!OzoneCrossSectionCovers(wavelengths_nm[i])) {
            report_.Fail(coverage_path, "\"" + result.name + "\" covers " +
                                            FormatNumber(sigma.wavelength_nm.front()) + " to " +
                                            FormatNumber(sigma.wavelength_nm.back()) + " nm, not the wavelength " +
                                            FormatNumber(wavelengths_nm[i]) + " nm");
          }
        }
        break;
      }
    }
    SpectralValue value;
    value.form = result;
    value.values = result.kind == SpectralForm::Kind::kTabulated ? TableValues(result, path, wavelengths_nm)
                                                                 : Evaluate(result, wavelengths_nm);
    for (int i = 0; i < kWavelengthCount; ++i) {
      if (!std::isfinite(value.values[i]))
        report_.Fail(path, "evaluates to " + FormatNumber(value.values[i]) + " at " +
                               FormatNumber(wavelengths_nm[i]) + " nm");
    }
    return value;
  }

  DensityProfile ReadDensity(const toml::node& node, const std::string& path) const {
    const toml::table* table = node.as_table();
    if (!table) report_.Fail(path, "expected a table, got " + TypeName(node));
    CheckKeys(*table, path, {"layers", "tabulated"});
    auto [which, value] = ExactlyOne(*table, path, {"layers", "tabulated"});
    DensityProfile profile;
    if (which == 0) {
      profile.kind = DensityProfile::Kind::kLayers;
      std::string layers_path = path + ".layers";
      const toml::array* layers = value->as_array();
      if (!layers) report_.Fail(layers_path, "expected an array of tables, got " + TypeName(*value));
      for (size_t i = 0; i < layers->size(); ++i) {
        std::string layer_path = Index(layers_path, i);
        const toml::table* layer = layers->get(i)->as_table();
        if (!layer) report_.Fail(layer_path, "expected a table, got " + TypeName(*layers->get(i)));
        CheckKeys(*layer, layer_path, {"width_m", "exp_term", "exp_scale_per_m",
                                       "linear_term_per_m", "constant_term"});
        auto term = [&](std::string_view key) {
          const toml::node* n = layer->get(key);
          return n ? ReadNumber(*n, Join(layer_path, key)) : 0.0;
        };
        DensityLayer l;
        l.width_m = term("width_m");
        l.exp_term = term("exp_term");
        l.exp_scale_per_m = term("exp_scale_per_m");
        l.linear_term_per_m = term("linear_term_per_m");
        l.constant_term = term("constant_term");
        profile.layers.push_back(l);
      }
    } else {
      profile.kind = DensityProfile::Kind::kTabulated;
      std::string table_path = path + ".tabulated";
      const toml::table* tabulated = value->as_table();
      if (!tabulated) report_.Fail(table_path, "expected a table, got " + TypeName(*value));
      CheckKeys(*tabulated, table_path, {"altitude_m", "density"});
      profile.altitudes_m = ReadNumbers(Require(*tabulated, table_path, "altitude_m"),
                                        table_path + ".altitude_m");
      profile.densities =
          ReadNumbers(Require(*tabulated, table_path, "density"), table_path + ".density");
    }
    return profile;
  }

  std::vector<double> ReadNumbers(const toml::node& node, const std::string& path) const {
    const toml::array* array = node.as_array();
    if (!array) report_.Fail(path, "expected an array of numbers, got " + TypeName(node));
    std::vector<double> values;
    for (size_t i = 0; i < array->size(); ++i)
      values.push_back(ReadNumber(*array->get(i), Index(path, i)));
    return values;
  }

  std::optional<Spectrum> wavelengths_override_;
  Spectrum file_wavelengths_nm_ = kDefaultWavelengthsNm;  // [spectrum] of the file
};

}  // namespace

Atmosphere ParseAtmosphere(std::string_view toml_text, const std::string& source_name,
                           std::optional<Spectrum> wavelengths_nm) {
  toml::table root = ParseDocument(toml_text, source_name);
  Atmosphere atmosphere = FileReader(source_name, wavelengths_nm).Read(root);
  Validate(atmosphere, source_name);
  return atmosphere;
}

void Validate(const Atmosphere& a, const std::string& source_name) {
  Reporter report(source_name);
  if (a.name.empty()) report.Fail("name", "must not be empty");
  CheckNumber(report, "planet.ground_radius_m", a.bottom_radius_m, kPositive);
  CheckNumber(report, "planet.top_radius_m", a.top_radius_m, kPositive);
  if (!(a.top_radius_m > a.bottom_radius_m))
    report.FailValue("planet.top_radius_m", a.top_radius_m,
                     "must exceed planet.ground_radius_m = " + FormatNumber(a.bottom_radius_m));
  CheckSpectrum(report, "planet.ground_albedo", a.ground_albedo, kUnit);
  CheckSpectrum(report, "spectrum.wavelengths_nm", a.wavelengths_nm, kPositive);
  CheckSpectrum(report, "sun.irradiance_w_m2_nm", a.solar_irradiance, kNonNegative);
  CheckNumber(report, "planet.ground_radius_m", a.bottom_radius_m, kRadiusRange);
  CheckNumber(report, "planet.top_radius_m", a.top_radius_m, kRadiusRange);
  CheckSpectrum(report, "sun.irradiance_w_m2_nm", a.solar_irradiance, kIrradianceRange);
  CheckNumber(report, "sun.angular_radius_rad", a.sun_angular_radius_rad, kSunRadiusRad);
  CheckNumber(report, "sun.mu_s_min", a.mu_s_min, kMuSMin);

  std::set<std::string> names;
  for (const Constituent& c : a.constituents) {
    if (c.name.empty()) report.Fail("constituents", "a constituent has an empty name");
    std::string path = Join("constituents", c.name);
    if (!names.insert(c.name).second) report.Fail(path, "appears more than once");
    CheckSpectrum(report, path + ".scattering_per_m", c.scattering_per_m, kNonNegative);
    CheckSpectrum(report, path + ".absorption_per_m", c.absorption_per_m, kNonNegative);
    CheckSpectrum(report, path + ".scattering_per_m", c.scattering_per_m, kCoefficientRange);
    CheckSpectrum(report, path + ".absorption_per_m", c.absorption_per_m, kCoefficientRange);
    CheckPhase(report, path + ".phase", c.phase);
    CheckDensityProfile(report, path + ".density", c.density, a.top_radius_m - a.bottom_radius_m);
  }
}

}  // namespace skybake
