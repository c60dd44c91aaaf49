#include "report/run_time_models.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

#include "core/errors.h"
#include "fit/optical_path.h"
#include "fit/sky_dome_fit.h"
#include "report/twin_query.h"
#include "shaders_runtime/hoffman_preetham.h"

namespace skybake::report {

ModelAnswer EvaluateTwin(const Twin& twin, const ReferenceCase& c) {
  ModelAnswer a;
  QueryGeometry g = MakeQueryGeometry(c.query, twin.parameters().bottom_radius);
  if (c.query.has_normal) {
    a.has_sun_irradiance = a.has_sky_irradiance = true;
    a.sun_irradiance = twin.SunAndSkyIrradiance(g.camera, g.normal, g.sun, &a.sky_irradiance);
    return a;
  }
  a.has_radiance = true;
  a.radiance = QuerySkyRadiance(twin, c.query, g, nullptr);
  return a;
}

ModelAnswer EvaluateRayMarch(const SingleScatteringRayMarch& march, double bottom_radius_m, const ReferenceCase& c,
                             long* density_samples) {
  ModelAnswer a;
  QueryGeometry g = MakeQueryGeometry(c.query, bottom_radius_m);
  if (c.query.has_normal) {
    a.has_sun_irradiance = true;
    a.sun_irradiance = march.SunIrradiance(g.camera, g.normal, g.sun, density_samples);
    return a;
  }
  a.has_radiance = true;
  a.radiance = march.Radiance(g.camera, g.view, g.sun, c.query.distance_m, nullptr, density_samples);
  return a;
}

// ---------------------------------------------------------------------------

struct HoffmanPreethamModel::Impl {
  std::string unavailable_reason;
  fit::FitSet fits;
  const fit::Surface* air = nullptr;
  const fit::Surface* haze = nullptr;  // null: no haze constituent
  double altitude_max_m = 0.0;         // of the fitted range
  double bottom_radius_m = 0.0;
  std::map<double, glsl::HoffmanPreethamParameters> frames;  // per camera altitude
};

namespace {

// Hoffman & Preetham's two constituents at the camera's altitude: air is
// every Rayleigh-phase constituent plus every absorber without scattering
// (ozone, zero at the ground), haze the first other scatterer.
glsl::HoffmanPreethamParameters FrameConstants(const Atmosphere& atmosphere, int haze_index, double altitude_m) {
  glsl::HoffmanPreethamParameters p{};
  p.sun_irradiance = atmosphere.solar_irradiance;
  p.sun_angular_radius = atmosphere.sun_angular_radius_rad;
  p.air_scattering = p.air_extinction = p.haze_scattering = p.haze_extinction = glsl::vec3(0.0);
  double air_column = 0.0, air_density = 0.0;
  for (int i = 0; i < static_cast<int>(atmosphere.constituents.size()); ++i) {
    const Constituent& c = atmosphere.constituents[i];
    double density = c.density.At(altitude_m);
    fit::ColumnIntegrator column(c.density, atmosphere.bottom_radius_m, atmosphere.top_radius_m);
    if (i == haze_index) {
      p.haze_scattering = c.scattering_per_m * density;
      p.haze_extinction = c.Extinction() * density;
      p.haze_g = c.phase.g;
      p.haze_zenith_optical_length = density > 0.0 ? column.VerticalColumn(altitude_m).value / density : 0.0;
    } else if (c.phase.kind == PhaseKind::kRayleigh || c.scattering_per_m == Spectrum(0.0)) {
      p.air_scattering += c.scattering_per_m * density;
      p.air_extinction += c.Extinction() * density;
      if (c.phase.kind == PhaseKind::kRayleigh && air_density == 0.0) {
        air_density = density;
        air_column = column.VerticalColumn(altitude_m).value;
      }
    }
  }
  p.air_zenith_optical_length = air_density > 0.0 ? air_column / air_density : 0.0;
  double r = atmosphere.bottom_radius_m + altitude_m;
  double ratio = atmosphere.bottom_radius_m / r;
  p.horizon_cos = -std::sqrt(std::max(1.0 - ratio * ratio, 0.0));
  return p;
}

}  // namespace

HoffmanPreethamModel::HoffmanPreethamModel(const Atmosphere& atmosphere,
                                           const std::vector<double>& camera_altitudes_m)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.bottom_radius_m = atmosphere.bottom_radius_m;
  int air = -1, haze = -1;
  for (int i = 0; i < static_cast<int>(atmosphere.constituents.size()); ++i) {
    const Constituent& c = atmosphere.constituents[i];
    if (c.scattering_per_m == Spectrum(0.0)) continue;
    if (c.phase.kind == PhaseKind::kRayleigh) {
      if (air < 0) air = i;
    } else if (haze < 0) {
      haze = i;
    }
  }
  if (air < 0) {
    m.unavailable_reason = "no Rayleigh constituent (air) to fit";
    return;
  }
  std::vector<std::string> names = {atmosphere.constituents[air].name};
  if (haze >= 0) names.push_back(atmosphere.constituents[haze].name);
  m.fits = fit::FitAtmosphere(atmosphere, names, fit::FitOptions{});
  for (const fit::ConstituentFit& f : m.fits.constituents) {
    if (!f.fitted) continue;
    if (f.name == atmosphere.constituents[air].name) m.air = &f.surface;
    if (haze >= 0 && f.name == atmosphere.constituents[haze].name) m.haze = &f.surface;
  }
  if (!m.air) {
    m.unavailable_reason = "the air's optical path could not be fitted";
    return;
  }
  m.altitude_max_m = m.fits.options.altitude_max_m;
  for (double h : camera_altitudes_m) {
    if (h <= m.altitude_max_m) m.frames[h] = FrameConstants(atmosphere, m.haze ? haze : -1, h);
  }
}

HoffmanPreethamModel::~HoffmanPreethamModel() = default;

bool HoffmanPreethamModel::available() const { return impl_->air != nullptr; }
const std::string& HoffmanPreethamModel::unavailable_reason() const { return impl_->unavailable_reason; }

ModelAnswer HoffmanPreethamModel::Evaluate(const ReferenceCase& c, long* fitted_path_evaluations) const {
  ModelAnswer a;
  auto frame = impl_->frames.find(c.query.altitude_m);
  if (!available() || frame == impl_->frames.end()) return a;  // from space: no dome
  const glsl::HoffmanPreethamParameters& p = frame->second;
  const double h = c.query.altitude_m;
  auto relative_paths = [&](double mu, double* air, double* haze) {
    *air = impl_->air->RelativeOpticalPath(mu, h);
    *haze = impl_->haze ? impl_->haze->RelativeOpticalPath(mu, h) : 0.0;
    if (fitted_path_evaluations) *fitted_path_evaluations += impl_->haze ? 2 : 1;
  };
  QueryGeometry g = MakeQueryGeometry(c.query, impl_->bottom_radius_m);
  double sun_air, sun_haze;
  relative_paths(g.sun.z, &sun_air, &sun_haze);
  glsl::vec3 sun = glsl::HoffmanPreethamSunIrradiance(p, g.sun.z, sun_air, sun_haze);
  if (c.query.has_normal) {
    a.has_sun_irradiance = true;
    a.sun_irradiance = sun * std::max(glm::dot(g.normal, g.sun), 0.0);
    return a;
  }
  double view_air, view_haze;
  relative_paths(g.view.z, &view_air, &view_haze);
  double air_length = view_air * p.air_zenith_optical_length;
  double haze_length = view_haze * p.haze_zenith_optical_length;
  if (c.query.distance_m > 0.0) {
    air_length = std::min(air_length, c.query.distance_m);
    haze_length = std::min(haze_length, c.query.distance_m);
  }
  a.has_radiance = true;
  a.radiance = glsl::HoffmanPreethamSkyRadiance(p, air_length, haze_length, glm::dot(g.view, g.sun), sun);
  return a;
}

// ---------------------------------------------------------------------------

double MedianNanosecondsPerEvaluation(const ReferenceSet& reference, const Model& model, int passes) {
  if (passes < 1 || reference.cases.empty()) throw InternalError("timing needs at least one pass and one case");
  // Summing a value from every answer keeps the evaluations from being
  // optimized away.
  volatile double sink = 0.0;
  auto pass = [&] {
    double sum = 0.0;
    for (const ReferenceCase& c : reference.cases) {
      ModelAnswer a = model(c);
      sum += a.radiance.x + a.sun_irradiance.x + a.sky_irradiance.x;
    }
    sink = sink + sum;
  };
  pass();
  std::vector<double> nanoseconds;
  for (int i = 0; i < passes; ++i) {
    auto start = std::chrono::steady_clock::now();
    pass();
    auto end = std::chrono::steady_clock::now();
    nanoseconds.push_back(std::chrono::duration<double, std::nano>(end - start).count() / reference.cases.size());
  }
  std::sort(nanoseconds.begin(), nanoseconds.end());
  size_t n = nanoseconds.size();
  return n % 2 ? nanoseconds[n / 2] : 0.5 * (nanoseconds[n / 2 - 1] + nanoseconds[n / 2]);
}

}  // namespace skybake::report
