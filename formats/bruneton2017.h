// A skybake set resampled into the parameterization and texel layout of
// Bruneton's 2017 rewrite of "Precomputed Atmospheric Scattering"
// (ebruneton/precomputed_atmospheric_scattering, functions.glsl), which the
// runtimes that copy it read (takram's three-atmosphere, Unity and Godot
// ports): transmittance.exr (transmittance, not optical depth),
// scattering.exr (rgb: single Rayleigh and all higher orders divided by the
// Rayleigh phase function; alpha: single Mie red, so that a runtime built
// for the combined layout reads it too), single_mie_scattering.exr,
// irradiance.exr (indirect ground irradiance), and parameters.json.
//
// Each texel holds the value skybake's CPU twin reads at that texel's
// (r, mu, mu_s, nu): the set's own accuracy, resampled, not a second bake.
// A sun below the set's lowest (parameters.mu_s_min) has no light in the set,
// so texels of a lower export mu_s_min are zero.
#pragma once

#include <filesystem>

#include "bake/bake.h"
#include "formats/table_file.h"

namespace skybake {

struct Bruneton2017Layout {
  // Bruneton's constants (constants.h of his reference implementation).
  int transmittance_width = 256;   // mu
  int transmittance_height = 64;   // r
  int scattering_r_size = 32;
  int scattering_mu_size = 128;    // two halves: rays that meet the ground, then the others
  int scattering_mu_s_size = 32;
  int scattering_nu_size = 8;
  int irradiance_width = 64;       // mu_s
  int irradiance_height = 16;      // r
  // Cosine of the lowest sun the scattering table's mu_s axis reaches.
  double mu_s_min = -0.2;
};

// The geometry at a texel of each table (texel centres, as Bruneton's
// precomputation shaders place them).
struct RMu {
  double r, mu;
};
RMu Bruneton2017TransmittanceTexel(const Bruneton2017Layout& layout, double bottom_radius, double top_radius, int x,
                                   int y);
RMu Bruneton2017IrradianceTexel(const Bruneton2017Layout& layout, double bottom_radius, double top_radius, int x,
                                int y);  // mu is mu_s
struct ScatteringTexelGeometry {
  double r, mu, mu_s, nu;
  bool ray_intersects_ground;
};
// x = nu index * mu_s size + mu_s index, y the mu row, z the r slice.
ScatteringTexelGeometry Bruneton2017ScatteringTexel(const Bruneton2017Layout& layout, double bottom_radius,
                                                    double top_radius, int x, int y, int z);

struct Bruneton2017Tables {
  TableImage transmittance, scattering, single_mie_scattering, irradiance;
};
// InputError for a set the layout cannot hold: a scene's restricted or partial
// tables, a spectral bake's colour channels, a Mie phase other than
// Cornette-Shanks (the only one those runtimes evaluate).
Bruneton2017Tables ResampleToBruneton2017(const LutSet& luts, const Bruneton2017Layout& layout, PixelType pixel_type);

// The parameters the runtimes take, under three-atmosphere's
// AtmosphereParameters names and units (radii in metres, coefficients per
// kilometre), as JSON text.
std::string Bruneton2017ParametersJson(const LutSet& luts, const Bruneton2017Layout& layout);

// Writes the four EXR files and parameters.json into `dir`, all or none.
void WriteBruneton2017Set(const LutSet& luts, const Bruneton2017Layout& layout, PixelType pixel_type,
                          const std::filesystem::path& dir);

}  // namespace skybake
