#include "bake/energy_balance.h"

#include <cmath>
#include <vector>

#include <tbb/parallel_for.h>

#include "core/constants.h"
#include "shaders_runtime/runtime.h"
#include "shaders_runtime/twin.h"

namespace skybake {

namespace {

using glsl::vec3;

// Midpoints of n equal intervals of [a, b] and their common width.
std::vector<double> Midpoints(double a, double b, int n, double* width) {
  *width = (b - a) / n;
  std::vector<double> x(n);
  for (int k = 0; k < n; ++k) x[k] = a + (k + 0.5) * *width;
  return x;
}

}  // namespace

// The top sphere is symmetric about the axis through the sun: a point on it
// is described by the sun's zenith cosine mu_s there, and the area between
// mu_s and mu_s + dmu_s is 2 pi R_top^2 dmu_s. With F(mu_s) the upward flux
// per unit area (outgoing radiance times cosine, over the hemisphere), the
// flux leaving is 2 pi R_top^2 * integral F dmu_s, and relative to the
// incoming pi R_top^2 E_sun it is 2 / E_sun * integral F dmu_s.
//
// The radiance leaving the top in direction w is what a camera at the top
// sees looking along -w: the sky radiance (every scattering order, which
// includes light the ground reflected and the air scattered again), plus,
// for rays that reach the ground, the ground's Lambertian radiance
// albedo / pi * (sun + sky irradiance) times the transmittance to it.
// Sunlight that crosses the limb without scattering leaves too: rays of
// impact parameter b in (R_ground, R_top) keep exp(-2 tau(b, mu = 0)).
EnergyBalance ComputeEnergyBalance(const LutSet& luts, int sun_samples, int direction_samples) {
  const Twin twin(MakeTwinTables(luts));
  const glsl::AtmosphereParameters& p = luts.parameters;
  const Spectrum albedo_over_pi = luts.atmosphere.ground_albedo / kPi;
  const Spectrum sun_irradiance = luts.atmosphere.solar_irradiance;
  const vec3 camera(0.0, 0.0, p.top_radius);
  // Outgoing zenith cosines are split where the ray seen from the top grazes
  // the ground: the radiance jumps there (the tables' horizon discontinuity).
  const double grazing = std::sqrt(1.0 - (p.bottom_radius / p.top_radius) * (p.bottom_radius / p.top_radius));
  double limb_width, ground_width, azimuth_width, sun_width;
  const std::vector<double> limb = Midpoints(0.0, grazing, direction_samples, &limb_width);
  const std::vector<double> ground = Midpoints(grazing, 1.0, direction_samples, &ground_width);
  const std::vector<double> azimuths = Midpoints(0.0, kPi, direction_samples, &azimuth_width);
  const std::vector<double> suns = Midpoints(p.mu_s_min, 1.0, sun_samples, &sun_width);

  std::vector<Spectrum> upward_flux(suns.size(), Spectrum(0.0));
  tbb::parallel_for(0, sun_samples, [&](int s) {
    const double mu_s = suns[s];
    const vec3 sun(std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s)), 0.0, mu_s);
    Spectrum flux(0.0);
    auto add_directions = [&](const std::vector<double>& cosines, double width, bool reaches_ground) {
      for (double mu_out : cosines) {
        const double sin_out = std::sqrt(std::max(0.0, 1.0 - mu_out * mu_out));
        for (double phi : azimuths) {
          const vec3 out(sin_out * std::cos(phi), sin_out * std::sin(phi), mu_out);
          vec3 unused;
          vec3 radiance = twin.SkyRadiance(camera, -out, sun, &unused);
          if (reaches_ground) {
            double distance = glsl::DistanceToBottomAtmosphereBoundary(p, p.top_radius, -mu_out);
            vec3 ground_point = camera - out * distance;
            vec3 transmittance, sky;
            twin.SkyRadianceToPoint(camera, ground_point, sun, &transmittance);
            vec3 direct = twin.SunAndSkyIrradiance(ground_point, glm::normalize(ground_point), sun, &sky);
            radiance += transmittance * albedo_over_pi * (direct + sky);
          }
          // Both halves of the azimuth circle: the field is symmetric about the sun's plane.
          flux += radiance * (mu_out * width * 2.0 * azimuth_width);
        }
      }
    };
    add_directions(limb, limb_width, false);
    add_directions(ground, ground_width, true);
    upward_flux[s] = flux;
  });

  EnergyBalance balance;
  Spectrum integral(0.0);
  for (const Spectrum& f : upward_flux) integral += f * sun_width;
  // A channel the sun does not light has nothing to balance.
  for (int c = 0; c < 3; ++c) balance.scattered[c] = sun_irradiance[c] > 0.0 ? 2.0 * integral[c] / sun_irradiance[c] : 0.0;

  // Limb: (1 / R_top^2) * integral of exp(-2 tau(b, 0)) d(b^2) over (R_ground^2, R_top^2).
  double square_width;
  const std::vector<double> squares = Midpoints(p.bottom_radius * p.bottom_radius, p.top_radius * p.top_radius,
                                                4 * sun_samples, &square_width);
  Spectrum limb_sum(0.0);
  for (double b_squared : squares) limb_sum += glm::exp(-2.0 * twin.OpticalDepthToTop(std::sqrt(b_squared), 0.0));
  balance.transmitted = limb_sum * square_width / (p.top_radius * p.top_radius);
  for (int c = 0; c < 3; ++c) {
    if (!(sun_irradiance[c] > 0.0)) balance.transmitted[c] = 0.0;
  }
  balance.uncovered_area = 0.5 * (1.0 + p.mu_s_min);
  return balance;
}

}  // namespace skybake
