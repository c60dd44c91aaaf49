#include "bake/spectral_form.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "bake/physics.h"
#include "bake/spectral_data.h"
#include "core/interpolation.h"

namespace skybake {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The 10 nm bins of data/astm_g173_03.csv (280-4000 nm).
constexpr double kAstmFirstNm = 280.0, kAstmLastNm = 4000.0, kAstmBinNm = 10.0;

const std::vector<double>& OzoneCrossSectionValues() {
  static const std::vector<double> values = [] {
    std::vector<double> v;
    for (const glm::dvec3& sample : OzoneCrossSection233K().values) v.push_back(sample.x);
    return v;
  }();
  return values;
}

// Angstrom's law through the neighbours around `wavelength_nm`, or through
// the outer pair beyond the samples.
double AngstromBetweenSamples(const std::vector<double>& nm, const std::vector<double>& values, double wavelength_nm) {
  const std::size_t n = nm.size();
  const std::size_t above = static_cast<std::size_t>(std::upper_bound(nm.begin(), nm.end(), wavelength_nm) - nm.begin());
  if (above > 0 && nm[above - 1] == wavelength_nm) return values[above - 1];
  const std::size_t i = std::clamp<std::size_t>(above, 1, n - 1) - 1;
  const double slope = std::log(values[i + 1] / values[i]) / std::log(nm[i + 1] / nm[i]);  // -alpha
  return values[i] * std::pow(wavelength_nm / nm[i], slope);
}

double Tabulated(const SpectralForm& form, double wavelength_nm) {
  const std::vector<double>& nm = form.wavelength_nm;
  if (nm.size() < 2 || form.values.size() != nm.size()) return kNaN;
  if (form.interpolation == SpectralForm::Interpolation::kAngstrom) {
    return AngstromBetweenSamples(nm, form.values, wavelength_nm);
  }
  if (!(wavelength_nm >= nm.front() && wavelength_nm <= nm.back())) return kNaN;
  return PiecewiseLinear(nm, form.values, wavelength_nm);
}

// Jakob & Hanika's sigmoid, 1/2 + x / (2 sqrt(1 + x^2)), and its inverse.
double Sigmoid(double x) { return 0.5 + 0.5 * (x / std::hypot(1.0, x)); }
double InverseSigmoid(double reflectance) {
  constexpr double kLeast = 1e-3;
  const double r = std::clamp(reflectance, kLeast, 1.0 - kLeast);
  return (2.0 * r - 1.0) / (2.0 * std::sqrt(r * (1.0 - r)));
}

}  // namespace

const char* ToString(SpectralForm::Interpolation interpolation) {
  switch (interpolation) {
    case SpectralForm::Interpolation::kLinear:
      return "linear";
    case SpectralForm::Interpolation::kAngstrom:
      return "angstrom";
  }
  return "?";
}

bool OzoneCrossSectionCovers(double wavelength_nm) {
  const std::vector<double>& nm = OzoneCrossSection233K().wavelength_nm;
  return wavelength_nm >= nm.front() && wavelength_nm <= nm.back();
}

bool AstmG173BinCovers(double wavelength_nm) {
  return wavelength_nm >= kAstmFirstNm && wavelength_nm + kAstmBinNm <= kAstmLastNm;
}

double Evaluate(const SpectralForm& form, double wavelength_nm) {
  const std::vector<double>& p = form.parameters;
  auto has = [&](std::size_t count) { return p.size() == count; };
  switch (form.kind) {
    case SpectralForm::Kind::kValues:
      return kNaN;
    case SpectralForm::Kind::kConstant:
      return has(1) ? p[0] : kNaN;
    case SpectralForm::Kind::kRayleighLaw:
      return has(1) ? RayleighLawCoefficient(p[0], wavelength_nm) : kNaN;
    case SpectralForm::Kind::kAngstrom:
      return has(3) ? AngstromCoefficient(p[0], p[1], p[2], wavelength_nm) : kNaN;
    case SpectralForm::Kind::kRefractiveIndex:
      return has(3) ? RayleighScatteringCoefficient(p[0], p[1], p[2], wavelength_nm * 1e-9) : kNaN;
    case SpectralForm::Kind::kTabulated:
      return Tabulated(form, wavelength_nm);
    case SpectralForm::Kind::kCrossSection:
      if (!has(1) || form.name != kOzone233K || !OzoneCrossSectionCovers(wavelength_nm)) return kNaN;
      return p[0] * PiecewiseLinear(OzoneCrossSection233K().wavelength_nm, OzoneCrossSectionValues(), wavelength_nm);
    case SpectralForm::Kind::kSolarSpectrum:
      // The spectrum at 1 AU, by the inverse-square law at distance_au.
      if (!has(1) || form.name != kAstmG173 || !AstmG173BinCovers(wavelength_nm)) return kNaN;
      return AstmG173ExtraterrestrialBinMean(wavelength_nm, kAstmBinNm) / (p[0] * p[0]);
  }
  return kNaN;
}

Spectrum Evaluate(const SpectralForm& form, const Spectrum& wavelengths_nm) {
  Spectrum values;
  for (int i = 0; i < kWavelengthCount; ++i) values[i] = Evaluate(form, wavelengths_nm[i]);
  return values;
}

double SmoothReflectance(const Spectrum& sample_nm, const Spectrum& reflectance, double wavelength_nm) {
  std::vector<double> nm, x;
  bool grey = true;
  for (int i = 0; i < kWavelengthCount; ++i) {
    if (sample_nm[i] == wavelength_nm) return reflectance[i];
    grey = grey && reflectance[i] == reflectance[0];
    if (std::find(nm.begin(), nm.end(), sample_nm[i]) != nm.end()) continue;
    nm.push_back(sample_nm[i]);
    x.push_back(InverseSigmoid(reflectance[i]));
  }
  if (grey) return reflectance[0];
  // Lagrange's form of the polynomial through the distinct samples.
  double q = 0.0;
  for (std::size_t i = 0; i < nm.size(); ++i) {
    double term = x[i];
    for (std::size_t j = 0; j < nm.size(); ++j) {
      if (j != i) term *= (wavelength_nm - nm[j]) / (nm[i] - nm[j]);
    }
    q += term;
  }
  return Sigmoid(q);
}

}  // namespace skybake
