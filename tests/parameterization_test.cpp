// Every table parameterization comes with its inverse; both directions must
// agree (map, inverse map, round trip), including at the horizon split.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include <glm/geometric.hpp>

#include "bake/bake.h"
#include "shaders_runtime/runtime.h"
#include "test_atmospheres.h"

namespace skybake {
namespace {

glsl::AtmosphereParameters Parameters() { return MakeAtmosphereParameters(testing::Earth(), BakeSettings{}); }

TEST(Parameterization, TransmittanceRoundTrip) {
  glsl::AtmosphereParameters p = Parameters();
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < 2000; ++i) {
    glsl::vec2 uv(unit(rng), unit(rng));
    uv = glsl::vec2(0.5 / p.transmittance_width + uv.x * (1.0 - 1.0 / p.transmittance_width),
                    0.5 / p.transmittance_height + uv.y * (1.0 - 1.0 / p.transmittance_height));
    double r, mu;
    glsl::GetRMuFromTransmittanceTextureUv(p, uv, r, mu);
    glsl::vec2 back = glsl::GetTransmittanceTextureUvFromRMu(p, r, mu);
    EXPECT_NEAR(back.x, uv.x, 1e-9);
    EXPECT_NEAR(back.y, uv.y, 1e-9);
  }
}

// A scene's table: altitudes 500 m to 3 km, suns from 20 to 95 degrees.
glsl::AtmosphereParameters RestrictedParameters() {
  BakeSettings settings;
  settings.scattering_r_size = 12;
  settings.scattering_range = ScatteringRange{500.0, 3000.0, std::cos(95.0 * glsl::PI / 180.0),
                                              std::cos(20.0 * glsl::PI / 180.0)};
  return MakeAtmosphereParameters(testing::Earth(), settings);
}

void ExpectScatteringRoundTrip(const glsl::AtmosphereParameters& p) {
  int ground = 0;
  for (int z = 0; z < p.scattering_r_size; z += 3) {
    for (int y = 0; y < p.scattering_mu_size; ++y) {
      for (int x = 0; x < p.scattering_mu_s_size * p.scattering_nu_size; x += 5) {
        ScatteringTexel t = GetScatteringTexel(p, x, y, z);
        glsl::vec4 uvwz = glsl::GetScatteringTextureUvwzFromRMuMuSNu(p, t.r, t.mu, t.mu_s, t.grid_nu,
                                                                     t.ray_intersects_ground);
        int nu_index = x / p.scattering_mu_s_size, mu_s_index = x % p.scattering_mu_s_size;
        // On the ground (r = bottom) every downward ray has length zero, so the
        // ground half of the mu axis collapses to one point by construction.
        bool degenerate = t.ray_intersects_ground && t.r == p.bottom_radius;
        // The first and last mu texels are the tangent ray, seen from each half.
        // It is ill-conditioned: its distances are square roots of a
        // discriminant that vanishes, so a rounding error of 1e-16 in mu moves
        // u_mu by ~1e-7, and a numerical ground test cannot decide; below the
        // split its shadow edge, and with it its own columns' u_mu_s, move
        // as much.
        bool tangent = y == 0 || y == p.scattering_mu_size - 1;
        double tolerance = tangent ? 1e-5 : 1e-7;
        EXPECT_NEAR(uvwz.x, double(nu_index) / (p.scattering_nu_size - 1), 1e-12);
        EXPECT_NEAR(uvwz.y, (mu_s_index + 0.5) / p.scattering_mu_s_size, tolerance) << "z " << z << " y " << y;
        if (!degenerate) {
          EXPECT_NEAR(uvwz.z, (y + 0.5) / p.scattering_mu_size, tolerance) << "z " << z << " y " << y;
        }
        EXPECT_NEAR(uvwz.w, (z + 0.5) / p.scattering_r_size, 1e-9);
        // The lower half of the mu axis holds exactly the rays that hit the ground.
        EXPECT_EQ(t.ray_intersects_ground, y < p.scattering_mu_size / 2);
        if (!tangent) {
          EXPECT_EQ(glsl::RayIntersectsGround(p, t.r, t.mu), t.ray_intersects_ground) << "z " << z << " y " << y;
        }
        ground += t.ray_intersects_ground;
      }
    }
  }
  EXPECT_GT(ground, 0);
}

TEST(Parameterization, ScatteringRoundTripBothHalves) { ExpectScatteringRoundTrip(Parameters()); }

TEST(Parameterization, RestrictedScatteringRoundTripBothHalves) { ExpectScatteringRoundTrip(RestrictedParameters()); }

TEST(Parameterization, RestrictedAxesSpanTheirRanges) {
  // The first and last texel centres of the r and mu_s axes are the ends of
  // the scene's ranges, the first mu_s column where a ray's shadow edge
  // lies at least 2 degrees before the lowest sun (its own columns below
  // the split end there; else 2 degrees past the edge); the mu axis is the
  // full one at each radius.
  const glsl::AtmosphereParameters p = RestrictedParameters();
  ASSERT_GT(p.scattering_mu_s_split, 0);
  double r, mu, mu_s, nu;
  bool ground;
  const double n_r = p.scattering_r_size, n_mu_s = p.scattering_mu_s_size, degree = glsl::PI / 180.0;
  glsl::GetRMuMuSNuFromScatteringTextureUvwz(p, glsl::vec4(0.5, 0.5 / n_mu_s, 0.75, 0.5 / n_r), r, mu, mu_s, nu,
                                             ground);
  EXPECT_NEAR(r, p.bottom_radius + 500.0, 1e-6);
  const double edge = glsl::ShadowEdgeSunZenith(p, r, mu, glsl::ViewSunAzimuthCosine(mu, mu_s, nu), ground);
  EXPECT_NEAR(mu_s, std::cos(std::max(95.0 * degree, edge + 2.0 * degree)), 1e-9);
  // A ray from 500 m up whose edge is 2 degrees and more before 95 degrees:
  // straight down.
  glsl::GetRMuMuSNuFromScatteringTextureUvwz(
      p, glsl::vec4(0.5, 0.5 / n_mu_s, 0.5 - 0.5 / p.scattering_mu_size, 0.5 / n_r), r, mu, mu_s, nu, ground);
  ASSERT_LT(glsl::ShadowEdgeSunZenith(p, r, mu, glsl::ViewSunAzimuthCosine(mu, mu_s, nu), ground), 93.0 * degree);
  EXPECT_NEAR(mu_s, std::cos(95.0 * glsl::PI / 180.0), 1e-9);
  glsl::GetRMuMuSNuFromScatteringTextureUvwz(p, glsl::vec4(0.5, 1.0 - 0.5 / n_mu_s, 0.75, 1.0 - 0.5 / n_r), r, mu,
                                             mu_s, nu, ground);
  EXPECT_NEAR(r, p.bottom_radius + 3000.0, 1e-6);
  EXPECT_NEAR(mu_s, std::cos(20.0 * glsl::PI / 180.0), 1e-9);
  // Straight up and straight down are the first texels of the mu axis's
  // halves there too.
  const double n_mu = p.scattering_mu_size;
  glsl::GetRMuMuSNuFromScatteringTextureUvwz(p, glsl::vec4(0.5, 0.5, 0.5 + 0.5 / n_mu, 0.5), r, mu, mu_s, nu, ground);
  EXPECT_NEAR(mu, 1.0, 1e-9);
  glsl::GetRMuMuSNuFromScatteringTextureUvwz(p, glsl::vec4(0.5, 0.5, 0.5 - 0.5 / n_mu, 0.5), r, mu, mu_s, nu, ground);
  EXPECT_NEAR(mu, -1.0, 1e-9);
}

TEST(Parameterization, MuSAxisSpansLowestSunToZenith) {
  glsl::AtmosphereParameters p = Parameters();
  // The ends of the mu_s axis (first and last texel-centre range) are the
  // lowest sun and the zenith.
  double r, mu, mu_s, nu;
  bool ground;
  double n = p.scattering_mu_s_size;
  glsl::GetRMuMuSNuFromScatteringTextureUvwz(p, glsl::vec4(0.5, 0.5 / n, 0.75, 0.5), r, mu, mu_s, nu, ground);
  EXPECT_NEAR(mu_s, p.mu_s_min, 1e-9);
  glsl::GetRMuMuSNuFromScatteringTextureUvwz(p, glsl::vec4(0.5, 1.0 - 0.5 / n, 0.75, 0.5), r, mu, mu_s, nu, ground);
  EXPECT_NEAR(mu_s, 1.0, 1e-9);
}

// nu of two unit vectors built from their zenith cosines and an azimuth
// difference stays as it is; a nu beyond what the cosines allow goes to the
// nearest of the two directions at azimuth 0 and pi.
TEST(Parameterization, NuIsClampedToTheDirectionsTheCosinesAllow) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> cosine(-1.0, 1.0), azimuth(0.0, 3.141592653589793);
  for (int i = 0; i < 1000; ++i) {
    const double mu = cosine(random), mu_s = cosine(random), phi = azimuth(random);
    const glsl::vec3 view(std::sqrt(1.0 - mu * mu), 0.0, mu);
    const glsl::vec3 sun(std::sqrt(1.0 - mu_s * mu_s) * std::cos(phi), std::sqrt(1.0 - mu_s * mu_s) * std::sin(phi),
                         mu_s);
    const double nu = glm::dot(view, sun);
    EXPECT_NEAR(ClampedNu(nu, mu, mu_s), nu, 1e-12);
    const glsl::vec3 toward(sun.x >= 0.0 ? std::sqrt(1.0 - mu_s * mu_s) : -std::sqrt(1.0 - mu_s * mu_s), 0.0, mu_s);
    const glsl::vec3 away(-toward.x, 0.0, mu_s);
    EXPECT_NEAR(ClampedNu(2.0, mu, mu_s), std::max(glm::dot(view, toward), glm::dot(view, away)), 1e-12);
    EXPECT_NEAR(ClampedNu(-2.0, mu, mu_s), std::min(glm::dot(view, toward), glm::dot(view, away)), 1e-12);
  }
}

TEST(Parameterization, IrradianceRoundTrip) {
  glsl::AtmosphereParameters p = Parameters();
  for (int y = 0; y < p.irradiance_height; ++y) {
    for (int x = 0; x < p.irradiance_width; ++x) {
      glsl::vec2 uv((x + 0.5) / p.irradiance_width, (y + 0.5) / p.irradiance_height);
      double r, mu_s;
      glsl::GetRMuSFromIrradianceTextureUv(p, uv, r, mu_s);
      glsl::vec2 back = glsl::GetIrradianceTextureUvFromRMuS(p, r, mu_s);
      EXPECT_NEAR(back.x, uv.x, 1e-12);
      EXPECT_NEAR(back.y, uv.y, 1e-12);
    }
  }
}

}  // namespace
}  // namespace skybake
