#include "bake/atmosphere.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/interpolation.h"
#include "shaders_runtime/primitives.h"

namespace skybake {

double DensityProfile::At(double altitude_m) const {
  if (kind == Kind::kTabulated) {
    return altitudes_m.empty() ? 0.0 : PiecewiseLinear(altitudes_m, densities, altitude_m);
  }
  double layer_base = 0.0;
  for (size_t i = 0; i < layers.size(); ++i) {
    const DensityLayer& layer = layers[i];
    bool last = i + 1 == layers.size();
    if (last || altitude_m < layer_base + layer.width_m) {
      double d = layer.exp_term * std::exp(layer.exp_scale_per_m * altitude_m) +
                 layer.linear_term_per_m * altitude_m + layer.constant_term;
      return std::clamp(d, 0.0, 1.0);
    }
    layer_base += layer.width_m;
  }
  return 0.0;
}

std::vector<double> DensityProfile::Breakpoints() const {
  if (kind == Kind::kTabulated) return altitudes_m;
  std::vector<double> result;
  double layer_base = 0.0;
  for (size_t i = 0; i < layers.size(); ++i) {
    const DensityLayer& layer = layers[i];
    bool last = i + 1 == layers.size();
    double layer_top = last ? std::numeric_limits<double>::infinity() : layer_base + layer.width_m;
    // The clamp to [0, 1] puts a kink where a linear layer crosses 0 or 1.
    if (layer.exp_term == 0.0 && layer.linear_term_per_m != 0.0) {
      for (double level : {0.0, 1.0}) {
        double h = (level - layer.constant_term) / layer.linear_term_per_m;
        if (h > layer_base && h < layer_top) result.push_back(h);
      }
    }
    if (!last) result.push_back(layer_top);
    layer_base = layer_top;
  }
  std::sort(result.begin(), result.end());
  // Coefficients written in decimal put one corner at, e.g., 25000 and
  // 24999.999999999996; report it once.
  auto same = [](double a, double b) { return std::abs(a - b) <= 1e-6 * std::max(1.0, std::abs(a)); };
  result.erase(std::unique(result.begin(), result.end(), same), result.end());
  return result;
}

double PhaseFunction::Evaluate(double cos_theta) const {
  switch (kind) {
    case PhaseKind::kIsotropic: return glsl::IsotropicPhaseFunction();
    case PhaseKind::kRayleigh: return glsl::RayleighPhaseFunction(cos_theta);
    case PhaseKind::kHenyeyGreenstein: return glsl::HenyeyGreensteinPhaseFunction(g, cos_theta);
    case PhaseKind::kCornetteShanks: return glsl::CornetteShanksPhaseFunction(g, cos_theta);
  }
  return 0.0;
}

const char* ToString(PhaseKind kind) {
  switch (kind) {
    case PhaseKind::kIsotropic: return "isotropic";
    case PhaseKind::kRayleigh: return "rayleigh";
    case PhaseKind::kHenyeyGreenstein: return "henyey-greenstein";
    case PhaseKind::kCornetteShanks: return "cornette-shanks";
  }
  return "unknown";
}

Spectrum Atmosphere::ScatteringAt(double altitude_m) const {
  Spectrum sum(0.0);
  for (const Constituent& c : constituents) sum += c.scattering_per_m * c.density.At(altitude_m);
  return sum;
}

Spectrum Atmosphere::ExtinctionAt(double altitude_m) const {
  Spectrum sum(0.0);
  for (const Constituent& c : constituents) sum += c.Extinction() * c.density.At(altitude_m);
  return sum;
}

}  // namespace skybake
