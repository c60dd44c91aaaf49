// How an atmosphere file gives a value per wavelength (the forms of
// examples/atmospheres/README.md): one number, a law, a tabulated spectrum,
// a published spectrum, or three numbers at the file's own wavelengths. An
// Atmosphere keeps the form beside the values at its three wavelengths, so
// that its canonical TOML (ToToml) writes the law back rather than three
// numbers, and stays defined at the wavelengths of a spectral bake.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/spectrum.h"

namespace skybake {

// The published data the forms can name (bake/spectral_data.h).
inline constexpr std::string_view kAstmG173 = "astm-g173";    // the solar spectrum
inline constexpr std::string_view kOzone233K = "ozone-233k";  // ozone's cross-section

struct SpectralForm {
  enum class Kind {
    kValues,           // three numbers, at the file's wavelengths only (and an Atmosphere built by hand)
    kConstant,         // one number at every wavelength: parameters {value}
    kRayleighLaw,      // parameters {rayleigh_at_1um}
    kAngstrom,         // parameters {angstrom_reference, reference_nm, exponent}
    kRefractiveIndex,  // parameters {refractive_index, number_density_per_m3, depolarization}
    kTabulated,        // samples wavelength_nm, values, between them `interpolation`
    kCrossSection,     // name (kOzone233K), parameters {molecules_per_m3}
    kSolarSpectrum,    // name (kAstmG173), parameters {distance_au}
  };
  // Between the samples of a table:
  enum class Interpolation {
    kLinear,    // linear; no value outside the samples
    kAngstrom,  // Angstrom's law b (lambda / lambda_i)^-alpha through each pair of
                // neighbours (linear in log b against log lambda), the outer
                // pairs' laws continued beyond the samples; values > 0
  };

  Kind kind = Kind::kValues;
  std::vector<double> parameters;
  std::vector<double> wavelength_nm, values;  // kTabulated: wavelengths increasing
  Interpolation interpolation = Interpolation::kLinear;
  std::string name;

  bool operator==(const SpectralForm& o) const {
    return kind == o.kind && parameters == o.parameters && wavelength_nm == o.wavelength_nm && values == o.values &&
           interpolation == o.interpolation && name == o.name;
  }
};

const char* ToString(SpectralForm::Interpolation interpolation);

// The form's value at `wavelength_nm`; NaN where it has none (kValues, a
// linear table or published data outside their wavelengths).
double Evaluate(const SpectralForm& form, double wavelength_nm);
Spectrum Evaluate(const SpectralForm& form, const Spectrum& wavelengths_nm);

// Where kOzone233K and kAstmG173 give values: the cross-section's samples,
// and the 10 nm bins of the solar spectrum from each wavelength up.
bool OzoneCrossSectionCovers(double wavelength_nm);
bool AstmG173BinCovers(double wavelength_nm);

// The rule by which a spectral bake reads a ground albedo given as three
// numbers `reflectance` at the file's wavelengths `sample_nm`: the smooth
// reflectance spectrum through them,
//   R(lambda) = S(q(lambda)),  S(x) = 1/2 + x / (2 sqrt(1 + x^2)),
// with q the polynomial through (sample_nm[i], S^-1(reflectance[i])), of
// degree 2 for three distinct wavelengths (fewer where wavelengths repeat;
// their values must then agree). This is the space of reflectance spectra
// of Jakob & Hanika 2019, "A Low-Dimensional Function Space for Efficient
// Spectral Upsampling" (Computer Graphics Forum 38(2)), a sigmoid of a
// quadratic, in which pbrt-v4 and Mitsuba 3 turn RGB albedos into spectra:
// smooth, as natural surfaces' reflectances are across the visible, and
// within [0, 1] at every wavelength, which no polynomial or power law
// through the samples is. It gives the samples exactly at their own
// wavelengths. S reaches 0 and 1 only at infinity, so the fit takes a
// reflectance below 0.001 or above 0.999 as 0.001 or 0.999 (between and
// beyond the samples; at a sample's wavelength its value stands).
double SmoothReflectance(const Spectrum& sample_nm, const Spectrum& reflectance, double wavelength_nm);

}  // namespace skybake
