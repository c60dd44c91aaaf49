// skybake GLSL runtime: Hoffman & Preetham's analytic scattering model (2002,
// "Rendering Outdoor Light Scattering in Real Time"), the cheapest of the
// run-time models skybake compares (docs/report.md). No tables: a handful of
// exp() per pixel.
//
// Compiled twice, like the runtime's sources: as GLSL after definitions.glsl (it
// uses Number, IN(), PI) and phase_functions.glsl, and as C++ in double
// precision through shaders_runtime/hoffman_preetham.h. It does not depend on
// the sky runtime's other sources.
//
// The model. Two constituents of constant density: air (Rayleigh phase) and
// haze (Henyey-Greenstein phase), with the scattering and extinction
// coefficients they have at the camera. Between the camera and a point at
// distance s, with beta = beta_air + beta_haze the total extinction:
//
//   F_ex(s) = exp(-beta s)
//   L_in(s, theta) = (beta_air(theta) + beta_haze(theta)) / beta * E_sun * (1 - exp(-beta s))
//
// where beta_x(theta) = beta_x,scattering * phase_x(theta) is the angular scattering
// coefficient, theta the angle between the view ray and the sun, and E_sun the
// sunlight at the camera. A surface at distance s is seen as
// L0 F_ex(s) + L_in(s, theta).
//
// Sunlight. E_sun = E_sun,0 * exp(-(beta_air l_air(theta_s) + beta_haze l_haze(theta_s)))
// with the optical lengths l(theta) = (slant column / density at the camera) of
// each constituent toward the sun. skybake fit (fit/README.md) fits the
// relative optical path m(theta, h) = slant column / vertical column of each
// constituent; l = m * l_zenith with l_zenith = vertical column / density at
// the camera (8.4 km for Earth's air at the ground, 1.25 km for
// Hoffman & Preetham's haze), a per-frame constant. The caller passes m from
// the generated functions skybake_relative_optical_path_<constituent>(mu,
// altitude_m), so this file needs no table and no generated code.
//
// The two-shell sky. Hoffman & Preetham draw the sky on a dome whose radius
// in each direction is the optical length; air and haze have different
// ones (l_air >> l_haze). Treat each as a shell of constant density from the
// camera out to its own optical length along the view ray. Over the nearer
// distance s1 = min(l_air, l_haze) both scatter, as in L_in above; beyond it,
// up to s2 = max(...), only the longer one does, seen through the first:
//
//   L_sky = E_sun [ (beta_air(theta) + beta_haze(theta)) A(beta, s1)
//                   + exp(-beta s1) beta_long(theta) A(beta_long, s2 - s1) ]
//   A(k, s) = (1 - exp(-k s)) / k
//
// For l_air = l_haze = s this is L_in(s, theta). Aerial perspective to a point at
// distance d uses the same equation with both lengths cut at d (a point
// closer than both shells gives Hoffman & Preetham's L_in(d, theta)).
//
// Phase functions are normalized per steradian: Rayleigh 3/(16 pi) (1 + cos^2 theta);
// Henyey-Greenstein (1 - g^2) / (4 pi (1 + g^2 - 2g cos theta)^1.5) (the source
// prints (1 - g)^2, which does not integrate to 1; its g column -1 ... -30 is
// outside the valid range (-1, 1): use measured values, g ~ 0.7-0.85).

struct HoffmanPreethamParameters {
  vec3 sun_irradiance;       // E_sun,0: at the top of the atmosphere, W m^-2 nm^-1 per channel
  Number sun_angular_radius;  // radians
  vec3 air_scattering;       // m^-1, at the camera's altitude
  vec3 air_extinction;       // m^-1, scattering + absorption, at the camera's altitude
  vec3 haze_scattering;      // m^-1
  vec3 haze_extinction;      // m^-1
  Number haze_g;             // Henyey-Greenstein asymmetry, in (-1, 1)
  // Vertical column above the camera / density at the camera, metres.
  Number air_zenith_optical_length;
  Number haze_zenith_optical_length;
  // Cosine of the zenith angle of the geometric horizon at the camera
  // (-sqrt(1 - (ground radius / camera radius)^2), 0 on the ground).
  Number horizon_cos;
};

// A(k, s) = (1 - exp(-k s)) / k, the length of a segment weighted by its
// transmittance back to the start; s when k s -> 0. In float the quotient
// loses digits as x = k s falls (relative error ~ 6e-8 / x), so below
// x = 0.1 the series s (1 - x/2 + x^2/6 - x^3/24 + x^4/120) replaces it
// (truncation error < x^5 / 720 < 1.4e-8).
Number HoffmanPreethamAttenuatedLength(Number k, Number s) {
  Number x = k * s;
  return x < 0.1 ? s * (1.0 - x * (0.5 - x * (1.0 / 6.0 - x * (1.0 / 24.0 - x / 120.0))))
                 : (1.0 - exp(-x)) / k;
}

vec3 HoffmanPreethamAttenuatedLength(IN(vec3) k, Number s) {
  return vec3(HoffmanPreethamAttenuatedLength(k.x, s), HoffmanPreethamAttenuatedLength(k.y, s),
              HoffmanPreethamAttenuatedLength(k.z, s));
}

// F_ex(s): transmittance over a distance s of both constituents.
vec3 HoffmanPreethamExtinction(IN(HoffmanPreethamParameters) p, Number s) {
  return exp(-(p.air_extinction + p.haze_extinction) * s);
}

// L_in(s, theta): light scattered toward the camera over a distance s;
// `cos_theta` = dot(view direction, sun direction).
vec3 HoffmanPreethamInScattering(IN(HoffmanPreethamParameters) p, Number s, Number cos_theta,
                                 IN(vec3) sun_irradiance) {
  vec3 angular = p.air_scattering * RayleighPhaseFunction(cos_theta) +
                 p.haze_scattering * HenyeyGreensteinPhaseFunction(p.haze_g, cos_theta);
  return angular * HoffmanPreethamAttenuatedLength(p.air_extinction + p.haze_extinction, s) * sun_irradiance;
}

// E_sun at the camera for the sun at cosine `mu_s` from the zenith, given the
// fitted relative optical paths m_air(mu_s, h), m_haze(mu_s, h). The part of
// the sun's disc below the geometric horizon is hidden by a smooth step over
// the disc (as Bruneton 2017's SunVisibleFraction).
vec3 HoffmanPreethamSunIrradiance(IN(HoffmanPreethamParameters) p, Number mu_s, Number air_relative_path,
                                  Number haze_relative_path) {
  vec3 optical_depth = p.air_extinction * (air_relative_path * p.air_zenith_optical_length) +
                       p.haze_extinction * (haze_relative_path * p.haze_zenith_optical_length);
  Number sin_h = sqrt(max(1.0 - p.horizon_cos * p.horizon_cos, 0.0));
  Number visible = smoothstep(-sin_h * p.sun_angular_radius, sin_h * p.sun_angular_radius, mu_s - p.horizon_cos);
  return p.sun_irradiance * exp(-optical_depth) * visible;
}

// The two-shell sky equation (file comment): in-scattered radiance along a
// view ray through an air shell of length `air_length` and a haze shell of
// length `haze_length` (metres: the optical lengths m * l_zenith for the sky,
// cut at d for a point at distance d).
vec3 HoffmanPreethamSkyRadiance(IN(HoffmanPreethamParameters) p, Number air_length, Number haze_length,
                                Number cos_theta, IN(vec3) sun_irradiance) {
  vec3 air_angular = p.air_scattering * RayleighPhaseFunction(cos_theta);
  vec3 haze_angular = p.haze_scattering * HenyeyGreensteinPhaseFunction(p.haze_g, cos_theta);
  vec3 both = p.air_extinction + p.haze_extinction;
  Number near = min(air_length, haze_length);
  vec3 radiance = (air_angular + haze_angular) * HoffmanPreethamAttenuatedLength(both, near);
  vec3 through_near = exp(-both * near);
  if (air_length > haze_length) {
    radiance += through_near * air_angular * HoffmanPreethamAttenuatedLength(p.air_extinction, air_length - near);
  } else {
    radiance += through_near * haze_angular * HoffmanPreethamAttenuatedLength(p.haze_extinction, haze_length - near);
  }
  return radiance * sun_irradiance;
}

// Transmittance through both shells.
vec3 HoffmanPreethamSkyTransmittance(IN(HoffmanPreethamParameters) p, Number air_length, Number haze_length) {
  return exp(-(p.air_extinction * air_length + p.haze_extinction * haze_length));
}
