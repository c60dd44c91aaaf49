#include "bake/invariants.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "core/constants.h"
#include "shaders_runtime/runtime.h"
#include "shaders_runtime/twin.h"

namespace skybake {

namespace {

using glsl::vec3;
constexpr std::size_t kMaxExamples = 5;
// Slack on the energy bounds for float storage and the quadratures of the
// bake (midpoint sums over the sphere, trapezoids along rays), which can
// overshoot an exact integral by a fraction of a percent.
constexpr double kBoundSlack = 1.01;
// Transmittance differences the tables cannot resolve. The transmittances to
// two points of a ray, or of one segment read from either end, come from
// different texels of the optical-depth table, and a view exactly at the
// horizon may fall on either side of the table's horizon discontinuity by
// rounding. At the stress tables' 64 x 16 texels these differences stay
// below 0.05 over the stress set and the presets (docs/stability.md,
// "Invariants", from `skybake stress`), while a formulation error, such as a
// segment looked up downward, gives differences of order 1.
constexpr double kTransmittanceTolerance = 0.05;

std::string Describe(const char* what, const vec3& value) {
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "%s (%.6g, %.6g, %.6g)", what, value.x, value.y, value.z);
  return buffer;
}

// Largest value of a phase function over all scattering angles: at 0 or pi
// for every kind skybake supports.
double MaxPhase(const PhaseFunction& phase) { return std::max(phase.Evaluate(1.0), phase.Evaluate(-1.0)); }

bool IsFinite(const vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Uniform doubles in [0, 1) from a generator whose output sequence the C++
// standard fixes, so a seed gives the same queries everywhere.
class UniformSource {
 public:
  explicit UniformSource(std::uint64_t seed) : engine_(seed) {}
  double operator()() { return static_cast<double>(engine_() >> 11) * 0x1p-53; }

 private:
  std::mt19937_64 engine_;
};

class TwinChecker {
 public:
  TwinChecker(const LutSet& luts, const EnergyBounds& bounds, UniformSource& uniform, InvariantReport& report)
      : luts_(luts), twin_(MakeTwinTables(luts)), bounds_(bounds), uniform_(uniform), report_(report) {}

  void Radiance(const char* what, const vec3& radiance) {
    report_.values_checked += 3;
    if (!IsFinite(radiance) || glm::any(glm::lessThan(radiance, vec3(0.0))) ||
        glm::any(glm::greaterThan(radiance, bounds_.radiance * kBoundSlack))) {
      report_.Violation(Describe(what, radiance) + " not finite, negative or above the energy bound" + where_);
    }
  }
  void Transmittance(const char* what, const vec3& t) {
    report_.values_checked += 3;
    if (!IsFinite(t) || glm::any(glm::lessThan(t, vec3(0.0))) || glm::any(glm::greaterThan(t, vec3(1.0)))) {
      report_.Violation(Describe(what, t) + " outside [0, 1]" + where_);
    }
  }
  void NotAbove(const char* what, const vec3& larger_or_equal, const vec3& smaller) {
    report_.values_checked += 3;
    vec3 excess = smaller - larger_or_equal;
    report_.largest_transmittance_increase =
        std::max(report_.largest_transmittance_increase, std::max({excess.x, excess.y, excess.z}));
    if (glm::any(glm::greaterThan(excess, vec3(kTransmittanceTolerance)))) {
      report_.Violation(Describe(what, excess) + where_);
    }
  }

  // `along_ray`: also the checks between points along the view ray, which
  // assume a camera in the atmosphere (r >= bottom radius).
  void Query(const vec3& camera, const vec3& view, const vec3& sun, const vec3& normal, bool along_ray) {
    const glsl::AtmosphereParameters& p = luts_.parameters;
    char where[200];
    std::snprintf(where, sizeof where, " at r = %.9g m, mu = %.9g, mu_s = %.9g, nu = %.9g", glm::length(camera),
                  view.z, sun.z, glm::dot(view, sun));
    where_ = where;

    vec3 sky_transmittance;
    Radiance("sky radiance", twin_.SkyRadiance(camera, view, sun, &sky_transmittance));
    Transmittance("transmittance to the top", sky_transmittance);

    vec3 sky_irradiance;
    vec3 sun_irradiance = twin_.SunAndSkyIrradiance(camera, normal, sun, &sky_irradiance);
    report_.values_checked += 6;
    if (!IsFinite(sun_irradiance) || glm::any(glm::lessThan(sun_irradiance, vec3(0.0))) ||
        glm::any(glm::greaterThan(sun_irradiance, p.solar_irradiance * kBoundSlack))) {
      report_.Violation(Describe("sun irradiance", sun_irradiance) + " not in [0, E_sun]" + where_);
    }
    if (!IsFinite(sky_irradiance) || glm::any(glm::lessThan(sky_irradiance, vec3(0.0))) ||
        glm::any(glm::greaterThan(sky_irradiance, bounds_.sky_irradiance * kBoundSlack))) {
      report_.Violation(Describe("sky irradiance", sky_irradiance) + " not finite, negative or above the bound" +
                        where_);
    }

    // Two points along the ray, inside the atmosphere.
    const double r = glm::length(camera), mu = view.z;
    if (!along_ray || r > p.top_radius) return;
    bool intersects_ground = glsl::RayIntersectsGround(p, r, mu);
    double length = glsl::DistanceToNearestAtmosphereBoundary(p, r, mu, intersects_ground);
    if (!(length > 0.0)) return;
    double d1 = length * (0.5 * uniform_() + 1e-9), d2 = d1 + (length - d1) * uniform_();
    char distances[120];
    std::snprintf(distances, sizeof distances, ", points at %.6g and %.6g m of %.6g m%s", d1, d2, length,
                  intersects_ground ? " (to the ground)" : "");
    where_ += distances;
    vec3 near_point = camera + view * d1, far_point = camera + view * d2;
    vec3 near_transmittance, far_transmittance, reverse_transmittance;
    Radiance("aerial perspective radiance", twin_.SkyRadianceToPoint(camera, near_point, sun, &near_transmittance));
    Radiance("aerial perspective radiance", twin_.SkyRadianceToPoint(camera, far_point, sun, &far_transmittance));
    Transmittance("transmittance to a point", near_transmittance);
    Transmittance("transmittance to a point", far_transmittance);
    NotAbove("transmittance increases with distance by", near_transmittance, far_transmittance);
    if (!intersects_ground) {
      NotAbove("transmittance to the top exceeds that to a point on the way by", far_transmittance,
               sky_transmittance);
    }
    Radiance("aerial perspective radiance (reversed)",
             twin_.SkyRadianceToPoint(far_point, camera, sun, &reverse_transmittance));
    Transmittance("transmittance to a point (reversed)", reverse_transmittance);
    report_.values_checked += 3;
    vec3 difference = glm::abs(reverse_transmittance - far_transmittance);
    report_.largest_direction_difference =
        std::max(report_.largest_direction_difference, std::max({difference.x, difference.y, difference.z}));
    if (glm::any(glm::greaterThan(difference, vec3(kTransmittanceTolerance)))) {
      report_.Violation(Describe("transmittance forward and reversed differ by", difference) + where_);
    }
  }

 private:
  const LutSet& luts_;
  Twin twin_;
  EnergyBounds bounds_;
  UniformSource& uniform_;
  InvariantReport& report_;
  std::string where_;
};

}  // namespace

void InvariantReport::Violation(const std::string& what) {
  ++violations;
  if (examples.size() < kMaxExamples) examples.push_back(what);
}

void InvariantReport::Merge(const InvariantReport& other) {
  values_checked += other.values_checked;
  violations += other.violations;
  largest_transmittance_increase = std::max(largest_transmittance_increase, other.largest_transmittance_increase);
  largest_direction_difference = std::max(largest_direction_difference, other.largest_direction_difference);
  for (const std::string& e : other.examples) {
    if (examples.size() < kMaxExamples) examples.push_back(e);
  }
}

EnergyBounds ComputeEnergyBounds(const LutSet& luts, const BakeReport& report) {
  const Atmosphere& a = luts.atmosphere;
  double max_phase = 0.0;
  for (const Constituent& c : a.constituents) {
    if (c.scattering_per_m != Spectrum(0.0)) max_phase = std::max(max_phase, MaxPhase(c.phase));
  }
  // Once scattered, a photon's radiance is bounded by the sun's irradiance
  // times the largest phase value (single scattering: the integral of
  // beta_s * T along a ray is at most 1 - T <= 1), or by the ground's
  // reflection of the sun, E a / pi. Each further order averages the
  // previous one over the phase function (weights summing to 1) and
  // attenuates it again, so it is no brighter than that first bound. With
  // N orders and the extrapolated tail q / (1 - q) of the last one:
  // L <= (N + q / (1 - q)) * E * max(p_max, a / pi).
  EnergyBounds b;
  b.single_scattering = a.solar_irradiance;
  double orders = report.orders_used;
  if (report.extrapolated_tail > 0.0) orders += report.order_ratio / (1.0 - report.order_ratio);
  for (int c = 0; c < 3; ++c) {
    double first_order = a.solar_irradiance[c] * std::max(max_phase, a.ground_albedo[c] / kPi);
    // The scattering table stores radiance divided by the Rayleigh phase at
    // its nu grid points; the runtime multiplies back by the phase at the
    // query's nu, which can be up to twice the grid point's (1 + nu^2 over [0, 1]).
    b.radiance[c] = 2.0 * orders * first_order;
    b.sky_irradiance[c] = kPi * b.radiance[c];
  }
  return b;
}

InvariantReport CheckTableInvariants(const LutSet& luts, const BakeReport& report) {
  InvariantReport result;
  const EnergyBounds bounds = ComputeEnergyBounds(luts, report);
  auto check = [&](const char* table, const glsl::Texture& texture, const Spectrum& bound, bool four_d,
                   bool rayleigh_encoded) {
    for (int z = 0; z < texture.depth; ++z) {
      for (int y = 0; y < texture.height; ++y) {
        for (int x = 0; x < texture.width; ++x) {
          glsl::vec4 texel = texture.Fetch(x, y, z);
          // 4D tables: slices past their range hold up to kLargestExtension
          // times the light at its edge.
          const ScatteringTexel t = four_d ? GetScatteringTexel(luts.parameters, x, y, z) : ScatteringTexel();
          const double phase = rayleigh_encoded ? glsl::RayleighPhaseFunction(t.nu) : 1.0;
          const double extension = four_d && t.nu != t.grid_nu ? kLargestExtension : 1.0;
          for (int c = 0; c < 4; ++c) {
            ++result.values_checked;
            double value = texel[c];
            bool bounded = c == 3 || !(value * phase > bound[c] * extension * kBoundSlack);
            if (!std::isfinite(value) || value < 0.0 || !bounded) {
              char buffer[200];
              std::snprintf(buffer, sizeof buffer, "%s texel (%d, %d, %d) channel %d = %.6g is %s", table, x, y, z, c,
                            value, !std::isfinite(value) ? "not finite" : value < 0.0 ? "negative" : "above the bound");
              result.Violation(buffer);
            }
          }
        }
      }
    }
  };
  const Spectrum unbounded(std::numeric_limits<double>::infinity());
  // Optical depth: finite and >= 0 is what makes every transmittance <= 1.
  check("transmittance (optical depth)", luts.transmittance, unbounded, false, false);
  check("irradiance", luts.irradiance, bounds.sky_irradiance, false, false);
  check("scattering", luts.scattering, bounds.radiance * 0.5, true, true);
  if (!luts.single_mie_scattering.empty()) {
    check("single Mie scattering", luts.single_mie_scattering, bounds.single_scattering, true, false);
  }
  return result;
}

InvariantReport CheckTwinInvariants(const LutSet& luts, const BakeReport& report, int queries, std::uint64_t seed) {
  InvariantReport result;
  UniformSource uniform(seed);
  TwinChecker checker(luts, ComputeEnergyBounds(luts, report), uniform, result);
  const glsl::AtmosphereParameters& p = luts.parameters;
  const double thickness = p.top_radius - p.bottom_radius;
  auto unit = [](double cosine) { return std::sqrt(std::max(0.0, 1.0 - cosine * cosine)); };
  for (int i = 0; i < queries; ++i) {
    double altitude = 0.0;  // case 0: on the ground
    switch (i % 6) {
      case 1: altitude = thickness; break;                                // exactly at the top
      case 2: altitude = thickness * uniform(); break;                    // anywhere inside
      case 3: altitude = thickness * std::pow(10.0, -9.0 * uniform()); break;  // just above the ground
      case 4: altitude = thickness + 10.0 * p.top_radius * uniform(); break;   // far in space
      // Below the ground, down to the centre (see the end of the loop).
      case 5: altitude = -p.bottom_radius * uniform(); break;
    }
    // A camera below the ground is evaluated on the ground, as `skybake eval`
    // does (formats/query_csv.cpp); the runtime functions expect the caller to
    // clamp it.
    const double r = p.bottom_radius + std::max(altitude, 0.0);
    double mu = 2.0 * uniform() - 1.0;
    switch (i / 6 % 10) {
      case 0: mu = -unit(p.bottom_radius / r); break;  // exactly at the ground's horizon
      case 1: mu = 0.0; break;                         // horizontal
      case 2: mu = 1.0; break;
      case 3: mu = -1.0; break;
    }
    double mu_s = i % 10 == 7 ? p.mu_s_min : p.mu_s_min + (1.0 - p.mu_s_min) * uniform();
    double azimuth = 2.0 * kPi * uniform();
    double normal_mu = 2.0 * uniform() - 1.0, normal_azimuth = 2.0 * kPi * uniform();
    vec3 camera(0.0, 0.0, r);
    vec3 view(unit(mu), 0.0, mu);
    vec3 sun(unit(mu_s) * std::cos(azimuth), unit(mu_s) * std::sin(azimuth), mu_s);
    vec3 normal(unit(normal_mu) * std::cos(normal_azimuth), unit(normal_mu) * std::sin(normal_azimuth), normal_mu);
    checker.Query(camera, view, sun, normal, true);
    // Unclamped, such a camera must still give finite, bounded values
    // (though not meaningful ones).
    if (altitude < 0.0) checker.Query(vec3(0.0, 0.0, p.bottom_radius + altitude), view, sun, normal, false);
  }
  return result;
}

}  // namespace skybake
