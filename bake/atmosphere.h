// The resolved atmosphere: everything the bake, the fit and the reference
// solvers know about a planet, in SI units (metres, m^-1, radians).
// Configuration files are parsed and validated into this (see config.h);
// nothing downstream re-reads the file.
#pragma once

#include <string>
#include <vector>

#include "bake/spectral_form.h"
#include "core/spectrum.h"

namespace skybake {

// density(h) = clamp(exp_term * exp(exp_scale * h) + linear_term * h + constant_term, 0, 1)
// for altitudes h inside the layer (h measured from the ground, not from the
// layer's base, as in Bruneton's 2017 reference model).
struct DensityLayer {
  double width_m = 0.0;  // ignored for the last layer, which extends to the top
  double exp_term = 0.0;
  double exp_scale_per_m = 0.0;
  double linear_term_per_m = 0.0;
  double constant_term = 0.0;
};

// Relative density (1 = the constituent's coefficients apply as given) as a
// function of altitude above the ground.
struct DensityProfile {
  enum class Kind { kLayers, kTabulated };
  Kind kind = Kind::kLayers;
  std::vector<DensityLayer> layers;  // kLayers: bottom to top
  // kTabulated: strictly increasing altitudes, linear interpolation between
  // samples, constant extension below the first and above the last sample.
  std::vector<double> altitudes_m;
  std::vector<double> densities;

  double At(double altitude_m) const;
  // Altitudes where the profile has a kink or jump (layer boundaries, where a
  // linear layer is clamped at 0 or 1, tabulated samples), sorted, for
  // integrators that must not step across them blindly.
  std::vector<double> Breakpoints() const;
};

enum class PhaseKind { kIsotropic, kRayleigh, kHenyeyGreenstein, kCornetteShanks };

struct PhaseFunction {
  PhaseKind kind = PhaseKind::kIsotropic;
  double g = 0.0;  // asymmetry, |g| < 1; only for Henyey-Greenstein and Cornette-Shanks

  // Phase function value per steradian for the cosine of the scattering angle;
  // integrates to 1 over the sphere.
  double Evaluate(double cos_theta) const;
  bool operator==(const PhaseFunction& o) const { return kind == o.kind && g == o.g; }
};

const char* ToString(PhaseKind kind);

struct Constituent {
  std::string name;
  DensityProfile density;
  Spectrum scattering_per_m{0.0};  // at relative density 1
  Spectrum absorption_per_m{0.0};  // at relative density 1
  // How the file gave them (bake/spectral_form.h); kValues when built by hand.
  SpectralForm scattering_form, absorption_form;
  PhaseFunction phase;

  Spectrum Extinction() const { return scattering_per_m + absorption_per_m; }
};

struct Atmosphere {
  std::string name;
  std::string description;
  double bottom_radius_m = 0.0;  // ground
  double top_radius_m = 0.0;     // top of the atmosphere
  Spectrum ground_albedo{0.0};
  Spectrum wavelengths_nm{680.0, 550.0, 440.0};
  Spectrum solar_irradiance{0.0};  // at the top of the atmosphere, W m^-2 nm^-1
  // How the file gave the albedo and the sun (bake/spectral_form.h): the
  // canonical TOML writes these forms where they give the values above;
  // kValues when built by hand.
  SpectralForm ground_albedo_form, solar_irradiance_form;
  double sun_angular_radius_rad = 0.0;
  double mu_s_min = -0.2;  // cosine of the lowest sun zenith the tables cover
  std::vector<Constituent> constituents;

  // Total scattering / extinction coefficient at an altitude above the ground.
  Spectrum ScatteringAt(double altitude_m) const;
  Spectrum ExtinctionAt(double altitude_m) const;
};

}  // namespace skybake
