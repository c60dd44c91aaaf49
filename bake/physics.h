// Closed-form optics used to turn the coefficient forms of an atmosphere file
// into per-wavelength scattering / absorption coefficients (m^-1).
#pragma once

namespace skybake {

// King correction factor (6 + 3p) / (6 - 7p) for a gas of depolarization
// ratio p: the extra scattering of anisotropic molecules over ideal spheres.
double KingFactor(double depolarization);

// Rayleigh's scattering coefficient of a gas (Hoffman & Preetham 2002, eq. for
// beta_R): beta = 8 pi^3 (n^2 - 1)^2 / (3 N lambda^4) * (6 + 3p) / (6 - 7p),
// with n the refractive index, N the number density (m^-3), p the
// depolarization ratio and lambda the wavelength (m). Returns m^-1.
double RayleighScatteringCoefficient(double refractive_index, double number_density_per_m3,
                                     double depolarization, double wavelength_m);

// The lambda^-4 law written from its value at 1 um, as Bruneton's 2017 model
// does (k = 1.24062e-6 m^-1 for Earth air): beta = k * (lambda / 1 um)^-4.
double RayleighLawCoefficient(double at_1um_per_m, double wavelength_nm);

// Angstrom's power law for aerosols: beta = b * (lambda / lambda0)^-alpha.
double AngstromCoefficient(double reference_per_m, double reference_nm, double exponent,
                           double wavelength_nm);

}  // namespace skybake
