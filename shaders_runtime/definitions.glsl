// skybake GLSL runtime: types shared by the runtime's functions.
// The C++ twin defines the same names in shaders_runtime/glsl_shim.h, so the
// function bodies compile unchanged as GLSL and as C++.
#ifdef GL_ES
precision highp float;
precision highp int;
precision highp sampler2D;
precision highp sampler3D;
#endif

#define Number float
#define IN(type) in type
#define OUT(type) out type
#define TransmittanceTexture sampler2D
#define ScatteringTexture sampler3D
#define IrradianceTexture sampler2D
// The per-frame tables an engine renders (per_frame.glsl).
#define SkyViewTexture sampler2D
#define AerialPerspectiveTexture sampler3D
// Bilinear / trilinear lookups of a table (each language's own sampling; the
// WGSL translation samples a separate texture with a shared sampler).
#define SampleTexture2D texture
#define SampleTexture3D texture

const Number PI = 3.14159265358979323846;

// Phase function applied at run time to the single Mie scattering table.
const int PHASE_NONE = 0;
const int PHASE_HENYEY_GREENSTEIN = 1;
const int PHASE_CORNETTE_SHANKS = 2;

// Coefficient profiles for integrating along short segments (aerial
// perspective near the horizon, aerial_perspective.glsl): samples at the altitudes
// (top_radius - bottom_radius) * (i / (ALTITUDE_PROFILE_SIZE - 1))^2, dense
// near the ground where the aerosols' scale height is short.
const int ALTITUDE_PROFILE_SIZE = 64;

struct AtmosphereParameters {
  // Solar irradiance at the top of the atmosphere, W m^-2 nm^-1 per channel.
  vec3 solar_irradiance;
  Number sun_angular_radius;  // radians
  Number bottom_radius;       // metres
  Number top_radius;          // metres
  // Cosine of the lowest sun zenith angle the tables cover.
  Number mu_s_min;
  // Phase function of the "Mie" constituents (those sharing the first
  // Henyey-Greenstein or Cornette-Shanks phase function), whose single
  // scattering is kept in its own table: PHASE_* and asymmetry g.
  int mie_phase;
  Number mie_g;
  // Ratio of the Mie constituents' scattering to the others', per channel at
  // the ground; only used to rebuild single Mie from alpha when the
  // bake packed its red channel into the scattering table.
  vec3 mie_to_rayleigh_scattering_ratio;
  int single_mie_in_scattering_alpha;  // 1 if packed, 0 if a separate table
  // 1 where the channels are colour (CIE XYZ of a spectral bake), 0 where
  // each is one wavelength. A colour's transmittance table holds the optical
  // depth of sunlight's colour, which does not add along a ray (light that
  // crosses two stretches is not attenuated by the product of their colour
  // transmittances), so aerial perspective then integrates a segment's
  // optical depth along it instead of subtracting two table values.
  int transmittance_is_colour;
  // Table sizes.
  int transmittance_width;   // mu
  int transmittance_height;  // r
  int scattering_r_size;
  int scattering_mu_size;
  int scattering_mu_s_size;
  int scattering_nu_size;
  // The radii and sun cosines the scattering tables cover: the whole
  // atmosphere (bottom_radius to top_radius, mu_s_min to 1) unless a scene's
  // bake restricted them to the altitudes and suns the scene shows.
  Number scattering_r_min;
  Number scattering_r_max;
  Number scattering_mu_s_min;
  Number scattering_mu_s_max;
  // The first mu_s column of the scattering tables that lies at the same
  // sun for every ray; below it each ray has its own columns, placed from
  // its shadow edge (shadow_edge.glsl, "The sun axis after sunset"). 0: every
  // column is the same for every ray.
  int scattering_mu_s_split;
  int irradiance_width;   // mu_s
  int irradiance_height;  // r
  // Extinction and scattering coefficients, m^-1, at the profile altitudes:
  // all constituents; the Mie group; every other group (applied with the
  // Rayleigh phase function, as the scattering table is).
  vec3 extinction_profile[ALTITUDE_PROFILE_SIZE];
  vec3 mie_scattering_profile[ALTITUDE_PROFILE_SIZE];
  vec3 rayleigh_scattering_profile[ALTITUDE_PROFILE_SIZE];
};
