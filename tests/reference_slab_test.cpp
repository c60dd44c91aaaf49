// The reference solver's Monte Carlo estimates in a homogeneous slab: orders
// one and two against a nested quadrature, and the net flux that a
// conservative slab must keep at every altitude. Tolerances: see
// reference_test_util.h.
#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "bake/atmosphere.h"
#include "core/constants.h"
#include "core/quadrature.h"
#include "reference/path_tracer.h"
#include "reference_test_util.h"

namespace skybake::reference {
namespace {

using glm::dvec3;

// A homogeneous slab (plane-parallel: planet radius 6.36e9 m) of Rayleigh
// and Henyey-Greenstein scatterers with some absorption, over a grey ground.
struct Slab {
  double height = 10e3;
  Spectrum rayleigh{1e-5, 2e-5, 4e-5};
  Spectrum haze{1e-5, 1e-5, 1e-5};
  Spectrum haze_absorption{2e-6, 2e-6, 2e-6};
  double g = 0.6;
  double albedo = 0.3;

  Atmosphere ToAtmosphere() const {
    Atmosphere a = Earth();
    a.name = "slab";
    a.bottom_radius_m = 6360e6;
    a.top_radius_m = a.bottom_radius_m + height;
    a.ground_albedo = Spectrum(albedo);
    a.constituents.resize(2);
    for (Constituent& c : a.constituents) c.density.layers = {DensityLayer{0.0, 0.0, 0.0, 0.0, 1.0}};
    a.constituents[0].scattering_per_m = rayleigh;
    a.constituents[1].scattering_per_m = haze;
    a.constituents[1].absorption_per_m = haze_absorption;
    a.constituents[1].phase = {PhaseKind::kHenyeyGreenstein, g};
    return a;
  }
};

// Orders 1 and 2 of the slab's radiance by quadrature, in closed form along
// rays: with constant coefficients every transmittance is an exponential.
// L1(z, w): light scattered once into the ray from height z along w (plus,
// when w looks down, the ground's reflection of direct sunlight); the
// camera's order 1 is its in-scattered part, its order 2 the integral along
// the view of T sigma_s,c P_c(w . v) L1(z, w) over all directions w.
class SlabQuadrature {
 public:
  SlabQuadrature(const Slab& slab, const Atmosphere& a, int w, const dvec3& sun)
      : slab_(slab), sun_(sun), e_(a.solar_irradiance[w]) {
    rayleigh_ = slab.rayleigh[w];
    haze_ = slab.haze[w];
    extinction_ = rayleigh_ + haze_ + slab.haze_absorption[w];
  }

  // Scattering coefficient times phase, summed over the two constituents.
  double ScatteringPhase(double cos_theta) const {
    PhaseFunction rayleigh{PhaseKind::kRayleigh, 0.0}, haze{PhaseKind::kHenyeyGreenstein, slab_.g};
    return rayleigh_ * rayleigh.Evaluate(cos_theta) + haze_ * haze.Evaluate(cos_theta);
  }

  double Boundary(double z, const dvec3& w) const {
    return w.z > 0.0 ? (slab_.height - z) / w.z : z / -w.z;
  }

  double InScattered(double z, const dvec3& w) const {
    double mu_s = sun_.z, k = 1.0 - w.z / mu_s;
    double sun = e_ * std::exp(-extinction_ * (slab_.height - z) / mu_s);
    double length = w.z == 0.0 ? std::numeric_limits<double>::infinity() : Boundary(z, w);
    double along = std::abs(k) < 1e-12 ? length : -std::expm1(-extinction_ * k * length) / (extinction_ * k);
    return ScatteringPhase(glm::dot(w, sun_)) * sun * along;
  }

  double OrderOne(double z, const dvec3& w) const {
    double l = InScattered(z, w);
    if (w.z < 0.0) {
      double ground = slab_.albedo / kPi * e_ * sun_.z * std::exp(-extinction_ * slab_.height / sun_.z);
      l += std::exp(-extinction_ * z / -w.z) * ground;
    }
    return l;
  }

  // Order 2 at height z looking along v: integral of T sigma_s P L1.
  double OrderTwo(double z0, const dvec3& v) const {
    const int t_nodes = 48, polar = 96, azimuths = 192;
    std::vector<double> x, wx;
    AppendGaussLegendre(polar, -1.0, 1.0, x, wx);
    double length = Boundary(z0, v), sum = 0.0;
    std::vector<double> tx, tw;
    AppendGaussLegendre(t_nodes, -1.0, 1.0, tx, tw);
    for (int i = 0; i < t_nodes; ++i) {
      double t = 0.5 * length * (tx[i] + 1.0), z = z0 + t * v.z;
      double inner = 0.0;
      for (int hemisphere = 0; hemisphere < 2; ++hemisphere) {
        for (int j = 0; j < polar; ++j) {
          double cz = 0.5 * (x[j] + 1.0) * (hemisphere ? 1.0 : -1.0), sz = std::sqrt(1.0 - cz * cz);
          for (int k = 0; k < azimuths; ++k) {
            double phi = 2.0 * kPi * (k + 0.5) / azimuths;
            dvec3 w(sz * std::cos(phi), sz * std::sin(phi), cz);
            inner += 0.5 * wx[j] * (2.0 * kPi / azimuths) * ScatteringPhase(glm::dot(w, v)) * OrderOne(z, w);
          }
        }
      }
      sum += 0.5 * length * tw[i] * std::exp(-extinction_ * t) * inner;
    }
    return sum;
  }

 private:
  Slab slab_;
  dvec3 sun_;
  double e_, rayleigh_ = 0.0, haze_ = 0.0, extinction_ = 0.0;
};

TEST(ReferenceEstimates, SlabOrdersOneAndTwoMatchQuadrature) {
  // Second-order scattering through every part of a path: the forced first
  // continuation, phase sampling of the constituent mixture, free flights,
  // the ground's reflection of sunlight as an event of its own (order 2 =
  // sunlight reflected then scattered once into the view, or scattered
  // twice). Tolerance 4 sigma plus 2e-5 relative for the quadrature
  // (doubling its nodes moves it by less than 2e-8).
  Slab slab;
  Atmosphere a = slab.ToAtmosphere();
  PathTracer tracer(a);
  Settings settings;
  settings.paths = Scaled(256 * kPathsPerBlock);
  settings.max_order = 2;
  struct Case {
    double altitude, view, sun, azimuth;
  };
  for (Case c : {Case{1000.0, 60.0, 30.0, 60.0}, Case{5000.0, 120.0, 50.0, 150.0}}) {
    RayQuery q = QueryAt(a, c.altitude, c.view, c.sun, c.azimuth);
    Result result = tracer.Evaluate(q, settings, 4);
    for (int w = 0; w < kWavelengthCount; ++w) {
      SlabQuadrature quadrature(slab, a, w, q.sun);
      double one = quadrature.InScattered(c.altitude, q.view), two = quadrature.OrderTwo(c.altitude, q.view);
      double mc = result.radiance.mean[w], sigma = result.radiance.standard_error[w];
      Note("slab: view %g sun %g w %d: mc %.7g quad %.7g (order 2: %.1f%%) rel.sigma %.2g dev %.2f sigma\n", c.view,
           c.sun, w, mc, one + two, 100.0 * two / (one + two), sigma / mc, (mc - one - two) / sigma);
      EXPECT_LT(sigma, 3e-3 * mc);
      EXPECT_NEAR(mc, one + two, 4.0 * sigma + 2e-5 * (one + two)) << "view " << c.view << " wavelength " << w;
    }
  }
}

TEST(ReferenceEstimates, NetFluxIsConstantWithAltitude) {
  // The slab thickened with Earth's Mie (Cornette-Shanks, g = 0.8) and made
  // conservative, over a ground of albedo 0.3: with nothing absorbed in the
  // air and nothing moving sideways on average, the net downward flux
  // (sun + sky from above - sky from below) is the same at the top, inside,
  // and at the ground, where the ground absorbs 1 - albedo of what arrives.
  // Exercises multiple scattering and reflection at every order, the
  // irradiance sampler's sun lobe, and the albedo weighting of bounces.
  Slab slab;
  slab.haze_absorption = Spectrum(0.0);
  slab.albedo = 0.3;
  Atmosphere a = slab.ToAtmosphere();
  a.constituents[0].scattering_per_m *= 3.0;  // vertical optical depth 0.4, 0.7, 1.3
  a.constituents[1].phase = {PhaseKind::kCornetteShanks, 0.8};
  PathTracer tracer(a);
  Settings settings;
  settings.paths = Scaled(96 * kPathsPerBlock);
  const double sun_zenith = 40.0;
  const dvec3 up(0.0, 0.0, 1.0), sun(std::sin(sun_zenith * kDegree), 0.0, std::cos(sun_zenith * kDegree));
  auto irradiance = [&](double altitude, const dvec3& normal, Spectrum* sigma) {
    RayQuery q;
    q.camera = dvec3(0.0, 0.0, a.bottom_radius_m + altitude);
    q.view = up;
    q.distance_m = 1e-3;  // no radiance wanted: a millimetre of view ray
    q.sun = sun;
    q.has_normal = true;
    q.normal = normal;
    Result r = tracer.Evaluate(q, settings, static_cast<uint64_t>(altitude) + (normal.z > 0.0 ? 1 : 2));
    *sigma = r.sky_irradiance.standard_error;
    return r.sun_irradiance + r.sky_irradiance.mean;
  };
  Spectrum s_top_up, s_mid_down, s_mid_up, s_ground_down;
  Spectrum top_up = irradiance(slab.height, -up, &s_top_up);
  Spectrum mid_down = irradiance(4000.0, up, &s_mid_down), mid_up = irradiance(4000.0, -up, &s_mid_up);
  Spectrum ground_down = irradiance(0.0, up, &s_ground_down);
  for (int w = 0; w < kWavelengthCount; ++w) {
    double top = sun.z * a.solar_irradiance[w] - top_up[w];
    double middle = mid_down[w] - mid_up[w];
    double ground = (1.0 - slab.albedo) * ground_down[w];
    double sigma_middle = std::hypot(s_mid_down[w], s_mid_up[w]);
    double sigma_ground = (1.0 - slab.albedo) * s_ground_down[w];
    Note("net flux w %d: top %.5g +- %.2g, middle %.5g +- %.2g, ground %.5g +- %.2g\n", w, top, s_top_up[w],
         middle, sigma_middle, ground, sigma_ground);
    EXPECT_NEAR(top, ground, 4.0 * std::hypot(s_top_up[w], sigma_ground)) << w;
    EXPECT_NEAR(middle, ground, 4.0 * std::hypot(sigma_middle, sigma_ground)) << w;
    EXPECT_LT(sigma_ground, 0.02 * ground);
  }
}

}  // namespace
}  // namespace skybake::reference
