// The run-time models `skybake report` sets side by side, as Models over the
// reference cases (case_errors.h), and what one evaluation of each costs:
//   - the table lookup: the CPU twin of the GLSL runtime (shaders_runtime/twin.h);
//   - Hoffman & Preetham's analytic model (shaders_runtime/hoffman_preetham.h)
//     with the relative optical paths of the sky-dome fit (fit/);
//   - the single-scattering ray march (ray_march.h).
#pragma once

#include <memory>
#include <vector>

#include "bake/bake.h"
#include "report/case_errors.h"
#include "report/ray_march.h"
#include "shaders_runtime/twin.h"

namespace skybake::report {

// Sky radiance (to the point for aerial perspective), or for a case with a
// normal sun and sky irradiance, from the tables.
ModelAnswer EvaluateTwin(const Twin& twin, const ReferenceCase& c);
// The number of texture() calls the same evaluation makes, counted by
// running the runtime's source once more with counting samplers.
long CountTwinTextureCalls(const LutSet& luts, const ReferenceCase& c);

// Sky radiance and sun irradiance; no sky irradiance (the march has no
// multiple scattering to light the sky).
ModelAnswer EvaluateRayMarch(const SingleScatteringRayMarch& march, double bottom_radius_m, const ReferenceCase& c,
                             long* density_samples = nullptr);

// Hoffman & Preetham with constants per camera altitude (the per-frame work:
// coefficients and zenith optical lengths at the camera) prepared up front,
// and per pixel the fitted relative optical paths of air and haze toward the
// view and the sun. It answers sky radiance and sun irradiance for cameras
// inside the fitted altitude range (0-10 km), nothing from space and no sky
// irradiance. Rays below the horizon get the horizon's optical length (the
// dome has no ground).
class HoffmanPreethamModel {
 public:
  // Fits the atmosphere's first Rayleigh constituent (air) and first other
  // scatterer (haze). `available()` is false, with a reason, when there is
  // no air to fit.
  HoffmanPreethamModel(const Atmosphere& atmosphere, const std::vector<double>& camera_altitudes_m);
  ~HoffmanPreethamModel();
  bool available() const;
  const std::string& unavailable_reason() const;
  // `fitted_path_evaluations`, if given, is increased by the number of
  // fitted-surface evaluations (the generated skybake_relative_optical_path_*).
  ModelAnswer Evaluate(const ReferenceCase& c, long* fitted_path_evaluations = nullptr) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Median over `passes` passes through every case of the wall time of one
// evaluation (nanoseconds), after one untimed pass.
double MedianNanosecondsPerEvaluation(const ReferenceSet& reference, const Model& model, int passes);

}  // namespace skybake::report
